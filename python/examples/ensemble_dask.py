"""A parameter study of the slider-crank: the spring's stiffness swept on a Dask cluster (a
local one here; pass the address of a real scheduler to use it instead).

    python python/examples/ensemble_dask.py [--scheduler tcp://host:8786] [--plot out.png]
"""

import argparse
from pathlib import Path

import numpy as np

import mbd

MODELS = Path(__file__).resolve().parents[2] / "examples" / "models"
# Dask's worker processes import this file again: the work runs only as a script
def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--scheduler", help="a running Dask scheduler's address")
    ap.add_argument("--plot", help="save a figure of the slider's travel (needs matplotlib)")
    args = ap.parse_args()

    from distributed import Client, LocalCluster

    client = Client(args.scheduler) if args.scheduler else Client(LocalCluster(n_workers=2))
    model = mbd.Model.from_file(MODELS / "slider_crank_spring.toml")
    k = np.linspace(50.0, 400.0, 8)
    ens = mbd.ensemble(model, "symplectic:2", t_end=2.0, h=1e-3, every=10,
                       stiffness={"return_spring": list(k)}, client=client)
    print(ens.summary())
    for r in ens.results():
        x = r["slider.x"]
        print(f"k = {r.parameters['stiffness']['return_spring']:6.1f} N/m: slider travel "
              f"{x.min():.4f} .. {x.max():.4f} m")
    if args.plot:
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots()
        for r in ens.results():
            ax.plot(r.t, r["slider.x"], label=f"k = {r.parameters['stiffness']['return_spring']:.0f}")
        ax.set(xlabel="t [s]", ylabel="slider.x [m]")
        ax.legend(fontsize="small")
        fig.savefig(args.plot)
    client.close()


if __name__ == "__main__":
    main()
