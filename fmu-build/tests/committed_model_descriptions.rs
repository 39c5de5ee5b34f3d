//! The committed model descriptions, `modelDescription/<Model>.xml` (FMI 2.0, mm),
//! `modelDescription/si/<Model>.xml` (SI) and the same under `modelDescription/fmi3/`
//! (FMI 3.0), must be exactly what the code renders: review sees every interface change,
//! and a stale file fails here.

mod common;

use std::path::Path;

use common::packaged;
use contour_fmu::framework::interface::UnitSystem;
use contour_fmu::models;
use fmu_build::model_description::{self, fmi2};
use fmu_build::standard::Standard;

#[test]
fn committed_xml_matches_the_code() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    for standard in Standard::ALL {
        for interface in packaged() {
            let path = model_description::committed(&root, interface, standard);
            let committed = std::fs::read_to_string(&path).unwrap_or_else(|e| {
                panic!(
                    "{}: {e}; run `cargo run --release -p fmu-build -- --bless`",
                    path.display()
                )
            });
            assert!(
                committed == standard.model_description(interface),
                "{} is stale: run `cargo run --release -p fmu-build -- --bless` and commit it",
                path.display()
            );
        }
    }
}

#[test]
fn every_output_is_listed_once_in_outputs_and_initial_unknowns() {
    for interface in packaged() {
        let model = interface.model;
        let xml = fmi2::render(interface);
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
        assert!(xml.contains(&format!("guid=\"{}\"", interface.guid)));
    }
}

/// The SI build declares metres where the mm build declares millimetres (per metre where
/// it declares per millimetre), with starts and bounds scaled by exactly the unit's
/// factor, and changes nothing else.
#[test]
fn the_si_interface_is_the_mm_one_in_metres() {
    for model in models::all() {
        let (mm, si) = (
            models::interface(model, UnitSystem::Millimetre),
            models::interface(model, UnitSystem::Si),
        );
        assert_ne!(mm.guid, si.guid);
        for (a, b) in mm.variables.iter().zip(&si.variables) {
            let (unit, factor) = match a.unit {
                Some("mm") => (Some("m"), 1e-3),
                Some("mm/s") => (Some("m/s"), 1e-3),
                Some("mm/s2") => (Some("m/s2"), 1e-3),
                Some("mm/s3") => (Some("m/s3"), 1e-3),
                Some("mm/rad") => (Some("m/rad"), 1e-3),
                Some("N.s/mm") => (Some("N.s/m"), 1e3),
                Some("N/mm") => (Some("N/m"), 1e3),
                other => (other, 1.0),
            };
            assert_eq!(b.unit, unit, "{}", a.name);
            assert_eq!(
                (b.name, b.causality, b.variability),
                (a.name, a.causality, a.variability)
            );
            assert_eq!(b.min, a.min.map(|x| x * factor), "{}", a.name);
            assert_eq!(b.max, a.max.map(|x| x * factor), "{}", a.name);
            match (a.start, b.start) {
                (
                    contour_fmu::framework::variables::Start::Real(x),
                    contour_fmu::framework::variables::Start::Real(y),
                ) => {
                    assert_eq!(y, x * factor, "{}", a.name)
                }
                (x, y) => assert_eq!(x, y, "{}", a.name),
            }
        }
        let xml = fmi2::render(si);
        let xml3 = Standard::Fmi3.model_description(si);
        assert!(
            !xml3.contains("unit=\"mm"),
            "{}: a length in mm (FMI 3.0)",
            model.identifier
        );
        assert!(
            !xml.contains("unit=\"mm"),
            "{}: a length in mm",
            model.identifier
        );
    }
}
