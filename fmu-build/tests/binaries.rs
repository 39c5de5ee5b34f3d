//! The packager's checks on real libraries: the host's own cdylib passes; the same bytes
//! claimed for another platform, a library that is not an FMU's, and binaries of two
//! source trees are refused, each with a message naming the file or the platforms.

mod common;

use common::host_library;
use contour_fmu::build_identity;
use fmu_build::binary_check::{check, same_build};
use fmu_build::platform::Platform;

#[test]
fn the_host_library_passes_and_carries_this_trees_build() {
    let host = Platform::host().unwrap();
    let bytes = std::fs::read(host_library()).unwrap();
    let checked = check(host, &bytes, "host").unwrap();
    assert_eq!(checked.build_id, build_identity::BUILD_ID);
    if host == Platform::Linux64 {
        // Some glibc version is needed (the host build makes no promise which).
        assert!(checked.glibc.is_some_and(|(major, _)| major == 2));
    }
}

#[test]
fn a_library_for_another_platform_or_of_another_kind_is_refused() {
    let bytes = std::fs::read(host_library()).unwrap();
    for other in Platform::ALL
        .into_iter()
        .filter(|p| Some(*p) != Platform::host())
    {
        let e = check(other, &bytes, "lib").unwrap_err();
        assert!(
            e.contains(&format!("binaries/{} needs", other.folder())),
            "{e}"
        );
    }
    // A real shared library that is no FMU's: the C library's maths.
    let libm = ["/lib/x86_64-linux-gnu/libm.so.6", "/usr/lib64/libm.so.6"]
        .into_iter()
        .find(|p| std::path::Path::new(p).exists());
    if let (Some(libm), Some(Platform::Linux64)) = (libm, Platform::host()) {
        let e = check(Platform::Linux64, &std::fs::read(libm).unwrap(), libm).unwrap_err();
        assert!(
            e.contains("must export exactly the 34 fmi2") && e.contains("fmi2DoStep"),
            "{e}"
        );
    }
}

#[test]
fn binaries_of_two_source_trees_are_refused() {
    let host = Platform::host().unwrap();
    let bytes = std::fs::read(host_library()).unwrap();
    // The same library with another fingerprint, as a binary of an older tree would have.
    let marked = format!("{}{}", build_identity::MARKER, build_identity::BUILD_ID);
    let at = bytes
        .windows(marked.len())
        .position(|w| w == marked.as_bytes())
        .expect("the library carries its marker");
    let mut older = bytes.clone();
    let digits = at + build_identity::MARKER.len();
    older[digits..digits + 32].copy_from_slice(b"0123456789abcdef0123456789abcdef");
    let a = check(host, &bytes, "new").unwrap();
    let b = check(host, &older, "old").unwrap();
    assert_eq!(b.build_id, "0123456789abcdef0123456789abcdef");
    assert!(same_build([(host, &a), (host, &a)]).is_ok());
    let e = same_build([(host, &a), (Platform::Win64, &b)]).unwrap_err();
    assert!(
        e.contains("different source trees") && e.contains("0123456789abcdef"),
        "{e}"
    );
}
