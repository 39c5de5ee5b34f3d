"""Engine: ecos (the ecospy package) runs a closed loop (by default PathInterpolator2D ->
ContourCCC2D <- XYServoPlant, with --loop five_axis PathInterpolator5X -> ContourCCC5X <-
FiveAxisPlant; see contour_fmu.loops.wiring) and prints the trajectories as one line of
JSON.

Kept in its own process: ecos is native code that can take the interpreter down on a broken
FMU, and it loads its own copy of each FMU.
usage: python -m contour_fmu.engines.ecos [--loop two_axis|five_axis] FMU_DIR STEP STEPS
                                          [UNIT.VARIABLE=VALUE ...]

Values are typed by their text: true/false -> Boolean, an integer -> Integer, a number ->
Real, anything else -> String (ecospy picks the setter from the Python type). They go into
an ecos parameter set applied in initialization mode; this is also how the plant's pos0.*
get the path's start point (ecos connections are transferred at every step, so they cannot
carry an output onto a fixed parameter once, as contour_fmu.engines.master's initial copies do).

The printed object holds
- "initial": {"unit.variable": value} after ecos' init() (outputs at t_0);
- "time": the simulation time after each step (ecos accumulates t += STEP);
- "series": {"unit.variable": [values after steps 1..STEPS]} for the loop's recorded
  outputs, read by a post-step listener once ecos has transferred the connections of that
  step.

Needs the engines extra (ecospy, whose engine needs Debian's libtbb12).
"""

import json
import sys

from ..extras import needs
from ..loops.wiring import engine_arguments

with needs("engines"):
    from ecospy import EcosLib, EcosSimulation, EcosSimulationStructure, SimulationListener


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
    def __init__(self, sim, recorded):
        self.sim, self.recorded, self.time = sim, recorded, []
        self.series = {f"{u}.{v}": [] for u, v in recorded}

    def post(self, info):
        self.time.append(info.time)
        for unit, name in self.recorded:
            self.series[f"{unit}.{name}"].append(self.sim.get_real(ident(unit, name)))


def main(argv, prog=None):
    args = engine_arguments(argv, "A closed loop in ecos", (float, "communication step (s)"), prog)
    loop = args.loop
    parameters = {ident(unit, name): parse_value(text) for unit, name, text in args.assignments}
    EcosLib.set_log_level("warn")

    structure = EcosSimulationStructure()
    for name, file in loop.units.items():
        structure.add_model(name, str(args.fmu_dir / file))
    for src, out, dst, inp in loop.connections:
        structure.make_real_connection(ident(src, out), ident(dst, inp))
    if parameters and not structure.add_parameter_set("start", parameters):
        raise SystemExit(f"ecos: parameter set refused: {EcosLib.get_last_error()}")

    sim = EcosSimulation(structure=structure, step_size=args.step)
    recorder = Recorder(sim, loop.recorded)
    sim.add_listener("recorder", recorder)
    if not sim.init(parameter_set="start" if parameters else None):
        raise SystemExit(f"ecos: init failed: {EcosLib.get_last_error()}")
    # The parameters really reached the FMUs.
    for key, value in parameters.items():
        get = {bool: sim.get_bool, int: sim.get_integer, float: sim.get_real, str: sim.get_string}
        got = get[type(value)](key)
        if got != value:
            raise SystemExit(f"ecos: {key} is {got!r}, expected {value!r}")
    initial = {f"{u}.{v}": sim.get_real(ident(u, v)) for u, v in loop.recorded}
    sim.step(args.steps)
    sim.terminate()
    print(json.dumps({"initial": initial, "time": recorder.time, "series": recorder.series}))


if __name__ == "__main__":
    main(sys.argv[1:])
