//! What the packager's tests share. Each test file uses some of it.
#![allow(dead_code)]

use std::io::Read;
use std::path::{Path, PathBuf};

use contour_fmu::framework::interface::{Interface, UnitSystem};
use contour_fmu::models;
use fmu_build::package::Binaries;
use fmu_build::platform::{Binary, Platform};

/// The contour-fmu cdylib cargo built for this test run: the dependency's cdylib lies
/// beside the test executable, in target/<profile>/deps/.
pub fn host_library() -> PathBuf {
    let deps = std::env::current_exe()
        .unwrap()
        .parent()
        .unwrap()
        .to_path_buf();
    deps.join(format!(
        "{}contour_fmu{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    ))
}

/// The host's library as cargo built it for this test run, read and checked.
pub fn host_binaries() -> Binaries {
    let file = host_library();
    let platform = Platform::host().expect("tests run on a platform FMUs carry");
    Binaries::load(&[Binary { platform, file }]).unwrap()
}

/// A fresh scratch folder per test file and test (no temp-file crate needed).
pub fn scratch(file: &str, test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fmu_build_{file}_{}_{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A model's interface in `units`, by identifier.
pub fn interface(identifier: &str, units: UnitSystem) -> &'static Interface {
    let model = models::all()
        .into_iter()
        .find(|m| m.identifier == identifier)
        .unwrap();
    models::interface(model, units)
}

/// Both interfaces of every packaged model.
pub fn packaged() -> Vec<&'static Interface> {
    models::all()
        .into_iter()
        .flat_map(|m| UnitSystem::ALL.map(|units| models::interface(m, units)))
        .collect()
}

/// Name → bytes of every file in the zip, in the zip's order.
pub fn entries(fmu: &Path) -> Vec<(String, Vec<u8>)> {
    let mut zip = zip::ZipArchive::new(std::fs::File::open(fmu).unwrap()).unwrap();
    (0..zip.len())
        .map(|i| {
            let mut f = zip.by_index(i).unwrap();
            let mut bytes = Vec::new();
            f.read_to_end(&mut bytes).unwrap();
            (f.name().to_string(), bytes)
        })
        .collect()
}
