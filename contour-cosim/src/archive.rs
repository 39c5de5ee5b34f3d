//! Unpacking .fmu and .ssp archives (zip) into a temporary folder that is removed when
//! dropped. An entry whose name would land outside the folder (an absolute path, `..`) is
//! refused, not skipped: such an archive is corrupt or hostile.

use std::fs::File;
use std::path::Path;

use crate::Error;

/// A folder holding an unpacked archive; removed on drop.
pub struct Unpacked {
    folder: tempfile::TempDir,
}

impl Unpacked {
    pub fn path(&self) -> &Path {
        self.folder.path()
    }
}

/// Unpacks the zip archive `file` (what it is for, e.g. "an FMU", goes into messages).
pub fn unpack(file: &Path, what: &str) -> Result<Unpacked, Error> {
    let refused = |why: String| Error::Refused(format!("{}: {why}", file.display()));
    let opened = File::open(file).map_err(|e| refused(format!("cannot open {what}: {e}")))?;
    let mut archive = zip::ZipArchive::new(opened)
        .map_err(|e| refused(format!("not {what} (not a readable zip archive: {e})")))?;
    let folder = tempfile::Builder::new()
        .prefix("contour-cosim-")
        .tempdir()
        .map_err(|e| refused(format!("cannot make a folder to unpack it into: {e}")))?;
    for index in 0..archive.len() {
        let mut entry = archive
            .by_index(index)
            .map_err(|e| refused(format!("entry {index} of the archive is unreadable: {e}")))?;
        let Some(relative) = entry.enclosed_name() else {
            return Err(refused(format!(
                "the archive entry {:?} would be written outside the folder it is unpacked into",
                entry.name()
            )));
        };
        let target = folder.path().join(&relative);
        let written = if entry.is_dir() {
            std::fs::create_dir_all(&target)
        } else {
            target
                .parent()
                .map_or(Ok(()), std::fs::create_dir_all)
                .and_then(|()| File::create(&target))
                .and_then(|mut out| std::io::copy(&mut entry, &mut out).map(drop))
        };
        written.map_err(|e| refused(format!("cannot unpack {}: {e}", relative.display())))?;
    }
    Ok(Unpacked { folder })
}
