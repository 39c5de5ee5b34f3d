//! What the packager's tests share.

use std::path::PathBuf;

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
