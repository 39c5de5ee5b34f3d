//! Developer tasks of the contour-fmu workspace.
//!
//! `bindings` turns the vendored FMI 2.0 and FMI 3.0 headers (`third_party/fmi2/`,
//! `third_party/fmi3/`) into committed Rust files, so that building the FMU library needs neither libclang nor a C compiler; only
//! regenerating (or checking) them does. The output depends only on the headers and the
//! bindgen version locked in Cargo.lock, not on the machine: no paths, no clang version,
//! no doc comments (clang versions attach them differently), no `BINDGEN_*` flags, and no
//! layout tests (FMI 2.0's two structs are pointers, C ints and a double, which `#[repr(C)]`
//! lays out as C does, and FMI 3.0 has none; size assertions for the generating host would
//! tie the files to it).

use std::fmt;
use std::fs;
use std::path::{Path, PathBuf};

use bindgen::{Builder, Formatter, RustEdition, RustTarget};

/// One standard's headers and what is generated from them.
pub struct Standard {
    /// The header bindgen reads (it includes the standard's other two).
    pub header: &'static str,
    /// The prefix of every name the standard declares: "fmi2", "fmi3".
    prefix: &'static str,
    /// The release the headers are, for the generated files' first line.
    release: &'static str,
    /// The library's types and constants.
    pub library: &'static str,
    /// The ABI tests' loader of a built library, and its struct's name.
    pub test_library: &'static str,
    loader: &'static str,
}

/// FMI 2.0 and FMI 3.0.
pub const STANDARDS: [Standard; 2] = [
    Standard {
        header: "third_party/fmi2/fmi2Functions.h",
        prefix: "fmi2",
        release: "FMI 2.0.4",
        library: "fmi2-bindings/src/bindings.rs",
        test_library: "tests/abi/common/fmi2_library.rs",
        loader: "Fmi2Binding",
    },
    Standard {
        header: "third_party/fmi3/fmi3Functions.h",
        prefix: "fmi3",
        release: "FMI 3.0",
        library: "fmi3-bindings/src/bindings.rs",
        test_library: "tests/abi/common/fmi3_library.rs",
        loader: "Fmi3Binding",
    },
];

/// One generated file, by its path relative to the workspace root.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Output {
    pub path: &'static str,
    pub contents: String,
}

/// Why the bindings could not be generated.
#[derive(Debug)]
pub struct Error(String);

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Error {}

/// The workspace root (the directory above xtask/).
pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask/ lies inside the workspace")
        .to_path_buf()
}

/// The settings both outputs of a standard share: every `fmi2*` (`fmi3*`) type and constant
/// of its headers, with bindgen's defaults for enums (`fmi2Status` plus
/// `fmi2Status_fmi2OK`, ...) and macros.
fn builder(root: &Path, standard: &Standard) -> Result<Builder, Error> {
    let header = root.join(standard.header);
    let header = header
        .to_str()
        .ok_or_else(|| Error(format!("{} is not valid UTF-8", header.display())))?;
    // Local clang flags would change the output without changing the headers.
    if let Some((name, _)) =
        std::env::vars_os().find(|(name, _)| name.to_string_lossy().starts_with("BINDGEN_"))
    {
        return Err(Error(format!(
            "{} is set: unset it, the committed bindings must not depend on local flags",
            name.to_string_lossy()
        )));
    }
    // MSVC gives C enums the type int, other compilers unsigned int: the committed files
    // are generated with the latter.
    if cfg!(windows) {
        return Err(Error(
            "generate the bindings on Linux or macOS (on Windows, C enums become c_int)".into(),
        ));
    }
    let rust_target = RustTarget::stable(77, 0).map_err(|e| Error(e.to_string()))?;
    let names = format!("{}.*", standard.prefix);
    Ok(Builder::default()
        .header(header)
        .rust_target(rust_target)
        .rust_edition(RustEdition::Edition2021)
        .formatter(Formatter::Prettyplease)
        .disable_header_comment()
        .layout_tests(false)
        .generate_comments(false)
        .allowlist_type(&names)
        .allowlist_var(&names))
}

fn generate_one(builder: Builder, path: &'static str) -> Result<Output, Error> {
    // clang-sys panics when it cannot load libclang; say what to install instead.
    let generated = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| builder.generate()))
        .map_err(|panic| {
        let why = panic
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| panic.downcast_ref::<&str>().copied())
            .unwrap_or("unknown cause");
        Error(format!(
            "bindgen could not run for {path} ({why}); it needs libclang \
                 (Debian: apt-get install libclang-dev, or `make bindings`)"
        ))
    })?;
    let bindings = generated.map_err(|e| Error(format!("bindgen failed for {path}: {e}")))?;
    Ok(Output {
        path,
        contents: bindings.to_string(),
    })
}

/// The generated-file comment (saying what the file holds and how to regenerate it) and
/// the lints bindgen's C names need.
fn with_preamble(builder: Builder, standard: &Standard, contents: &str) -> Builder {
    builder
        .raw_line(format!(
            "// @generated by `cargo run -p xtask -- bindings` (bindgen) from the {}",
            standard.release
        ))
        .raw_line(format!("// headers, {}:", standard.header))
        .raw_line(format!("// {contents}"))
        .raw_line("// Do not edit: regenerate. `cargo run -p xtask -- bindings --check` fails when")
        .raw_line("// this file is out of date.")
        .raw_line(
            "#![allow(non_camel_case_types, non_snake_case, non_upper_case_globals, dead_code)]",
        )
}

/// The generated files, in memory. Needs libclang (Debian: libclang-dev).
pub fn generate() -> Result<Vec<Output>, Error> {
    let root = workspace_root();
    let mut outputs = Vec::new();
    for standard in &STANDARDS {
        let prefix = standard.prefix;
        // The library's view: types, constants, callback types and one `...TYPE` typedef
        // per function, but no declarations of the functions, which src/fmi/ defines.
        let library = with_preamble(
            builder(&root, standard)?,
            standard,
            &format!("the types, constants, callback types and {prefix}...TYPE typedefs."),
        );
        // The ABI tests' view: a struct that dlopens a built FMU library (with libloading)
        // and calls its functions as an importer would. The types are the library's own
        // (the bindings crate), not a second copy.
        let test_library = with_preamble(
            builder(&root, standard)?
                .allowlist_function(format!("{prefix}.*"))
                .blocklist_type(format!("{prefix}.*"))
                .blocklist_var(format!("{prefix}.*"))
                .dynamic_library_name(standard.loader)
                .dynamic_link_require_all(false),
            standard,
            &format!(
                "`{}`, which loads an FMU's library and calls it (types from the library).",
                standard.loader
            ),
        )
        .raw_line(
            "#![allow(clippy::missing_safety_doc, clippy::too_many_arguments, clippy::type_complexity)]",
        )
        .raw_line(format!("use {prefix}_bindings::*;"));
        outputs.push(generate_one(library, standard.library)?);
        outputs.push(generate_one(test_library, standard.test_library)?);
    }
    Ok(outputs)
}

/// How a committed file compares with its generated version.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Drift {
    Missing,
    /// The first line (1-based) where they differ.
    Differs {
        line: usize,
    },
}

/// The committed file's drift from `output`, if any.
pub fn drift(root: &Path, output: &Output) -> Option<Drift> {
    let Ok(committed) = fs::read_to_string(root.join(output.path)) else {
        return Some(Drift::Missing);
    };
    if committed == output.contents {
        return None;
    }
    // Different texts split into different line sequences, so this stops at the first
    // line that differs or exists in only one of them.
    let mut generated = output.contents.split('\n');
    let mut on_disk = committed.split('\n');
    let mut line = 1;
    while generated.next() == on_disk.next() {
        line += 1;
    }
    Some(Drift::Differs { line })
}

impl fmt::Display for Drift {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Drift::Missing => f.write_str("is missing"),
            Drift::Differs { line } => write!(f, "differs from bindgen's output from line {line}"),
        }
    }
}
