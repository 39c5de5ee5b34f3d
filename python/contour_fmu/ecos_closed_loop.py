"""Runs the closed loop PathInterpolator2D -> ContourCCC2D <- XYServoPlant in ecos (the
ecospy package) and prints the trajectories as one line of JSON.

Kept in its own process: ecos is native code that can take the interpreter down on a broken
FMU, and it loads its own copy of each FMU.
usage: python -m contour_fmu.ecos_closed_loop FMU_DIR STEP STEPS [UNIT.VARIABLE=VALUE ...]

Values are typed by their text: true/false -> Boolean, an integer -> Integer, a number ->
Real, anything else -> String (ecospy picks the setter from the Python type). They go into
an ecos parameter set applied in initialization mode; this is also how the plant's pos0.*
get the path's start point (ecos connections are transferred at every step, so they cannot
carry an output onto a fixed parameter once, as contour_fmu.master's PATH_START does).

The printed object holds
- "initial": {"unit.variable": value} after ecos' init() (outputs at t_0);
- "time": the simulation time after each step (ecos accumulates t += STEP);
- "series": {"unit.variable": [values after steps 1..STEPS]}, read by a post-step listener
  once ecos has transferred the connections of that step.
"""

import json
import sys
from pathlib import Path

from ecospy import EcosLib, EcosSimulation, EcosSimulationStructure, SimulationListener

from .wiring import CLOSED_LOOP_CONNECTIONS

UNITS = {  # instance name -> FMU file, in contour_fmu.master.closed_loop's order
    "controller": "ContourCCC2D.fmu",
    "plant": "XYServoPlant.fmu",
    "interpolator": "PathInterpolator2D.fmu",
}
SERIES = [
    ("interpolator", "ref.x"), ("interpolator", "ref.y"),
    ("plant", "pos.x"), ("plant", "pos.y"),
    ("controller", "u.x"), ("controller", "u.y"), ("controller", "contourError"),
    ("controller", "ccc.Kp"),
]


def ident(unit, name):
    return f"{unit}::{name}"


def parse_value(text):
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


class Recorder(SimulationListener):
    def __init__(self, sim):
        self.sim, self.time = sim, []
        self.series = {f"{u}.{v}": [] for u, v in SERIES}

    def post(self, info):
        self.time.append(info.time)
        for unit, name in SERIES:
            self.series[f"{unit}.{name}"].append(self.sim.get_real(ident(unit, name)))


def main(argv):
    fmu_dir, step, steps = Path(argv[0]), float(argv[1]), int(argv[2])
    parameters = {}
    for assignment in argv[3:]:
        target, text = assignment.split("=", 1)
        unit, name = target.split(".", 1)
        parameters[ident(unit, name)] = parse_value(text)
    EcosLib.set_log_level("warn")

    structure = EcosSimulationStructure()
    for name, file in UNITS.items():
        structure.add_model(name, str(fmu_dir / file))
    for src, out, dst, inp in CLOSED_LOOP_CONNECTIONS:
        structure.make_real_connection(ident(src, out), ident(dst, inp))
    if parameters and not structure.add_parameter_set("start", parameters):
        raise SystemExit(f"ecos: parameter set refused: {EcosLib.get_last_error()}")

    sim = EcosSimulation(structure=structure, step_size=step)
    recorder = Recorder(sim)
    sim.add_listener("recorder", recorder)
    if not sim.init(parameter_set="start" if parameters else None):
        raise SystemExit(f"ecos: init failed: {EcosLib.get_last_error()}")
    # The parameters really reached the FMUs.
    for key, value in parameters.items():
        get = {bool: sim.get_bool, int: sim.get_integer, float: sim.get_real, str: sim.get_string}
        got = get[type(value)](key)
        if got != value:
            raise SystemExit(f"ecos: {key} is {got!r}, expected {value!r}")
    initial = {f"{u}.{v}": sim.get_real(ident(u, v)) for u, v in SERIES}
    sim.step(steps)
    sim.terminate()
    print(json.dumps({"initial": initial, "time": recorder.time, "series": recorder.series}))


if __name__ == "__main__":
    main(sys.argv[1:])
