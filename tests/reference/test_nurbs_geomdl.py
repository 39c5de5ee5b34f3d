"""The Rust NURBS evaluator (point, first and second derivative) against geomdl.

The built-in curves are rebuilt from the control points listed in docs/design/two-axis.md §4.6
(contour_fmu.checks.reference_paths, not from the Rust output), so the test also checks the Rust
data entry. Rational evaluation is checked on the exact 9-point unit circle and on a random
degree-4 NURBS with random weights and a non-uniform knot vector, written to a JSON file and
loaded by the Rust file loader.
"""

import json
import math
import random

import numpy as np
import pytest

from contour_fmu.checks.reference_paths import INFINITY, TRIDENT, clamped_uniform, geomdl_curve

S = math.sqrt(2) / 2
UNIT_CIRCLE = dict(
    degree=2,
    knots=[0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1],
    control_points=[(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1), (1, 0)],
    weights=[1, S, 1, S, 1, S, 1, S, 1],
)


def compare(rust, curve, tol=1e-10):
    """Max scaled deviation of point, C', C'' over all samples (|Δ| / max(1, |ref|))."""
    worst = 0.0
    for s in rust["samples"]:
        ref = curve.derivatives(s["u"], order=2)
        for got, exp in zip((s["p"], s["d1"], s["d2"]), ref):
            for g, e in zip(got, exp):
                worst = max(worst, abs(g - e) / max(1.0, abs(e)))
    assert worst <= tol, f"max scaled deviation {worst:.3e}"
    return worst


@pytest.mark.parametrize("name,ctrl", [("infinity", INFINITY), ("trident", TRIDENT)])
def test_builtin_nurbs_match_geomdl(rust_json, name, ctrl):
    rust = rust_json("nurbs_dump", name, 1000)
    assert rust["degree"] == 3
    assert np.allclose(rust["control_points"], ctrl, rtol=0, atol=0)
    knots = clamped_uniform(len(ctrl), 3)
    assert np.allclose(rust["knots"], knots, rtol=0, atol=1e-15)
    assert rust["weights"] == [1.0] * len(ctrl)
    assert len(rust["samples"]) >= 1000
    worst = compare(rust, geomdl_curve(3, knots, ctrl))
    print(f"{name}: max scaled deviation from geomdl {worst:.2e}")
    # Arc length against dense chord sums of the geomdl curve.
    pts = np.array(geomdl_curve(3, knots, ctrl).evaluate_list(list(np.linspace(0, 1, 200001))))
    chords = np.hypot(*np.diff(pts, axis=0).T).sum()
    assert abs(rust["length"] - chords) < 1e-6


def test_rational_unit_circle_matches_geomdl(rust_json):
    rust = rust_json("nurbs_dump", "unit_circle", 1000)
    c = UNIT_CIRCLE
    curve = geomdl_curve(c["degree"], c["knots"], c["control_points"], c["weights"])
    compare(rust, curve)
    for s in rust["samples"]:
        assert abs(math.hypot(*s["p"]) - 1.0) < 1e-14
    assert abs(rust["length"] - 2 * math.pi) < 1e-9


def test_random_rational_file_matches_geomdl(rust_json, tmp_path):
    rng = random.Random(4)
    degree, n = 4, 11
    interior = sorted(rng.uniform(0.0, 2.0) for _ in range(n - degree - 1))
    interior[3] = interior[2]  # a double interior knot
    knots = [0.0] * (degree + 1) + interior + [2.0] * (degree + 1)
    ctrl = [(rng.uniform(-50, 50), rng.uniform(-50, 50)) for _ in range(n)]
    weights = [rng.uniform(0.2, 3.0) for _ in range(n)]
    f = tmp_path / "random.json"
    f.write_text(json.dumps(dict(degree=degree, knots=knots, control_points=ctrl, weights=weights)))
    rust = rust_json("nurbs_dump", f, 1000)
    # geomdl normalises knot vectors to [0, 1] by default; compare at the same points.
    curve = geomdl_curve(degree, [k / 2.0 for k in knots], ctrl, weights)
    scaled = {"samples": []}
    for s in rust["samples"]:
        # d/du with u = 2v: C'_u = C'_v / 2, C''_u = C''_v / 4.
        scaled["samples"].append(
            dict(u=s["u"] / 2.0, p=s["p"], d1=[2 * x for x in s["d1"]], d2=[4 * x for x in s["d2"]])
        )
    compare(scaled, curve, tol=1e-9)


def test_bad_file_reports_line(tmp_path):
    import os
    import subprocess
    from pathlib import Path

    repo = Path(__file__).resolve().parents[2]
    f = tmp_path / "bad.json"
    f.write_text('{\n  "degree": 3,\n  "knots": [0, 0,, 1]\n}\n')
    done = subprocess.run(
        ["cargo", "run", "--quiet", "--release", "--example", "nurbs_dump", "--", str(f)],
        cwd=repo, capture_output=True, text=True, env=os.environ.copy(),
    )
    assert done.returncode != 0
    assert f"{f}:3:" in done.stderr
