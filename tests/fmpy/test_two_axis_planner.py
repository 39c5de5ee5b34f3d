"""PathInterpolator2D's feed planner (docs/design/two-axis.md §4.9) through fmpy: single
lines against the reference jerk-limited planner (the `ruckig` package, Ruckig's own C++
implementation) and the trapezoid's closed form, a G-code part under acceleration and jerk
limits in the closed loop with the `program` estimator, and the planned reference across
communication steps and a saved state."""

import numpy as np
import pytest
from ruckig import InputParameter, Ruckig, Trajectory

from contour_fmu.engines.fmu_log import FmuLog
from contour_fmu.engines.master import CLOSED_LOOP_RECORD, Master, Unit, closed_loop
from contour_fmu.loops.wiring import CLOSED_LOOP_CONNECTIONS, PATH_START
from helpers.fmu_slave import Slave
from test_two_axis_fmus import ESTIMATOR, PART, PART_PIECES, distance_to_pieces

LIMITS = {"accel": 2000.0, "jerk": 1e5}


@pytest.fixture
def interpolator(fmu_dir):
    s = Slave(str(fmu_dir / "PathInterpolator2D.fmu"))
    yield s
    s.close()


def ruckig_duration(length, speed, accel, jerk):
    otg = Ruckig(1)
    inp = InputParameter(1)
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [0.0], [0.0]
    inp.target_position, inp.target_velocity, inp.target_acceleration = [length], [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [speed], [accel], [jerk]
    trajectory = Trajectory(1)
    otg.calculate(inp, trajectory)
    return trajectory.duration


def planned_duration(fmu_dir, **parameters):
    s = Slave(str(fmu_dir / "PathInterpolator2D.fmu"))
    try:
        s.set(**parameters)
        s.fmu.exitInitializationMode()
        return s.reals(["plannedDuration"])[0]
    finally:
        s.close()


def line_duration(fmu_dir, length, **limits):
    return planned_duration(fmu_dir, path="line", line__x1=length, line__y1=0.0, feed=50.0,
                            **limits)


def planned_closed_loops(fmu_dir, path, interpolator, controller):
    """The closed loop on `path` planned with `interpolator`, run 0.3 s past the plan's
    duration with the CCC and without: {name: (before, after, reference samples)}."""
    stop = round(planned_duration(fmu_dir, path=path, **interpolator) + 0.3, 3)
    runs = {}
    for name, extra in [("ccc", {}), ("no ccc", {"ccc.enable": False})]:
        before, after = closed_loop(fmu_dir, path=path, stop=stop, interpolator=interpolator,
                                    controller={**controller, **extra})
        reference = np.stack([before["interpolator.ref.x"], before["interpolator.ref.y"]], axis=1)
        runs[name] = (before, after, reference)
    return runs


@pytest.mark.parametrize("length", [0.001, 0.01, 0.1, 0.3, 1.0, 3.0, 30.0, 300.0])
def test_a_line_takes_the_time_optimal_time_of_the_reference_planner(fmu_dir, length):
    want = ruckig_duration(length, 50.0, 2000.0, 1e5)
    got = line_duration(fmu_dir, length, **LIMITS)
    assert abs(got - want) <= 0.01 * want, (got, want)
    # Ruckig's algorithm on both sides: far closer than the 1 % asked.
    assert abs(got - want) <= 1e-6 * want, (got, want)


@pytest.mark.parametrize("length", [0.01, 1.0, 1.25, 10.0])
def test_without_a_jerk_limit_a_line_takes_the_trapezoids_time(fmu_dir, length):
    v, a = 50.0, 2000.0
    want = length / v + v / a if length >= v * v / a else 2.0 * np.sqrt(length / a)
    got = line_duration(fmu_dir, length, accel=a, jerk=0.0)
    assert abs(got - want) <= 1e-9 * want, (got, want)


def test_a_gcode_part_runs_under_acceleration_and_jerk_limits_in_the_closed_loop(fmu_dir, tmp_path):
    part = tmp_path / "part.ngc"
    part.write_text(PART)  # F1200 = 20 mm/s; corners blended (bare G64) within `tolerance`
    tolerance = 0.02
    interpolator = {"accel": 2000.0, "jerk": 1e5, "tolerance": tolerance, "feed": 50.0}
    controller = {"estimator": ESTIMATOR["program"], "path": str(part), "tolerance": tolerance}
    runs = {}
    loops = planned_closed_loops(fmu_dir, str(part), interpolator, controller)
    for name, (before, after, reference) in loops.items():
        # Start and end at rest; done when the plan says.
        assert np.allclose(reference[0], [0.0, 0.0]) and np.allclose(reference[-1], [0.0, 0.0])
        # By finite differences of the samples: speed within F, acceleration within accel.
        velocity = np.diff(reference, axis=0) / 1e-3
        assert np.linalg.norm(velocity, axis=1).max() <= 20.0 * (1 + 1e-9)
        acceleration = np.diff(velocity, axis=0) / 1e-3
        assert np.linalg.norm(acceleration, axis=1).max() <= 2000.0 * (1 + 1e-6)
        # The reference within the tolerance of the programmed part.
        off, _ = distance_to_pieces(PART_PIECES, reference)
        assert off.max() <= tolerance + 1e-9
        assert off.max() > 0.5 * tolerance  # the corners are blended
        points = np.stack([before["plant.pos.x"], before["plant.pos.y"]], axis=1)
        runs[name] = distance_to_pieces(PART_PIECES, points)[0]
        assert np.isfinite(after["controller.contourError"]).all()
    assert runs["ccc"].max() < runs["no ccc"].max()


def test_the_controller_warns_when_its_tolerance_is_not_the_interpolators(fmu_dir, tmp_path):
    part = tmp_path / "part.ngc"
    part.write_text(PART)
    log = FmuLog()
    units = [
        Unit("controller", str(fmu_dir / "ContourCCC2D.fmu"),
             {"estimator": ESTIMATOR["program"], "path": str(part), "tolerance": 0.0}),
        Unit("plant", str(fmu_dir / "XYServoPlant.fmu"), {}),
        Unit("interpolator", str(fmu_dir / "PathInterpolator2D.fmu"),
             {"path": str(part), "accel": 2000.0, "tolerance": 0.05}),
    ]
    with Master(units, CLOSED_LOOP_CONNECTIONS, 1e-3, 3.0, initial=PATH_START, log=log) as master:
        master.slaves["controller"].setDebugLogging(True, ["logStatusWarning"])
        master.run(CLOSED_LOOP_RECORD)
    warnings = [w for w in log.warnings() if "off the path of parameter 'path'" in w]
    assert len(warnings) == 1, log.warnings()


def run_interpolator(fmu_dir, step, stop=1.0):
    s = Slave(str(fmu_dir / "PathInterpolator2D.fmu"))
    s.set(path="arc", feed=30.0, accel=1500.0, jerk=5e4)
    s.fmu.exitInitializationMode()
    rows, t = [], 0.0
    for _ in range(int(round(stop / step))):
        s.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=step)
        t += step
        rows.append((t, *s.reals(["ref.x", "ref.y", "feedRate"])))
    s.close()
    return np.array(rows)


def test_the_planned_reference_is_the_same_on_any_communication_step(fmu_dir):
    fine = run_interpolator(fmu_dir, 1e-3)
    coarse = run_interpolator(fmu_dir, 1e-2)
    assert np.array_equal(fine[9::10, 1:], coarse[:, 1:])
    assert fine[:, 3].max() > 29.0  # it reaches the feed


def test_a_saved_planned_reference_continues_in_a_fresh_instance(fmu_dir, interpolator):
    interpolator.set(path="arc", feed=30.0, accel=1500.0, jerk=5e4)
    interpolator.fmu.exitInitializationMode()
    interpolator.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.4)
    state = interpolator.fmu.serializeFMUstate(interpolator.fmu.getFMUstate())
    fresh = Slave(str(fmu_dir / "PathInterpolator2D.fmu"), name="fresh")
    try:
        fresh.fmu.setFMUstate(fresh.fmu.deSerializeFMUstate(state))
        for k in range(5):
            t = 0.4 + 0.1 * k
            interpolator.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=0.1)
            fresh.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=0.1)
            names = ["ref.x", "ref.y", "feedRate", "plannedDuration"]
            assert np.array_equal(interpolator.reals(names), fresh.reals(names))
    finally:
        fresh.close()


# A user's NURBS file: a cubic B-spline hairpin, out along y = 0 and back along y = 12,
# with a tight turn (radius 3.76 mm at u = 1.7601 and 2.2399) between long gentle stretches.
HAIRPIN = {
    "degree": 3,
    "knots": [0, 0, 0, 0, 1, 2, 3, 4, 4, 4, 4],
    "control_points": [[0, 0], [30, 0], [45, 0], [49, 6], [45, 12], [30, 12], [0, 12]],
}


def hairpin_distance(points):
    """The test's own distance from each point to HAIRPIN (scipy's B-spline: the nearest of
    4001 samples, then Newton on (C - P).C' = 0 from it, all points at once)."""
    from scipy.interpolate import BSpline
    curve = BSpline(np.array(HAIRPIN["knots"], float),
                    np.array(HAIRPIN["control_points"], float), HAIRPIN["degree"])
    d1, d2 = curve.derivative(1), curve.derivative(2)
    u = np.linspace(0.0, 4.0, 4001)
    dense = curve(u)
    nearest = np.array([np.argmin(np.sum((dense - p) ** 2, axis=1)) for p in points])
    v = u[nearest]
    for _ in range(30):
        q, t, c = curve(v) - points, d1(v), d2(v)
        step = np.sum(q * t, axis=1) / (np.sum(t * t, axis=1) + np.sum(q * c, axis=1))
        v = np.clip(v - step, 0.0, 4.0)
    return np.linalg.norm(curve(v) - points, axis=1), curve


def test_a_nurbs_file_runs_planned_within_the_limits_with_the_exact_estimate(fmu_dir, tmp_path):
    import json
    hairpin = tmp_path / "hairpin.json"
    hairpin.write_text(json.dumps(HAIRPIN))
    feed = 80.0
    interpolator = {"accel": 2000.0, "jerk": 1e5, "feed": feed}
    controller = {"estimator": ESTIMATOR["program"], "path": str(hairpin)}
    runs = {}
    loops = planned_closed_loops(fmu_dir, str(hairpin), interpolator, controller)
    for name, (before, after, reference) in loops.items():
        # From rest at the start to rest at the end, on the curve all along.
        assert np.allclose(reference[0], [0.0, 0.0]) and np.allclose(reference[-1], [0.0, 12.0])
        off, curve = hairpin_distance(reference[::7])
        assert off.max() < 1e-9, off.max()
        # By finite differences of the samples: speed within the feed, acceleration and
        # jerk within the limits (no curvature jump on a cubic: no junction allowance).
        velocity = np.diff(reference, axis=0) / 1e-3
        speed = np.linalg.norm(velocity, axis=1)
        assert feed * (1 + 1e-9) >= speed.max() > 0.99 * feed
        acceleration = np.diff(velocity, axis=0) / 1e-3
        assert np.linalg.norm(acceleration, axis=1).max() <= 2000.0 * (1 + 1e-6)
        jerk = np.diff(acceleration, axis=0) / 1e-3
        assert np.linalg.norm(jerk, axis=1).max() <= 1e5 * (1 + 1e-6)
        # It slows for the tight turn, where the centripetal acceleration alone would
        # exceed the limit at the feed: v^2 kappa there within the normal share accel/sqrt 2.
        for u in [1.7601, 2.2399]:
            tight = np.argmin(np.linalg.norm(reference[:-1] - curve(u), axis=1))
            assert speed[tight] ** 2 * 0.26591 <= 2000.0 / np.sqrt(2) * (1 + 1e-3), speed[tight]
        # The program estimator: the exact distance to the NURBS, every sample.
        points = np.stack([before["plant.pos.x"], before["plant.pos.y"]], axis=1)
        want, _ = hairpin_distance(points)
        got = after["controller.contourError"]
        assert np.abs(np.abs(got) - want).max() < 1e-9, name
        runs[name] = want
    assert runs["ccc"].max() < 0.5 * runs["no ccc"].max(), (runs["ccc"].max(), runs["no ccc"].max())


def test_dwells_stops_and_home_moves_take_the_time_ruckig_gives_their_pieces(fmu_dir, tmp_path):
    # The reader's parameters through the FMU: a dwell of P (seconds in the LinuxCNC
    # dialect, milliseconds in Fanuc's), M1 with the optional stop off and on, G28 to
    # home.x. Each straight piece from rest to rest takes Ruckig's time; a stop or a
    # dwell adds its own; collinear pieces without a stop run as one.
    a, j, feed, rapid = 2000.0, 1e5, 10.0, 100.0
    piece = {length: ruckig_duration(length, feed, a, j) for length in (10.0, 20.0)}
    program = tmp_path / "dwell.ngc"
    program.write_text("G21 G90\nG1 X10 F600\nG4 P250\nG1 X20\nM30\n")
    limits = dict(path=str(program), accel=a, jerk=j, rapid=rapid)
    linuxcnc = planned_duration(fmu_dir, **limits)
    fanuc = planned_duration(fmu_dir, dialect=2, **limits)
    assert linuxcnc == pytest.approx(2 * piece[10.0] + 250.0, abs=1e-9)
    assert fanuc == pytest.approx(2 * piece[10.0] + 0.25, abs=1e-9)
    program.write_text("G21 G90\nG1 X10 F600\nM1\nG1 X20\nM30\n")
    assert planned_duration(fmu_dir, **limits) == pytest.approx(piece[20.0], abs=1e-6)
    assert planned_duration(fmu_dir, optionalStop=True, **limits) == pytest.approx(
        2 * piece[10.0], abs=1e-9)
    program.write_text("G21 G90\nG1 X10 F600\nG28\nM30\n")
    home = ruckig_duration(15.0, rapid, a, j)
    assert planned_duration(fmu_dir, home__x=-5.0, **limits) == pytest.approx(
        piece[10.0] + home, abs=1e-9)
