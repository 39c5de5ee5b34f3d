//! Which source tree this binary was built from: a fingerprint of the sources (the build
//! script's), stored in the binary as a marker the packager reads back from every
//! platform's library (ELF or PE alike) before it zips them into one FMU.

/// What precedes the fingerprint in the binary.
pub const MARKER: &str = "contour-fmu build ";

/// The fingerprint of the sources: 32 hex digits.
pub const BUILD_ID: &str = env!("CONTOUR_FMU_BUILD_ID");

const MARKED_LEN: usize = MARKER.len() + BUILD_ID.len();

/// The marker and fingerprint as bytes in the binary, read by [`described`] (the
/// instantiation's log message), which keeps them through the linker's garbage collection.
static MARKED: [u8; MARKED_LEN] = marked();

/// `contour-fmu build <fingerprint>`, as the binary carries it.
pub fn described() -> &'static str {
    std::str::from_utf8(&MARKED).expect("the marker and the digits are ASCII")
}

const fn marked() -> [u8; MARKED_LEN] {
    let mut out = [0u8; MARKED_LEN];
    let (marker, id) = (MARKER.as_bytes(), BUILD_ID.as_bytes());
    let mut i = 0;
    while i < MARKED_LEN {
        out[i] = if i < marker.len() {
            marker[i]
        } else {
            id[i - marker.len()]
        };
        i += 1;
    }
    out
}

/// The build identity a library's bytes carry, if any: the first marker followed by the
/// fingerprint's digits (the marker's text alone may also appear elsewhere in a binary).
pub fn read(binary: &[u8]) -> Option<&str> {
    let marker = MARKER.as_bytes();
    binary
        .windows(marker.len())
        .enumerate()
        .filter(|(_, w)| *w == marker)
        .find_map(|(at, _)| {
            let id = binary.get(at + marker.len()..at + marker.len() + BUILD_ID.len())?;
            id.iter()
                .all(u8::is_ascii_hexdigit)
                .then(|| std::str::from_utf8(id).ok())
                .flatten()
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_marker_reads_back_from_bytes_around_it() {
        let mut binary = b"\x7fELF junk contour-fmu build src/lib.rs ".to_vec();
        binary.extend_from_slice(described().as_bytes());
        binary.extend_from_slice(b"\0more");
        assert_eq!(read(&binary), Some(BUILD_ID));
        assert_eq!(BUILD_ID.len(), 32);
        assert_eq!(read(b"no marker here"), None);
        assert_eq!(read(MARKER.as_bytes()), None, "a marker without its digits");
    }
}
