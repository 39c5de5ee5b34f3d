//! `modelDescription.xml` of FMI 2.0 Co-Simulation: variables as `ScalarVariable`s with a
//! typed child, ModelStructure by 1-based index.

use std::fmt::Write;

use contour_fmu::framework::interface::Interface;
use contour_fmu::framework::variables::Variable;

use super::{definitions, dependencies, initial, outputs, start_text, unit_and_bounds};
use crate::escape;
use crate::standard::Standard;

fn type_element(v: &Variable) -> String {
    let mut attributes = match start_text(v) {
        Some(start) => format!(" start=\"{}\"", escape(&start)),
        None => String::new(),
    };
    attributes.push_str(&unit_and_bounds(v));
    match v.enumeration {
        // An Integer with a declared enumeration type is an FMI Enumeration variable.
        Some(e) => format!(
            "<Enumeration declaredType=\"{}\"{attributes}/>",
            escape(e.name)
        ),
        None => format!("<{}{attributes}/>", v.var_type().name()),
    }
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

    definitions(w, interface, Standard::Fmi2);

    writeln!(w, "  <ModelVariables>").unwrap();
    for (index, v) in variables.iter().enumerate() {
        writeln!(w, "    <!-- index {} -->", index + 1).unwrap();
        writeln!(
            w,
            "    <ScalarVariable name=\"{}\" valueReference=\"{}\" description=\"{}\" causality=\"{}\" variability=\"{}\"{}>",
            escape(&v.name.to_string()),
            v.vr,
            escape(&v.description.to_string()),
            v.causality.name(),
            v.variability.name(),
            initial(v),
        )
        .unwrap();
        writeln!(w, "      {}", type_element(v)).unwrap();
        writeln!(w, "    </ScalarVariable>").unwrap();
    }
    writeln!(w, "  </ModelVariables>").unwrap();

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
    let outputs: Vec<&Variable> = outputs(interface).collect();
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
