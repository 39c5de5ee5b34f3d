"""Our standard and improved PSO on the classic benchmarks (D = 5, 30 particles, 200
iterations, 20 seeds) next to pyswarms' GlobalBestPSO with the same budget.

The optima are known (0 for all three); the tolerances say what a PSO of this budget
is expected to reach: the sphere solved to 1e-8, Rosenbrock at least into the basin of
its minima (the local minimum near x1 = -1 is 3.93, so below 4), Rastrigin within a few
of its unit-spaced local minima. The side-by-side table is printed (pytest -s).
"""

import logging
import statistics

import numpy as np

SEEDS, SWARM, ITERATIONS = 20, 30, 200

FUNCTIONS = {
    "sphere": (lambda x: (x**2).sum(axis=1), 5.12),
    "rosenbrock": (lambda x: (100 * (x[:, 1:] - x[:, :-1] ** 2) ** 2 + (1 - x[:, :-1]) ** 2).sum(axis=1), 5.0),
    "rastrigin": (lambda x: 10 * x.shape[1] + (x**2 - 10 * np.cos(2 * np.pi * x)).sum(axis=1), 5.12),
}

TOLERANCE = {"sphere": 1e-8, "rosenbrock": 4.0, "rastrigin": 10.0}


def pyswarms_runs(f, bound):
    import pyswarms as ps  # imported late: it creates report.log in the working directory

    logging.disable(logging.CRITICAL)  # pyswarms logs every run
    finals = []
    for seed in range(SEEDS):
        np.random.seed(seed)
        optimizer = ps.single.GlobalBestPSO(
            n_particles=SWARM, dimensions=5,
            options={"c1": 1.49445, "c2": 1.49445, "w": 0.729},  # Clerc's constriction values
            bounds=(np.full(5, -bound), np.full(5, bound)))
        cost, _ = optimizer.optimize(f, iters=ITERATIONS, verbose=False)
        finals.append(cost)
    logging.disable(logging.NOTSET)
    return finals


def summary(values):
    return f"{statistics.mean(values):10.3g} ± {statistics.pstdev(values):8.2g} (max {max(values):8.3g})"


def test_pso_reaches_the_known_optima_and_stands_next_to_pyswarms(rust_json, capsys, monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)  # pyswarms writes report.log into the working directory
    ours = rust_json("pso_benchmarks", SEEDS, SWARM, ITERATIONS)
    lines = [f"{'function':11} {'standard PSO (ours)':>38} {'improved PSO (ours)':>38} {'pyswarms GlobalBestPSO':>38}"]
    for name, (f, bound) in FUNCTIONS.items():
        reference = pyswarms_runs(f, bound)
        standard, improved = ours[name]["standard"], ours[name]["improved"]
        assert len(standard) == len(improved) == SEEDS
        lines.append(f"{name:11} {summary(standard):>38} {summary(improved):>38} {summary(reference):>38}")
        for runs in (standard, improved):
            assert max(runs) < TOLERANCE[name], (name, runs)
        # The reference itself behaves as expected with this budget.
        assert max(reference) < TOLERANCE[name]
    # The improved schedule converges faster on the unimodal sphere.
    assert statistics.median(ours["sphere"]["improved"]) < statistics.median(ours["sphere"]["standard"])
    with capsys.disabled():
        print("\nPSO benchmarks, D = 5, 30 particles x 200 iterations, mean ± spread over 20 seeds")
        print("\n".join(lines))
