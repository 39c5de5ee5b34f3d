//! `modelDescription.xml` (FMI 2.0 Co-Simulation) rendered from a model's variable table.
//! The output is deterministic (no timestamps), so the committed copies under
//! `modelDescription/` can be compared byte for byte.

use std::fmt::Write;

use contour_fmu::fmi2::LogCategory;
use contour_fmu::models::units::{self, UnitDefinition};
use contour_fmu::models::{Causality, ModelInfo, Start, Variable};

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
    format!("<{}{attributes}/>", v.var_type().name())
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

/// The complete `modelDescription.xml` of one model.
pub fn render(model: &ModelInfo) -> String {
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
        guid = model.guid(),
        description = escape(model.description),
        version = env!("CARGO_PKG_VERSION"),
    )
    .unwrap();

    let mut used: Vec<&'static str> = model.variables.iter().filter_map(|v| v.unit).collect();
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
    for (index, v) in model.variables.iter().enumerate() {
        let initial = if v.causality == Causality::Output {
            " initial=\"calculated\""
        } else {
            ""
        };
        writeln!(w, "    <!-- index {} -->", index + 1).unwrap();
        writeln!(
            w,
            "    <ScalarVariable name=\"{}\" valueReference=\"{}\" description=\"{}\" causality=\"{}\" variability=\"{}\"{initial}>",
            escape(v.name),
            v.vr,
            escape(v.description),
            v.causality.name(),
            v.variability.name(),
        )
        .unwrap();
        writeln!(w, "      {}", type_element(v)).unwrap();
        writeln!(w, "    </ScalarVariable>").unwrap();
    }
    writeln!(w, "  </ModelVariables>").unwrap();

    // Outputs only change inside fmi2DoStep (no direct feedthrough), hence the empty
    // dependency lists; initial values may depend on any parameter.
    let outputs: Vec<usize> = model
        .variables
        .iter()
        .enumerate()
        .filter(|(_, v)| v.causality == Causality::Output)
        .map(|(i, _)| i + 1)
        .collect();
    writeln!(w, "  <ModelStructure>").unwrap();
    if !outputs.is_empty() {
        writeln!(w, "    <Outputs>").unwrap();
        for i in &outputs {
            writeln!(w, "      <Unknown index=\"{i}\" dependencies=\"\"/>").unwrap();
        }
        writeln!(w, "    </Outputs>").unwrap();
        writeln!(w, "    <InitialUnknowns>").unwrap();
        for i in &outputs {
            writeln!(w, "      <Unknown index=\"{i}\"/>").unwrap();
        }
        writeln!(w, "    </InitialUnknowns>").unwrap();
    }
    writeln!(w, "  </ModelStructure>").unwrap();
    writeln!(w, "</fmiModelDescription>").unwrap();
    xml
}
