//! `fmuResourceLocation` → a folder path. Importers differ: `file:///abs/path`,
//! `file:/abs/path`, `file://localhost/abs/path`, percent-encoded characters, with or
//! without a trailing slash, or NULL (libcosim).

use std::path::PathBuf;

/// The local folder the URI names, or an error saying why it names none.
pub fn resource_dir(uri: &str) -> Result<PathBuf, String> {
    let rest = strip_prefix_ignore_case(uri, "file:")
        .ok_or_else(|| format!("resource location '{uri}' is not a file: URI"))?;
    let path = if let Some(authority_and_path) = rest.strip_prefix("//") {
        // file://host/path: only the local host is meaningful.
        let slash = authority_and_path
            .find('/')
            .unwrap_or(authority_and_path.len());
        let (host, path) = authority_and_path.split_at(slash);
        if !(host.is_empty() || host.eq_ignore_ascii_case("localhost")) {
            return Err(format!(
                "resource location '{uri}' names the remote host '{host}'"
            ));
        }
        path
    } else {
        rest
    };
    if !path.starts_with('/') {
        return Err(format!("resource location '{uri}' is not an absolute path"));
    }
    let decoded = percent_decode(path)
        .ok_or_else(|| format!("resource location '{uri}' has a bad %-escape"))?;
    let trimmed = decoded.trim_end_matches('/');
    Ok(PathBuf::from(if trimmed.is_empty() {
        "/"
    } else {
        trimmed
    }))
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
            assert_eq!(resource_dir(uri).unwrap(), expected, "{uri}");
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
            assert!(resource_dir(uri).is_err(), "{uri}");
        }
    }
}
