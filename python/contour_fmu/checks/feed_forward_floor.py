"""Reference check: the floor of feed-forward, what an ideal inverse-model feed-forward leaves
on the test plants (docs/design/two-axis.md §4.12b).

The test plants' drives are known exactly (docs/design/two-axis.md §4.5): per axis the states
position x, velocity v and the PI integral z, linear in the velocity command u,

    dv/dt = (CT·(Kvp·(u − v) + Kvi·z) − B·v) / J,    dz/dt = u − v,

and the command is held over each step h. `ideal_commands` inverts that model, discretised
exactly here (scipy's matrix exponential, independently of the Rust plant): the command
held over [t_k, t_k+h] that brings the model's velocity to the reference's velocity at
t_k+h, from the model's own state (open loop, from rest). That is the inverse any
feed-forward approximates, with a one-sample preview that the controller's `vref` and
`aref` do not have. `floor_run` adds the controller's P position loop on what is left and
drives the plant FMU with it: its contour error is what no feed-forward on these drives
can remove, the floor the shipped loop is measured against.
"""

from pathlib import Path

import numpy as np
from fmpy import read_model_description
from scipy.linalg import expm

from ..engines.master import Master, Unit


def axis_matrices(J, B, CT, Kvp, Kvi, h):
    """The exact discretisation (A_d, b_d) of one axis's (x, v, z) for a command held over h."""
    a = np.array([[0.0, 1.0, 0.0],
                  [0.0, -(CT * Kvp + B) / J, CT * Kvi / J],
                  [0.0, -1.0, 0.0]])
    b = np.array([0.0, CT * Kvp / J, 1.0])
    augmented = np.zeros((4, 4))
    augmented[:3, :3], augmented[:3, 3] = a * h, b * h
    e = expm(augmented)
    return e[:3, :3], e[:3, 3]


def ideal_commands(velocities, drive, h):
    """The held commands u_k (one per sample but the last) that bring the model axis from
    rest at velocities[0] = 0 to velocities[k+1] at every t_k+1. `drive` = dict(J, B, CT,
    Kvp, Kvi)."""
    a_d, b_d = axis_matrices(drive["J"], drive["B"], drive["CT"], drive["Kvp"], drive["Kvi"], h)
    state = np.zeros(3)
    commands = np.empty(len(velocities) - 1)
    for k in range(len(commands)):
        free = a_d @ state
        commands[k] = (velocities[k + 1] - free[1]) / b_d[1]
        state = free + b_d * commands[k]
    return commands


def acceleration_time(drive, h):
    """The acceleration feed-forward time (s) that fits a drive whose PI zero cancels its
    mechanical pole (Kvi/Kvp = B/J, the test plants'): its velocity loop is then first order
    with time constant tau = J/(CT·Kvp), and a command held over h reaches the velocity v_k
    + a·h at t_k+h when it is v_k + a·h/(1 − e^(−h/tau)) = v_k + a·(tau + h/2 + h²/(12 tau)
    + ...)."""
    tau = drive["J"] / (drive["CT"] * drive["Kvp"])
    return h / -np.expm1(-h / tau)


def drive_parameters(fmu_path, axes, values=None):
    """Each axis's dict(J, B, CT, Kvp, Kvi): the plant FMU's start values, with `values`
    (name -> value) over them."""
    values = values or {}
    md = read_model_description(str(fmu_path))
    start = {v.name: float(v.start) for v in md.modelVariables
             if v.causality == "parameter" and v.type == "Real"}
    start.update(values)
    return {a: {p: start[f"{a}.{p}"] for p in ("J", "B", "CT", "Kvp", "Kvi")} for a in axes}


def _record_reference(fmu_path, start_values, names, h, steps):
    """Runs the interpolator FMU alone: its outputs `names` at t_0 .. t_steps."""
    units = [Unit("reference", str(fmu_path), start_values)]
    with Master(units, [], h, steps * h) as master:
        before, after = master.run([("reference", n) for n in names])
    columns = [f"reference.{n}" for n in names]
    first = np.array([[before[c][0] for c in columns]])
    return np.vstack([first, np.column_stack([after[c] for c in columns])])


def floor_run(fmu_dir, loop, interpolator, stop, h=1e-3, position_gain=28.5, plant=None):
    """The plant FMU of `loop` ("two_axis": PathInterpolator2D, XYServoPlant; "five_axis":
    PathInterpolator5X, FiveAxisPlant) driven by the ideal inverse-model feed-forward plus a
    P position loop of `position_gain` (ContourCCC's default): (reference, positions), one
    row per sample t_0 .. t_stop."""
    fmu_dir = Path(fmu_dir)
    if loop == "two_axis":
        names, interpolator_fmu, plant_fmu = ("x", "y"), "PathInterpolator2D", "XYServoPlant"
    else:
        names, interpolator_fmu = ("X", "Y", "Z", "A", "C"), "PathInterpolator5X"
        plant_fmu = "FiveAxisPlant"
    steps = int(round(stop / h))
    recorded = _record_reference(fmu_dir / f"{interpolator_fmu}.fmu", interpolator,
                                 [f"ref.{a}" for a in names] + [f"vref.{a}" for a in names],
                                 h, steps)
    reference, velocity = recorded[:, :len(names)], recorded[:, len(names):]
    drives = drive_parameters(fmu_dir / f"{plant_fmu}.fmu", names, plant)
    feed_forward = np.column_stack([ideal_commands(velocity[:, i], drives[a], h)
                                    for i, a in enumerate(names)])
    start = {**(plant or {}), **{f"pos0.{a}": reference[0, i] for i, a in enumerate(names)}}
    units = [Unit("plant", str(fmu_dir / f"{plant_fmu}.fmu"), start)]
    with Master(units, [], h, stop) as master:
        slave, variables = master.slaves["plant"], master.variables["plant"]
        position = [variables[f"pos.{a}"].valueReference for a in names]
        command = [variables[f"u.{a}"].valueReference for a in names]
        rows = [slave.getReal(position)]
        for k in range(steps):
            u = position_gain * (reference[k] - np.array(rows[-1])) + feed_forward[k]
            slave.setReal(command, list(u))
            slave.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
            rows.append(slave.getReal(position))
    return reference, np.array(rows)
