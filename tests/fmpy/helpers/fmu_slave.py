"""One FMU instance through fmpy's FMU2Slave, with its log captured and its variables
reached by name (shared by the FMU tests)."""

import shutil

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from contour_fmu.engines.fmu_log import FmuLog


class Slave:
    """One FMU2Slave with a captured log and access by variable name."""

    def __init__(self, fmu_path, name="test"):
        self.md = read_model_description(fmu_path)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.dir = extract(fmu_path)
        self.log = FmuLog()
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.dir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate(callbacks=self.log.callbacks)
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()

    def set(self, **values):
        for name, value in values.items():
            name = name.replace("__", ".")
            kind = next(v.type for v in self.md.modelVariables if v.name == name)
            setter = {"Real": self.fmu.setReal, "Boolean": self.fmu.setBoolean,
                      "String": self.fmu.setString, "Integer": self.fmu.setInteger,
                      "Enumeration": self.fmu.setInteger}[kind]
            setter([self.vr[name]], [value])

    def reals(self, names):
        return np.array(self.fmu.getReal([self.vr[n] for n in names]))

    def close(self):
        self.fmu.freeInstance()
        shutil.rmtree(self.dir, ignore_errors=True)
