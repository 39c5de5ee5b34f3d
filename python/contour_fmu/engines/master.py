"""Engine: the fmpy master, a small fixed-step co-simulation master on fmpy's FMU2Slave and
FMU3Slave: FMI 2.0 and FMI 3.0 Co-Simulation FMUs, in any mix (closed_loop,
five_axis_closed_loop; contour_fmu.master.closed_loop is the documented entry point).

Connects FMU outputs to inputs and steps every FMU with one communication step. Two
coupling schemes:

- "gauss-seidel" (default): the FMUs step one after another in the given order, each
  input refreshed from its source just before its FMU steps. With the order
  controller -> plant -> interpolator this is the in-process simulator's sequence: the
  controller acts on the reference and position at t_k, then the plant integrates that
  command over [t_k, t_k+1).
- "jacobi": every input is set from the outputs at t_k, then all FMUs step; this is what
  libcosim does (values exchanged at step boundaries), one step of delay per link.
"""

import shutil
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description

from ..loops.wiring import FIVE_AXIS, LOOPS, TWO_AXIS
from .slaves import PYTHON_TYPES, accessors, kind, open_slave, start
from .stepping import SCHEMES, Stepping


def co_simulation_description(path):
    """The model description of the FMI 2.0 or FMI 3.0 Co-Simulation FMU at `path`.
    Anything else is refused with a ValueError naming the file and saying why: a master
    steps its FMUs through fmi2DoStep or fmi3DoStep, which an FMU exported for Model
    Exchange only does not have (it needs an ODE solver that the FMU does not carry)."""
    md = read_model_description(str(path))
    if md.fmiVersion not in ("2.0", "3.0"):
        raise ValueError(f"{path}: an FMI {md.fmiVersion} FMU; these masters run FMI 2.0 "
                         f"and FMI 3.0 Co-Simulation FMUs")
    if md.coSimulation is None:
        raise ValueError(
            f"{path}: exported for Model Exchange only (no <CoSimulation> in its model "
            f"description), so a co-simulation master cannot step it: it needs an ODE solver "
            f"the FMU does not carry. Export the model for Co-Simulation (Modelica tools "
            f"offer it, with their solver inside), or wrap it in a Co-Simulation FMU.")
    return md


def _unit(variable):
    """A variable's declared unit, its own or its type's (None: none declared)."""
    if variable.unit:
        return variable.unit
    declared = getattr(variable, "declaredType", None)
    return getattr(declared, "unit", None) if declared is not None else None


def check_connections(descriptions, connections):
    """Refuses, with a ValueError naming both ends, a connection (source unit, output,
    destination unit, input) to a unit or variable that does not exist, between
    variables of different types, or between Real variables whose declared units differ
    (an mm controller on an SI plant moves it a thousand times too far: take every FMU
    from one build, target/fmu or target/fmu-si). `descriptions` maps unit names to
    model descriptions."""
    def variable(unit, name):
        if unit not in descriptions:
            raise ValueError(f"connection names unit {unit!r}, which the loop does not have "
                             f"(units: {', '.join(descriptions)})")
        found = next((v for v in descriptions[unit].modelVariables if v.name == name), None)
        if found is None:
            raise ValueError(f"{unit} has no variable {name!r}")
        return found
    for src, out, dst, inp in connections:
        a, b = variable(src, out), variable(dst, inp)
        if kind(a.type) != kind(b.type):
            raise ValueError(f"connection {src}.{out} -> {dst}.{inp}: a {a.type} onto a {b.type}")
        ua, ub = _unit(a), _unit(b)
        if ua and ub and ua != ub:
            raise ValueError(
                f"connection {src}.{out} -> {dst}.{inp}: units differ ({ua} onto {ub}); take "
                f"every FMU from one build (target/fmu in mm, target/fmu-si in SI) or convert "
                f"in the plant model")


def set_value(slave, variable, value):
    """Sets one variable (an fmpy model variable) of a slave of either standard, by its
    type."""
    _, put = accessors(slave, variable.type)
    put([variable.valueReference], [PYTHON_TYPES[kind(variable.type)](value)])


def free_all(slaves):
    """Terminates (when it can) and frees every slave: a failed run still frees its
    instances."""
    for slave in slaves:
        try:
            slave.terminate()
        except Exception:  # noqa: BLE001  an instance in an error state may refuse to terminate
            pass
        slave.freeInstance()


@dataclass
class Unit:
    name: str
    path: str
    start_values: dict = field(default_factory=dict)


class Master:
    """Use as a context manager: instantiated and initialized on entry, freed on exit."""

    def __init__(self, units, connections, step, stop, scheme="gauss-seidel", initial=(), log=None):
        """units: list of Unit in stepping order; connections: list of (source unit,
        output name, destination unit, input name); initial: connections applied once in
        initialization mode, in order (e.g. an output onto a parameter); log: a
        contour_fmu.engines.fmu_log.FmuLog that collects the FMUs' messages (default: fmpy's
        logger, which prints them)."""
        if scheme not in SCHEMES:
            raise ValueError(f"unknown coupling scheme {scheme!r}; expected one of {SCHEMES}")
        self.units, self.connections, self.initial = units, connections, initial
        self.step, self.stop, self.scheme, self.log = step, stop, scheme, log
        self.slaves, self.variables, self._dirs = {}, {}, []

    def __enter__(self):
        descriptions = {u.name: co_simulation_description(u.path) for u in self.units}
        check_connections(descriptions, list(self.connections) + list(self.initial))
        for u in self.units:
            md = descriptions[u.name]
            directory = extract(u.path)
            self._dirs.append(directory)
            slave = open_slave(md, directory, u.name)
            self.slaves[u.name] = slave
            self.variables[u.name] = {v.name: v for v in md.modelVariables}
            start(slave, self.stop, self.log)
            for name, value in u.start_values.items():
                self.set(u.name, name, value)
        for src, out, dst, inp in self.initial:
            self.set(dst, inp, self.get(src, out))
        for u in self.units:
            self.slaves[u.name].exitInitializationMode()
        return self

    def __exit__(self, *exc):
        free_all(self.slaves.values())
        for d in self._dirs:
            shutil.rmtree(d, ignore_errors=True)

    def set(self, unit, name, value):
        set_value(self.slaves[unit], self.variables[unit][name], value)

    def get(self, unit, name):
        v = self.variables[unit][name]
        get, _ = accessors(self.slaves[unit], v.type)
        return get([v.valueReference])[0]

    def run(self, record):
        """Steps from 0 to the stop time (contour_fmu.engines.stepping). Returns two structured
        arrays with a 'time' column and one column "unit.variable" per (unit, variable) in
        `record`: `before[k]` holds the outputs at t_k before the step from t_k, `after[k]`
        the outputs once every FMU has stepped to t_k+1 (for a sampled controller: the
        command it computed at t_k)."""
        steps = int(round(self.stop / self.step))
        stepping = Stepping({u.name: self.slaves[u.name] for u in self.units}, self.variables,
                            self.connections, self.scheme)
        _, before, after = stepping.run(self.step, steps, before=record, after=record)
        dtype = [("time", float)] + [(f"{u}.{v}", float) for u, v in record]
        before = [(k * self.step, *row) for k, row in enumerate(before)]
        after = [(k * self.step + self.step, *row) for k, row in enumerate(after)]
        return np.array(before, dtype=dtype), np.array(after, dtype=dtype)


CLOSED_LOOP_RECORD = [
    ("interpolator", "ref.x"), ("interpolator", "ref.y"),
    ("plant", "pos.x"), ("plant", "pos.y"),
    ("controller", "u.x"), ("controller", "u.y"),
    ("controller", "contourError"),
    ("controller", "ccc.Kp"), ("controller", "ccc.Ki"), ("controller", "ccc.Kd"),
]


def closed_loop(fmu_dir, path="circle", feed=None, stop=2.0, step=1e-3, controller=None,
                plant=None, scheme="gauss-seidel", interpolator=None):
    """Runs PathInterpolator2D -> ContourCCC2D <- XYServoPlant; returns (before, after).
    `interpolator` holds further PathInterpolator2D start values (they override `path`).
    The FMUs' own defaults apply where nothing is given: the paper's loop, without
    feed-forward; `controller=LOOPS["two_axis"].feed_forward` (contour_fmu.loops.wiring)
    adds the shipped loop's."""
    return _shipped_loop(TWO_AXIS, CLOSED_LOOP_RECORD, fmu_dir, path, feed, stop, step,
                         controller, plant, scheme, interpolator)


def _shipped_loop(structure, record, fmu_dir, path, feed, stop, step, controller, plant,
                  scheme, interpolator):
    """A shipped loop from t = 0 to `stop`, `record` recorded: (before, after)."""
    interpolator = {"path": path, **(interpolator or {})}
    if feed is not None:
        interpolator["feed"] = feed
    units = loop_units(structure, fmu_dir, {"controller": controller, "plant": plant,
                                            "interpolator": interpolator})
    with Master(units, structure.connections, step, stop, scheme,
                initial=structure.initial_copies) as master:
        return master.run(record)


def loop_units(structure, fmu_dir, start_values):
    """The Units of a shipped loop, its FMUs in `fmu_dir`, in its stepping order
    (controller -> plant -> interpolator: with Gauss-Seidel the controller acts on ref(t_k)
    and pos(t_k), and the plant integrates the command u_k it produced)."""
    return [Unit(name, str(Path(fmu_dir) / structure.units[name]),
                 dict(start_values.get(name) or {})) for name in structure.order]


# Every output the engines record for the five-axis loop (contour_fmu.loops.wiring.LOOPS).
FIVE_AXIS_RECORD = LOOPS["five_axis"].recorded


def five_axis_closed_loop(fmu_dir, path="tilted_helix", feed=None, stop=1.0, step=1e-3,
                          controller=None, plant=None, scheme="gauss-seidel", interpolator=None):
    """Runs PathInterpolator5X -> ContourCCC5X <- FiveAxisPlant; returns (before, after) as
    `closed_loop` does. `interpolator` holds further PathInterpolator5X start values."""
    return _shipped_loop(FIVE_AXIS, FIVE_AXIS_RECORD, fmu_dir, path, feed, stop, step,
                         controller, plant, scheme, interpolator)
