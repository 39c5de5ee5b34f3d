"""The demo's ballbar test (contour_fmu.demo.ballbar): the circular test of ISO 230-4 on
XYServoPlant with friction through the FMUs. Its figures come from contour-eval; here
they are recomputed from the runs' CSVs by the standard's definitions (scipy's
least_squares for the least-squares circle), and the controllers must rank as a machine
tool engineer expects: the CCC shrinks the circular deviation, feed-forward more, and
the CCC on top of feed-forward (the shipped loop) keeps it."""

import subprocess

import numpy as np
import pytest
from scipy.optimize import least_squares

from contour_fmu.demo import ballbar as ballbar_demo
from helpers.checkout import REPO


@pytest.fixture(scope="module")
def results(fmu_dir, tmp_path_factory):
    done = subprocess.run(["cargo", "build", "--quiet", "--release", "-p", "contour-eval"],
                          cwd=REPO, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    out = tmp_path_factory.mktemp("ballbar")
    return ballbar_demo.ballbar_demo(fmu_dir, out), out


def circular_deviation(points):
    """G about the least-squares circle (um)."""
    def residuals(x):
        return np.hypot(points[:, 0] - x[0], points[:, 1] - x[1]) - x[2]
    cx, cy, _ = least_squares(residuals, x0=[0.0, 0.0, ballbar_demo.RADIUS], xtol=1e-15,
                              ftol=1e-15, gtol=1e-15).x
    d = np.hypot(points[:, 0] - cx, points[:, 1] - cy)
    return (d.max() - d.min()) * 1e3


def test_the_figures_are_the_standards_and_rank_the_controllers(results):
    figures, out = results
    ballbar_demo.print_table(figures)
    for label in figures:
        name = ballbar_demo.file_name(label)
        assert (out / f"ballbar_{name}.png").stat().st_size > 10_000
        for index, direction in enumerate(("ccw", "cw")):
            run = np.genfromtxt(out / f"ballbar_{name}_{direction}.csv", delimiter=",", names=True)
            start, end = figures[label]["window"]
            on = (run["time"] >= start) & (run["time"] <= end)
            points = np.column_stack([run["X"][on], run["Y"][on]])
            assert abs(figures[label]["G"][index] - circular_deviation(points)) < 1e-3
    g = {label: f["Gb"] for label, f in figures.items()}
    assert g["fuzzy CCC"] < 0.6 * g["no CCC"]
    # Feed-forward takes the lag but not the friction's quadrant glitch; the CCC on top
    # (the shipped loop) takes most of that.
    assert g["feed-forward"] < 0.5 * g["no CCC"]
    assert g["fuzzy CCC + feed-forward (shipped)"] < 0.5 * min(g["fuzzy CCC"], g["feed-forward"])
