//! `modelDescription.xml` (FMI 2.0 Co-Simulation) rendered from a model's variable table.
//! The output is deterministic (no timestamps), so the committed copies under
//! `modelDescription/` can be compared byte for byte.

use std::fmt::Write;

use contour_fmu::fmi2::LogCategory;
use contour_fmu::framework::interface::Interface;
use contour_fmu::framework::units::{self, UnitDefinition};
use contour_fmu::framework::variables::{Causality, EnumType, Start, Variable};

use crate::escape;

fn number(x: f64) -> String {
    // Debug formatting round-trips every f64 exactly and never loses the exponent.
    format!("{x:?}")
}

fn type_element(v: &Variable) -> String {
    // Outputs are computed by the model (initial="calculated"): no start value.
    let start = match (v.causality, v.start) {
        (Causality::Output, _) => String::new(),
        (_, Start::Real(x)) => format!(" start=\"{}\"", number(x)),
        (_, Start::Integer(x)) => format!(" start=\"{x}\""),
        (_, Start::Boolean(x)) => format!(" start=\"{x}\""),
        (_, Start::String(x)) => format!(" start=\"{}\"", escape(x)),
    };
    let mut attributes = start;
    if let Some(unit) = v.unit {
        write!(attributes, " unit=\"{}\"", escape(unit)).unwrap();
    }
    for (name, bound) in [("min", v.min), ("max", v.max)] {
        if let Some(bound) = bound {
            let text = match v.start {
                Start::Integer(_) => format!("{}", bound as i64),
                _ => number(bound),
            };
            write!(attributes, " {name}=\"{text}\"").unwrap();
        }
    }
    match v.enumeration {
        // An Integer with a declared enumeration type is an FMI Enumeration variable.
        Some(e) => format!(
            "<Enumeration declaredType=\"{}\"{attributes}/>",
            escape(e.name)
        ),
        None => format!("<{}{attributes}/>", v.var_type().name()),
    }
}

fn type_definition(e: &EnumType) -> String {
    let mut xml = format!(
        "    <SimpleType name=\"{}\" description=\"{}\">\n      <Enumeration>\n",
        escape(e.name),
        escape(e.description)
    );
    for (i, item) in e.items.iter().enumerate() {
        writeln!(
            xml,
            "        <Item name=\"{}\" value=\"{}\" description=\"{}\"/>",
            escape(item.name),
            i + 1,
            escape(item.description)
        )
        .unwrap();
    }
    xml.push_str("      </Enumeration>\n    </SimpleType>\n");
    xml
}

/// A `dependencies` attribute: ScalarVariable indices (1-based, ascending), or the empty
/// list for "depends on none of the Knowns".
fn dependencies(indices: &[usize]) -> String {
    let list: Vec<String> = indices.iter().map(|i| i.to_string()).collect();
    format!(" dependencies=\"{}\"", list.join(" "))
}

fn unit_element(u: &UnitDefinition) -> String {
    let mut base = String::new();
    for (name, exponent) in [
        ("kg", u.kg),
        ("m", u.m),
        ("s", u.s),
        ("A", u.a),
        ("rad", u.rad),
    ] {
        if exponent != 0 {
            write!(base, " {name}=\"{exponent}\"").unwrap();
        }
    }
    if u.factor != 1.0 {
        write!(base, " factor=\"{}\"", number(u.factor)).unwrap();
    }
    format!(
        "    <Unit name=\"{}\">\n      <BaseUnit{base}/>\n    </Unit>\n",
        escape(u.name)
    )
}

/// The complete `modelDescription.xml` of one model's interface.
pub fn render(interface: &Interface) -> String {
    let model = interface.model;
    let variables = &interface.variables;
    let mut xml = String::new();
    let w = &mut xml;
    writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#).unwrap();
    writeln!(
        w,
        r#"<fmiModelDescription
  fmiVersion="2.0"
  modelName="{id}"
  guid="{guid}"
  description="{description}"
  generationTool="contour-fmu fmu-build {version}"
  variableNamingConvention="structured"
  numberOfEventIndicators="0">
  <CoSimulation
    modelIdentifier="{id}"
    needsExecutionTool="false"
    canHandleVariableCommunicationStepSize="true"
    canInterpolateInputs="false"
    maxOutputDerivativeOrder="0"
    canRunAsynchronuously="false"
    canBeInstantiatedOnlyOncePerProcess="false"
    canNotUseMemoryManagementFunctions="true"
    canGetAndSetFMUstate="true"
    canSerializeFMUstate="true"
    providesDirectionalDerivative="false"/>"#,
        id = model.identifier,
        guid = interface.guid,
        description = escape(&interface.description()),
        version = env!("CARGO_PKG_VERSION"),
    )
    .unwrap();

    let mut used: Vec<&'static str> = variables.iter().filter_map(|v| v.unit).collect();
    used.sort_unstable();
    used.dedup();
    if !used.is_empty() {
        writeln!(w, "  <UnitDefinitions>").unwrap();
        for name in used {
            let unit = units::find(name).unwrap_or_else(|| panic!("unit '{name}' is not defined"));
            w.push_str(&unit_element(unit));
        }
        writeln!(w, "  </UnitDefinitions>").unwrap();
    }

    let mut types: Vec<&'static EnumType> = Vec::new();
    for e in variables.iter().filter_map(|v| v.enumeration) {
        if !types.iter().any(|t| t.name == e.name) {
            types.push(e);
        }
    }
    if !types.is_empty() {
        writeln!(w, "  <TypeDefinitions>").unwrap();
        for e in types {
            w.push_str(&type_definition(e));
        }
        writeln!(w, "  </TypeDefinitions>").unwrap();
    }

    writeln!(w, "  <LogCategories>").unwrap();
    for c in LogCategory::ALL {
        writeln!(
            w,
            "    <Category name=\"{}\" description=\"{}\"/>",
            c.name(),
            escape(c.description())
        )
        .unwrap();
    }
    writeln!(w, "  </LogCategories>").unwrap();

    let e = model.default_experiment;
    writeln!(
        w,
        "  <DefaultExperiment startTime=\"{}\" stopTime=\"{}\" stepSize=\"{}\"/>",
        number(e.start_time),
        number(e.stop_time),
        number(e.step_size)
    )
    .unwrap();

    writeln!(w, "  <ModelVariables>").unwrap();
    for (index, v) in variables.iter().enumerate() {
        let initial = if v.causality == Causality::Output {
            " initial=\"calculated\""
        } else {
            ""
        };
        writeln!(w, "    <!-- index {} -->", index + 1).unwrap();
        writeln!(
            w,
            "    <ScalarVariable name=\"{}\" valueReference=\"{}\" description=\"{}\" causality=\"{}\" variability=\"{}\"{initial}>",
            escape(&v.name.to_string()),
            v.vr,
            escape(&v.description.to_string()),
            v.causality.name(),
            v.variability.name(),
        )
        .unwrap();
        writeln!(w, "      {}", type_element(v)).unwrap();
        writeln!(w, "    </ScalarVariable>").unwrap();
    }
    writeln!(w, "  </ModelVariables>").unwrap();

    // Dependencies are always written, also when empty: an importer (syssimx) fails on a
    // missing attribute, which FMI 2.0 reads as "depends on every Known".
    //
    // Outputs (FMI 2.0 ModelStructure/Outputs; for Co-Simulation the dependency "at
    // communication points" on the Knowns: inputs, continuous states, time): these FMUs
    // compute their outputs only inside fmi2DoStep, from the inputs held over the step,
    // and keep them until the next one. Setting an input at a communication point changes
    // no output before the next step: there is no direct feedthrough, and FMI 2.0 writes
    // that as the empty list, "depends on none of the Knowns". Listing the inputs instead
    // would be false and would make masters see an algebraic loop in the closed loop
    // controller -> plant -> controller that does not exist.
    //
    // InitialUnknowns (the outputs again; Knowns in Initialization Mode: inputs and
    // variables with initial="exact", i.e. our parameters): the initial value of an output
    // is computed from a few parameters (the plant's position from pos0.*, the
    // interpolator's first sample from the path); the model lists them
    // (`ModelInfo::initial_dependencies`, tested by perturbing every variable).
    let outputs: Vec<&Variable> = variables
        .iter()
        .filter(|v| v.causality == Causality::Output)
        .collect();
    let index = |v: &Variable| v.vr + 1; // the value reference is the table index
    writeln!(w, "  <ModelStructure>").unwrap();
    if !outputs.is_empty() {
        writeln!(w, "    <Outputs>").unwrap();
        for v in &outputs {
            writeln!(
                w,
                "      <Unknown index=\"{}\"{}/>",
                index(v),
                dependencies(&[])
            )
            .unwrap();
        }
        writeln!(w, "    </Outputs>").unwrap();
        writeln!(w, "    <InitialUnknowns>").unwrap();
        for v in &outputs {
            let knowns: Vec<usize> = model
                .initial_dependencies_of(v.vr)
                .into_iter()
                .map(|vr| index(&variables[vr]))
                .collect();
            writeln!(
                w,
                "      <Unknown index=\"{}\"{}/>",
                index(v),
                dependencies(&knowns)
            )
            .unwrap();
        }
        writeln!(w, "    </InitialUnknowns>").unwrap();
    }
    writeln!(w, "  </ModelStructure>").unwrap();
    writeln!(w, "</fmiModelDescription>").unwrap();
    xml
}
