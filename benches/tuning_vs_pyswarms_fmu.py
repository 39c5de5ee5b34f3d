"""Tuning speed and result: `ccc-tune` (improved PSO) at the paper's full budget (m = 50,
T = 100, D = 5) on the 2 s circle at Ts = 1 ms, against pyswarms' GlobalBestPSO driving
the FMUs (PathInterpolator2D -> ContourCCC2D <- XYServoPlant) through fmpy with the same
objective (mean |true contour error|), timed on a reduced budget and scaled up to the
same 5000 evaluations. Prints both wall times and their ratio (target >= 100).

Result quality at the same number of evaluations: ccc-tune also runs the reduced budget
(particles x iterations), and the best factors of both optimisers are scored by the same
fmpy closed loop; the ratio pyswarms / ours > 1 means ours found the better factors.

Run from the repository root after `make fmus` and building ccc-tune (`make bench` does both):
    .venv/bin/python benches/tuning_vs_pyswarms_fmu.py [--particles 4] [--iters 2] [--json FILE]
"""

import argparse
import json
import logging
import os
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from contour_fmu import repo
from contour_fmu.engines.master import closed_loop
from contour_fmu.checks.reference_paths import ContourReference

# The default search box of ccc-tune (contour-tune/src/objective.rs, docs/design/two-axis.md §4.4).
SWARM, ITERATIONS, LOWER, UPPER = 50, 100, [0.0] * 5, [10.0, 10.0, 340.0, 6800.0, 3.8]
FACTORS = ("ke", "kde", "kp", "ki", "kd")


def ccc_tune(swarm, iterations, scratch):
    """Wall time (s) of one ccc-tune run and the factors it found."""
    out = Path(scratch) / f"tuned-{swarm}x{iterations}.json"
    start = time.perf_counter()
    subprocess.run([str(repo.ccc_tune()), "--path", "circle", "--swarm", str(swarm),
                    "--iters", str(iterations), "--fitness", "mean", "--out", str(out)],
                   check=True, stderr=subprocess.DEVNULL)
    seconds = time.perf_counter() - start
    factors = json.loads(out.read_text())["factors"]
    return seconds, [factors[name] for name in FACTORS]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--particles", type=int, default=4)
    parser.add_argument("--iters", type=int, default=2)
    parser.add_argument("--json", type=Path, help="also write the figures to this file")
    args = parser.parse_args()
    json_path = args.json.resolve() if args.json else None  # before the chdir below

    with tempfile.TemporaryDirectory() as tmp:
        ours, _ = ccc_tune(SWARM, ITERATIONS, tmp)
        ours_small, ours_small_factors = ccc_tune(args.particles, args.iters, tmp)

    circle = ContourReference("circle")
    fmu_dir = repo.fmu_dir()

    def cost(positions):
        out = []
        for ke, kde, kp, ki, kd in positions:
            before, _ = closed_loop(fmu_dir, controller={"fuzzy.ke": ke, "fuzzy.kde": kde, "fuzzy.kp": kp,
                                                        "fuzzy.ki": ki, "fuzzy.kd": kd})
            out.append(circle.distance(np.column_stack([before["plant.pos.x"], before["plant.pos.y"]])).mean())
        return np.array(out)

    logging.disable(logging.CRITICAL)
    os.chdir(tempfile.mkdtemp())  # pyswarms writes report.log into the working directory
    import pyswarms as ps
    np.random.seed(1)  # pyswarms draws from numpy's global generator
    optimizer = ps.single.GlobalBestPSO(n_particles=args.particles, dimensions=5,
                                        options={"c1": 1.49445, "c2": 1.49445, "w": 0.729},
                                        bounds=(np.array(LOWER), np.array(UPPER)))
    start = time.perf_counter()
    theirs_best, _ = optimizer.optimize(cost, iters=args.iters, verbose=False)
    measured = time.perf_counter() - start
    evaluations = args.particles * args.iters
    scaled = measured * (SWARM * ITERATIONS) / evaluations
    ours_best = float(cost([ours_small_factors])[0])

    print(f"ccc-tune, {SWARM} x {ITERATIONS} evaluations on the 2 s circle: {ours:.2f} s (target <= 5 s)")
    print(f"pyswarms + fmpy FMUs: {measured:.2f} s for {evaluations} evaluations, "
          f"{scaled:.0f} s scaled to {SWARM * ITERATIONS}")
    print(f"ratio: {scaled / ours:.0f}x (target >= 100x)")
    print(f"best mean |contour error| after {evaluations} evaluations, scored through fmpy: "
          f"ccc-tune {ours_best * 1e3:.3f} um ({ours_small:.2f} s), pyswarms {theirs_best * 1e3:.3f} um "
          f"-> pyswarms / ours {theirs_best / ours_best:.3f}")
    if json_path:
        json_path.parent.mkdir(parents=True, exist_ok=True)
        json_path.write_text(json.dumps({
            "evaluations_full": SWARM * ITERATIONS,
            "ccc_tune_full_s": ours,
            "pyswarms_evaluations": evaluations,
            "pyswarms_s": measured,
            "pyswarms_scaled_s": scaled,
            "wall_ratio": scaled / ours,
            "ccc_tune_small_s": ours_small,
            "ccc_tune_small_best_mm": ours_best,
            "pyswarms_best_mm": float(theirs_best),
            "quality_ratio": float(theirs_best) / ours_best,
        }, indent=2) + "\n")


if __name__ == "__main__":
    main()
