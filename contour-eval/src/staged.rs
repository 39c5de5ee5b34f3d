//! Outputs written beside their targets under a temporary name and renamed into place
//! only when every one of them is complete: a failed run leaves existing files as they
//! were.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// An output written under a temporary name beside its target.
pub struct Staged {
    pub temporary: PathBuf,
    pub target: PathBuf,
}

impl Staged {
    pub fn new(target: &Path) -> Staged {
        let name = target
            .file_name()
            .map_or("output".into(), |n| n.to_string_lossy().into_owned());
        // Same extension at the end: the PNG encoder picks its format from it.
        let extension = target
            .extension()
            .map_or("tmp".into(), |e| e.to_string_lossy().into_owned());
        let temporary = target.with_file_name(format!(
            ".{name}.partial-{}.{extension}",
            std::process::id()
        ));
        Staged {
            temporary,
            target: target.to_path_buf(),
        }
    }

    pub fn create(&self) -> Result<BufWriter<File>, String> {
        File::create(&self.temporary)
            .map(|f| BufWriter::with_capacity(1 << 20, f))
            .map_err(|e| format!("cannot write {}: {e}", self.target.display()))
    }
}

/// All or nothing: when every output was `written`, renames them into place; otherwise
/// (or when a rename fails) removes the temporary files and returns the message.
pub fn commit(staged: &[Staged], written: Result<(), String>) -> Result<(), String> {
    let renamed = written.and_then(|()| {
        staged.iter().try_for_each(|s| {
            std::fs::rename(&s.temporary, &s.target)
                .map_err(|e| format!("cannot write {}: {e}", s.target.display()))
        })
    });
    if renamed.is_err() {
        for s in staged {
            let _ = std::fs::remove_file(&s.temporary);
        }
    }
    renamed
}
