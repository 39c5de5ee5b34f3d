//! What both CLI test files need: a fresh scratch folder, the binary, and a folder's
//! entries (a failed run must leave no temporary file).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// An empty folder of its own under the temporary folder: `<prefix>-<pid>-<name>`.
pub fn scratch(prefix: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("{prefix}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `contour-eval` with `args`.
pub fn contour_eval(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_contour-eval"))
        .args(args)
        .output()
        .unwrap()
}

pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The names in `dir`, sorted.
pub fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}
