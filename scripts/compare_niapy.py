#!/usr/bin/env python3
"""Side-by-side comparison of mbd-firefly with NiaPy's FireflyAlgorithm.

Not part of CI. Needs a Rust toolchain and, for the NiaPy columns,
``pip install niapy`` (without it only mbd-firefly's numbers are printed).

Both optimisers get the same functions, domains, dimensions, seeds count,
population, alpha, alpha decay and *evaluation budget*. The budget is the
fair unit: NiaPy (like mbd-firefly's ``classic`` variant) evaluates after every
move, i.e. up to n^2 evaluations per generation, while the ``snapshot``
variant evaluates each firefly once per generation.

Distances: NiaPy measures r in raw coordinates, mbd-firefly (by default) in
box-normalised ones. With ``--niapy-gamma scaled`` (default) NiaPy gets
``gamma / width^2`` per function, which is the same attractiveness law;
pass a number to use it verbatim.

Example::

    python3 scripts/compare_niapy.py --seeds 5 --evaluations 36060 \
        --variants snapshot,classic
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from collections import defaultdict

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

NIAPY_PROBLEMS = {
    "sphere": "Sphere",
    "rosenbrock": "Rosenbrock",
    "rastrigin": "Rastrigin",
    "ackley": "Ackley",
    "griewank": "Griewank",
}


def parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--functions", default=",".join(NIAPY_PROBLEMS))
    p.add_argument("--dims", default="2,10")
    p.add_argument("--seeds", type=int, default=20, help="number of seeds, 0..N-1")
    p.add_argument("--evaluations", type=int, default=36060, help="evaluation budget per run")
    p.add_argument("--population", type=int, default=60)
    p.add_argument("--alpha", type=float, default=0.2)
    p.add_argument("--decay", type=float, default=0.98, help="alpha decay per generation (NiaPy: theta)")
    p.add_argument("--beta0", type=float, default=1.0)
    p.add_argument("--gamma", type=float, default=1.0, help="mbd-firefly gamma (normalised distances)")
    p.add_argument("--niapy-gamma", default="scaled", help="'scaled' (gamma / width^2) or a number")
    p.add_argument("--variants", default="snapshot,classic", help="mbd-firefly variants to run")
    p.add_argument("--no-niapy", action="store_true", help="skip NiaPy")
    return p.parse_args()


def run_ours(args: argparse.Namespace, variant: str) -> dict:
    """Runs the crate's example binary and returns {(function, dim): [best_f, ...]}, domains."""
    cmd = [
        "cargo", "run", "--quiet", "--release", "-p", "mbd-firefly",
        "--example", "benchmark_functions", "--",
        "--functions", args.functions,
        "--dims", args.dims,
        "--seeds", f"0-{args.seeds - 1}",
        "--evaluations", str(args.evaluations),
        "--generations", str(10**9),
        "--population", str(args.population),
        "--alpha", str(args.alpha),
        "--decay", str(args.decay),
        "--beta0", str(args.beta0),
        "--gamma", str(args.gamma),
        "--variant", variant,
    ]
    out = subprocess.run(cmd, cwd=REPO, check=True, capture_output=True, text=True)
    doc = json.loads(out.stdout)
    finals: dict = defaultdict(list)
    domains = {}
    for r in doc["runs"]:
        key = (r["function"], r["dim"])
        finals[key].append(r["best_f"])
        domains[r["function"]] = (r["lo"], r["hi"])
    return {"finals": finals, "domains": domains}


def run_niapy(args: argparse.Namespace, domains: dict) -> dict | None:
    try:
        from niapy.algorithms.basic import FireflyAlgorithm
        from niapy import problems
        from niapy.task import Task
    except ImportError:
        print("niapy not installed (pip install niapy): NiaPy columns skipped", file=sys.stderr)
        return None
    finals: dict = defaultdict(list)
    for name in args.functions.split(","):
        lo, hi = domains[name]
        width = hi - lo
        if args.niapy_gamma == "scaled":
            gamma = args.gamma / (width * width)
        else:
            gamma = float(args.niapy_gamma)
        for d in (int(x) for x in args.dims.split(",")):
            for seed in range(args.seeds):
                problem = getattr(problems, NIAPY_PROBLEMS[name])(dimension=d, lower=lo, upper=hi)
                task = Task(problem=problem, max_evals=args.evaluations)
                algo = FireflyAlgorithm(
                    population_size=args.population,
                    alpha=args.alpha,
                    beta0=args.beta0,
                    gamma=gamma,
                    theta=args.decay,
                    seed=seed,
                )
                _, best_f = algo.run(task)
                finals[(name, d)].append(float(best_f))
            print(f"niapy {name} d={d} done", file=sys.stderr)
    return finals


def summary(values: list) -> str:
    if not values:
        return f"{'-':>21}"
    return f"{statistics.median(values):>10.3e} {max(values):>10.3e}"


def main() -> int:
    args = parse_args()
    variants = [v for v in args.variants.split(",") if v]
    ours = {}
    domains = {}
    for v in variants:
        res = run_ours(args, v)
        ours[v] = res["finals"]
        domains = res["domains"]
    niapy = None if args.no_niapy else run_niapy(args, domains)

    columns = [f"mbd-firefly {v}" for v in variants] + (["NiaPy FA"] if niapy is not None else [])
    print(
        f"budget {args.evaluations} evaluations, population {args.population}, alpha {args.alpha}, "
        f"decay {args.decay}, beta0 {args.beta0}, gamma {args.gamma} (normalised), "
        f"{args.seeds} seeds; each cell: median worst"
    )
    header = f"{'function':<11} {'d':>3} " + " ".join(f"{c:>21}" for c in columns)
    print(header)
    print("-" * len(header))
    for name in args.functions.split(","):
        for d in (int(x) for x in args.dims.split(",")):
            cells = [summary(ours[v].get((name, d), [])) for v in variants]
            if niapy is not None:
                cells.append(summary(niapy.get((name, d), [])))
            print(f"{name:<11} {d:>3} " + " ".join(cells))
    return 0


if __name__ == "__main__":
    sys.exit(main())
