//! `fmuResourceLocation` → a folder path. Importers differ: `file:///abs/path`,
//! `file:/abs/path`, `file://localhost/abs/path`, percent-encoded characters, with or
//! without a trailing slash, or NULL (libcosim). On Windows also a drive
//! (`file:///C:/dir`, `file:///C|/dir`), a share's host (`file://server/share/dir`, a UNC
//! path) and backslashes where a URI has slashes, which some importers send.

use std::path::PathBuf;

/// How the platform spells a folder: POSIX (`/dir`) or Windows (`C:\dir`, `\\server\share`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathStyle {
    Posix,
    Windows,
}

impl PathStyle {
    /// The style of the platform this library runs on.
    pub const HOST: PathStyle = if cfg!(windows) {
        PathStyle::Windows
    } else {
        PathStyle::Posix
    };
}

/// The local folder the URI names on this platform, or an error saying why it names none.
pub fn resource_dir(uri: &str) -> Result<PathBuf, String> {
    resource_dir_in(uri, PathStyle::HOST).map(PathBuf::from)
}

/// The folder `uri` names in `style`, as text (testable for either style on any platform).
pub fn resource_dir_in(uri: &str, style: PathStyle) -> Result<String, String> {
    let rest = strip_prefix_ignore_case(uri, "file:")
        .ok_or_else(|| format!("resource location '{uri}' is not a file: URI"))?;
    // Backslashes in a URI are an importer's Windows path pasted in; on Windows they mean
    // what a slash means. Elsewhere a backslash is a character of a file name.
    let rest = match style {
        PathStyle::Windows => rest.replace('\\', "/"),
        PathStyle::Posix => rest.to_string(),
    };
    let (host, path) = match rest.strip_prefix("//") {
        Some(authority_and_path) => {
            let slash = authority_and_path
                .find('/')
                .unwrap_or(authority_and_path.len());
            let (host, path) = authority_and_path.split_at(slash);
            if host.is_empty() || host.eq_ignore_ascii_case("localhost") {
                ("", path)
            } else {
                (host, path)
            }
        }
        None => ("", rest.as_str()),
    };
    let decoded = percent_decode(path)
        .ok_or_else(|| format!("resource location '{uri}' has a bad %-escape"))?;
    match style {
        PathStyle::Posix => {
            if !host.is_empty() {
                return Err(format!(
                    "resource location '{uri}' names the remote host '{host}'"
                ));
            }
            if !decoded.starts_with('/') {
                return Err(format!("resource location '{uri}' is not an absolute path"));
            }
            let trimmed = decoded.trim_end_matches('/');
            Ok(if trimmed.is_empty() { "/" } else { trimmed }.to_string())
        }
        PathStyle::Windows => windows_folder(uri, host, &decoded),
    }
}

/// `/C:/dir/` → `C:\dir`, `/C|/dir` → `C:\dir`, host `server` and `/share/dir` →
/// `\\server\share\dir`, `/dir` → `\dir` (the current drive's root).
fn windows_folder(uri: &str, host: &str, path: &str) -> Result<String, String> {
    let segments: Vec<&str> = path.split('/').filter(|s| !s.is_empty()).collect();
    if !host.is_empty() {
        if segments.is_empty() {
            return Err(format!(
                "resource location '{uri}' names the host '{host}' but no share on it"
            ));
        }
        return Ok(format!("\\\\{host}\\{}", segments.join("\\")));
    }
    let drive = segments.first().and_then(|first| {
        let bytes = first.as_bytes();
        (bytes.len() == 2 && bytes[0].is_ascii_alphabetic() && matches!(bytes[1], b':' | b'|'))
            .then(|| format!("{}:", bytes[0] as char))
    });
    match drive {
        Some(drive) => Ok(format!("{drive}\\{}", segments[1..].join("\\"))),
        None if path.starts_with('/') => Ok(format!("\\{}", segments.join("\\"))),
        None => Err(format!("resource location '{uri}' is not an absolute path")),
    }
}

fn strip_prefix_ignore_case<'a>(text: &'a str, prefix: &str) -> Option<&'a str> {
    let head = text.get(..prefix.len())?;
    head.eq_ignore_ascii_case(prefix)
        .then(|| &text[prefix.len()..])
}

fn percent_decode(text: &str) -> Option<String> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = text.get(i + 1..i + 3)?;
            // from_str_radix alone would also take a sign ("%+1").
            if !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
                return None;
            }
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_the_forms_importers_send() {
        let expected = PathBuf::from("/tmp/my fmu/resources");
        for uri in [
            "file:///tmp/my%20fmu/resources",
            "file:///tmp/my%20fmu/resources/",
            "file:/tmp/my%20fmu/resources",
            "file:/tmp/my fmu/resources/",
            "file://localhost/tmp/my%20fmu/resources",
            "FILE:///tmp/my%20fmu/resources",
        ] {
            assert_eq!(
                resource_dir_in(uri, PathStyle::Posix).map(PathBuf::from),
                Ok(expected.clone()),
                "{uri}"
            );
        }
    }

    #[test]
    fn refuses_what_is_not_a_local_folder() {
        for uri in [
            "http://example.org/r",
            "file://server/share",
            "file:relative/path",
            "file:///bad%2",
            "file:///bad%zz",
            "file:///bad%+1",
        ] {
            assert!(resource_dir_in(uri, PathStyle::Posix).is_err(), "{uri}");
        }
    }

    /// What Windows importers send (Dymola, Simulink, FMPy and fmusim on Windows, and
    /// hand-made URIs with backslashes), and the folder Windows means by it.
    #[test]
    fn windows_drives_shares_and_backslashes() {
        for (uri, folder) in [
            (
                "file:///C:/Users/me/My%20FMU/resources/",
                r"C:\Users\me\My FMU\resources",
            ),
            ("file:///c:/tmp/resources", r"c:\tmp\resources"),
            ("file:/C:/tmp/resources", r"C:\tmp\resources"),
            ("file://localhost/C:/tmp/resources", r"C:\tmp\resources"),
            ("file:///C|/tmp/resources", r"C:\tmp\resources"),
            ("file:///C%3A/tmp/resources", r"C:\tmp\resources"),
            (r"file:///C:\tmp\x y\resources\", r"C:\tmp\x y\resources"),
            (r"file:\\\C:\tmp\resources", r"C:\tmp\resources"),
            ("file:///C:/", r"C:\"),
            (
                "file://fileserver/models/ccc/resources",
                r"\\fileserver\models\ccc\resources",
            ),
            (
                r"file://fileserver\models\ccc%20x\resources",
                r"\\fileserver\models\ccc x\resources",
            ),
            ("file:///tmp/resources", r"\tmp\resources"),
        ] {
            assert_eq!(
                resource_dir_in(uri, PathStyle::Windows).as_deref(),
                Ok(folder),
                "{uri}"
            );
        }
        for uri in [
            "file://fileserver/",
            "file:C:relative",
            "file:///C:/bad%zz",
            "http://x/C:/",
        ] {
            assert!(resource_dir_in(uri, PathStyle::Windows).is_err(), "{uri}");
        }
    }
}
