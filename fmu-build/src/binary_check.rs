//! What the packager checks in every platform's library before it zips it into an FMU:
//! that it exports exactly the 34 functions of FMI 2.0 Co-Simulation and the 75 of FMI 3.0
//! (one library serves both standards' FMUs; read from the ELF
//! dynamic symbol table or the PE export table, the tables an importer's dlsym and
//! GetProcAddress look in; for the untested macOS builds, the Mach-O exports), that all binaries of one FMU carry the same build identity,
//! and, for Linux, the newest glibc symbol version it needs.

use std::collections::BTreeSet;

use object::read::elf::{ElfFile64, FileHeader};
use object::{Object, ObjectKind};

use contour_fmu::build_identity;
use contour_fmu::fmi::{FMI2_CO_SIMULATION, FMI3_FUNCTIONS};

use crate::platform::Platform;

/// What zig's Mach-O linker exports from any dylib: the image's header and handle, and
/// the compiler runtime's OS version checks.
const MACHO_LINKER_EXPORTS: [&str; 4] = [
    "__mh_dylib_header",
    "___dso_handle",
    "___isOSVersionAtLeast",
    "___isPlatformVersionAtLeast",
];

/// The checked facts of one library.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Checked {
    /// The build identity the library carries (`contour_fmu::build_identity`).
    pub build_id: String,
    /// For an ELF library, the newest `GLIBC_x.y` it requires (weak references excluded,
    /// as the dynamic loader does not insist on them), as (x, y).
    pub glibc: Option<(u32, u32)>,
}

/// Checks one library's bytes, built for `platform`; the error names `what`.
pub fn check(platform: Platform, bytes: &[u8], what: &str) -> Result<Checked, String> {
    let file = object::File::parse(bytes).map_err(|e| format!("{what}: not a library: {e}"))?;
    let expected_format = match platform {
        Platform::Win64 => object::BinaryFormat::Pe,
        Platform::Linux64 | Platform::Aarch64Linux => object::BinaryFormat::Elf,
        Platform::Darwin64 | Platform::Aarch64Darwin => object::BinaryFormat::MachO,
    };
    let expected_architecture = match platform {
        Platform::Linux64 | Platform::Win64 | Platform::Darwin64 => object::Architecture::X86_64,
        Platform::Aarch64Linux | Platform::Aarch64Darwin => object::Architecture::Aarch64,
    };
    if file.format() != expected_format
        || file.architecture() != expected_architecture
        || file.kind() != ObjectKind::Dynamic
    {
        return Err(format!(
            "{what}: a {:?} {:?} {:?} file, not the {:?} {:?} shared library binaries/{} needs",
            file.architecture(),
            file.format(),
            file.kind(),
            expected_architecture,
            expected_format,
            platform.folder()
        ));
    }
    let exported = file
        .exports()
        .and_then(|exports| {
            exports
                .map(|e| {
                    e.map(|e| match e.name() {
                        object::read::NameOrOrdinal::Name(name) => {
                            String::from_utf8_lossy(name).into_owned()
                        }
                        object::read::NameOrOrdinal::Ordinal(n) => format!("#{n}"),
                    })
                })
                .collect::<Result<BTreeSet<String>, _>>()
        })
        .map_err(|e| format!("{what}: cannot read its exports: {e}"))?;
    let exported: BTreeSet<String> = match expected_format {
        // Mach-O spells C names with a leading underscore; zig's linker exports a few
        // symbols of its own and of the runtime's OS version check besides.
        object::BinaryFormat::MachO => exported
            .iter()
            .filter(|name| !MACHO_LINKER_EXPORTS.contains(&name.as_str()))
            .map(|name| name.strip_prefix('_').unwrap_or(name).to_string())
            .collect(),
        _ => exported,
    };
    exports_exactly_fmi(&exported).map_err(|e| format!("{what}: {e}"))?;
    let build_id = build_identity::read(bytes)
        .ok_or_else(|| format!("{what}: carries no contour-fmu build identity"))?
        .to_string();
    let glibc = match expected_format {
        object::BinaryFormat::Elf => newest_glibc(bytes).map_err(|e| format!("{what}: {e}"))?,
        _ => None,
    };
    Ok(Checked { build_id, glibc })
}

/// Refuses a set of exported names that is not exactly FMI 2.0 Co-Simulation's 34 functions
/// and FMI 3.0's 75 (an importer of either standard looks each of its own up; anything
/// more is a symbol that leaked).
fn exports_exactly_fmi(exported: &BTreeSet<String>) -> Result<(), String> {
    let expected: BTreeSet<String> = FMI2_CO_SIMULATION
        .iter()
        .chain(&FMI3_FUNCTIONS)
        .map(|s| s.to_string())
        .collect();
    let missing: Vec<_> = expected.difference(exported).collect();
    let extra: Vec<_> = exported.difference(&expected).collect();
    if missing.is_empty() && extra.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "must export exactly the {} fmi2 Co-Simulation functions and the {} fmi3 \
             functions; missing {missing:?}, extra {extra:?}",
            FMI2_CO_SIMULATION.len(),
            FMI3_FUNCTIONS.len()
        ))
    }
}

/// Refuses binaries of one FMU that come from different source trees.
pub fn same_build<'a>(
    checked: impl IntoIterator<Item = (Platform, &'a Checked)>,
) -> Result<(), String> {
    let mut first: Option<(Platform, &Checked)> = None;
    for (platform, c) in checked {
        match first {
            None => first = Some((platform, c)),
            Some((p, f)) if f.build_id != c.build_id => {
                return Err(format!(
                    "the {} binary is build {} but the {} binary is build {}: binaries of \
                     different source trees never go into one FMU (rebuild them together)",
                    p.folder(),
                    f.build_id,
                    platform.folder(),
                    c.build_id
                ))
            }
            Some(_) => {}
        }
    }
    Ok(())
}

/// The newest non-weak `GLIBC_x.y` among the ELF file's version requirements.
fn newest_glibc(bytes: &[u8]) -> Result<Option<(u32, u32)>, String> {
    let elf = ElfFile64::<object::Endianness>::parse(bytes).map_err(|e| e.to_string())?;
    let endian = elf.endian();
    let sections = elf
        .elf_header()
        .sections(endian, bytes)
        .map_err(|e| e.to_string())?;
    let Some((mut needs, link)) = sections
        .gnu_verneed(endian, bytes)
        .map_err(|e| e.to_string())?
    else {
        return Ok(None);
    };
    let strings = sections
        .strings(endian, bytes, link)
        .map_err(|e| e.to_string())?;
    let mut newest = None;
    while let Some((_, mut auxiliaries)) = needs.next().map_err(|e| e.to_string())? {
        while let Some(aux) = auxiliaries.next().map_err(|e| e.to_string())? {
            if aux.vna_flags.get(endian).0 & object::elf::VER_FLG_WEAK.0 != 0 {
                continue;
            }
            let name = aux.name(endian, strings).map_err(|e| e.to_string())?;
            if let Some(version) = parse_glibc(&String::from_utf8_lossy(name)) {
                newest = newest.max(Some(version));
            }
        }
    }
    Ok(newest)
}

/// `GLIBC_2.28` → (2, 28); other version names → None.
fn parse_glibc(name: &str) -> Option<(u32, u32)> {
    let (major, minor) = name.strip_prefix("GLIBC_")?.split_once('.')?;
    let minor = minor.split('.').next()?;
    Some((major.parse().ok()?, minor.parse().ok()?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glibc_version_names_parse() {
        assert_eq!(parse_glibc("GLIBC_2.28"), Some((2, 28)));
        assert_eq!(parse_glibc("GLIBC_2.2.5"), Some((2, 2)));
        assert_eq!(parse_glibc("GLIBC_PRIVATE"), None);
        assert_eq!(parse_glibc("GCC_3.0"), None);
    }

    fn names(lists: &[&[&str]]) -> BTreeSet<String> {
        lists
            .iter()
            .flat_map(|l| l.iter())
            .map(|s| s.to_string())
            .collect()
    }

    #[test]
    fn both_standards_functions_and_nothing_else_are_required() {
        assert_eq!(
            exports_exactly_fmi(&names(&[&FMI2_CO_SIMULATION, &FMI3_FUNCTIONS])),
            Ok(())
        );
        // A library of FMI 2.0 only (as before the fmi3 exports) is refused, naming them.
        let e = exports_exactly_fmi(&names(&[&FMI2_CO_SIMULATION])).unwrap_err();
        assert!(
            e.contains("exactly the 34 fmi2 Co-Simulation functions and the 75 fmi3")
                && e.contains("\"fmi3DoStep\"")
                && e.contains("extra []"),
            "{e}"
        );
        // So is one without a fmi2 function, and one that exports a function of its own.
        let mut without = names(&[&FMI2_CO_SIMULATION, &FMI3_FUNCTIONS]);
        without.remove("fmi2DoStep");
        let e = exports_exactly_fmi(&without).unwrap_err();
        assert!(e.contains("missing [\"fmi2DoStep\"]"), "{e}");
        let mut leaked = names(&[&FMI2_CO_SIMULATION, &FMI3_FUNCTIONS]);
        leaked.insert("rust_eh_personality".into());
        let e = exports_exactly_fmi(&leaked).unwrap_err();
        assert!(
            e.contains("missing [], extra [\"rust_eh_personality\"]"),
            "{e}"
        );
    }

    #[test]
    fn the_two_lists_are_disjoint_and_complete() {
        assert_eq!(
            names(&[&FMI2_CO_SIMULATION, &FMI3_FUNCTIONS]).len(),
            34 + 75
        );
        assert!(FMI2_CO_SIMULATION.iter().all(|f| f.starts_with("fmi2")));
        assert!(FMI3_FUNCTIONS.iter().all(|f| f.starts_with("fmi3")));
    }

    #[test]
    fn what_is_no_library_is_refused() {
        let error = check(Platform::Win64, b"MZ not really", "x.dll").unwrap_err();
        assert!(error.contains("x.dll: not a library"), "{error}");
    }
}
