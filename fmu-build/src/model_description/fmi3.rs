//! `modelDescription.xml` of FMI 3.0 Co-Simulation, from the same interface as FMI 2.0's:
//! typed variable elements (`Float64`, `Int32`, `Boolean`, `String`, `Enumeration`), the
//! independent variable `time` that FMI 3.0 requires, the `instantiationToken` in place of
//! the GUID, and ModelStructure by value reference. Every table variable keeps its FMI 2.0
//! value reference.

use std::fmt::Write;

use contour_fmu::framework::interface::Interface;
use contour_fmu::framework::variables::{VarType, Variable};

use super::{definitions, dependencies, initial, outputs, start_text, unit_and_bounds};
use crate::escape;
use crate::standard::Standard;

/// The element FMI 3.0 declares a variable of `var_type` with (Enumerations aside): the
/// binary reads Reals as `fmi3GetFloat64`, Integers as `fmi3GetInt32`.
pub fn type_name(var_type: VarType) -> &'static str {
    match var_type {
        VarType::Real => "Float64",
        VarType::Integer => "Int32",
        VarType::Boolean => "Boolean",
        VarType::String => "String",
    }
}

/// One variable's element. A String's start is a child element in FMI 3.0; every other
/// start is an attribute.
fn variable_element(v: &Variable) -> String {
    let (element, declared) = match v.enumeration {
        // Read and set with fmi3GetInt64 / fmi3SetInt64, values from 1 as in FMI 2.0.
        Some(e) => (
            "Enumeration",
            format!(" declaredType=\"{}\"", escape(e.name)),
        ),
        None => (type_name(v.var_type()), String::new()),
    };
    let mut xml = format!(
        "    <{element} name=\"{}\" valueReference=\"{}\"{declared} description=\"{}\" causality=\"{}\" variability=\"{}\"{}",
        escape(&v.name.to_string()),
        v.vr,
        escape(&v.description.to_string()),
        v.causality.name(),
        v.variability.name(),
        initial(v),
    );
    match (v.var_type(), start_text(v)) {
        (VarType::String, Some(start)) => {
            write!(
                xml,
                "{}>\n      <Start value=\"{}\"/>\n    </{element}>",
                unit_and_bounds(v),
                escape(&start)
            )
            .unwrap();
        }
        (_, start) => {
            if let Some(start) = start {
                write!(xml, " start=\"{}\"", escape(&start)).unwrap();
            }
            write!(xml, "{}/>", unit_and_bounds(v)).unwrap();
        }
    }
    xml
}

/// The complete FMI 3.0 `modelDescription.xml` of one model's interface.
pub fn render(interface: &Interface) -> String {
    let model = interface.model;
    let variables = &interface.variables;
    let mut xml = String::new();
    let w = &mut xml;
    writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#).unwrap();
    // Steps are synchronous and whole: no event mode, no intermediate update, no early
    // return; no clocks.
    writeln!(
        w,
        r#"<fmiModelDescription
  fmiVersion="3.0"
  modelName="{id}"
  instantiationToken="{token}"
  description="{description}"
  generationTool="contour-fmu fmu-build {version}"
  variableNamingConvention="structured">
  <CoSimulation
    modelIdentifier="{id}"
    needsExecutionTool="false"
    canBeInstantiatedOnlyOncePerProcess="false"
    canGetAndSetFMUState="true"
    canSerializeFMUState="true"
    providesDirectionalDerivatives="false"
    providesAdjointDerivatives="false"
    canHandleVariableCommunicationStepSize="true"
    maxOutputDerivativeOrder="0"
    providesIntermediateUpdate="false"
    mightReturnEarlyFromDoStep="false"
    canReturnEarlyAfterIntermediateUpdate="false"
    hasEventMode="false"/>"#,
        id = model.identifier,
        token = interface.instantiation_token,
        description = escape(&interface.description()),
        version = env!("CARGO_PKG_VERSION"),
    )
    .unwrap();

    definitions(w, interface, Standard::Fmi3);

    // The independent variable first (FMI 3.0 requires exactly one; no start, no initial),
    // under the first value reference after the table's so that every other keeps its
    // FMI 2.0 number.
    writeln!(w, "  <ModelVariables>").unwrap();
    writeln!(
        w,
        "    <Float64 name=\"time\" valueReference=\"{}\" description=\"Simulation time\" causality=\"independent\" variability=\"continuous\" unit=\"s\"/>",
        interface.time_vr()
    )
    .unwrap();
    for v in variables {
        writeln!(w, "{}", variable_element(v)).unwrap();
    }
    writeln!(w, "  </ModelVariables>").unwrap();

    // As in FMI 2.0 (fmi2.rs says why at length), by value reference here.
    //
    // Output (for Co-Simulation the dependency at communication points on the Knowns:
    // inputs, continuous states, the independent variable): the outputs are computed only
    // inside fmi3DoStep and held until the next one, so none depends on an input or on
    // time at the same communication point: no direct feedthrough, the empty list. Listing
    // the inputs would make masters see an algebraic loop in the closed loop that does not
    // exist.
    //
    // InitialUnknown (the outputs again; Knowns in Initialization Mode: inputs and
    // variables with initial="exact", i.e. our parameters): the parameters an output's
    // initial value is computed from (`ModelInfo::initial_dependencies`).
    writeln!(w, "  <ModelStructure>").unwrap();
    for v in outputs(interface) {
        writeln!(
            w,
            "    <Output valueReference=\"{}\"{}/>",
            v.vr,
            dependencies(&[])
        )
        .unwrap();
    }
    for v in outputs(interface) {
        writeln!(
            w,
            "    <InitialUnknown valueReference=\"{}\"{}/>",
            v.vr,
            dependencies(&model.initial_dependencies_of(v.vr))
        )
        .unwrap();
    }
    writeln!(w, "  </ModelStructure>").unwrap();
    writeln!(w, "</fmiModelDescription>").unwrap();
    xml
}
