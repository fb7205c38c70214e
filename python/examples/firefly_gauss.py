"""Paper C: the firefly-Gauss solver, seeded and deterministic; an ensemble of seeds shows the
spread of its swarm's answers (local threads, or a Dask cluster with --dask N).

    python python/examples/firefly_gauss.py [--dask 2]
"""

import argparse
from pathlib import Path

import numpy as np

import mbd

MODELS = Path(__file__).resolve().parents[2] / "examples" / "models"
# Dask's worker processes import this file again: the work runs only as a script
def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--dask", type=int, default=0, help="run on a local Dask cluster of N workers")
    args = ap.parse_args()

    model = mbd.Model.from_file(MODELS / "pendulum.toml")
    one = model.run("firefly-gauss:polish", t_end=0.1, h=1e-2)
    print(f"firefly-gauss:polish: {one.stats.steps} steps, e(H) = {one.stats.e_h:.2e}")

    client = None
    if args.dask:
        from distributed import Client, LocalCluster

        client = Client(LocalCluster(n_workers=args.dask, threads_per_worker=1))
    # the same model four times: each member gets its own seed from the root seed 7
    ens = mbd.ensemble(model, "firefly-gauss", t_end=0.1, h=1e-2, seed=7,
                       gravity=[[0.0, -9.81]] * 4, client=client)
    print(ens.summary())
    finals = np.array([r.q[-1, 2] for r in ens.results()])
    print(f"final angle over the seeds: mean {finals.mean():.6f} rad, spread {np.ptp(finals):.1e}")
    if client is not None:
        client.close()


if __name__ == "__main__":
    main()
