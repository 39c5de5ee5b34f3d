"""Reference check: true five-axis contour errors of an FMU run, computed in Python
independently of the Rust code: the machine's forward kinematics
(docs/design/five-axis.md §5.1) written out again with numpy, and the nearest point on
the reference found by brute force.

The reference is the interpolator's own output, one pose per sample (0.05 mm apart at
50 mm/s). Between samples the tip path is taken as the Catmull-Rom cubic through the
neighbouring samples, sampled 16 times per interval (its deviation from the true curve
is of order h⁴·curvature³, far below a nanometre here; a plain polyline would be off by
the sagitta, 0.016 µm on the helix) and the axis as the normalised interpolation of its
end axes. Each measured tip is projected onto the segments of that dense polyline within
a window of reference samples up to its own time (so at the figure-eight's crossing the
branch not yet reached, or long passed, is never taken); the orientation error is the
angle between the measured tool axis and the reference axis at that foot point.
"""

import numpy as np

UPSAMPLE = 16
WINDOW = 150  # reference samples searched back from a measured sample's own time


def _rx(a):
    c, s = np.cos(a), np.sin(a)
    one, zero = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([one, zero, zero], -1),
                     np.stack([zero, c, -s], -1),
                     np.stack([zero, s, c], -1)], -2)


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    one, zero = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, -s, zero], -1),
                     np.stack([s, c, zero], -1),
                     np.stack([zero, zero, one], -1)], -2)


def forward(joints, a_pivot=(0.0, 0.0, 0.0), c_pivot=(0.0, 0.0, 0.0)):
    """Tool tips and unit tool axes in the workpiece frame of joints (N × 5: X Y Z mm, A C
    rad): w = Rz(−C)·(Rx(−A)·(P − a) + a − c) + c and o = Rz(−C)·Rx(−A)·e_z."""
    q = np.atleast_2d(np.asarray(joints, float))
    a, c = np.asarray(a_pivot, float), np.asarray(c_pivot, float)
    ra, rc = _rx(-q[:, 3]), _rz(-q[:, 4])
    inner = np.einsum("nij,nj->ni", ra, q[:, :3] - a) + a - c
    tips = np.einsum("nij,nj->ni", rc, inner) + c
    axes = np.einsum("nij,j->ni", rc @ ra, np.array([0.0, 0.0, 1.0]))
    return tips, axes


def _densify(tips, axes):
    """Catmull-Rom tips and interpolated unit axes, UPSAMPLE points per interval."""
    n = len(tips)
    padded = np.vstack([2 * tips[0] - tips[1], tips, 2 * tips[-1] - tips[-2]])
    p0, p1, p2, p3 = padded[:-3], padded[1:-2], padded[2:-1], padded[3:]
    s = (np.arange(UPSAMPLE) / UPSAMPLE)[None, :, None]
    dense = 0.5 * (2 * p1[:, None] + (p2 - p0)[:, None] * s
                   + (2 * p0 - 5 * p1 + 4 * p2 - p3)[:, None] * s ** 2
                   + (3 * p1 - p0 - 3 * p2 + p3)[:, None] * s ** 3)
    turn = axes[:-1, None] * (1 - s) + axes[1:, None] * s
    dense = np.vstack([dense.reshape(-1, 3), tips[-1:]])
    turn = np.vstack([turn.reshape(-1, 3), axes[-1:]])
    return dense, turn / np.linalg.norm(turn, axis=1, keepdims=True), n


def contour_errors(reference_joints, measured_joints, a_pivot=(0, 0, 0), c_pivot=(0, 0, 0),
                   ahead=0):
    """(tip mm, orientation rad) per measured sample k; reference_joints[k] is the
    reference at the same instant. Later reference samples are searched up to `ahead`
    samples past it: a loop with feed-forward may lead its reference (braking), and a
    tool ahead of the newest point is not off the path."""
    tips, axes = forward(reference_joints, a_pivot, c_pivot)
    # Repeated samples (before the start, after the end) would make zero-length pieces.
    keep = np.concatenate([[True], np.any(tips[1:] != tips[:-1], axis=1)])
    index = np.cumsum(keep) - 1  # sample k -> its distinct reference point
    dense, turn, _ = _densify(tips[keep], axes[keep])
    ptips, paxes = forward(measured_joints, a_pivot, c_pivot)
    tip_error = np.empty(len(ptips))
    orientation_error = np.empty(len(ptips))
    for k, (p, o) in enumerate(zip(ptips, paxes)):
        newest = index[min(k + ahead, len(index) - 1)]
        lo, hi = max(newest - WINDOW, 0) * UPSAMPLE, min(newest * UPSAMPLE, len(dense) - 1)
        if hi == lo:
            hi = min(lo + UPSAMPLE, len(dense) - 1)
        a, b = dense[lo:hi], dense[lo + 1:hi + 1]
        ab = b - a
        t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.einsum("ij,ij->i", ab, ab), 0.0, 1.0)
        foot = a + t[:, None] * ab
        d = np.linalg.norm(p - foot, axis=1)
        j = int(np.argmin(d))
        axis = turn[lo + j] * (1 - t[j]) + turn[lo + j + 1] * t[j]
        axis /= np.linalg.norm(axis)
        tip_error[k] = d[j]
        orientation_error[k] = np.arctan2(np.linalg.norm(np.cross(o, axis)), np.dot(o, axis))
    return tip_error, orientation_error
