//! One library, two standards: a model's FMI 3.0 FMU carries the very bytes of the FMI 2.0
//! FMU's library, under FMI 3.0's platform tuple, beside FMI 3.0's model description and
//! documentation; resources go into both alike.

mod common;

use common::{entries, host_binaries, interface, scratch};
use contour_fmu::framework::interface::UnitSystem;
use fmu_build::package::{self, Resource};
use fmu_build::platform::Platform;
use fmu_build::standard::Standard;

#[test]
fn the_fmi3_fmu_carries_the_same_library_under_its_platform_tuple() {
    let dir = scratch("standards", "same_library");
    let part = dir.join("part.ngc");
    std::fs::write(&part, "G21\nG1 X10 F600\nG2 X0 R5\n").unwrap();
    let resources = vec![Resource::new("PathInterpolator2D", &part).unwrap()];
    let host = Platform::host().unwrap();
    let library = std::fs::read(common::host_library()).unwrap();
    let binaries = host_binaries();
    for units in UnitSystem::ALL {
        let model = interface("PathInterpolator2D", units);
        let id = model.model.identifier;
        let written = Standard::ALL.map(|standard| {
            let out = standard.output_folder(&dir.join("fmu"), units);
            let fmu =
                package::write_fmu_with_resources(model, standard, &binaries, &out, &resources)
                    .unwrap();
            assert_eq!(fmu, out.join(format!("{id}.fmu")));
            entries(&fmu)
        });
        for (standard, files) in Standard::ALL.into_iter().zip(&written) {
            let file = |name: &str| -> &[u8] {
                files
                    .iter()
                    .find(|(n, _)| n == name)
                    .map(|(_, b)| b.as_slice())
                    .unwrap_or_else(|| panic!("{name} missing from the {standard:?} FMU"))
            };
            let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
            let binary = format!(
                "binaries/{}/{id}.{}",
                standard.binaries_folder(host),
                host.library_extension()
            );
            assert_eq!(file(&binary), library.as_slice(), "{standard:?}");
            assert_eq!(
                file("modelDescription.xml"),
                standard.model_description(model).as_bytes()
            );
            let html = String::from_utf8(file("documentation/index.html").to_vec()).unwrap();
            assert!(
                html.contains(&format!("{} Co-Simulation", standard.name())),
                "{standard:?}"
            );
            assert!(!html.contains(match standard {
                Standard::Fmi2 => "fmi3",
                Standard::Fmi3 => "fmi2",
            }));
            assert_eq!(
                file("resources/part.ngc"),
                std::fs::read(&part).unwrap().as_slice()
            );
            // Nothing else: one library, no folder of the other standard's names.
            assert_eq!(names.len(), 4, "{names:?}");
        }
    }
    assert_eq!(
        Platform::ALL.map(Platform::fmi3_folder),
        ["x86_64-linux", "x86_64-windows", "aarch64-linux"]
    );
    assert_eq!(
        Platform::UNTESTED.map(Platform::fmi3_folder),
        ["x86_64-darwin", "aarch64-darwin"]
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// `--out DIR` names the other builds' folders after DIR: DIR-si, DIR3, DIR3-si.
#[test]
fn the_four_builds_go_to_four_folders() {
    let out = std::path::Path::new("target").join("fmu");
    let folders: Vec<_> = Standard::ALL
        .into_iter()
        .flat_map(|s| UnitSystem::ALL.map(|u| s.output_folder(&out, u)))
        .collect();
    let expected: Vec<_> = ["fmu", "fmu-si", "fmu3", "fmu3-si"]
        .map(|name| std::path::Path::new("target").join(name))
        .to_vec();
    assert_eq!(folders, expected);
}
