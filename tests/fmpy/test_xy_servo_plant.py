"""XYServoPlant through fmpy: validation, and the physics against scipy."""

import numpy as np
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from helpers.plant_reference import PAPER_AXIS, simulate_axis, simulate_axis_with_friction

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


# Friction on X: Coulomb 0.3 N.m, static 0.5 N.m, Stribeck velocity 1 mm/s (at the motor,
# a 10 mm lead: 188 N and 314 N at the table).
FRICTION = dict(coulomb=0.3, stiction=0.5, stribeck=1.0)


def test_friction_matches_a_hybrid_scipy_model(xy_plant_fmu):
    """Stick-slip against solve_ivp with events: a command that reverses (the axis stops,
    sticks while the integral builds up the breakaway torque, and slides back) and a slow
    one (0.05 mm/s, whose proportional torque alone is below the static friction: it
    sticks until the integral breaks it away, then slides). The plant decides friction at the start of each 10 us substep, so it places
    each stop and each breakaway up to one substep (dt) late; the reference places them
    exactly. Both happen at zero speed, so a late one moves the axis by about a*dt^2/2
    (a its acceleration then, below 2000 mm/s^2 here: 1e-7 mm) and the velocity loop's
    integral carries that on: the bound is 1 um/1000, ten such events. Friction itself
    changes the run by over a hundred times that (it is the reference's friction that
    matches, not the linear axis)."""
    x_cmd = lambda t: 20.0 * np.sin(2.0 * np.pi * t)  # noqa: E731
    y_cmd = lambda t: 0.05  # noqa: E731
    start_values = {"x.coulomb": FRICTION["coulomb"], "x.stiction": FRICTION["stiction"],
                    "x.stribeckVelocity": FRICTION["stribeck"]}
    for name in ("coulomb", "stiction"):
        start_values[f"y.{name}"] = FRICTION[name]
    start_values["y.stribeckVelocity"] = FRICTION["stribeck"]
    times, result = run(xy_plant_fmu, 1.5, (x_cmd, y_cmd), start_values)
    bound = 1e-6
    for name, signal in (("x", x_cmd), ("y", y_cmd)):
        commands = held_commands(times, signal)
        pos, vel = simulate_axis_with_friction(PAPER_AXIS, times, commands, **FRICTION)
        error = np.max(np.abs(result[f"pos.{name}"] - pos))
        print(f"{name}: max |position - reference| {error:.3g} mm (bound {bound:.3g})")
        assert error < bound, name
        plain, _ = simulate_axis(PAPER_AXIS, times, commands)
        print(f"{name}: friction changes the position by {np.max(np.abs(plain - pos)):.3g} mm")
        assert np.max(np.abs(plain - pos)) > 100 * bound, name
    # Y breaks away when CT k (Kvp v + Kvi v t) reaches the static torque: at
    # t_b = (Ts / (CT k v) - Kvp) / Kvi = 29.8 ms; it stands still at every sample before.
    a = PAPER_AXIS
    k = 2.0 * np.pi / a["lead"]
    t_b = (FRICTION["stiction"] / (a["CT"] * k * 0.05) - a["Kvp"]) / a["Kvi"]
    still = np.flatnonzero(result["vel.y"] != 0.0)[0]
    assert times[still - 1] < t_b < times[still], (t_b, times[still])
