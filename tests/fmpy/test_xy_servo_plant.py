"""XYServoPlant through fmpy: validation, and the physics against scipy."""

import numpy as np
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from helpers.plant_reference import PAPER_AXIS, simulate_axis

STEP = 1e-3


def test_validates_without_problems(xy_plant_fmu):
    assert validate_fmu(xy_plant_fmu) == []


def test_model_description_states_the_interface(xy_plant_fmu):
    md = read_model_description(xy_plant_fmu, validate=True)
    assert md.coSimulation.modelIdentifier == "XYServoPlant"
    names = {v.name: v for v in md.modelVariables}
    assert [n for n, v in names.items() if v.causality == "input"] == ["u.x", "u.y"]
    assert [n for n, v in names.items() if v.causality == "output"] == ["pos.x", "pos.y", "vel.x", "vel.y"]
    assert names["x.J"].start == "0.015" and names["x.J"].unit == "kg.m2"
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate


def held_commands(times, signal):
    """The command a master applies on each interval: the signal at its start, taking
    the right-hand value at a discontinuity (as fmpy does)."""
    return np.array([signal(t) for t in times])


def run(fmu, stop, signals, start_values=None):
    times = np.round(np.arange(0.0, stop + STEP / 2, STEP), 12)
    rows = [(t, signals[0](t), signals[1](t)) for t in times]
    inputs = np.array(rows, dtype=[("time", float), ("u.x", float), ("u.y", float)])
    result = simulate_fmu(
        fmu,
        stop_time=stop,
        step_size=STEP,
        output_interval=STEP,
        input=inputs,
        start_values=start_values or {},
        output=["pos.x", "pos.y", "vel.x", "vel.y"],
    )
    return times, result


def test_step_and_ramp_commands_match_scipy(xy_plant_fmu):
    step_x = lambda t: 0.0 if t < 0.1 - 1e-12 else 40.0  # noqa: E731  step of 40 mm/s
    ramp_y = lambda t: 100.0 * t  # noqa: E731  ramp of 100 mm/s²
    times, result = run(xy_plant_fmu, 0.5, (step_x, ramp_y))
    assert np.allclose(result["time"], times)
    for name, signal in (("x", step_x), ("y", ramp_y)):
        pos, vel = simulate_axis(PAPER_AXIS, times, held_commands(times, signal))
        assert np.max(np.abs(result[f"pos.{name}"] - pos)) < 1e-6, name
        assert np.max(np.abs(result[f"vel.{name}"] - vel)) < 1e-6, name
    # The step response really moved: a stub would fail here.
    assert result["pos.x"][-1] > 0.4 * 40.0 * 0.3


def test_mismatched_axis_and_start_position_match_scipy(xy_plant_fmu):
    params = dict(PAPER_AXIS, J=0.0225)
    sine = lambda t: 30.0 * np.sin(2 * np.pi * 2.0 * t)  # noqa: E731
    times, result = run(xy_plant_fmu, 0.3, (sine, sine), start_values={"y.J": 0.0225, "pos0.y": -3.5})
    pos_x, _ = simulate_axis(PAPER_AXIS, times, held_commands(times, sine))
    pos_y, _ = simulate_axis(params, times, held_commands(times, sine), x0=-3.5)
    assert np.max(np.abs(result["pos.x"] - pos_x)) < 1e-6
    assert np.max(np.abs(result["pos.y"] - pos_y)) < 1e-6
    # The heavier axis lags: the two really differ.
    assert np.max(np.abs((result["pos.y"] + 3.5) - result["pos.x"])) > 1e-3
