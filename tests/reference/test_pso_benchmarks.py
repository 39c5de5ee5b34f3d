"""Our standard and improved PSO on the classic benchmarks (D = 5, 30 particles, 200
iterations, 20 seeds), whose optima are known (0 for all three).

The tolerances say what a PSO of this budget must reach: the sphere solved to 1e-8,
Rosenbrock at least into the basin of its minima (the local minimum near x1 = -1 is
3.93, so below 4), Rastrigin within a few of its unit-spaced local minima. pyswarms'
GlobalBestPSO meets the same tolerances with the same budget; the side-by-side table and
the improved-vs-standard comparison are benchmarks, not tests (`benches/pso_tables.py`).
"""

import numpy as np
import pytest
from contour_fmu.repo import TUNER_PACKAGE

SEEDS, SWARM, ITERATIONS = 20, 30, 200

# Known optimum 0 at the origin (sphere, Rastrigin) or at (1, ..., 1) (Rosenbrock).
FUNCTIONS = {
    "sphere": lambda x: float((x**2).sum()),
    "rosenbrock": lambda x: float((100 * (x[1:] - x[:-1] ** 2) ** 2 + (1 - x[:-1]) ** 2).sum()),
    "rastrigin": lambda x: float(10 * len(x) + (x**2 - 10 * np.cos(2 * np.pi * x)).sum()),
}
TOLERANCE = {"sphere": 1e-8, "rosenbrock": 4.0, "rastrigin": 10.0}


@pytest.mark.parametrize("name", FUNCTIONS)
def test_pso_reaches_the_known_optima(rust_json, name):
    ours = rust_json("pso_benchmarks", SEEDS, SWARM, ITERATIONS, package=TUNER_PACKAGE)[name]
    f = FUNCTIONS[name]
    for algorithm in ("standard", "improved"):
        runs = ours[algorithm]
        assert len(runs) == SEEDS
        assert max(r["fitness"] for r in runs) < TOLERANCE[name], (name, algorithm, runs)
        # The reported fitness is the function at the reported position (recomputed here).
        for r in runs:
            assert f(np.array(r["best"])) == pytest.approx(r["fitness"], rel=1e-9, abs=1e-300)
