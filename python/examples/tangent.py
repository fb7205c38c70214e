"""Paper B: Runge-Kutta on the state equations of a tangent-space chart, with fixed steps
(tangent:rk4) or adaptive ones (tangent:dopri5 with tol); the constraints stay at round-off.

    python python/examples/tangent.py [--plot out.png]
"""

import argparse
from pathlib import Path

import mbd

MODELS = Path(__file__).resolve().parents[2] / "examples" / "models"

ap = argparse.ArgumentParser(description=__doc__)
ap.add_argument("--plot", help="save a figure of the manipulator's joint angles (needs matplotlib)")
args = ap.parse_args()

model = mbd.Model.from_file(MODELS / "manipulator.json")
fixed = model.run("tangent:rk4", t_end=3.0, h=1e-3, every=10)
adaptive = model.run("tangent:dopri5", t_end=3.0, tol=1e-8)
for name, r in (("tangent:rk4", fixed), ("tangent:dopri5", adaptive)):
    s = r.stats
    print(f"{name:15s} {s.steps} steps ({s.rejected} rejected), e(Phi) = {s.e_phi:.1e}, "
          f"h in [{s.min_step:.1e}, {s.max_step:.1e}]")

if args.plot:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    for c in [c for c in model.coordinates if c.endswith(".theta")]:
        ax.plot(fixed.t, fixed[c], label=c)
        ax.plot(adaptive.t, adaptive[c], "k.", ms=2)
    ax.set(xlabel="t [s]", ylabel="angle [rad]", title="manipulator (dots: adaptive steps)")
    ax.legend()
    fig.savefig(args.plot)
