"""Engine: libcosim (libcosimpy) runs a closed loop (by default PathInterpolator2D ->
ContourCCC2D <- XYServoPlant, with --loop five_axis PathInterpolator5X -> ContourCCC5X <-
FiveAxisPlant; see contour_fmu.loops.wiring) and prints the trajectories as one line of
JSON.

Kept in its own process: libcosim can take the interpreter down on a broken FMU.
usage: python -m contour_fmu.engines.libcosim [--loop two_axis|five_axis] [--ssp]
                                              FMU_DIR STEP_NS STEPS [UNIT.VARIABLE=VALUE ...]

By default the script adds the loop's FMUs and connections itself; with --ssp libcosim
reads them from the loop's SSP file beside the FMUs (FMU_DIR/<loop>.ssd, which make fmus
puts there), applying its first parameter set (the default path).

libcosim connections are transferred at every step, so they cannot carry an output onto a
fixed parameter once: the plant's pos0.* (the path's start) come as UNIT.VARIABLE=VALUE,
or from the SSP file's parameter set of a built-in path.

The printed object holds
- "time_ns": the execution's final time (integer ns);
- "steps", "time_ns_points": step numbers 1..STEPS and their time points (ns) from the
  time-series observer, which samples every observed variable after each step: step n is
  the state at t = n * STEP_NS;
- "series": {"unit.variable": [values at steps 1..STEPS]} for the loop's recorded outputs;
- "last": {"unit.variable": value} of the same outputs and interpolator.done, from a
  last-value observer after the run.

Needs the engines extra (libcosimpy).
"""

import json
import sys

from ..extras import needs
from ..loops.wiring import engine_arguments

with needs("engines"):
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

DONE = ("interpolator", "done")


def check(ok, what):
    if ok is False or (not isinstance(ok, bool) and ok != 0):
        raise SystemExit(f"libcosim: {what} failed")


def set_initial(execution, index, variable, text):
    kind = CosimVariableType(variable.type)
    ref = variable.reference
    if kind == CosimVariableType.REAL:
        check(execution.real_initial_value(index, ref, float(text)), f"initial value {text}")
    elif kind == CosimVariableType.INTEGER:
        check(execution.integer_initial_value(index, ref, int(text)), f"initial value {text}")
    elif kind == CosimVariableType.BOOLEAN:
        check(execution.boolean_initial_value(index, ref, text.lower() in ("1", "true")), f"initial value {text}")
    else:
        check(execution.string_initial_value(index, ref, text), f"initial value {text}")


def main(argv, prog=None):
    ssp = "--ssp" in argv
    args = engine_arguments([a for a in argv if a != "--ssp"], "A closed loop in libcosim",
                            (int, "communication step (ns)"), prog)
    loop, steps = args.loop, args.steps
    log_output_level(CosimLogLevel.WARNING)

    slaves, index, variables = {}, {}, {}
    if ssp:
        file = args.fmu_dir / f"{loop.structure.name}.ssd"
        if not file.is_file():
            raise SystemExit(f"libcosim: {file} is missing (make fmus puts it beside the FMUs)")
        execution = CosimExecution.from_ssp_file(str(file), step_size=args.step)
        for name in loop.units:
            index[name] = execution.slave_index_from_instance_name(name)
            check(index[name] is not None and index[name] >= 0, f"finding {name} in {file}")
    else:
        execution = CosimExecution.from_step_size(step_size=args.step)
        for name, file in loop.units.items():
            slaves[name] = CosimLocalSlave(fmu_path=str(args.fmu_dir / file), instance_name=name)
            index[name] = execution.add_local_slave(local_slave=slaves[name])
            check(index[name] >= 0, f"adding {file}")
    for name in loop.units:
        variables[name] = {v.name.decode(): v for v in execution.slave_variables(index[name])}

    def ref(unit, name):
        return variables[unit][name].reference

    if not ssp:
        for src, out, dst, inp in loop.connections:
            check(execution.connect_real_variables(index[src], ref(src, out), index[dst],
                                                   ref(dst, inp)),
                  f"connecting {src}.{out} -> {dst}.{inp}")
    for unit, name, text in args.assignments:
        set_initial(execution, index[unit], variables[unit][name], text)

    series = CosimObserver.create_time_series(buffer_size=steps + 16)
    check(execution.add_observer(observer=series), "adding the time-series observer")
    for unit, name in loop.recorded:
        check(series.start_time_series(index[unit], ref(unit, name), CosimVariableType.REAL),
              f"observing {unit}.{name}")
    last = CosimObserver.create_last_value()
    check(execution.add_observer(observer=last), "adding the last-value observer")

    check(execution.step(step_count=steps), "stepping")
    status = execution.status()

    result = {"time_ns": status.current_time, "series": {}, "last": {}}
    for unit, name in loop.recorded:
        # From step 1: libcosimpy trims its sample arrays by the number of zero step numbers,
        # so asking from step 0 would drop the last sample.
        points, numbers, values = series.time_series_real_samples(
            index[unit], ref(unit, name), from_step=1, sample_count=steps)
        result["series"][f"{unit}.{name}"] = list(values)
        result["steps"], result["time_ns_points"] = list(numbers), list(points)
        result["last"][f"{unit}.{name}"] = last.last_real_values(index[unit], [ref(unit, name)])[0]
    unit, name = DONE
    result["last"][f"{unit}.{name}"] = bool(last.last_boolean_values(index[unit], [ref(unit, name)])[0])
    print(json.dumps(result))


if __name__ == "__main__":
    main(sys.argv[1:])
