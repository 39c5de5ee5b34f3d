"""Tuning speed: `ccc-tune` at the paper's full budget (m = 50, T = 100, D = 5) on the
2 s circle at Ts = 1 ms, against pyswarms' GlobalBestPSO driving the FMUs
(PathInterpolator2D -> ContourCCC2D <- XYServoPlant) through fmpy with the same
objective (mean |true contour error|), timed on a reduced budget and scaled up to the
same 5000 evaluations. Prints both wall times and their ratio (target >= 100).

Run from the repository root after `make fmus` and building ccc-tune (`make bench` does both):
    .venv/bin/python benches/tuning_vs_pyswarms_fmu.py [--particles 4] [--iters 2]
"""

import argparse
import logging
import os
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from contour_fmu.master import closed_loop
from contour_fmu.reference_paths import ContourReference

REPO = Path(__file__).resolve().parents[1]

# The default search box of ccc-tune (tuner/src/objective.rs, docs/design.md §4.4).
SWARM, ITERATIONS, LOWER, UPPER = 50, 100, [0.0] * 5, [10.0, 10.0, 340.0, 6800.0, 3.8]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--particles", type=int, default=4)
    parser.add_argument("--iters", type=int, default=2)
    args = parser.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        subprocess.run([str(REPO / "target" / "release" / "ccc-tune"), "--path", "circle",
                        "--swarm", str(SWARM), "--iters", str(ITERATIONS), "--fitness", "mean",
                        "--out", str(Path(tmp) / "tuned.json")], check=True, stderr=subprocess.DEVNULL)
        ours = time.perf_counter() - start

    circle = ContourReference("circle")
    fmu_dir = REPO / "target" / "fmu"

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
    optimizer = ps.single.GlobalBestPSO(n_particles=args.particles, dimensions=5,
                                        options={"c1": 1.49445, "c2": 1.49445, "w": 0.729},
                                        bounds=(np.array(LOWER), np.array(UPPER)))
    start = time.perf_counter()
    optimizer.optimize(cost, iters=args.iters, verbose=False)
    measured = time.perf_counter() - start
    evaluations = args.particles * args.iters
    scaled = measured * (SWARM * ITERATIONS) / evaluations

    print(f"ccc-tune, {SWARM} x {ITERATIONS} evaluations on the 2 s circle: {ours:.2f} s (target <= 5 s)")
    print(f"pyswarms + fmpy FMUs: {measured:.2f} s for {evaluations} evaluations, "
          f"{scaled:.0f} s scaled to {SWARM * ITERATIONS}")
    print(f"ratio: {scaled / ours:.0f}x (target >= 100x)")


if __name__ == "__main__":
    main()
