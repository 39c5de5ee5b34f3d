//! The FMI 3.0 model description says what the FMI 2.0 one says of the same interface, in
//! FMI 3.0's form: one independent `time` under a value reference of its own, every table
//! variable under its FMI 2.0 value reference with the same causality, variability, start,
//! unit and bounds, an instantiation token that is not the GUID, and every output in
//! ModelStructure by value reference, with the same dependencies as FMI 2.0's indices.
//! (fmpy's schema and rule checks of the same files run in the Python tests.)

mod common;

use std::collections::BTreeMap;

use common::packaged;
use contour_fmu::framework::interface::Interface;
use contour_fmu::framework::variables::Causality;
use fmu_build::model_description::{fmi2, fmi3};

/// One element of a rendered model description: its tag, its attributes (unescaped) and
/// the tags of the elements it is inside.
#[derive(Debug)]
struct Element {
    tag: String,
    attributes: BTreeMap<String, String>,
    ancestors: Vec<String>,
}

impl Element {
    fn get(&self, name: &str) -> Option<&str> {
        self.attributes.get(name).map(String::as_str)
    }

    fn parent(&self) -> &str {
        self.ancestors.last().map_or("", String::as_str)
    }
}

fn unescape(text: &str) -> String {
    text.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

/// The elements of the XML the renderers write, in document order: attribute values never
/// hold a raw `<` or `>` (they are escaped), so each tag runs from `<` to the next `>`.
fn elements(xml: &str) -> Vec<Element> {
    let mut open: Vec<String> = Vec::new();
    let mut found = Vec::new();
    for chunk in xml.split('<').skip(1) {
        let tag_text = &chunk[..chunk.find('>').expect("a closed tag")];
        if tag_text.starts_with('?') || tag_text.starts_with('!') {
            continue;
        }
        if let Some(name) = tag_text.strip_prefix('/') {
            assert_eq!(open.pop().as_deref(), Some(name.trim()), "nesting");
            continue;
        }
        let closed = tag_text.ends_with('/');
        let body = tag_text.trim_end_matches('/');
        let (tag, mut rest) = body.split_once(char::is_whitespace).unwrap_or((body, ""));
        let mut attributes = BTreeMap::new();
        while let Some((name, value)) = rest.split_once("=\"") {
            let (value, after) = value.split_once('"').expect("a quoted value");
            attributes.insert(name.trim().to_string(), unescape(value));
            rest = after;
        }
        found.push(Element {
            tag: tag.to_string(),
            attributes,
            ancestors: open.clone(),
        });
        if !closed {
            open.push(tag.to_string());
        }
    }
    assert!(open.is_empty(), "unclosed {open:?}");
    found
}

/// The FMI 2.0 variables by name: (value reference, causality, variability, type element).
fn fmi2_variables(interface: &Interface) -> BTreeMap<String, (Element, Element)> {
    let all = elements(&fmi2::render(interface));
    let mut variables = BTreeMap::new();
    let mut current: Option<Element> = None;
    for e in all {
        if e.tag == "ScalarVariable" {
            current = Some(e);
        } else if e.parent() == "ScalarVariable" {
            let v = current.take().expect("a ScalarVariable first");
            variables.insert(v.get("name").unwrap().to_string(), (v, e));
        }
    }
    variables
}

/// The FMI 3.0 variables: the children of ModelVariables, with a String's `Start` value as
/// its `start`.
fn fmi3_variables(all: &[Element]) -> Vec<Element> {
    let mut variables: Vec<Element> = Vec::new();
    for e in all {
        if e.parent() == "ModelVariables" {
            variables.push(Element {
                tag: e.tag.clone(),
                attributes: e.attributes.clone(),
                ancestors: e.ancestors.clone(),
            });
        } else if e.tag == "Start" {
            let v = variables.last_mut().expect("a variable first");
            assert_eq!(v.tag, "String");
            v.attributes
                .insert("start".into(), e.get("value").unwrap().to_string());
        }
    }
    variables
}

#[test]
fn the_header_names_the_instantiation_token_not_the_guid() {
    for interface in packaged() {
        let all = elements(&fmi3::render(interface));
        let root = &all[0];
        assert_eq!(root.tag, "fmiModelDescription");
        assert_eq!(root.get("fmiVersion"), Some("3.0"));
        assert_eq!(root.get("modelName"), Some(interface.model.identifier));
        let token = root.get("instantiationToken").unwrap();
        assert_eq!(token, interface.instantiation_token);
        assert_ne!(token, interface.guid);
        assert!(token.starts_with('{') && token.ends_with('}') && token.len() == 38);
        assert_eq!(root.get("guid"), None);
        assert_eq!(root.get("variableNamingConvention"), Some("structured"));
        let cs = all.iter().find(|e| e.tag == "CoSimulation").unwrap();
        assert_eq!(cs.get("modelIdentifier"), Some(interface.model.identifier));
        for (name, value) in [
            ("canHandleVariableCommunicationStepSize", "true"),
            ("canGetAndSetFMUState", "true"),
            ("canSerializeFMUState", "true"),
            ("canBeInstantiatedOnlyOncePerProcess", "false"),
            ("hasEventMode", "false"),
            ("providesDirectionalDerivatives", "false"),
            ("maxOutputDerivativeOrder", "0"),
        ] {
            assert_eq!(cs.get(name), Some(value), "{name}");
        }
        assert!(all
            .iter()
            .all(|e| e.tag != "ModelExchange" && e.tag != "Clock"));
    }
}

#[test]
fn time_is_the_one_independent_variable_after_the_tables_value_references() {
    for interface in packaged() {
        let all = elements(&fmi3::render(interface));
        let variables = fmi3_variables(&all);
        let independent: Vec<&Element> = variables
            .iter()
            .filter(|v| v.get("causality") == Some("independent"))
            .collect();
        assert_eq!(independent.len(), 1, "{}", interface.model.identifier);
        let time = independent[0];
        assert!(std::ptr::eq(time, &variables[0]), "time comes first");
        assert_eq!(time.tag, "Float64");
        assert_eq!(time.get("name"), Some("time"));
        assert_eq!(time.get("variability"), Some("continuous"));
        assert_eq!(time.get("unit"), Some("s"));
        assert_eq!((time.get("start"), time.get("initial")), (None, None));
        let vr: usize = time.get("valueReference").unwrap().parse().unwrap();
        assert_eq!(vr, interface.time_vr() as usize);
        assert_eq!(vr, interface.variables.len());
        // Its unit is declared, as every unit a variable names.
        let units: Vec<&str> = all
            .iter()
            .filter(|e| e.tag == "Unit")
            .map(|e| e.get("name").unwrap())
            .collect();
        for v in &variables {
            if let Some(unit) = v.get("unit") {
                assert!(units.contains(&unit), "{unit} is not declared");
            }
        }
    }
}

#[test]
fn every_table_variable_keeps_its_fmi2_value_reference_and_declaration() {
    for interface in packaged() {
        let id = interface.model.identifier;
        let fmi2 = fmi2_variables(interface);
        let all = elements(&fmi3::render(interface));
        let variables = fmi3_variables(&all);
        assert_eq!(variables.len(), fmi2.len() + 1, "{id}: the table and time");
        let mut references: Vec<&str> = variables
            .iter()
            .map(|v| v.get("valueReference").unwrap())
            .collect();
        references.sort_unstable();
        references.dedup();
        assert_eq!(references.len(), variables.len(), "{id}: unique");
        for v in variables.iter().skip(1) {
            let name = v.get("name").unwrap();
            let (scalar, typed) = fmi2.get(name).unwrap_or_else(|| panic!("{id}: {name}"));
            for attribute in [
                "valueReference",
                "description",
                "causality",
                "variability",
                "initial",
            ] {
                assert_eq!(
                    v.get(attribute),
                    scalar.get(attribute),
                    "{id}.{name}: {attribute}"
                );
            }
            for attribute in ["start", "unit", "min", "max", "declaredType"] {
                assert_eq!(
                    v.get(attribute),
                    typed.get(attribute),
                    "{id}.{name}: {attribute}"
                );
            }
            let expected = match typed.tag.as_str() {
                "Real" => "Float64",
                "Integer" => "Int32",
                other => other, // Boolean, String, Enumeration
            };
            assert_eq!(v.tag, expected, "{id}.{name}");
            // Outputs are calculated: no start value in either standard.
            if v.get("causality") == Some("output") {
                assert_eq!(v.get("initial"), Some("calculated"), "{id}.{name}");
                assert_eq!(v.get("start"), None, "{id}.{name}");
            } else {
                assert!(v.get("start").is_some(), "{id}.{name}: a start");
            }
        }
    }
}

#[test]
fn enumeration_types_have_the_fmi2_items() {
    // (type, items): FMI 2.0's SimpleType/Enumeration is FMI 3.0's EnumerationType.
    let types = |xml: &str, tag: &str| -> Vec<(String, Vec<[String; 3]>)> {
        let mut types: Vec<(String, Vec<[String; 3]>)> = Vec::new();
        for e in elements(xml) {
            if e.tag == tag && e.parent() == "TypeDefinitions" {
                types.push((e.get("name").unwrap().to_string(), Vec::new()));
            } else if e.tag == "Item" {
                assert!(e.ancestors.iter().any(|a| a == tag), "an Item inside {tag}");
                let item = ["name", "value", "description"].map(|a| e.get(a).unwrap().to_string());
                types.last_mut().expect("a type first").1.push(item);
            }
        }
        types
    };
    for interface in packaged() {
        assert_eq!(
            types(&fmi2::render(interface), "SimpleType"),
            types(&fmi3::render(interface), "EnumerationType"),
            "{}",
            interface.model.identifier
        );
    }
}

#[test]
fn every_output_is_in_model_structure_by_value_reference() {
    for interface in packaged() {
        let id = interface.model.identifier;
        let all = elements(&fmi3::render(interface));
        let structure = |tag: &str| -> Vec<(usize, String)> {
            all.iter()
                .filter(|e| e.tag == tag)
                .map(|e| {
                    assert_eq!(e.parent(), "ModelStructure");
                    (
                        e.get("valueReference").unwrap().parse().unwrap(),
                        e.get("dependencies")
                            .expect("dependencies are always written")
                            .to_string(),
                    )
                })
                .collect()
        };
        let outputs: Vec<usize> = interface
            .variables
            .iter()
            .filter(|v| v.causality == Causality::Output)
            .map(|v| v.vr)
            .collect();
        let listed = structure("Output");
        assert_eq!(
            listed.iter().map(|(vr, _)| *vr).collect::<Vec<_>>(),
            outputs,
            "{id}"
        );
        assert!(
            listed.iter().all(|(_, d)| d.is_empty()),
            "{id}: no feedthrough"
        );

        // InitialUnknown: the same outputs; its dependencies are value references of
        // parameters, the same variables FMI 2.0 names by index.
        let fmi2_initial: Vec<Vec<usize>> = elements(&fmi2::render(interface))
            .into_iter()
            .filter(|e| e.tag == "Unknown" && e.parent() == "InitialUnknowns")
            .map(|e| {
                e.get("dependencies")
                    .unwrap()
                    .split_whitespace()
                    .map(|i| i.parse::<usize>().unwrap() - 1)
                    .collect()
            })
            .collect();
        let initial = structure("InitialUnknown");
        assert_eq!(
            initial.iter().map(|(vr, _)| *vr).collect::<Vec<_>>(),
            outputs,
            "{id}"
        );
        for ((vr, dependencies), by_index) in initial.iter().zip(&fmi2_initial) {
            let knowns: Vec<usize> = dependencies
                .split_whitespace()
                .map(|k| k.parse().unwrap())
                .collect();
            assert_eq!(knowns, interface.model.initial_dependencies_of(*vr), "{id}");
            assert_eq!(&knowns, by_index, "{id}: as FMI 2.0 says by index");
            for k in knowns {
                assert_eq!(
                    interface.variables[k].causality,
                    Causality::Parameter,
                    "{id}: {vr} depends on a parameter"
                );
            }
        }
    }
}
