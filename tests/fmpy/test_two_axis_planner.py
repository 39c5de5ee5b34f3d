"""PathInterpolator2D's feed planner (docs/design/two-axis.md §4.9) through fmpy: single
lines against the reference jerk-limited planner (the `ruckig` package, Ruckig's own C++
implementation) and the trapezoid's closed form, a G-code part under acceleration and jerk
limits in the closed loop with the `program` estimator, and the planned reference across
communication steps and a saved state."""

import numpy as np
import pytest
from ruckig import InputParameter, Ruckig, Trajectory

from contour_fmu.fmu_log import FmuLog
from contour_fmu.master import (CLOSED_LOOP_CONNECTIONS, CLOSED_LOOP_RECORD, PATH_START, Master,
                                Unit, closed_loop)
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


def planned_duration(fmu_dir, length, **limits):
    s = Slave(str(fmu_dir / "PathInterpolator2D.fmu"))
    try:
        s.set(path="line", line__x1=length, line__y1=0.0, feed=50.0, **limits)
        s.fmu.exitInitializationMode()
        return s.reals(["plannedDuration"])[0]
    finally:
        s.close()


@pytest.mark.parametrize("length", [0.001, 0.01, 0.1, 0.3, 1.0, 3.0, 30.0, 300.0])
def test_a_line_takes_the_time_optimal_time_of_the_reference_planner(fmu_dir, length):
    want = ruckig_duration(length, 50.0, 2000.0, 1e5)
    got = planned_duration(fmu_dir, length, **LIMITS)
    assert abs(got - want) <= 0.01 * want, (got, want)
    # Ruckig's algorithm on both sides: far closer than the 1 % asked.
    assert abs(got - want) <= 1e-6 * want, (got, want)


@pytest.mark.parametrize("length", [0.01, 1.0, 1.25, 10.0])
def test_without_a_jerk_limit_a_line_takes_the_trapezoids_time(fmu_dir, length):
    v, a = 50.0, 2000.0
    want = length / v + v / a if length >= v * v / a else 2.0 * np.sqrt(length / a)
    got = planned_duration(fmu_dir, length, accel=a, jerk=0.0)
    assert abs(got - want) <= 1e-9 * want, (got, want)


def test_a_gcode_part_runs_under_acceleration_and_jerk_limits_in_the_closed_loop(fmu_dir, tmp_path):
    part = tmp_path / "part.ngc"
    part.write_text(PART)  # F1200 = 20 mm/s; corners blended (bare G64) within `tolerance`
    tolerance = 0.02
    interpolator = {"accel": 2000.0, "jerk": 1e5, "tolerance": tolerance, "feed": 50.0}
    probe = Slave(str(fmu_dir / "PathInterpolator2D.fmu"))
    probe.set(path=str(part), **interpolator)
    probe.fmu.exitInitializationMode()
    duration = probe.reals(["plannedDuration"])[0]
    probe.close()
    stop = round(duration + 0.3, 3)
    controller = {"estimator": ESTIMATOR["program"], "path": str(part), "tolerance": tolerance}
    runs = {}
    for name, extra in [("ccc", {}), ("no ccc", {"ccc.enable": False})]:
        before, after = closed_loop(fmu_dir, path=str(part), stop=stop, interpolator=interpolator,
                                    controller={**controller, **extra})
        reference = np.stack([before["interpolator.ref.x"], before["interpolator.ref.y"]], axis=1)
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
