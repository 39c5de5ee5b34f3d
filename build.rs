//! Fingerprints the sources the library is built from (its own `src/`, contour-core's and
//! fmi2-bindings' `src/`, the manifests and `Cargo.lock`), so that every platform's binary built from the
//! same tree carries the same build identity and the packager can refuse an FMU whose
//! binaries come from different trees (`src/build_identity.rs`).

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

fn main() {
    let root = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let inputs = [
        root.join("src"),
        root.join("Cargo.toml"),
        root.join("Cargo.lock"),
        root.join("contour-core").join("src"),
        root.join("contour-core").join("Cargo.toml"),
        root.join("fmi2-bindings").join("src"),
        root.join("fmi2-bindings").join("Cargo.toml"),
    ];
    let mut files = Vec::new();
    for input in &inputs {
        println!("cargo:rerun-if-changed={}", input.display());
        collect(input, &mut files);
    }
    files.sort();
    let mut hash = Sha256::new();
    for file in &files {
        let relative = file.strip_prefix(&root).unwrap_or(file);
        // Separators normalised, so a tree checked out on Windows hashes the same.
        hash.update(relative.to_string_lossy().replace('\\', "/").as_bytes());
        hash.update([0]);
        let bytes = std::fs::read(file).unwrap_or_default();
        hash.update((bytes.len() as u64).to_le_bytes());
        hash.update(&bytes);
    }
    let digest: String = hash
        .finalize()
        .iter()
        .take(16)
        .map(|b| format!("{b:02x}"))
        .collect();
    println!("cargo:rustc-env=CONTOUR_FMU_BUILD_ID={digest}");
}

/// Every regular file under `path` (or `path` itself when it is a file).
fn collect(path: &Path, files: &mut Vec<PathBuf>) {
    match std::fs::read_dir(path) {
        Ok(entries) => {
            for entry in entries.flatten() {
                collect(&entry.path(), files);
            }
        }
        Err(_) if path.is_file() => files.push(path.to_path_buf()),
        Err(_) => {}
    }
}
