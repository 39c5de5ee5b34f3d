"""The Rust true contour error against an independent brute force.

Python side: the path is sampled densely (geomdl for the NURBS, rebuilt from
docs/design/two-axis.md §4.6 in contour_fmu.checks.reference_paths; closed forms for circle, line and
arc), every promising local minimum of the sampled distance is refined with scipy's
bounded Brent minimiser, and the sign comes from the side of the tangent at the foot
(positive right of travel). Rust side: `estimator_dump` prints the global brute force
and the hint-accelerated index result for a few hundred pseudo-random points, most within
2 mm of the path, some up to 20 mm away.
"""

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from contour_fmu.checks.reference_paths import INFINITY, TRIDENT, clamped_uniform, geomdl_curve


def nurbs_path(ctrl):
    curve = geomdl_curve(3, clamped_uniform(len(ctrl), 3), ctrl)
    point = lambda u: np.array(curve.evaluate_single(min(max(u, 0.0), 1.0)))
    tangent = lambda u: np.array(curve.derivatives(min(max(u, 0.0), 1.0), order=1)[1])
    dense = np.array(curve.evaluate_list(list(np.linspace(0.0, 1.0, 40001))))
    return point, tangent, dense


def circle_path(centre, radius, start, sweep):
    def point(u):
        a = start + sweep * u
        return np.array([centre[0] + radius * math.cos(a), centre[1] + radius * math.sin(a)])

    def tangent(u):
        a = start + sweep * u
        return sweep * radius * np.array([-math.sin(a), math.cos(a)])

    return point, tangent, np.array([point(u) for u in np.linspace(0.0, 1.0, 40001)])


def line_path(a, b):
    a, b = np.array(a, float), np.array(b, float)
    return (lambda u: a + u * (b - a)), (lambda u: b - a), np.array([a + u * (b - a) for u in np.linspace(0, 1, 1001)])


PATHS = {
    "infinity": lambda: nurbs_path(INFINITY),
    "trident": lambda: nurbs_path(TRIDENT),
    "circle": lambda: circle_path((-10.0, 0.0), 10.0, 0.0, 2 * math.pi),
    "arc": lambda: circle_path((-20.0, 0.0), 20.0, 0.0, -math.pi),
    "line": lambda: line_path((0, 0), (40, 30)),
}


def brute_force(point, tangent, dense, p):
    n = len(dense) - 1
    us = np.linspace(0.0, 1.0, n + 1)
    d = np.hypot(dense[:, 0] - p[0], dense[:, 1] - p[1])
    chord = np.hypot(*np.diff(dense, axis=0).T).max()
    best = (math.inf, 0.0)
    for i in np.flatnonzero(d <= d.min() + chord):
        if (i > 0 and d[i] > d[i - 1]) or (i < n and d[i] > d[i + 1]):
            continue
        lo, hi = us[max(i - 1, 0)], us[min(i + 1, n)]
        r = minimize_scalar(lambda u: np.linalg.norm(point(u) - p), bounds=(lo, hi),
                            method="bounded", options={"xatol": 1e-14})
        for u, f in ((r.x, r.fun), (lo, np.linalg.norm(point(lo) - p)), (hi, np.linalg.norm(point(hi) - p))):
            if f < best[0]:
                best = (f, u)
    dist, u = best
    t = tangent(u)
    q = p - point(u)
    side = -(t[0] * q[1] - t[1] * q[0])
    return math.copysign(dist, side), u


@pytest.mark.parametrize("name", ["infinity", "trident", "circle", "arc", "line"])
def test_true_error_matches_independent_brute_force(rust_json, name):
    count = 300 if name in ("infinity", "trident") else 100
    rust = rust_json("estimator_dump", "true_error", name, count, 7)
    point, tangent, dense = PATHS[name]()
    worst = 0.0
    for rec in rust["points"]:
        p = np.array(rec["p"])
        err, u = brute_force(point, tangent, dense, p)
        worst = max(worst, abs(rec["error"] - err))
        assert abs(abs(rec["error"]) - abs(err)) < 1e-9, (rec, err, u)
        if abs(err) > 1e-6:
            assert math.copysign(1, rec["error"]) == math.copysign(1, err), (rec, err)
        # The hint-accelerated index gives the global answer.
        assert abs(rec["index_error"] - rec["error"]) < 1e-12, rec
        assert np.linalg.norm(np.array(rec["foot"]) - point(rec["u"])) < 1e-9
    print(f"{name}: {len(rust['points'])} points, max |Δ| = {worst:.2e} mm")
