//! Zips one FMU of a standard: `modelDescription.xml`, one library per platform
//! (`binaries/<platform>/<id>.<so|dll>`, the platform folder named as the standard names it),
//! `documentation/index.html` and, on request, files under `resources/`.

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};

use zip::write::SimpleFileOptions;
use zip::CompressionMethod;

use contour_fmu::framework::interface::Interface;
use contour_fmu::models;

use crate::binary_check::{self, Checked};
use crate::documentation;
use crate::platform::{Binary, Platform};
use crate::standard::Standard;

/// The libraries one FMU carries, read and checked ([`binary_check`]): each exports exactly
/// the fmi2 Co-Simulation and the fmi3 functions, all come from one source tree, one per
/// platform.
#[derive(Debug)]
pub struct Binaries {
    libraries: Vec<(Platform, Vec<u8>, Checked)>,
}

impl Binaries {
    /// Reads and checks the built libraries; refused, naming the file, when one fails a
    /// check, when two are for the same platform or when they come from different builds.
    pub fn load(built: &[Binary]) -> Result<Binaries, String> {
        let mut libraries: Vec<(Platform, Vec<u8>, Checked)> = Vec::new();
        for binary in built {
            if libraries.iter().any(|(p, _, _)| *p == binary.platform) {
                return Err(format!(
                    "two binaries for binaries/{}",
                    binary.platform.folder()
                ));
            }
            let bytes = std::fs::read(&binary.file)
                .map_err(|e| format!("cannot read {}: {e}", binary.file.display()))?;
            let checked =
                binary_check::check(binary.platform, &bytes, &binary.file.display().to_string())?;
            libraries.push((binary.platform, bytes, checked));
        }
        if libraries.is_empty() {
            return Err("no binary to package".into());
        }
        binary_check::same_build(libraries.iter().map(|(p, _, c)| (*p, c)))?;
        Ok(Binaries { libraries })
    }

    /// The platforms, in the order given.
    pub fn platforms(&self) -> impl Iterator<Item = (Platform, &Checked)> {
        self.libraries.iter().map(|(p, _, c)| (*p, c))
    }
}

/// The model that reads path files from its `resources/` folder (its `path` parameter
/// takes a file name relative to it).
const PATH_MODEL: &str = "PathInterpolator2D";

/// A file to put into a model's `resources/` folder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Resource {
    /// `modelIdentifier` of the FMU that receives the file.
    pub model: String,
    /// The file on disk.
    pub source: PathBuf,
    /// Its name inside the FMU: `resources/<name>`.
    pub name: String,
}

impl Resource {
    /// A resource for `model` from the file `source`, stored under its own file name.
    ///
    /// Refused, with a message naming the file or the model: an unknown model, a file
    /// that does not exist or is not a regular file, and a `.json` or G-code file
    /// (`.ngc`, `.nc`, `.gcode`, `.tap`) for `PathInterpolator2D` that is not a valid
    /// NURBS path file or program (the FMU would otherwise only fail when an importer
    /// initializes it).
    pub fn new(model: &str, source: impl Into<PathBuf>) -> Result<Self, String> {
        let source = source.into();
        let known: Vec<&str> = models::all().iter().map(|m| m.identifier).collect();
        if !known.contains(&model) {
            return Err(format!(
                "--resource {model}={}: unknown model '{model}' (the models are {})",
                source.display(),
                known.join(", ")
            ));
        }
        let metadata = std::fs::metadata(&source).map_err(|e| {
            format!(
                "--resource {model}={}: cannot read the file: {e}",
                source.display()
            )
        })?;
        if !metadata.is_file() {
            return Err(format!(
                "--resource {model}={}: not a regular file",
                source.display()
            ));
        }
        let name = source
            .file_name()
            .and_then(|n| n.to_str())
            .ok_or_else(|| {
                format!(
                    "--resource {model}={}: the file name is not valid UTF-8",
                    source.display()
                )
            })?
            .to_string();
        use contour_core::part_program::{file_kind, FileKind};
        let checked = match file_kind(&source) {
            _ if model != PATH_MODEL => Ok(()),
            Some(FileKind::Json) => {
                contour_core::path::nurbs_file::load_nurbs::<2>(&source).map(drop)
            }
            Some(FileKind::GCode) => contour_core::path::planar::Program::load(&source).map(drop),
            _ => Ok(()),
        };
        checked.map_err(|e| format!("--resource {model}={}: {e}", source.display()))?;
        Ok(Resource {
            model: model.to_string(),
            source,
            name,
        })
    }

    /// Parses the command-line form `Model=FILE` (see [`Resource::new`]).
    pub fn parse(arg: &str) -> Result<Self, String> {
        match arg.split_once('=') {
            Some((model, file)) if !model.is_empty() && !file.is_empty() => {
                Resource::new(model, file)
            }
            _ => Err(format!(
                "--resource needs MODEL=FILE, e.g. {PATH_MODEL}=path.json (got '{arg}')"
            )),
        }
    }
}

/// Checks that no model receives two resources under the same name.
pub fn check_unique(resources: &[Resource]) -> Result<(), String> {
    for (i, a) in resources.iter().enumerate() {
        if let Some(b) = resources[..i]
            .iter()
            .find(|b| b.model == a.model && b.name == a.name)
        {
            return Err(format!(
                "--resource: {} and {} would both be {}'s resources/{}",
                b.source.display(),
                a.source.display(),
                a.model,
                a.name
            ));
        }
    }
    Ok(())
}

/// Writes `<out_dir>/<id>.fmu`, an FMU of `standard` holding each of `binaries` under the
/// name that standard requires: `binaries/<platform>/<modelIdentifier>.<so|dll>`. No
/// resources.
pub fn write_fmu(
    interface: &Interface,
    standard: Standard,
    binaries: &Binaries,
    out_dir: &Path,
) -> Result<PathBuf, String> {
    write_fmu_with_resources(interface, standard, binaries, out_dir, &[])
}

/// As [`write_fmu`], plus every entry of `resources` whose `model` is this model's
/// identifier as `resources/<name>` (entries for other models are skipped).
pub fn write_fmu_with_resources(
    interface: &Interface,
    standard: Standard,
    binaries: &Binaries,
    out_dir: &Path,
    resources: &[Resource],
) -> Result<PathBuf, String> {
    let model = interface.model;
    check_unique(resources)?;
    let mut files = Vec::new();
    for r in resources.iter().filter(|r| r.model == model.identifier) {
        let bytes = std::fs::read(&r.source)
            .map_err(|e| format!("cannot read {}: {e}", r.source.display()))?;
        files.push((format!("resources/{}", r.name), bytes));
    }
    std::fs::create_dir_all(out_dir)
        .map_err(|e| format!("cannot create {}: {e}", out_dir.display()))?;
    let path = out_dir.join(format!("{}.fmu", model.identifier));
    // Written under a temporary name and renamed, so a failed run never leaves a
    // truncated .fmu that looks valid.
    let partial = out_dir.join(format!(".{}.fmu.partial", model.identifier));
    let file =
        File::create(&partial).map_err(|e| format!("cannot create {}: {e}", partial.display()))?;
    let mut zip = zip::ZipWriter::new(file);
    let options = SimpleFileOptions::default().compression_method(CompressionMethod::Deflated);
    let xml = standard.model_description(interface);
    let html = documentation::render(interface, standard);
    let mut entries: Vec<(String, &[u8])> = vec![("modelDescription.xml".into(), xml.as_bytes())];
    for (platform, bytes, _) in &binaries.libraries {
        let name = format!(
            "binaries/{}/{}.{}",
            standard.binaries_folder(*platform),
            model.identifier,
            platform.library_extension()
        );
        entries.push((name, bytes));
    }
    entries.push(("documentation/index.html".into(), html.as_bytes()));
    entries.extend(files.iter().map(|(n, b)| (n.clone(), b.as_slice())));
    let write_err = |e: &dyn std::fmt::Display| format!("cannot write {}: {e}", partial.display());
    for (name, bytes) in entries {
        zip.start_file(name, options).map_err(|e| write_err(&e))?;
        zip.write_all(bytes).map_err(|e| write_err(&e))?;
    }
    zip.finish().map_err(|e| write_err(&e))?;
    std::fs::rename(&partial, &path)
        .map_err(|e| format!("cannot rename to {}: {e}", path.display()))?;
    Ok(path)
}
