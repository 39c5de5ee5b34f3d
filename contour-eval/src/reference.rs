//! What `--path` names, read for the kind of run the measured columns say it is: a path
//! of the XY table (a G-code program, a NURBS JSON file, a built-in of
//! [`builtin::NAMES`]) or a five-axis reference (a CL file, a G-code program, a two-curve
//! JSON file, a built-in of [`BUILTIN_TOOL_PATHS`]). A built-in name in both lists is read
//! as the columns say; a path of the other kind is refused, naming both. A G-code
//! program's reference is the tool centre's path (cutter radius compensation applied), or
//! with `--against programmed` (XY runs) the programmed contour with the offset of each
//! move, so that the part's edge is evaluated.

use contour_core::kinematics::Pose;
use contour_core::part_program::gcode::{load_gcode, GcodeOptions};
use contour_core::part_program::{self, FileKind};
use contour_core::path::five_axis::{load_poses_with, ToolPath, BUILTIN_TOOL_PATHS};
use contour_core::path::planar::{builtin, Path, Program};

use crate::measured::Kind;

/// Longest tip chord when a five-axis JSON reference's curves are sampled into poses, mm.
const JSON_CHORD: f64 = 0.01;

/// A reference of the run's kind.
pub enum Reference {
    /// The path, and with `--against programmed` each programmed move's offset (mm,
    /// signed as the contour error: > 0 the tool right of travel, G42).
    Planar(Path, Option<Vec<f64>>),
    /// The poses and the CL reader's warnings.
    FiveAxis(Vec<Pose>, Vec<String>),
}

/// The kind a built-in name belongs to; a name in both lists is the run's `columns`.
fn builtin_kind(spec: &str, columns: Kind, planar: &[&str], five_axis: &[&str]) -> Option<Kind> {
    // As the readers compare: the XY table's names case-insensitively and trimmed.
    let in_planar = planar.iter().any(|n| n.eq_ignore_ascii_case(spec.trim()));
    let in_five_axis = five_axis.contains(&spec);
    match (in_planar, in_five_axis) {
        (true, true) => Some(columns),
        (true, false) => Some(Kind::Planar),
        (false, true) => Some(Kind::FiveAxis),
        (false, false) => None,
    }
}

/// The machine a file is for by its kind alone (a `.json` file can be either).
fn file_kind(spec: &str) -> Option<Kind> {
    match part_program::file_kind(std::path::Path::new(spec))? {
        FileKind::ClData => Some(Kind::FiveAxis),
        FileKind::GCode | FileKind::Json => None,
    }
}

fn what(kind: Kind) -> &'static str {
    match kind {
        Kind::Planar => "a path of the XY table",
        Kind::FiveAxis => "a five-axis reference",
    }
}

fn mismatch(spec: &str, path: Kind, measured: &str, columns: Kind) -> String {
    format!(
        "--path {spec} is {} but {measured} has {}: evaluate it with a run of {}",
        what(path),
        columns.columns(),
        match path {
            Kind::Planar => "the XY table (time,X,Y)",
            Kind::FiveAxis => "five axes (time,X,Y,Z,A,C)",
        }
    )
}

fn planar(spec: &str, gcode: &GcodeOptions) -> Result<Path, String> {
    Path::from_spec_with(spec, None, gcode).map_err(|e| e.to_string())
}

/// A G-code program's programmed contour (compensation not applied) and each of its
/// moves' offset: the part's edge, which the tool centre should run the offset from.
pub fn programmed_contour(spec: &str, gcode: &GcodeOptions) -> Result<(Path, Vec<f64>), String> {
    let mut part = load_gcode(spec, gcode).map_err(|e| e.to_string())?;
    let mut by_line = std::collections::BTreeMap::new();
    for m in &mut part.moves {
        // Signed as the contour error, > 0 right of travel: the left normal's opposite.
        let offset = m
            .compensation
            .take()
            .map_or(0.0, |c| -c.side.sign() * c.radius);
        by_line.entry(m.place.line).or_insert(offset);
    }
    let program = Program::from_part_program(&part).map_err(|e| e.to_string())?;
    let offsets = program
        .moves()
        .iter()
        .map(|m| by_line.get(&m.line).copied().unwrap_or(0.0))
        .collect();
    Ok((Path::Program(program), offsets))
}

fn five_axis(spec: &str, gcode: &GcodeOptions) -> Result<Reference, String> {
    load_poses_with(spec, JSON_CHORD, gcode)
        .map(|(poses, warnings)| Reference::FiveAxis(poses, warnings))
        .map_err(|e| e.to_string())
}

/// The reference `spec` names, read for a run of `columns` (the file `measured`, named
/// in messages; a G-code program read with `gcode`; `programmed`: an XY run's program
/// as programmed, with its offsets). Errors are the readers' own, or a mismatch naming
/// both kinds.
pub fn load(
    spec: &str,
    columns: Kind,
    measured: &str,
    gcode: &GcodeOptions,
    programmed: bool,
) -> Result<Reference, String> {
    let by_name = builtin_kind(spec, columns, &builtin::NAMES, &BUILTIN_TOOL_PATHS);
    if let Some(kind) = by_name.or_else(|| file_kind(spec)) {
        if kind != columns {
            return Err(mismatch(spec, kind, measured, columns));
        }
    }
    // A JSON file the run's kind cannot read may be one of the other kind.
    let json = part_program::file_kind(std::path::Path::new(spec)) == Some(FileKind::Json);
    let is_gcode = part_program::file_kind(std::path::Path::new(spec)) == Some(FileKind::GCode);
    if programmed {
        if !(is_gcode && columns == Kind::Planar) {
            return Err(format!(
                "--against programmed applies to a G-code program and a run of the XY table, \
                 not --path {spec} with {measured}"
            ));
        }
        let (path, offsets) = programmed_contour(spec, gcode)?;
        return Ok(Reference::Planar(path, Some(offsets)));
    }
    match columns {
        Kind::Planar => planar(spec, gcode)
            .map(|p| Reference::Planar(p, None))
            .map_err(|e| {
                if json && ToolPath::load(spec).is_ok() {
                    mismatch(spec, Kind::FiveAxis, measured, columns)
                } else {
                    e
                }
            }),
        Kind::FiveAxis => five_axis(spec, gcode).map_err(|e| {
            if json && planar(spec, gcode).is_ok() {
                mismatch(spec, Kind::Planar, measured, columns)
            } else {
                e
            }
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_name_in_both_lists_is_read_as_the_columns_say() {
        let (planar, five) = (["line", "both"], ["both", "helix"]);
        for columns in [Kind::Planar, Kind::FiveAxis] {
            let kind = |name: &str| builtin_kind(name, columns, &planar, &five);
            assert_eq!(kind("both"), Some(columns));
            assert_eq!(kind("line"), Some(Kind::Planar));
            assert_eq!(kind(" LINE "), Some(Kind::Planar));
            assert_eq!(kind("helix"), Some(Kind::FiveAxis));
            assert_eq!(kind("part.ngc"), None);
        }
    }

    #[test]
    fn the_shipped_names_are_in_one_list_each() {
        for name in builtin::NAMES {
            assert_eq!(
                builtin_kind(name, Kind::FiveAxis, &builtin::NAMES, &BUILTIN_TOOL_PATHS),
                Some(Kind::Planar)
            );
        }
        for name in BUILTIN_TOOL_PATHS {
            assert_eq!(
                builtin_kind(name, Kind::Planar, &builtin::NAMES, &BUILTIN_TOOL_PATHS),
                Some(Kind::FiveAxis)
            );
        }
    }

    #[test]
    fn file_endings_say_the_kind() {
        // G-code runs on either machine, as a JSON file is read by either.
        assert_eq!(file_kind("a/part.NGC"), None);
        assert_eq!(file_kind("part.tap"), None);
        assert_eq!(file_kind("blade.cl"), Some(Kind::FiveAxis));
        assert_eq!(file_kind("blade.APT"), Some(Kind::FiveAxis));
        assert_eq!(file_kind("curve.json"), None);
    }
}
