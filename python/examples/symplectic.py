"""Paper A: the symplectic Galerkin integrators keep the energy of a conservative model
bounded; their order shows when the step is halved.

    python python/examples/symplectic.py [--plot out.png]
"""

import argparse
from pathlib import Path

import mbd

MODELS = Path(__file__).resolve().parents[2] / "examples" / "models"

ap = argparse.ArgumentParser(description=__doc__)
ap.add_argument("--plot", help="save a figure of the energy error (needs matplotlib)")
args = ap.parse_args()

model = mbd.Model.from_file(MODELS / "pendulum.toml")
results = {}
for solver in ("symplectic:1", "symplectic:2"):
    for h in (0.02, 0.01):
        r = model.run(solver, t_end=5.0, h=h)
        results[solver, h] = r
        print(f"{solver:13s} h = {h:<5} e(H) = {r.stats.e_h:.3e}")

if args.plot:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    for (solver, h), r in results.items():
        ax.semilogy(r.t, abs(r.H - r.H[0]) / abs(r.H[0]) + 1e-17, label=f"{solver}, h = {h}")
    ax.set(xlabel="t [s]", ylabel="|H - H0| / |H0|", title="pendulum: energy error")
    ax.legend()
    fig.savefig(args.plot)
