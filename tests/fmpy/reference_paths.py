"""True contour error for the demo and the closed-loop tests, computed independently of
the Rust code: the built-in paths are rebuilt here (closed forms for circle, line and
arc; geomdl for the NURBS of docs/design.md §4.6), sampled densely, and each point is projected
onto the segments next to its nearest sample (about 1e-9 mm from the exact distance at 200 001 samples).
"""

import math
import sys
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "reference"))
from test_nurbs_geomdl import INFINITY, TRIDENT, clamped_uniform, geomdl_curve  # noqa: E402

SAMPLES = 200_001


def _circle(centre, radius, start, sweep, n):
    a = start + sweep * np.linspace(0.0, 1.0, n)
    return np.column_stack([centre[0] + radius * np.cos(a), centre[1] + radius * np.sin(a)])


def polyline(name, n=SAMPLES):
    """Dense points along the built-in path `name`, in travel order."""
    if name == "circle":
        return _circle((-10.0, 0.0), 10.0, 0.0, 2 * math.pi, n)
    if name == "arc":
        return _circle((-20.0, 0.0), 20.0, 0.0, -math.pi, n)
    if name == "line":
        u = np.linspace(0.0, 1.0, n)[:, None]
        return np.array([0.0, 0.0]) + u * np.array([40.0, 30.0])
    ctrl = {"infinity": INFINITY, "trident": TRIDENT}[name]
    curve = geomdl_curve(3, clamped_uniform(len(ctrl), 3), ctrl)
    return np.array(curve.evaluate_list(list(np.linspace(0.0, 1.0, n))))


class ContourReference:
    """Distance from points to one built-in path, or to its mirror image about the x axis
    (y -> -y) when `mirrored`."""

    def __init__(self, name, n=SAMPLES, mirrored=False):
        self.points = polyline(name, n)
        if mirrored:
            self.points[:, 1] *= -1.0
        self.tree = cKDTree(self.points)

    def distance(self, xy):
        xy = np.atleast_2d(np.asarray(xy, float))
        _, idx = self.tree.query(xy)
        best = np.full(len(xy), np.inf)
        last = len(self.points) - 1
        for offset in (-1, 0):  # the segments before and after the nearest sample
            i = np.clip(idx + offset, 0, last - 1)
            a, b = self.points[i], self.points[i + 1]
            ab = b - a
            t = np.clip(np.einsum("ij,ij->i", xy - a, ab) / np.einsum("ij,ij->i", ab, ab), 0.0, 1.0)
            foot = a + t[:, None] * ab
            best = np.minimum(best, np.hypot(*(xy - foot).T))
        return best


def paper_circle_distance(x, y):
    """Distance (mm) of points from the paper's circle x = 10 cos(pi t) - 10, y = 10 sin(pi t)."""
    return np.abs(np.hypot(np.asarray(x) + 10.0, y) - 10.0)
