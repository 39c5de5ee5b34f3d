//! What the master needs from an FMU's `modelDescription.xml`: that it is an FMI 2.0
//! Co-Simulation FMU, its GUID and model identifier, and its variables (name, value
//! reference, type, causality, unit).

use std::collections::HashMap;
use std::path::Path;

use crate::Error;

/// The type of a scalar variable, as the FMI 2.0 get/set functions group them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum VariableType {
    Real,
    /// Integer and Enumeration (both set and read with fmi2SetInteger / fmi2GetInteger).
    Integer,
    Boolean,
    String,
}

impl VariableType {
    pub fn name(self) -> &'static str {
        match self {
            VariableType::Real => "Real",
            VariableType::Integer => "Integer",
            VariableType::Boolean => "Boolean",
            VariableType::String => "String",
        }
    }
}

#[derive(Clone, Debug)]
pub struct Variable {
    pub name: String,
    pub value_reference: u32,
    pub kind: VariableType,
    /// "parameter", "input", "output", "local", ... (FMI 2.0's default: "local").
    pub causality: String,
    /// The declared unit, the variable's own or its type's.
    pub unit: Option<String>,
}

#[derive(Clone, Debug)]
pub struct ModelDescription {
    pub model_name: String,
    pub guid: String,
    pub model_identifier: String,
    pub can_handle_variable_step: bool,
    /// canBeInstantiatedOnlyOncePerProcess: one instance of it at a time in a process.
    pub once_per_process: bool,
    pub variables: Vec<Variable>,
    by_name: HashMap<String, usize>,
}

impl ModelDescription {
    /// Reads the description in `text`; `file` names the FMU in every message.
    pub fn parse(text: &str, file: &Path) -> Result<ModelDescription, Error> {
        let refused = |why: String| Error::Refused(format!("{}: {why}", file.display()));
        let document = roxmltree::Document::parse(text)
            .map_err(|e| refused(format!("modelDescription.xml is not well-formed XML: {e}")))?;
        let root = document.root_element();
        // FMI 1.0 and 3.0 descriptions are also fmiModelDescription elements; the version
        // attribute tells them apart.
        let version = root.attribute("fmiVersion").unwrap_or("");
        if root.tag_name().name() != "fmiModelDescription" || version != "2.0" {
            let found = if version.is_empty() {
                "not an FMI model description".into()
            } else {
                format!("an FMI {version} FMU")
            };
            return Err(refused(format!(
                "{found}; this master runs FMI 2.0 Co-Simulation FMUs"
            )));
        }
        let co_simulation = child(root, "CoSimulation").ok_or_else(|| {
            refused(
                "exported for Model Exchange only (no <CoSimulation> in its model description), \
                 so a co-simulation master cannot step it: it needs an ODE solver the FMU does \
                 not carry. Export the model for Co-Simulation, with its solver inside."
                    .into(),
            )
        })?;
        let model_identifier = co_simulation
            .attribute("modelIdentifier")
            .filter(|id| !id.is_empty())
            .ok_or_else(|| refused("<CoSimulation> has no modelIdentifier".into()))?
            .to_string();
        let type_units: HashMap<&str, &str> = child(root, "TypeDefinitions")
            .into_iter()
            .flat_map(|types| types.children().filter(|n| n.has_tag_name("SimpleType")))
            .filter_map(|t| {
                let unit = t.children().find(|n| n.is_element())?.attribute("unit")?;
                Some((t.attribute("name")?, unit))
            })
            .collect();
        let mut variables = Vec::new();
        for scalar in child(root, "ModelVariables")
            .into_iter()
            .flat_map(|list| list.children().filter(|n| n.has_tag_name("ScalarVariable")))
        {
            let name = scalar.attribute("name").unwrap_or("");
            let what = |why: &str| refused(format!("variable {name:?}: {why}"));
            let value_reference = scalar
                .attribute("valueReference")
                .and_then(|vr| vr.parse().ok())
                .ok_or_else(|| what("no valueReference that is an unsigned integer"))?;
            let typed = scalar
                .children()
                .find(|n| n.is_element() && n.tag_name().name() != "Annotations")
                .ok_or_else(|| what("no type element"))?;
            let kind = match typed.tag_name().name() {
                "Real" => VariableType::Real,
                "Integer" | "Enumeration" => VariableType::Integer,
                "Boolean" => VariableType::Boolean,
                "String" => VariableType::String,
                other => return Err(what(&format!("unknown type <{other}>"))),
            };
            let unit = typed
                .attribute("unit")
                .or_else(|| type_units.get(typed.attribute("declaredType")?).copied())
                .map(str::to_string);
            variables.push(Variable {
                name: name.to_string(),
                value_reference,
                kind,
                causality: scalar.attribute("causality").unwrap_or("local").to_string(),
                unit,
            });
        }
        let by_name = variables
            .iter()
            .enumerate()
            .map(|(i, v)| (v.name.clone(), i))
            .collect();
        Ok(ModelDescription {
            model_name: root.attribute("modelName").unwrap_or("").to_string(),
            guid: root.attribute("guid").unwrap_or("").to_string(),
            model_identifier,
            can_handle_variable_step: co_simulation
                .attribute("canHandleVariableCommunicationStepSize")
                == Some("true"),
            once_per_process: co_simulation.attribute("canBeInstantiatedOnlyOncePerProcess")
                == Some("true"),
            variables,
            by_name,
        })
    }

    pub fn variable(&self, name: &str) -> Option<&Variable> {
        self.by_name.get(name).map(|&i| &self.variables[i])
    }
}

fn child<'a, 'input>(
    node: roxmltree::Node<'a, 'input>,
    tag: &str,
) -> Option<roxmltree::Node<'a, 'input>> {
    node.children().find(|n| n.has_tag_name(tag))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<ModelDescription, Error> {
        ModelDescription::parse(text, Path::new("M.fmu"))
    }

    #[test]
    fn reads_variables_with_their_types_and_units() {
        let md = parse(
            r#"<fmiModelDescription fmiVersion="2.0" modelName="M" guid="{g}">
              <CoSimulation modelIdentifier="M"/>
              <TypeDefinitions><SimpleType name="Length"><Real unit="mm"/></SimpleType></TypeDefinitions>
              <ModelVariables>
                <ScalarVariable name="x" valueReference="3" causality="output"><Real declaredType="Length"/></ScalarVariable>
                <ScalarVariable name="mode" valueReference="4" causality="parameter"><Enumeration declaredType="E" start="1"/></ScalarVariable>
                <ScalarVariable name="on" valueReference="5"><Boolean/></ScalarVariable>
              </ModelVariables></fmiModelDescription>"#,
        )
        .unwrap();
        assert_eq!(
            (md.guid.as_str(), md.model_identifier.as_str()),
            ("{g}", "M")
        );
        let x = md.variable("x").unwrap();
        assert_eq!(
            (x.value_reference, x.kind, x.unit.as_deref()),
            (3, VariableType::Real, Some("mm"))
        );
        assert_eq!(md.variable("mode").unwrap().kind, VariableType::Integer);
        assert_eq!(md.variable("on").unwrap().causality, "local");
        assert!(md.variable("y").is_none());
    }

    #[test]
    fn refuses_other_versions_and_model_exchange_only() {
        for (text, expected) in [
            (
                r#"<fmiModelDescription fmiVersion="1.0"/>"#,
                "M.fmu: an FMI 1.0 FMU",
            ),
            (
                r#"<fmiModelDescription fmiVersion="3.0"/>"#,
                "M.fmu: an FMI 3.0 FMU",
            ),
            (
                r#"<fmiModelDescription fmiVersion="2.0"><ModelExchange modelIdentifier="M"/></fmiModelDescription>"#,
                "M.fmu: exported for Model Exchange only",
            ),
            (
                "<fmiModelDescription",
                "M.fmu: modelDescription.xml is not well-formed",
            ),
        ] {
            let message = parse(text).unwrap_err().to_string();
            assert!(message.starts_with(expected), "{message}");
        }
    }
}
