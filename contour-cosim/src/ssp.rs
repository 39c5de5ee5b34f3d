//! Reads a loop from SSP 1.0 files: a System Structure Description (`.ssd`, its FMUs beside
//! it) or an SSP archive (`.ssp`, a zip holding `SystemStructure.ssd` and the FMUs it
//! names). What SSP itself has no word for, the order a Gauss-Seidel master steps the units
//! in and outputs copied onto parameters once in initialization mode, comes from our
//! annotation `com.contour-fmu.loop` (docs/usage.md, "The loops as SSP files"). The same
//! reading as `contour_fmu.ssp` in Python.

use std::path::{Path, PathBuf};

use crate::archive::{unpack, Unpacked};
use crate::Error;

const SSD: &str = "http://ssp-standard.org/SSP1/SystemStructureDescription";
const SSC: &str = "http://ssp-standard.org/SSP1/SystemStructureCommon";
const SSV: &str = "http://ssp-standard.org/SSP1/SystemStructureParameterValues";
const LOOP: &str = "urn:contour-fmu:ssp:loop";
const OSP: &str = "https://opensimulationplatform.com/SSP/OSPAnnotations";
const LOOP_ANNOTATION: &str = "com.contour-fmu.loop";

/// A start value, typed as the SSP parameter declares it.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Real(f64),
    Integer(i32),
    Boolean(bool),
    String(String),
}

/// A variable of a component: (component name, variable name).
pub type Port = (String, String);

#[derive(Clone, Debug, PartialEq)]
pub struct Connection {
    pub from: Port,
    pub to: Port,
}

#[derive(Clone, Debug)]
pub struct Component {
    pub name: String,
    /// The FMU file, resolved against the folder of the .ssd (or the unpacked .ssp).
    pub source: PathBuf,
    /// The connectors the SSD declares: (name, kind, type) with type e.g. "Real".
    pub connectors: Vec<(String, String, Option<String>)>,
}

/// Start values: (component, variable, value), in the file's order.
pub type StartValues = Vec<(String, String, Value)>;

pub struct SystemStructure {
    pub name: String,
    /// The file read (the .ssd, or the .ssp archive).
    pub file: PathBuf,
    pub components: Vec<Component>,
    /// The component names in the order a Gauss-Seidel master steps them.
    pub order: Vec<String>,
    /// At every step.
    pub connections: Vec<Connection>,
    /// Once, in initialization mode, after the start values.
    pub initial_copies: Vec<Connection>,
    pub parameter_sets: Vec<(String, StartValues)>,
    /// The default experiment's communication step (the OSP fixed-step annotation) and stop time.
    pub step: Option<f64>,
    pub stop: Option<f64>,
    /// An .ssp's unpacked folder, which the component sources point into.
    _unpacked: Option<Unpacked>,
}

impl SystemStructure {
    /// Reads `file`, an .ssd or an .ssp; every error names the file.
    pub fn read(file: &Path) -> Result<SystemStructure, Error> {
        let is_archive = file
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("ssp"));
        let (ssd, folder, unpacked) = if is_archive {
            let unpacked = unpack(file, "an SSP archive")?;
            let ssd = unpacked.path().join("SystemStructure.ssd");
            if !ssd.is_file() {
                return Err(Error::Refused(format!(
                    "{}: the archive holds no SystemStructure.ssd at its root",
                    file.display()
                )));
            }
            (ssd, unpacked.path().to_path_buf(), Some(unpacked))
        } else {
            let folder = file.parent().map(Path::to_path_buf).unwrap_or_default();
            (file.to_path_buf(), folder, None)
        };
        let text = std::fs::read_to_string(&ssd)
            .map_err(|e| Error::Refused(format!("{}: cannot read it: {e}", file.display())))?;
        let mut structure = parse(&text, file, &folder)?;
        structure._unpacked = unpacked;
        Ok(structure)
    }

    pub fn component(&self, name: &str) -> Option<&Component> {
        self.components.iter().find(|c| c.name == name)
    }

    /// Runs the component `name` from the FMU `source` instead (the same connectors).
    pub fn replace_source(&mut self, name: &str, source: &Path) -> Result<(), Error> {
        let file = self.file.display().to_string();
        let component = self
            .components
            .iter_mut()
            .find(|c| c.name == name)
            .ok_or_else(|| Error::Refused(format!("{file}: no component {name:?} to replace")))?;
        component.source = source.to_path_buf();
        Ok(())
    }

    /// The start values of the parameter set `name`.
    pub fn parameter_set(&self, name: &str) -> Result<&StartValues, Error> {
        self.parameter_sets
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v)
            .ok_or_else(|| {
                let names: Vec<&str> = self
                    .parameter_sets
                    .iter()
                    .map(|(n, _)| n.as_str())
                    .collect();
                Error::Refused(format!(
                    "{}: no parameter set {name:?} (it has {})",
                    self.file.display(),
                    if names.is_empty() {
                        "none".to_string()
                    } else {
                        names.join(", ")
                    }
                ))
            })
    }
}

fn children<'a, 'i: 'a>(
    node: roxmltree::Node<'a, 'i>,
    namespace: &'a str,
    tag: &'a str,
) -> impl Iterator<Item = roxmltree::Node<'a, 'i>> + 'a {
    node.children()
        .filter(move |n| n.has_tag_name((namespace, tag)))
}

fn child<'a, 'i: 'a>(
    node: roxmltree::Node<'a, 'i>,
    namespace: &'a str,
    tag: &'a str,
) -> Option<roxmltree::Node<'a, 'i>> {
    children(node, namespace, tag).next()
}

/// Follows a path of (namespace, tag) steps from `node`, every match at every step.
fn descendants<'a, 'i: 'a>(
    node: roxmltree::Node<'a, 'i>,
    path: &[(&'a str, &'a str)],
) -> Vec<roxmltree::Node<'a, 'i>> {
    let mut nodes = vec![node];
    for &(namespace, tag) in path {
        nodes = nodes
            .into_iter()
            .flat_map(|n| children(n, namespace, tag))
            .collect();
    }
    nodes
}

fn parse(text: &str, file: &Path, folder: &Path) -> Result<SystemStructure, Error> {
    let refused = |why: String| Error::Refused(format!("{}: {why}", file.display()));
    let document = roxmltree::Document::parse(text)
        .map_err(|e| refused(format!("not a readable system structure description: {e}")))?;
    let root = document.root_element();
    if !root.has_tag_name((SSD, "SystemStructureDescription"))
        || root.attribute("version") != Some("1.0")
    {
        return Err(refused("not an SSP 1.0 SystemStructureDescription".into()));
    }
    let system = child(root, SSD, "System").ok_or_else(|| refused("no <ssd:System>".into()))?;
    let mut components = Vec::new();
    let mut sets: Vec<(String, StartValues)> = Vec::new();
    for element in descendants(system, &[(SSD, "Elements"), (SSD, "Component")]) {
        let (Some(name), Some(source)) = (element.attribute("name"), element.attribute("source"))
        else {
            return Err(refused("a component without a name or a source".into()));
        };
        let connectors = descendants(element, &[(SSD, "Connectors"), (SSD, "Connector")])
            .into_iter()
            .map(|c| {
                let kind = c
                    .children()
                    .find(|n| n.is_element())
                    .map(|t| t.tag_name().name().to_string());
                (
                    c.attribute("name").unwrap_or("").to_string(),
                    c.attribute("kind").unwrap_or("").to_string(),
                    kind,
                )
            })
            .collect();
        components.push(Component {
            name: name.to_string(),
            source: folder.join(source),
            connectors,
        });
        let bound = descendants(
            element,
            &[
                (SSD, "ParameterBindings"),
                (SSD, "ParameterBinding"),
                (SSD, "ParameterValues"),
                (SSV, "ParameterSet"),
            ],
        );
        for values in bound {
            let set_name = values.attribute("name").unwrap_or("").to_string();
            let index = match sets.iter().position(|(n, _)| *n == set_name) {
                Some(i) => i,
                None => {
                    sets.push((set_name, Vec::new()));
                    sets.len() - 1
                }
            };
            for parameter in descendants(values, &[(SSV, "Parameters"), (SSV, "Parameter")]) {
                let parameter_name = parameter.attribute("name").unwrap_or("");
                let typed: Vec<_> = parameter.children().filter(|n| n.is_element()).collect();
                let what = format!("{name}.{parameter_name}");
                let value = match typed.as_slice() {
                    [one] => typed_value(*one).map_err(|why| refused(format!("{what}: {why}")))?,
                    _ => return Err(refused(format!("{what}: a parameter needs one value of type Real, Integer, Boolean, String"))),
                };
                sets[index]
                    .1
                    .push((name.to_string(), parameter_name.to_string(), value));
            }
        }
    }
    let names: Vec<&str> = components.iter().map(|c| c.name.as_str()).collect();
    if let Some(twice) = names
        .iter()
        .enumerate()
        .find_map(|(i, n)| names[..i].contains(n).then_some(n))
    {
        return Err(refused(format!("two components are named {twice:?}")));
    }
    let checked = |node: roxmltree::Node, what: &str| -> Result<Connection, Error> {
        let end = |element: &str, connector: &str| -> Result<Port, Error> {
            let unit = node.attribute(element).unwrap_or("");
            let variable = node.attribute(connector).unwrap_or("");
            let Some(component) = components.iter().find(|c| c.name == unit) else {
                return Err(refused(format!(
                    "{what} names component {unit:?}, which is not one of {}",
                    names.join(", ")
                )));
            };
            if !component.connectors.iter().any(|(n, _, _)| n == variable) {
                return Err(refused(format!(
                    "{what} names {unit}.{variable}, which is not among {unit}'s connectors"
                )));
            }
            Ok((unit.to_string(), variable.to_string()))
        };
        Ok(Connection {
            from: end("startElement", "startConnector")?,
            to: end("endElement", "endConnector")?,
        })
    };
    let connections = descendants(system, &[(SSD, "Connections"), (SSD, "Connection")])
        .into_iter()
        .map(|c| checked(c, "a connection"))
        .collect::<Result<Vec<_>, _>>()?;
    let loop_annotation = descendants(system, &[(SSD, "Annotations"), (SSC, "Annotation")])
        .into_iter()
        .filter(|a| a.attribute("type") == Some(LOOP_ANNOTATION))
        .find_map(|a| child(a, LOOP, "Loop"));
    let order: Vec<String> = match loop_annotation.and_then(|l| l.attribute("order")) {
        Some(order) => order.split_whitespace().map(str::to_string).collect(),
        None => names.iter().map(|n| n.to_string()).collect(),
    };
    let mut sorted_order = order.clone();
    sorted_order.sort();
    let mut sorted_names: Vec<String> = names.iter().map(|n| n.to_string()).collect();
    sorted_names.sort();
    if sorted_order != sorted_names {
        return Err(refused(format!(
            "the step order {order:?} does not list each component once"
        )));
    }
    let initial_copies = loop_annotation
        .map(|l| {
            children(l, LOOP, "InitialCopy")
                .map(|c| checked(c, "an initial copy"))
                .collect::<Result<Vec<_>, _>>()
        })
        .transpose()?
        .unwrap_or_default();
    let experiment = child(root, SSD, "DefaultExperiment");
    let number = |node: Option<roxmltree::Node>, attribute: &str| -> Result<Option<f64>, Error> {
        match node.and_then(|n| n.attribute(attribute)) {
            None => Ok(None),
            Some(text) => text.trim().parse().map(Some).map_err(|_| {
                refused(format!(
                    "the default experiment's {attribute} {text:?} is not a number"
                ))
            }),
        }
    };
    let fixed_step = experiment.and_then(|e| {
        e.descendants()
            .find(|n| n.has_tag_name((OSP, "FixedStepAlgorithm")))
    });
    Ok(SystemStructure {
        name: root.attribute("name").unwrap_or("").to_string(),
        file: file.to_path_buf(),
        components,
        order,
        connections,
        initial_copies,
        parameter_sets: sets,
        step: number(fixed_step, "baseStepSize")?,
        stop: number(experiment, "stopTime")?,
        _unpacked: None,
    })
}

fn typed_value(node: roxmltree::Node) -> Result<Value, String> {
    let text = node.attribute("value").unwrap_or("");
    let kind = node.tag_name().name();
    let wrong = || format!("{text:?} is no {kind}");
    match kind {
        "Real" => text.trim().parse().map(Value::Real).map_err(|_| wrong()),
        "Integer" => text.trim().parse().map(Value::Integer).map_err(|_| wrong()),
        // xs:boolean is true, false, 1 or 0.
        "Boolean" => match text.trim() {
            "true" | "1" => Ok(Value::Boolean(true)),
            "false" | "0" => Ok(Value::Boolean(false)),
            _ => Err(wrong()),
        },
        "String" => Ok(Value::String(text.to_string())),
        _ => Err("a parameter needs one value of type Real, Integer, Boolean, String".into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ssd(body: &str) -> String {
        format!(
            r#"<ssd:SystemStructureDescription xmlns:ssd="{SSD}" xmlns:ssc="{SSC}" xmlns:ssv="{SSV}" xmlns:cf="{LOOP}" version="1.0" name="s">
            <ssd:System name="s">{body}</ssd:System></ssd:SystemStructureDescription>"#
        )
    }

    const ELEMENTS: &str = r#"<ssd:Elements>
        <ssd:Component name="a" source="A.fmu"><ssd:Connectors><ssd:Connector name="y" kind="output"><ssc:Real/></ssd:Connector></ssd:Connectors>
          <ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues><ssv:ParameterSet version="1.0" name="p">
            <ssv:Parameters><ssv:Parameter name="k"><ssv:Integer value="3"/></ssv:Parameter><ssv:Parameter name="on"><ssv:Boolean value="1"/></ssv:Parameter></ssv:Parameters>
          </ssv:ParameterSet></ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings></ssd:Component>
        <ssd:Component name="b" source="sub/B.fmu"><ssd:Connectors><ssd:Connector name="u" kind="input"><ssc:Real/></ssd:Connector></ssd:Connectors></ssd:Component>
      </ssd:Elements>"#;

    fn read(body: &str) -> Result<SystemStructure, Error> {
        parse(&ssd(body), Path::new("loop.ssd"), Path::new("/f"))
    }

    #[test]
    fn reads_components_connections_order_and_parameter_sets() {
        let s = read(&format!(
            r#"{ELEMENTS}<ssd:Connections><ssd:Connection startElement="a" startConnector="y" endElement="b" endConnector="u"/></ssd:Connections>
            <ssd:Annotations><ssc:Annotation type="com.contour-fmu.loop"><cf:Loop order="b a"/></ssc:Annotation></ssd:Annotations>"#
        ))
        .unwrap();
        assert_eq!(s.order, ["b", "a"]);
        assert_eq!(s.component("b").unwrap().source, Path::new("/f/sub/B.fmu"));
        assert_eq!(
            s.connections,
            [Connection {
                from: ("a".into(), "y".into()),
                to: ("b".into(), "u".into())
            }]
        );
        assert_eq!(
            s.parameter_set("p").unwrap(),
            &vec![
                ("a".into(), "k".into(), Value::Integer(3)),
                ("a".into(), "on".into(), Value::Boolean(true))
            ]
        );
        assert!(s
            .parameter_set("q")
            .unwrap_err()
            .to_string()
            .contains("no parameter set \"q\" (it has p)"));
    }

    #[test]
    fn refuses_connections_to_unknown_components_or_connectors_naming_the_file() {
        for (connection, expected) in [
            (
                r#"startElement="c" startConnector="y" endElement="b" endConnector="u""#,
                "names component \"c\"",
            ),
            (
                r#"startElement="a" startConnector="z" endElement="b" endConnector="u""#,
                "names a.z, which is not among",
            ),
        ] {
            let body = format!(
                "{ELEMENTS}<ssd:Connections><ssd:Connection {connection}/></ssd:Connections>"
            );
            let message = read(&body).err().unwrap().to_string();
            assert!(
                message.starts_with("loop.ssd: a connection") && message.contains(expected),
                "{message}"
            );
        }
        let message = read(&format!(
            r#"{ELEMENTS}<ssd:Annotations><ssc:Annotation type="com.contour-fmu.loop"><cf:Loop order="a a"/></ssc:Annotation></ssd:Annotations>"#
        ))
        .err()
        .unwrap()
        .to_string();
        assert!(
            message.contains("does not list each component once"),
            "{message}"
        );
        let twice = ELEMENTS.replace(
            r#"name="b" source="sub/B.fmu""#,
            r#"name="a" source="sub/B.fmu""#,
        );
        let message = read(&twice).err().unwrap().to_string();
        assert!(
            message.contains("two components are named \"a\""),
            "{message}"
        );
        assert!(parse("<x", Path::new("l.ssd"), Path::new(""))
            .err()
            .unwrap()
            .to_string()
            .starts_with("l.ssd: not a readable"));
    }
}
