//! The committed `modelDescription/<Model>.xml` files must be exactly what the code
//! renders: review sees every interface change, and a stale file fails here.

use std::path::Path;

use contour_fmu::models;
use fmu_build::model_description;

#[test]
fn committed_xml_matches_the_code() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../modelDescription");
    for model in models::all() {
        let path = dir.join(format!("{}.xml", model.identifier));
        let committed = std::fs::read_to_string(&path).unwrap_or_else(|e| {
            panic!(
                "{}: {e}; run `cargo run -p fmu-build -- --bless`",
                path.display()
            )
        });
        assert!(
            committed == model_description::render(model),
            "{} is stale: run `cargo run --release -p fmu-build -- --bless` and commit it",
            path.display()
        );
    }
}

#[test]
fn every_output_is_listed_once_in_outputs_and_initial_unknowns() {
    for model in models::all() {
        let xml = model_description::render(model);
        let outputs = model
            .variables
            .iter()
            .filter(|v| v.causality == contour_fmu::framework::variables::Causality::Output)
            .count();
        // Every Unknown states its dependencies explicitly; outputs have no direct
        // feedthrough (empty list), initial values depend on the listed parameters.
        assert_eq!(xml.matches("<Unknown index=").count(), 2 * outputs);
        let with_dependencies = xml
            .split("<Unknown index=\"")
            .skip(1)
            .filter(|rest| {
                rest.split_once('"')
                    .is_some_and(|(_, attrs)| attrs.starts_with(" dependencies=\""))
            })
            .count();
        assert_eq!(with_dependencies, 2 * outputs);
        let section = |name: &str| {
            let start = xml.find(&format!("<{name}>")).expect(name);
            let end = xml.find(&format!("</{name}>")).expect(name);
            xml[start..end].to_string()
        };
        assert_eq!(
            section("Outputs").matches("dependencies=\"\"/>").count(),
            outputs
        );
        assert!(xml.contains(&format!("guid=\"{}\"", model.guid())));
    }
}
