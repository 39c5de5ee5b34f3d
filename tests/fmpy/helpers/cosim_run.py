"""Runs one FMU in libcosim (libcosimpy) and prints the last values as JSON.

Kept in its own process: libcosim can take the interpreter down on a broken FMU.
usage: python tests/fmpy/helpers/cosim_run.py FMU STEP_NS STEPS VR_IN=VALUE... --observe VR...
"""

import json
import sys

from libcosimpy.CosimEnums import CosimVariableType  # noqa: F401  (imported for clarity)
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave


def main(argv):
    fmu, step_ns, steps = argv[0], int(argv[1]), int(argv[2])
    split = argv.index("--observe")
    inputs = [a.split("=") for a in argv[3:split]]
    observe = [int(v) for v in argv[split + 1 :]]
    log_output_level(CosimLogLevel.WARNING)
    execution = CosimExecution.from_step_size(step_size=step_ns)
    slave = CosimLocalSlave(fmu_path=fmu, instance_name="plant")
    index = execution.add_local_slave(local_slave=slave)
    for vr, value in inputs:
        execution.real_initial_value(slave_index=index, variable_reference=int(vr), value=float(value))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer=observer)
    assert execution.step(step_count=steps)
    values = observer.last_real_values(slave_index=index, variable_references=observe)
    status = execution.status()
    print(json.dumps({"values": list(values), "time_ns": status.current_time}))


if __name__ == "__main__":
    main(sys.argv[1:])
