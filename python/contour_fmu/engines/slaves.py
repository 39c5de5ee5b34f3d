"""Engine: an FMU of either standard as the masters' slave. FMI 2.0 FMUs are fmpy's
FMU2Slave; FMI 3.0 Co-Simulation FMUs are fmpy's FMU3Slave. Both are opened, started and
read through the functions here, by the variables' types, so the stepping loop does not
care which standard a unit speaks (an FMI 2.0 plant can drive an FMI 3.0 controller)."""

from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

# A variable's type in either standard, as the kind of value it holds: FMI 3.0's Float64
# is FMI 2.0's Real, Int32 its Integer; an Enumeration is an Integer in FMI 2.0 and is read
# and written as Int64 in FMI 3.0.
KINDS = {"Real": "Real", "Float64": "Real", "Integer": "Integer", "Int32": "Integer",
         "Int64": "Integer", "Enumeration": "Integer", "Boolean": "Boolean", "String": "String"}
PYTHON_TYPES = {"Real": float, "Integer": int, "Boolean": bool, "String": str}


def kind(variable_type):
    """The kind of value ('Real', 'Integer', 'Boolean', 'String') of an fmpy variable type."""
    try:
        return KINDS[variable_type]
    except KeyError:
        raise ValueError(f"variables of type {variable_type} are not supported") from None


def open_slave(description, directory, name):
    """An uninstantiated slave of the FMU unpacked in `directory` (its `description` read
    by fmpy), of the class its fmiVersion calls for."""
    identifier = description.coSimulation.modelIdentifier
    if description.fmiVersion.startswith("3."):
        return FMU3Slave(guid=description.instantiationToken, unzipDirectory=directory,
                         modelIdentifier=identifier, instanceName=name)
    return FMU2Slave(guid=description.guid, unzipDirectory=directory,
                     modelIdentifier=identifier, instanceName=name)


def start(slave, stop, log=None):
    """Instantiates `slave` and enters initialization mode for an experiment from t = 0 to
    `stop` (FMI 3.0 takes the experiment there, FMI 2.0 in fmi2SetupExperiment). `log`: a
    contour_fmu.engines.fmu_log.FmuLog (None: fmpy prints the messages)."""
    if isinstance(slave, FMU3Slave):
        slave.instantiate(logMessage=None if log is None else log.fmi3_callback(slave.instanceName))
        slave.enterInitializationMode(startTime=0.0, stopTime=stop)
        return
    slave.instantiate(callbacks=None if log is None else log.callbacks)
    slave.setupExperiment(startTime=0.0, stopTime=stop)
    slave.enterInitializationMode()


def accessors(slave, variable_type):
    """(get, set) of `slave` for variables of `variable_type` (lists of value references;
    strings read as str)."""
    value_kind = kind(variable_type)
    if isinstance(slave, FMU3Slave):
        if value_kind == "Real":
            return slave.getFloat64, slave.setFloat64
        if value_kind == "Integer":
            if variable_type in ("Enumeration", "Int64"):
                return slave.getInt64, slave.setInt64
            return slave.getInt32, slave.setInt32
        if value_kind == "Boolean":
            return slave.getBoolean, slave.setBoolean
        return slave.getString, slave.setString
    if value_kind == "Real":
        return slave.getReal, slave.setReal
    if value_kind == "Integer":
        return slave.getInteger, slave.setInteger
    if value_kind == "Boolean":
        return slave.getBoolean, slave.setBoolean
    return (lambda vrs: [s.decode() for s in slave.getString(vrs)]), slave.setString
