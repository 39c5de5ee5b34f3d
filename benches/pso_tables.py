"""PSO comparisons that are measurements, not requirements (printed, never asserted):

1. our standard and improved PSO on the classic benchmarks (D = 5, 30 particles,
   200 iterations, 20 seeds) next to pyswarms' GlobalBestPSO with the same budget;
2. the paper's claim, improved vs standard PSO on the contour-tuning objective, at a
   reduced budget (m = 20, T = 20, 10 seeds; the full budget is `make pso-claim`).

Run from the repository root: .venv/bin/python benches/pso_tables.py [--json FILE]
"""

import argparse
import json
import logging
import os
import statistics
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from contour_fmu.repo import TUNER_PACKAGE

REPO = Path(__file__).resolve().parents[1]
SEEDS, SWARM, ITERATIONS = 20, 30, 200
BOUNDS = {"sphere": 5.12, "rosenbrock": 5.0, "rastrigin": 5.12}
FUNCTIONS = {
    "sphere": lambda x: (x**2).sum(axis=1),
    "rosenbrock": lambda x: (100 * (x[:, 1:] - x[:, :-1] ** 2) ** 2 + (1 - x[:, :-1]) ** 2).sum(axis=1),
    "rastrigin": lambda x: 10 * x.shape[1] + (x**2 - 10 * np.cos(2 * np.pi * x)).sum(axis=1),
}


def example(name, *args):
    done = subprocess.run(["cargo", "run", "--quiet", "--release", "-p", TUNER_PACKAGE, "--example", name, "--",
                           *map(str, args)], cwd=REPO, check=True, capture_output=True, text=True)
    return json.loads(done.stdout)


def pyswarms_runs(f, bound):
    cwd = os.getcwd()
    with tempfile.TemporaryDirectory() as scratch:
        os.chdir(scratch)  # pyswarms writes report.log into the working directory
        try:
            import pyswarms as ps

            logging.disable(logging.CRITICAL)
            finals = []
            for seed in range(SEEDS):
                np.random.seed(seed)
                optimizer = ps.single.GlobalBestPSO(
                    n_particles=SWARM, dimensions=5,
                    options={"c1": 1.49445, "c2": 1.49445, "w": 0.729},  # Clerc's constriction
                    bounds=(np.full(5, -bound), np.full(5, bound)))
                cost, _ = optimizer.optimize(f, iters=ITERATIONS, verbose=False)
                finals.append(cost)
            logging.disable(logging.NOTSET)
            return finals
        finally:
            os.chdir(cwd)


def summary(values):
    return f"{statistics.mean(values):10.3g} ± {statistics.pstdev(values):8.2g} (max {max(values):8.3g})"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path, help="also write the mean final fitness values to this file")
    args = parser.parse_args()
    figures = {"benchmarks": {}, "claim": {}}

    ours = example("pso_benchmarks", SEEDS, SWARM, ITERATIONS)
    print(f"PSO benchmarks, D = 5, {SWARM} particles x {ITERATIONS} iterations, mean ± spread over {SEEDS} seeds")
    print(f"{'function':11} {'standard PSO (ours)':>38} {'improved PSO (ours)':>38} {'pyswarms GlobalBestPSO':>38}")
    for name, f in FUNCTIONS.items():
        standard = [r["fitness"] for r in ours[name]["standard"]]
        improved = [r["fitness"] for r in ours[name]["improved"]]
        reference = pyswarms_runs(f, BOUNDS[name])
        print(f"{name:11} {summary(standard):>38} {summary(improved):>38} {summary(reference):>38}")
        figures["benchmarks"][name] = {"standard": statistics.mean(standard), "improved": statistics.mean(improved),
                                       "pyswarms": statistics.mean(reference)}

    claim = example("pso_claim", 10, 20, 20, "json")
    print("\nPSO claim at m = 20, T = 20 (mean final fitness over 10 seeds)")
    for case, runs in claim.items():
        wins = sum(i < s for i, s in zip(runs["improved"], runs["standard"]))
        print(f"{case:14} standard {statistics.mean(runs['standard']):8.4f} um  "
              f"improved {statistics.mean(runs['improved']):8.4f} um  "
              f"paper {runs['paper']:8.4f} um  improved better on {wins}/10 seeds")
        figures["claim"][case] = {"standard": statistics.mean(runs["standard"]),
                                  "improved": statistics.mean(runs["improved"]), "wins": wins,
                                  "seeds": len(runs["improved"])}
    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(figures, indent=2) + "\n")


if __name__ == "__main__":
    main()
