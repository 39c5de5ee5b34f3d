"""Feed-forward in the two-axis loop (issue 24): PathInterpolator2D's `vref.*` and `aref.*`
are the reference's velocity and acceleration at each sample, and ContourCCC2D adds
`feedForward`·vref + `accelerationFeedForward`·aref to its commands.

vref against independent references: on the paper's circle at constant feed, the feed
along the circle's tangent at the sampled point (exact); on a G-code part planned within
acceleration and jerk, the central difference of the reference samples. Where the
acceleration is continuous that differs from the velocity by Ts^2/6 times the jerk
(Taylor: (p(t+Ts) - p(t-Ts))/(2 Ts) = p' + Ts^2 p'''/6 + ...); where the curvature jumps
(a line meeting an arc) the plan lets the acceleration jump by up to jerk*Ts, and a jump
da inside (t, t+Ts) adds da*(t+Ts-tau)^2/(4 Ts) <= jerk*Ts^2/4: the bound.

aref likewise: on the circle the centripetal feed^2/R toward the centre (exact); on the
part the second central difference (p(t+Ts) - 2 p(t) + p(t-Ts))/Ts^2, which differs from
the acceleration by an acceleration jump da inside the window times at most 1/2 (da <=
jerk*Ts where the curvature jumps) and a jerk jump dj (at most 2*jerk, where the
S-curve's phases meet) times at most Ts/6 each side: within jerk*Ts*(1/2 + 1/3).

`ahead.*`, the look-ahead: the mean acceleration over the coming period, the next sample's
vref less this one's over Ts, on both (exact to rounding).
"""

import numpy as np

from contour_fmu.engines.master import closed_loop
from helpers.fmu_slave import Slave
from test_two_axis_fmus import PART

TS = 1e-3


def interpolate(fmu_dir, steps, **parameters):
    s = Slave(str(fmu_dir / "PathInterpolator2D.fmu"))
    try:
        s.set(**parameters)
        s.fmu.exitInitializationMode()
        names = ["ref.x", "ref.y", "vref.x", "vref.y", "feedRate", "aref.x", "aref.y",
                 "ahead.x", "ahead.y"]
        rows = [s.reals(names)]
        for k in range(steps):
            s.fmu.doStep(currentCommunicationPoint=k * TS, communicationStepSize=TS)
            rows.append(s.reals(names))
        return np.array(rows)
    finally:
        s.close()


def test_vref_on_the_circle_is_the_feed_along_the_tangent(fmu_dir):
    rows = interpolate(fmu_dir, 1990)
    feed = 10.0 * np.pi
    # The paper's circle: centre (-10, 0), radius 10, counter-clockwise.
    tangent = np.column_stack([-rows[:, 1], rows[:, 0] + 10.0]) / 10.0
    assert np.max(np.abs(rows[:, 2:4] - feed * tangent)) < 1e-9
    assert np.allclose(np.hypot(rows[:, 2], rows[:, 3]), rows[:, 4], atol=1e-9)
    centre = np.array([-10.0, 0.0])
    centripetal = -(feed / 10.0) ** 2 * (rows[:, :2] - centre)
    assert np.max(np.abs(rows[:, 5:7] - centripetal)) < 1e-9
    assert_ahead_is_the_next_velocity(rows)


def assert_ahead_is_the_next_velocity(rows):
    mean = (rows[1:, 2:4] - rows[:-1, 2:4]) / TS
    assert np.max(np.abs(rows[:-1, 7:9] - mean)) < 1e-6


def test_vref_of_a_planned_part_is_the_derivative_of_its_samples(fmu_dir, tmp_path):
    program = tmp_path / "part.ngc"
    program.write_text(PART)
    jerk = 1e5
    rows = interpolate(fmu_dir, 4000, path=str(program), accel=2000.0, jerk=jerk, feed=30.0)
    central = (rows[2:, :2] - rows[:-2, :2]) / (2 * TS)
    error = np.max(np.abs(central - rows[1:-1, 2:4]))
    bound = TS**2 / 4 * jerk
    print(f"max |central difference - vref| = {error:.3g} mm/s (bound {bound:.3g})")
    assert error <= bound + 1e-9
    assert np.allclose(np.hypot(rows[:, 2], rows[:, 3]), rows[:, 4], atol=1e-9)
    assert rows[:, 4].max() == 20.0  # it moved at the program's F1200
    second = (rows[2:, :2] - 2 * rows[1:-1, :2] + rows[:-2, :2]) / TS**2
    error = np.max(np.abs(second - rows[1:-1, 5:7]))
    bound = jerk * TS * (1 / 2 + 1 / 3)
    print(f"max |second difference - aref| = {error:.3g} mm/s2 (bound {bound:.3g})")
    assert error <= bound
    assert np.abs(rows[:, 5:7]).max() > 1000.0  # it accelerated
    assert_ahead_is_the_next_velocity(rows)
    assert np.all(rows[-1, 7:9] == 0.0)  # at the end, at rest


def test_feed_forward_removes_the_lag_and_the_ccc_the_rest(fmu_dir):
    """The paper's circle: without feed-forward the P position loops lag by v/Kpp
    (1.1 mm) and the contour error is their lag's; with gain 1 only the velocity loops'
    lag is left (its 3.2 ms time constant: 12.7 um on the circle, 12.6 um of contour
    error), the acceleration term with that time constant takes most of it, and the CCC
    takes the contour error below 0.3 um either way."""
    figures = {}
    for ff, aff in ((0.0, 0.0), (1.0, 0.0), (1.0, 1 / 314)):
        for ccc in (False, True):
            controller = {"ccc.enable": ccc, "feedForward": ff, "accelerationFeedForward": aff}
            before, _ = closed_loop(fmu_dir, controller=controller)
            x, y = before["plant.pos.x"], before["plant.pos.y"]
            contour = np.abs(np.hypot(x + 10.0, y) - 10.0)[200:]
            lag = np.hypot(before["interpolator.ref.x"] - x, before["interpolator.ref.y"] - y)[200:]
            figures[aff or ff, ccc] = (contour.max(), lag.max())
    print({k: tuple(round(v * 1e3, 3) for v in f) for k, f in figures.items()})
    assert figures[1.0, False][1] < figures[0.0, False][1] / 50
    assert figures[1.0, False][0] < figures[0.0, False][0] / 3
    assert figures[1.0, True][0] < figures[1.0, False][0] / 100
    assert figures[0.0, True][0] < 0.3e-3
    # The acceleration term: the velocity loops' lag mostly gone too.
    assert figures[1 / 314, False][0] < figures[1.0, False][0] / 5
    assert figures[1 / 314, False][1] < figures[1.0, False][1] / 5
    assert figures[1 / 314, True][0] <= figures[1.0, True][0]
    # Gain 0 is the paper's loop: the same as ever (tests/fmpy/test_closed_loop_vs_sim.py).
    assert figures[0.0, False][0] > 0.04
