//! `fmu-build --resource MODEL=FILE`: the file lands in that model's `resources/` folder
//! of the zip, byte for byte, and nowhere else; bad requests are refused before anything
//! is written.

use std::path::PathBuf;

mod common;

use common::{entries, host_binaries};
use contour_fmu::framework::interface::{Interface, UnitSystem};
use fmu_build::package::{self, Resource};
use fmu_build::standard::Standard;

/// The documented example of the README (a rational cubic NURBS).
const NURBS: &str = r#"{"degree": 3, "knots": [0, 0, 0, 0, 0.5, 1, 1, 1, 1],
 "control_points": [[0, 0], [10, 5], [20, 0], [30, 5], [40, 0]], "weights": [1, 1, 2, 1, 1]}"#;

fn scratch(test: &str) -> PathBuf {
    common::scratch("resources", test)
}

fn model(identifier: &str) -> &'static Interface {
    common::interface(identifier, UnitSystem::Millimetre)
}

#[test]
fn a_nurbs_file_lands_in_the_interpolators_resources_folder() {
    let dir = scratch("lands");
    let json = dir.join("part.json");
    std::fs::write(&json, NURBS).unwrap();
    let library = host_binaries();
    let resources =
        vec![Resource::parse(&format!("PathInterpolator2D={}", json.display())).unwrap()];
    assert_eq!(resources[0].name, "part.json");

    let out = dir.join("fmu");
    let fmu = package::write_fmu_with_resources(
        model("PathInterpolator2D"),
        Standard::Fmi2,
        &library,
        &out,
        &resources,
    )
    .unwrap();
    let files = entries(&fmu);
    let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
    for expected in [
        "modelDescription.xml",
        "binaries/linux64/PathInterpolator2D.so",
        "documentation/index.html",
        "resources/part.json",
    ] {
        assert!(
            names.contains(&expected),
            "{expected} missing from {names:?}"
        );
    }
    let (_, bytes) = files
        .iter()
        .find(|(n, _)| n == "resources/part.json")
        .unwrap();
    assert_eq!(bytes.as_slice(), NURBS.as_bytes());
    // What the FMU will read is a valid path.
    let text = std::str::from_utf8(bytes).unwrap();
    assert!(contour_core::path::nurbs_file::parse_nurbs::<2>(text, "part.json").is_ok());

    // The other models' FMUs carry no resources.
    let controller = package::write_fmu_with_resources(
        model("ContourCCC2D"),
        Standard::Fmi2,
        &library,
        &out,
        &resources,
    )
    .unwrap();
    assert!(entries(&controller)
        .iter()
        .all(|(n, _)| !n.starts_with("resources/")));
    // Without --resource nothing changes: no resources/ entry at all.
    let plain =
        package::write_fmu(model("PathInterpolator2D"), Standard::Fmi2, &library, &out).unwrap();
    assert!(entries(&plain)
        .iter()
        .all(|(n, _)| !n.starts_with("resources/")));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_resource_requests_are_refused_with_a_clear_message() {
    let dir = scratch("refused");
    let missing = dir.join("missing.json");
    let e = Resource::parse(&format!("PathInterpolator2D={}", missing.display())).unwrap_err();
    assert!(
        e.contains(&missing.display().to_string()) && e.contains("cannot read"),
        "{e}"
    );

    let json = dir.join("part.json");
    std::fs::write(&json, NURBS).unwrap();
    let e = Resource::parse(&format!("Interpolator={}", json.display())).unwrap_err();
    assert!(
        e.contains("unknown model 'Interpolator'") && e.contains("PathInterpolator2D"),
        "{e}"
    );
    for malformed in ["PathInterpolator2D", "=part.json", "PathInterpolator2D="] {
        let e = Resource::parse(malformed).unwrap_err();
        assert!(e.contains("MODEL=FILE"), "{malformed}: {e}");
    }
    let e = Resource::new("PathInterpolator2D", &dir).unwrap_err();
    assert!(e.contains("not a regular file"), "{e}");

    // A broken path file is caught at packaging time, naming the file and the line.
    let broken = dir.join("broken.json");
    std::fs::write(&broken, "{\n \"degree\": 3,\n \"knots\": [0, 0,, 1]\n}").unwrap();
    let e = Resource::new("PathInterpolator2D", &broken).unwrap_err();
    assert!(e.contains("broken.json:3:"), "{e}");
    let program = dir.join("part.NGC");
    std::fs::write(&program, "G21\nG1 X10 F600\nG18 G2 X0 Z10 I-5 K5\n").unwrap();
    let e = Resource::new("PathInterpolator2D", &program).unwrap_err();
    assert!(e.contains("part.NGC:3:1: G18 arcs are in a plane"), "{e}");
    std::fs::write(&program, "G21\nG1 X10 F600\nG2 X0 R5\n").unwrap();
    assert!(Resource::new("PathInterpolator2D", &program).is_ok());

    // Two files that would land on the same name.
    let other = dir.join("sub");
    std::fs::create_dir_all(&other).unwrap();
    std::fs::write(other.join("part.json"), NURBS).unwrap();
    let twice = [
        Resource::new("PathInterpolator2D", &json).unwrap(),
        Resource::new("PathInterpolator2D", other.join("part.json")).unwrap(),
    ];
    let e = package::check_unique(&twice).unwrap_err();
    assert!(e.contains("resources/part.json"), "{e}");
    let library = host_binaries();
    assert!(package::write_fmu_with_resources(
        model("PathInterpolator2D"),
        Standard::Fmi2,
        &library,
        &dir.join("fmu"),
        &twice
    )
    .is_err());
    assert!(!dir.join("fmu").exists(), "nothing is written when refused");
    std::fs::remove_dir_all(&dir).ok();
}
