//! Zips one FMU: `modelDescription.xml`, `binaries/linux64/<id>.so` and
//! `documentation/index.html`.

use std::fs::File;
use std::io::Write;
use std::path::Path;

use zip::write::SimpleFileOptions;
use zip::CompressionMethod;

use contour_fmu::models::ModelInfo;

use crate::{documentation, model_description};

/// Writes `<out_dir>/<id>.fmu` holding `library` (the built cdylib) under the name FMI
/// requires: `binaries/linux64/<modelIdentifier>.so`.
pub fn write_fmu(
    model: &ModelInfo,
    library: &Path,
    out_dir: &Path,
) -> Result<std::path::PathBuf, String> {
    let binary =
        std::fs::read(library).map_err(|e| format!("cannot read {}: {e}", library.display()))?;
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
    let xml = model_description::render(model);
    let html = documentation::render(model);
    let entries: [(String, &[u8]); 3] = [
        ("modelDescription.xml".into(), xml.as_bytes()),
        (format!("binaries/linux64/{}.so", model.identifier), &binary),
        ("documentation/index.html".into(), html.as_bytes()),
    ];
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
