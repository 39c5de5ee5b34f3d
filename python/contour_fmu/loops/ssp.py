"""Loop wiring: the SSP 1.0 format of the loops, system structure descriptions (.ssd)
read and written: which FMUs, how they are wired, the start values of each built-in path,
and what SSP itself has no word for (the order a Gauss-Seidel master steps the units in,
and outputs copied onto parameters once in initialization mode), in an annotation of
ours. Standard library only: any process can read a loop without loading fmpy or an
engine.
"""

import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
LOOP = "urn:contour-fmu:ssp:loop"
LOOP_ANNOTATION = "com.contour-fmu.loop"
# The folder of the loops shipped with the package.
SHIPPED = Path(__file__).resolve().parent
# xs:boolean is true, false, 1 or 0.
TYPES = {"Real": float, "Integer": int, "Boolean": lambda text: {"true": True, "1": True,
                                                                 "false": False, "0": False}[text],
         "String": str}


@dataclass(frozen=True)
class SystemStructure:
    name: str
    file: Path
    units: dict  # component name -> FMU file (relative to the .ssd), in the file's order
    order: list  # the component names in the order a Gauss-Seidel master steps them
    connections: list  # (source unit, output, destination unit, input), at every step
    initial_copies: list  # the same, copied once in initialization mode
    parameter_sets: dict  # set name -> {unit: {variable: value}}, in the file's order

    def start_values(self, parameter_set):
        """{unit: {variable: value}} of `parameter_set` (an unknown name is refused)."""
        if parameter_set not in self.parameter_sets:
            raise ValueError(f"{self.file}: no parameter set {parameter_set!r} (it has "
                             f"{', '.join(self.parameter_sets) or 'none'})")
        return self.parameter_sets[parameter_set]


def _ends(element):
    return (element.get("startElement"), element.get("startConnector"),
            element.get("endElement"), element.get("endConnector"))


def read(file):
    """The system structure in `file`; a ValueError naming the file says what is wrong."""
    file = Path(file)
    try:
        root = ET.parse(file).getroot()
    except (OSError, ET.ParseError) as e:
        raise ValueError(f"{file}: not a readable system structure description: {e}") from None
    if root.tag != f"{{{SSD}}}SystemStructureDescription" or root.get("version") != "1.0":
        raise ValueError(f"{file}: not an SSP 1.0 SystemStructureDescription")
    system = root.find(f"{{{SSD}}}System")
    if system is None:
        raise ValueError(f"{file}: no <ssd:System>")
    units, connectors, sets = {}, {}, {}
    for component in system.iterfind(f"{{{SSD}}}Elements/{{{SSD}}}Component"):
        name, source = component.get("name"), component.get("source")
        if not name or not source:
            raise ValueError(f"{file}: a component without a name or a source")
        units[name] = source
        connectors[name] = {c.get("name"): c for c in
                            component.iterfind(f"{{{SSD}}}Connectors/{{{SSD}}}Connector")}
        for values in component.iterfind(f"{{{SSD}}}ParameterBindings/{{{SSD}}}ParameterBinding/"
                                         f"{{{SSD}}}ParameterValues/{{{SSV}}}ParameterSet"):
            assigned = sets.setdefault(values.get("name"), {}).setdefault(name, {})
            for parameter in values.iterfind(f"{{{SSV}}}Parameters/{{{SSV}}}Parameter"):
                what = f"{file}: {name}.{parameter.get('name')}"
                typed = list(parameter)
                kind = typed[0].tag.rsplit("}", 1)[1] if len(typed) == 1 else None
                if kind not in TYPES:
                    raise ValueError(f"{what}: a parameter needs one value of type "
                                     f"{', '.join(TYPES)}")
                try:
                    assigned[parameter.get("name")] = TYPES[kind](typed[0].get("value"))
                except (TypeError, ValueError, KeyError):
                    raise ValueError(f"{what}: {typed[0].get('value')!r} is no {kind}") from None

    def checked(ends, what):
        for unit, connector in (ends[:2], ends[2:]):
            if unit not in units:
                raise ValueError(f"{file}: {what} names component {unit!r}, which is not one "
                                 f"of {', '.join(units)}")
            if connector not in connectors[unit]:
                raise ValueError(f"{file}: {what} names {unit}.{connector}, which is not "
                                 f"among {unit}'s connectors")
        return ends

    connections = [checked(_ends(c), "a connection")
                   for c in system.iterfind(f"{{{SSD}}}Connections/{{{SSD}}}Connection")]
    loop = None
    for annotation in system.iterfind(f"{{{SSD}}}Annotations/{{{SSC}}}Annotation"):
        if annotation.get("type") == LOOP_ANNOTATION:
            loop = annotation.find(f"{{{LOOP}}}Loop")
    order = loop.get("order", "").split() if loop is not None else list(units)
    if sorted(order) != sorted(units):
        raise ValueError(f"{file}: the step order {order} does not list each component once")
    copies = ([checked(_ends(c), "an initial copy") for c in loop.iterfind(f"{{{LOOP}}}InitialCopy")]
              if loop is not None else [])
    return SystemStructure(name=root.get("name"), file=file, units=units, order=order,
                           connections=connections, initial_copies=copies, parameter_sets=sets)


def shipped(name):
    """The loop `name` (two_axis, five_axis) shipped with the package."""
    return read(SHIPPED / f"{name}.ssd")


def _variables(fmu):
    """{name: (causality, type)} of the FMU archive `fmu`, from its model description."""
    import zipfile

    with zipfile.ZipFile(fmu) as archive:
        root = ET.fromstring(archive.read("modelDescription.xml"))
    found = {}
    for variable in root.iter("ScalarVariable"):
        typed = next(child for child in variable if child.tag in ("Real", "Integer", "Enumeration",
                                                                   "Boolean", "String"))
        kind = "Integer" if typed.tag == "Enumeration" else typed.tag
        found[variable.get("name")] = (variable.get("causality", "local"), kind)
    return found


def _xml_value(kind, value):
    if kind == "Boolean":
        return "true" if value else "false"
    return repr(float(value)) if kind == "Real" else str(value)


def write_loop(file, name, units, order, connections, initial_copies=(), start_values=None,
               step=None):
    """Writes a loop as an SSP 1.0 system structure description at `file`, readable by
    `read`, by contour-cosim and by libcosim: `units` (component -> FMU file, an absolute
    path or one relative to the file's folder), the Gauss-Seidel `order`, `connections` and
    `initial_copies` as (source unit, output, destination unit, input), `start_values`
    ({unit: {variable: value}}) as the parameter set "default", and `step` (s) as the
    default experiment's fixed step. Each connector's kind and type come from its FMU's
    model description."""
    file = Path(file)
    start_values = start_values or {}
    described = {unit: _variables(Path(fmu) if Path(fmu).is_absolute() else file.parent / fmu)
                 for unit, fmu in units.items()}
    used = {unit: [] for unit in units}
    for src, out, dst, inp in [*connections, *initial_copies]:
        for unit, variable in ((src, out), (dst, inp)):
            if variable not in described[unit]:
                raise ValueError(f"{units[unit]} ({unit}) has no variable {variable!r}")
            if variable not in used[unit]:
                used[unit].append(variable)
    for unit, values in start_values.items():
        for variable in values:
            if variable not in described[unit]:
                raise ValueError(f"{units[unit]} ({unit}) has no variable {variable!r}")
            if variable not in used[unit]:
                used[unit].append(variable)
    from xml.sax.saxutils import quoteattr

    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f'<ssd:SystemStructureDescription xmlns:ssd="{SSD}" xmlns:ssc="{SSC}" xmlns:ssv="{SSV}"',
             f'    xmlns:osp="https://opensimulationplatform.com/SSP/OSPAnnotations" xmlns:cf="{LOOP}"',
             f'    version="1.0" name={quoteattr(name)} generationTool="contour-fmu">',
             f'  <ssd:System name={quoteattr(name)}>', "    <ssd:Elements>"]
    for unit, fmu in units.items():
        lines.append(f'      <ssd:Component name={quoteattr(unit)} source={quoteattr(str(fmu))} '
                     'type="application/x-fmu-sharedlibrary">')
        lines.append("        <ssd:Connectors>")
        for variable in used[unit]:
            causality, kind = described[unit][variable]
            lines.append(f'          <ssd:Connector name={quoteattr(variable)} kind={quoteattr(causality)}>'
                         f'<ssc:{kind}/></ssd:Connector>')
        lines.append("        </ssd:Connectors>")
        if start_values.get(unit):
            lines += ["        <ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues>",
                      '          <ssv:ParameterSet version="1.0" name="default"><ssv:Parameters>']
            for variable, value in start_values[unit].items():
                kind = described[unit][variable][1]
                lines.append(f'            <ssv:Parameter name={quoteattr(variable)}><ssv:{kind} '
                             f'value={quoteattr(_xml_value(kind, value))}/></ssv:Parameter>')
            lines += ["          </ssv:Parameters></ssv:ParameterSet>",
                      "        </ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>"]
        lines.append("      </ssd:Component>")
    lines += ["    </ssd:Elements>", "    <ssd:Connections>"]
    ends = lambda c: (f'startElement={quoteattr(c[0])} startConnector={quoteattr(c[1])} '  # noqa: E731
                      f'endElement={quoteattr(c[2])} endConnector={quoteattr(c[3])}')
    lines += [f"      <ssd:Connection {ends(c)}/>" for c in connections]
    lines += ["    </ssd:Connections>", "    <ssd:Annotations>",
              f'      <ssc:Annotation type="{LOOP_ANNOTATION}">',
              f'        <cf:Loop order={quoteattr(" ".join(order))}>']
    lines += [f"          <cf:InitialCopy {ends(c)}/>" for c in initial_copies]
    lines += ["        </cf:Loop>", "      </ssc:Annotation>", "    </ssd:Annotations>", "  </ssd:System>"]
    if step is not None:
        lines += ['  <ssd:DefaultExperiment startTime="0.0"><ssd:Annotations>',
                  '    <ssc:Annotation type="com.opensimulationplatform"><osp:Algorithm>'
                  f'<osp:FixedStepAlgorithm baseStepSize="{float(step)!r}"/></osp:Algorithm></ssc:Annotation>',
                  "  </ssd:Annotations></ssd:DefaultExperiment>"]
    lines.append("</ssd:SystemStructureDescription>")
    file.write_text("\n".join(lines) + "\n")
    return file


def with_sources(file, sources):
    """The text of the SSP file `file` with the FMU files of some components renamed
    (`sources`: component name -> file name); the rest unchanged."""
    ET.register_namespace("ssd", SSD)
    ET.register_namespace("ssc", SSC)
    ET.register_namespace("ssv", SSV)
    ET.register_namespace("cf", LOOP)
    ET.register_namespace("osp", "https://opensimulationplatform.com/SSP/OSPAnnotations")
    tree = ET.parse(file)
    for component in tree.getroot().iterfind(f"{{{SSD}}}System/{{{SSD}}}Elements/{{{SSD}}}Component"):
        if component.get("name") in sources:
            component.set("source", sources[component.get("name")])
    return ET.tostring(tree.getroot(), encoding="unicode", xml_declaration=True)


def si_variant(file, model_descriptions):
    """The text of the SSP file `file` for the SI build: every Real start value of a
    length (a variable the mm model description in `model_descriptions`, a folder of
    <Model>.xml, declares in mm, mm/s, ...) in metres; the rest unchanged, line for line.
    make fmus puts the result beside the SI FMUs (python -m contour_fmu.loops.ssp writes them)."""
    file = Path(file)
    scale_of = {}
    for component, source in read(file).units.items():
        description = ET.parse(Path(model_descriptions) / f"{Path(source).stem}.xml").getroot()
        for variable in description.iter("ScalarVariable"):
            real = variable.find("Real")
            if real is not None and (real.get("unit") or "").startswith("mm"):
                scale_of[component, variable.get("name")] = 1e-3
    lines, component = [], None
    for line in file.read_text().splitlines(keepends=True):
        found = re.search(r'<ssd:Component name="([^"]+)"', line)
        if found:
            component = found.group(1)
        parameter = re.search(r'<ssv:Parameter name="([^"]+)"><ssv:Real value="([^"]+)"/>', line)
        if parameter and (component, parameter.group(1)) in scale_of:
            value = float(parameter.group(2)) * scale_of[component, parameter.group(1)]
            line = line.replace(f'value="{parameter.group(2)}"', f'value="{value!r}"')
        line = line.replace("copies it into target/fmu.", "copies it into target/fmu-si.")
        line = line.replace("The loop every contour_fmu master runs (contour_fmu.loops.wiring reads this file).",
                            "The SI build's copy, lengths in m (python -m contour_fmu.loops.ssp writes it).")
        lines.append(line)
    return "".join(lines)


def main(argv=None):
    """Writes the SI variants of the shipped loops (loops/si/) from the mm ones and the
    committed model descriptions of the repository at `argv[0]` (default: the checkout)."""
    import sys
    argv = sys.argv[1:] if argv is None else argv
    root = Path(argv[0]) if argv else SHIPPED.parents[2]
    (SHIPPED / "si").mkdir(exist_ok=True)
    for file in sorted(SHIPPED.glob("*.ssd")):
        target = SHIPPED / "si" / file.name
        target.write_text(si_variant(file, root / "modelDescription"))
        print(f"wrote {target}")


if __name__ == "__main__":
    main()
