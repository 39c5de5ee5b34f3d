"""`contour-eval --circle` (the ISO 230-4 circular test) against the standard's
definitions computed here, on synthetic clockwise and counter-clockwise traces whose
centre, radius and deviations are known by construction.

Each trace: a lead-in, the circle, a lead-out (outside --from/--to), on the circle of
radius R about a centre offset from the nominal one, its radius carrying an oval term
(two axes of unequal gain) and quadrant glitches (a reversal spike at 0, 90, 180, 270
degrees, as friction makes), different in each direction. Test side: the least-squares
circle by scipy's least_squares on the geometric residuals |p - c| - R, then
G = max |p - c| - min |p - c| about it, F about the nominal circle, and G(b) about the
LSC of both traces together.
"""

import json
import math
import os
import re
import subprocess

import numpy as np
import pytest
from scipy.optimize import least_squares

REPO = __import__("pathlib").Path(__file__).resolve().parents[2]

NOMINAL = (-10.0, 0.0, 10.0)  # centre x, y and radius, mm
CENTRE = np.array([-10.0012, 0.0007])  # the machine's circle, mm
RADIUS = 9.9985


def trace(direction, glitch):
    """time,X,Y rows: 0.1 s of lead-in from inside, the circle in 2 s at 1 kHz, 0.1 s out."""
    rows = []
    for k in range(2001):
        angle = direction * math.pi * k / 1000.0
        r = RADIUS + 0.003 * math.cos(2 * angle)
        r += sum(glitch * math.exp(-(((angle - q) * 20.0) ** 2))
                 for q in np.arange(-4, 5) * math.pi / 2)
        rows.append((0.1 + k * 1e-3, *(CENTRE + r * np.array([math.cos(angle), math.sin(angle)]))))
    lead_in = [(k * 1e-3, CENTRE[0] + 0.1 * k, CENTRE[1]) for k in range(100)]
    lead_out = [(2.101 + k * 1e-3, CENTRE[0] + RADIUS - 0.1 * k, CENTRE[1]) for k in range(100)]
    return np.array(lead_in + rows + lead_out)


def lsc(points):
    def residuals(x):
        return np.hypot(points[:, 0] - x[0], points[:, 1] - x[1]) - x[2]
    fit = least_squares(residuals, x0=[NOMINAL[0], NOMINAL[1], NOMINAL[2]], xtol=1e-15, ftol=1e-15,
                        gtol=1e-15)
    return fit.x


def figures(points):
    cx, cy, r = lsc(points)
    d = np.hypot(points[:, 0] - cx, points[:, 1] - cy)
    f = np.hypot(points[:, 0] - NOMINAL[0], points[:, 1] - NOMINAL[1]) - NOMINAL[2]
    return dict(centre=(cx, cy), radius=r, G=d.max() - d.min(), F=(f.min(), f.max()))


@pytest.fixture(scope="module")
def contour_eval():
    done = subprocess.run(["cargo", "build", "--quiet", "--release", "-p", "contour-eval"],
                          cwd=REPO, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    target = os.environ.get("CARGO_TARGET_DIR", REPO / "target")
    return str(os.path.join(target, "release", "contour-eval"))


def numbers(line):
    return [float(x) for x in re.findall(r"-?\d+\.\d+", line)]


def test_circular_test_matches_the_definitions(contour_eval, tmp_path):
    files = []
    for name, direction, glitch in (("ccw", 1, 0.004), ("cw", -1, 0.006)):
        file = tmp_path / f"{name}.csv"
        np.savetxt(file, trace(direction, glitch), delimiter=",", header="time,X,Y", comments="")
        files.append(file)
    out, plot, written = tmp_path / "dev.csv", tmp_path / "ballbar.png", tmp_path / "fig.json"
    done = subprocess.run(
        [contour_eval, "--circle", ",".join(map(str, NOMINAL)), "--measured", str(files[0]),
         "--reverse", str(files[1]), "--from", "0.1", "--to", "2.1", "--out", str(out),
         "--plot", str(plot), "--figures", str(written)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    print(done.stdout)
    circles = [trace(d, g)[100:2101, 1:] for d, g in ((1, 0.004), (-1, 0.006))]
    for index, points in enumerate(circles):
        want = figures(points)
        block = lines[4 * index:4 * index + 4]
        cx, cy, r = numbers(block[1])
        assert abs(cx - want["centre"][0]) < 1e-6 and abs(cy - want["centre"][1]) < 1e-6
        assert abs(r - want["radius"]) < 1e-6
        (g,) = numbers(block[2])
        assert abs(g - want["G"] * 1e3) < 1e-3  # um, printed to 1 nm
        f_min, f_max = numbers(block[3])
        assert abs(f_min - want["F"][0] * 1e3) < 1e-3 and abs(f_max - want["F"][1] * 1e3) < 1e-3
        # By construction: the LSC is the machine's circle to a fraction of a micrometre
        # (the glitches pull it a little), G the oval's 6 um plus the glitch.
        assert np.hypot(*(np.array(want["centre"]) - CENTRE)) < 2e-4
        assert 6.0 < g < 6.0 + 1e3 * (0.004, 0.006)[index] + 0.1
    both = figures(np.vstack(circles))
    (g_b, cx, cy) = numbers(lines[8])
    assert abs(g_b - both["G"] * 1e3) < 1e-3
    assert abs(cx - both["centre"][0]) < 1e-6 and abs(cy - both["centre"][1]) < 1e-6
    # Per-sample deviations: only the circle's samples, from the nominal circle.
    rows = np.loadtxt(out, delimiter=",", skiprows=1)
    assert len(rows) == 2 * 2001
    nominal = np.hypot(circles[0][:, 0] - NOMINAL[0], circles[0][:, 1] - NOMINAL[1]) - NOMINAL[2]
    assert np.allclose(rows[rows[:, 0] == 0][:, 3], nominal, atol=1e-12)
    assert plot.stat().st_size > 10_000
    # The figures file for scripts: the same, unrounded (mm).
    data = json.loads(written.read_text())
    assert data["unit"] == "mm" and [r["samples"] for r in data["runs"]] == [2001, 2001]
    for run, points in zip(data["runs"], circles):
        want = figures(points)
        assert np.allclose(run["centre"], want["centre"], atol=1e-9)
        assert abs(run["radius"] - want["radius"]) < 1e-9
        assert abs(run["G"] - want["G"]) < 1e-9
        assert np.allclose(run["F"], want["F"], atol=1e-9)
    assert abs(data["Gb"] - both["G"]) < 1e-9


def test_a_run_that_is_no_circle_is_refused(contour_eval, tmp_path):
    file = tmp_path / "line.csv"
    np.savetxt(file, [(k * 1e-3, k * 0.1, 1.0) for k in range(50)], delimiter=",",
               header="time,X,Y", comments="")
    done = subprocess.run([contour_eval, "--circle", "0,0,5", "--measured", str(file)],
                          capture_output=True, text=True)
    assert done.returncode == 2
    assert "line" in done.stderr and str(file) in done.stderr
    done = subprocess.run([contour_eval, "--circle", "0,0,-5", "--measured", str(file)],
                          capture_output=True, text=True)
    assert done.returncode == 2 and "radius" in done.stderr
