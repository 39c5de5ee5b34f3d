"""Engine: fmpy's container FMU, a closed loop (by default PathInterpolator2D ->
ContourCCC2D <- XYServoPlant, or PathInterpolator5X -> ContourCCC5X <- FiveAxisPlant; see
contour_fmu.loops.wiring) packed into one FMI 2.0 co-simulation container FMU with
fmpy.container_fmu.

The container exposes the loop's outputs and some parameters as "<component>.<variable>",
among them the targets of the loop's path_start (the plant's pos0.*): the container's
connections are copied at every step, so they cannot carry the path's start onto a fixed
parameter once, and a caller that wants the plant to start on the path sets them.

Conventions of fmpy's container runtime (container_fmu.so) that the description must follow:
- value reference 0 is the container's own time, so modelVariables[0] is "time"
  (causality="independent") and has no entry in the variable mappings;
- value reference i >= 1 is the i-th entry of `variableMappings` (container.json lists the
  mappings in dict order), and create_container_fmu renumbers the variables with their
  index in modelVariables; so modelVariables must be [time] + the mapped variables in the
  mappings' order;
- the container steps its components with `fixedStepSize`, taken from
  coSimulation.fixedInternalStepSize (not written to an FMI 2.0 modelDescription.xml).

fmpy 0.3.32 quirks met here: connection types (see _as_fmi3_type); create_container_fmu
needs `unzipdir` to exist (it removes it first) and zips that directory into a file inside
it, so the FMU carries a stray, truncated "Container.zip" (harmless); parallelDoStep aborts
(see build_container).
"""

import shutil
import uuid
from pathlib import Path

from attrs import evolve
from fmpy import read_model_description
from fmpy.container_fmu import Configuration
from fmpy.container_fmu.cli import create_container_fmu
from fmpy.container_fmu.config import Component, Connection
from fmpy.model_description import (CoSimulation, DefaultExperiment, ModelDescription,
                                    ModelVariable, Unknown)

from ..loops.wiring import LOOPS

_FMI3_TYPES = {"Real": "Float64", "Integer": "Int32", "Enumeration": "Int32"}


def _exposed(name, source, causality):
    """A container variable mirroring `source` (a component's ModelVariable)."""
    v = ModelVariable(name=name, type=source.type, causality=causality,
                      description=source.description, unit=source.unit)
    if causality == "parameter":
        # FMI 2.0 requires a start value on a fixed parameter; it is the component's own,
        # and the container applies it to the component when it is instantiated.
        v.variability, v.initial, v.start = "fixed", "exact", source.start
    else:
        v.variability, v.initial = source.variability, "calculated"
    return v


def _as_fmi3_type(variable):
    """A copy of a component variable typed as the container runtime spells it.

    Works around fmpy 0.3.32: write_configuration() translates Real -> Float64 and
    Integer -> Int32 for the container's variables but writes a connection's type as is, and
    container_fmu.so rejects "Real" ("Failed to parse configuration file: unknown variant
    `Real`"), so FMI 2.0 components could not be connected at all. Only the connection's
    type and value references are taken from the connectors."""
    return evolve(variable, type=_FMI3_TYPES.get(variable.type, variable.type))


def build_container(fmu_dir, workdir, step=1e-3, stop=2.0, order=None, parallel_do_step=False,
                    loop="two_axis"):
    """Writes the container FMU of `loop` (a name in contour_fmu.loops.wiring.LOOPS) into
    `workdir` and returns its path (ContourLoop.fmu for the two-axis loop).

    order: the components' order in container.json, in which the runtime steps them
    (default: the loop's, interpolator, controller, plant).
    parallel_do_step: container.json's "parallelDoStep" (step the components on a thread
    pool). fmpy 0.3.32's runtime does not implement it: fmi2DoStep panics with "not yet
    implemented" and, the panic being unable to unwind through the C ABI, aborts the
    process; only ever try it in a subprocess."""
    loop = LOOPS[loop]
    fmu_dir, workdir = Path(fmu_dir), Path(workdir)
    components, variables, units = {}, {}, {}
    for name in order or loop.units:
        file = loop.units[name]
        md = read_model_description(fmu_dir / file)
        components[name] = Component(name=name, filename=fmu_dir / file, modelDescription=md)
        variables[name] = {v.name: v for v in md.modelVariables}
        units.update((u.name, u) for u in md.unitDefinitions)  # same names, same definitions

    time = ModelVariable(name="time", type="Real", causality="independent",
                         variability="continuous", description="Simulation time")
    mappings = {}
    path_start_targets = [(dst, inp) for _, _, dst, inp in loop.path_start]
    for (unit, name), causality in ([(x, "output") for x in loop.recorded + loop.more_outputs]
                                    + [(x, "parameter") for x in loop.parameters + path_start_targets]):
        source = variables[unit][name]
        mappings[_exposed(f"{unit}.{name}", source, causality)] = [(components[unit], source)]
    model_variables = [time, *mappings]
    outputs = [Unknown(variable=v, dependencies=[]) for v in model_variables if v.causality == "output"]

    model_description = ModelDescription(
        fmiVersion="2.0",
        modelName=loop.container_name,
        instantiationToken="{" + str(uuid.uuid4()) + "}",
        description=f"{loop.title} in an fmpy container",
        generationTool="contour_fmu.engines.container_build (fmpy.container_fmu)",
        variableNamingConvention="structured",
        coSimulation=CoSimulation(modelIdentifier="container_fmu", fixedInternalStepSize=step,
                                  canHandleVariableCommunicationStepSize=False),
        defaultExperiment=DefaultExperiment(startTime="0.0", stopTime=str(stop), stepSize=str(step)),
        unitDefinitions=[units[n] for n in sorted({v.unit for v in model_variables if v.unit})],
        modelVariables=model_variables,
        outputs=outputs,
        initialUnknowns=[Unknown(variable=u.variable) for u in outputs],
    )

    connections = [
        Connection(startElement=components[src], startConnectors=[_as_fmi3_type(variables[src][out])],
                   endElement=components[dst], endConnectors=[_as_fmi3_type(variables[dst][inp])])
        for src, out, dst, inp in loop.connections
    ]

    configuration = Configuration(parallelDoStep=parallel_do_step,
                                  modelDescription=model_description,
                                  components=list(components.values()),
                                  connections=connections, variableMappings=mappings)

    unzipdir = workdir / f"{loop.container_name}.unzipped"
    unzipdir.mkdir(parents=True, exist_ok=True)  # create_container_fmu rmtree()s it first
    filename = workdir / f"{loop.container_name}.fmu"
    filename.unlink(missing_ok=True)
    create_container_fmu(configuration, unzipdir, filename)
    shutil.rmtree(unzipdir, ignore_errors=True)
    return filename
