"""Reference check: the built-in paths rebuilt in Python, and the true contour error
computed from them, independently of the Rust code.

The NURBS `infinity` and `trident` come from the control points listed in docs/design/two-axis.md
§4.6 (cubic, clamped uniform knots; evaluated with geomdl), the circle, line and arc from
their closed forms. For the true contour error each path is sampled densely and every
point is projected onto the segments next to its two nearest samples (off the exact
distance by at most the polygon's sagitta at 200 001 samples: about 1e-9 mm on the circle,
up to 6e-8 mm on the NURBS).

Needs the reference extra (geomdl, scipy).
"""

import math

import numpy as np

from ..extras import needs

with needs("reference"):
    from geomdl import NURBS
    from scipy.spatial import cKDTree

# Control points (mm) of the built-in NURBS paths, docs/design/two-axis.md §4.6.
INFINITY = [
    (0, 0), (4.5, 4.5), (18.1, 21.5), (41.5, 19.0), (42.1, -19.4), (17.2, -20.1), (0, 0),
    (-17.2, 20.1), (-42.1, 19.4), (-41.5, -19.0), (-18.1, -21.5), (-4.5, -4.5), (0, 0),
]
TRIDENT = [
    (40.2, -0.1), (39.2, 4.5), (30.9, 7.7), (19.0, 7.5), (7.0, 3.7), (-3.5, -1.3),
    (-13.4, -10.5), (-19.9, -17.8), (-25.5, -34.2), (-11.3, -36.1), (-4.8, -22.6),
    (-0.7, -12.6), (0.3, 0), (-0.7, 12.6), (-4.8, 22.6), (-11.3, 36.1), (-25.5, 34.2),
    (-19.9, 17.8), (-13.4, 10.5), (-3.5, 1.3), (7.0, -3.7), (19.0, -7.5), (30.9, -7.7),
    (39.2, -4.5), (40.2, 0.1),
]
SAMPLES = 200_001


def clamped_uniform(n, p):
    """The clamped uniform knot vector on [0, 1] of n control points and degree p."""
    spans = n - p
    return [0.0] * (p + 1) + [k / spans for k in range(1, spans)] + [1.0] * (p + 1)


def geomdl_curve(degree, knots, ctrl, weights=None):
    """A geomdl NURBS curve (unit weights unless given)."""
    c = NURBS.Curve()
    c.degree = degree
    c.ctrlpts = [list(map(float, p)) for p in ctrl]
    c.weights = [1.0] * len(ctrl) if weights is None else [float(w) for w in weights]
    c.knotvector = list(knots)
    return c


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
        # The two nearest samples: a closed path's start and end are one point, and the
        # tree gives either; the segments next to the other may hold the foot.
        _, nearest = self.tree.query(xy, k=2)
        best = np.full(len(xy), np.inf)
        last = len(self.points) - 1
        for idx in nearest.T:
            for offset in (-1, 0):  # the segments before and after the sample
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
