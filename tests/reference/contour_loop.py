"""Stability of the contour loop with frozen CCC gains, computed from the plant's physics
with scipy, independently of the Rust code (docs/design/two-axis.md §4.4, the PSO search box).

Along a straight contour with identical axes the contour error is the position error of
one axis in the normal direction, regulated by the axis P loop (Kpp) plus the CCC PID
(Kp, Ki, Kd). The axis is the test plant of §4.5: a PI velocity loop on the motor
(states: velocity-error integral, motor speed, motor angle), driven by a velocity command
held over each sample (zero-order hold, exact matrix exponential). The controller is the
discrete PID of contour-core/src/control/pid.rs: u = (Kpp + Kp)·e + Ki·Σe·Ts + Kd·(e − e_prev)/Ts, with
the current sample in the sum. The loop is stable when every eigenvalue of the sampled
closed loop lies inside the unit circle.
"""

import numpy as np
from scipy.linalg import expm

# The paper's motor and the design's drive (§4.5): J kg·m², B N·m·s, CT N·m/A, lead mm,
# Kvp A·s/rad, Kvi A/rad.
PAPER_AXIS = dict(J=0.015, B=1.2, CT=0.57, lead=10.0, Kvp=8.26, Kvi=661.0)
KPP = 28.5  # axis position-loop gain, 1/s
TS = 1e-3


def sampled_axis(ts=TS, J=0.015, B=1.2, CT=0.57, lead=10.0, Kvp=8.26, Kvi=661.0):
    """(Ad, Bd, C) of one axis: velocity command (mm/s) held over ts -> position (mm)."""
    g = 2 * np.pi / lead  # rad per mm
    a = np.array([[0.0, -1.0, 0.0],
                  [CT * Kvi / J, -(CT * Kvp + B) / J, 0.0],
                  [0.0, 1.0, 0.0]])
    b = np.array([g, CT * Kvp * g / J, 0.0])
    m = np.zeros((4, 4))
    m[:3, :3], m[:3, 3] = a, b
    e = expm(m * ts)
    return e[:3, :3], e[:3, 3], np.array([0.0, 0.0, 1.0 / g])


def spectral_radius(kp, ki, kd, kpp=KPP, ts=TS, **axis):
    """Largest |eigenvalue| of the closed contour loop with frozen gains."""
    ad, bd, c = sampled_axis(ts, **axis)
    ce = -c  # e = −position: the loop regulates the normal deviation to zero
    f = np.zeros((5, 5))  # state: plant (3), Σe·Ts, e_prev
    f[:3, :3] = ad + np.outer(bd, (kpp + kp + ki * ts + kd / ts) * ce)
    f[:3, 3] = bd * ki
    f[:3, 4] = -bd * kd / ts
    f[3, :3], f[3, 3] = ts * ce, 1.0
    f[4, :3] = ce
    if ki == 0.0:  # without integral action Σe is not fed back: drop its unit eigenvalue
        keep = [0, 1, 2, 4]
        f = f[np.ix_(keep, keep)]
    return max(abs(np.linalg.eigvals(f)))


def critical(gain, base, hi):
    """The value of `gain` ('kp', 'ki' or 'kd') at which the loop with the other gains at
    `base` loses stability (bisection on the spectral radius; hi must be unstable)."""
    lo = 0.0
    def stable(v):
        return spectral_radius(**{**base, gain: v}) < 1.0
    assert stable(lo) and not stable(hi), (gain, base, hi)
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
    return lo


if __name__ == "__main__":
    base = dict(kp=100.0, ki=5000.0, kd=0.0)
    for gain, hi in (("kp", 1e5), ("ki", 1e7), ("kd", 1e3)):
        print(f"critical {gain} with the others at Kp0, Ki0, Kd0: {critical(gain, base, hi):.6g}")
