//! APT cutter-location (CL) data, the format five-axis CAM post-processors write: each
//! `GOTO/x,y,z,i,j,k` record gives the tool tip (mm) and the tool-axis vector, both in
//! the workpiece frame (docs/design/five-axis.md §5.3a).
//!
//! Read: `GOTO` with six numbers, or three (the tool axis then stays as it was, +Z at the
//! start). Skipped: `$$` comments (to the end of the line), `PARTNO`, `MULTAX`, `FEDRAT`
//! and any other record. A line ending in `$` continues on the next one. Axis vectors are
//! normalised; one whose length is off 1 by more than 1e-6 gets a warning. A malformed
//! `GOTO` (wrong count, not a number, non-finite, a zero axis) is refused with the file
//! and line.

use super::{Corner, Motion, PartMove, PartProgram, Place, Speed, Warning};
use crate::geometry::{self, Vector};
use crate::path::nurbs_file::read_path_file;
use crate::path::PathError;

/// How far an axis vector's length may be off 1 before it is worth a warning.
const UNIT_TOLERANCE: f64 = 1e-6;

/// Reads a CL file.
pub fn load_cl(file: impl AsRef<std::path::Path>) -> Result<PartProgram, PathError> {
    let (name, text) = read_path_file(file.as_ref())?;
    parse_cl(&text, &name)
}

/// Parses the text of a CL file; `name` is used in messages.
pub fn parse_cl(text: &str, name: &str) -> Result<PartProgram, PathError> {
    let fail = |line: usize, message: String| PathError::File {
        file: name.to_string(),
        line,
        column: 0,
        message,
    };
    let mut data = PartProgram {
        file: name.to_string(),
        start: Vector::<3>::zeros(),
        moves: Vec::new(),
        warnings: Vec::new(),
    };
    let mut axis = Vector::<3>::z();
    let mut record = String::new();
    let mut first_line = 0;
    for (index, raw) in text.lines().enumerate() {
        let line = raw.split("$$").next().unwrap_or("").trim();
        if record.is_empty() {
            first_line = index + 1;
        }
        // A single `$` at the end continues the record on the next line.
        if let Some(head) = line.strip_suffix('$') {
            record.push_str(head);
            continue;
        }
        record.push_str(line);
        let whole = std::mem::take(&mut record);
        let Some((word, args)) = whole.split_once('/') else {
            continue; // MULTAX, RAPID, FINI, blank lines …
        };
        if !word.trim().eq_ignore_ascii_case("GOTO") {
            continue;
        }
        let numbers = args
            .split(',')
            .map(|field| {
                let field = field.trim();
                field
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        fail(
                            first_line,
                            format!("GOTO: '{field}' is not a finite number"),
                        )
                    })
            })
            .collect::<Result<Vec<f64>, PathError>>()?;
        let tip = match numbers.len() {
            3 | 6 => Vector::<3>::new(numbers[0], numbers[1], numbers[2]),
            n => {
                return Err(fail(
                    first_line,
                    format!("GOTO needs x,y,z or x,y,z,i,j,k, got {n} numbers"),
                ))
            }
        };
        if numbers.len() == 6 {
            let given = Vector::<3>::new(numbers[3], numbers[4], numbers[5]);
            let length = geometry::norm(&given);
            if length == 0.0 {
                return Err(fail(first_line, "GOTO: the tool axis i,j,k is zero".into()));
            }
            if (length - 1.0).abs() > UNIT_TOLERANCE {
                data.warnings.push(Warning {
                    file: name.to_string(),
                    place: Place {
                        line: first_line,
                        column: 0,
                    },
                    message: format!("tool axis of length {length} normalised"),
                });
            }
            // A length within a few ulps of 1 is unit already: dividing would only
            // round (and a written unit axis would not read back as written).
            axis = if (length - 1.0).abs() <= 4.0 * f64::EPSILON {
                given
            } else {
                given / length
            };
        }
        // The first GOTO is where the tool path starts.
        if data.moves.is_empty() {
            data.start = tip;
        }
        data.moves.push(PartMove {
            motion: Motion::Line,
            speed: Speed::Default,
            end: tip,
            tool_axis: Some(axis),
            corner: Corner::BlendDefault,
            place: Place {
                line: first_line,
                column: 0,
            },
            z_place: None,
        });
    }
    if !record.is_empty() {
        return Err(fail(
            first_line,
            "the last record ends in a continuation '$'".into(),
        ));
    }
    if data.moves.len() < 2 {
        return Err(fail(
            0,
            format!(
                "a path needs at least two GOTO points, found {}",
                data.moves.len()
            ),
        ));
    }
    Ok(data)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::Pose;
    use crate::math;

    const EXAMPLE: &str = "PARTNO/BLADE 7\n\
        $$ generated by a CAM system\n\
        MULTAX\n\
        FEDRAT/MMPM,1200.0\n\
        GOTO/10.0000,20.0000,5.0000,0.000000,0.000000,1.000000\n\
        goto / 11.5, 20.0, 5.25, 0.0, 0.6, 0.8   $$ lower case, spaces\n\
        GOTO/12.0,21.0,$\n\
        5.5,0.0,0.0,2.0\n\
        RAPID\n\
        GOTO/13.0,21.0,6.0\n\
        FINI\n";

    #[test]
    fn reads_goto_records_and_skips_the_rest() {
        let data = parse_cl(EXAMPLE, "blade.cl").unwrap();
        let tips: Vec<[f64; 3]> = data.poses().iter().map(|p| p.tip.into()).collect();
        assert_eq!(
            tips,
            [
                [10.0, 20.0, 5.0],
                [11.5, 20.0, 5.25],
                [12.0, 21.0, 5.5],
                [13.0, 21.0, 6.0]
            ]
        );
        let axes: Vec<[f64; 3]> = data.poses().iter().map(|p| p.axis.into()).collect();
        assert_eq!(
            axes,
            [
                [0.0, 0.0, 1.0],
                [0.0, 0.6, 0.8],
                [0.0, 0.0, 1.0],
                [0.0, 0.0, 1.0]
            ]
        );
        // (0, 0, 2) was normalised, with a warning naming file and line.
        assert_eq!(
            data.warning_lines(),
            ["blade.cl:7: tool axis of length 2 normalised"]
        );
    }

    #[test]
    fn written_records_read_back_exactly() {
        // Poses written as a post-processor would (shortest round-trip decimals, a
        // continuation line, comments and other records around) come back bit for bit.
        let poses: Vec<Pose> = (0..50)
            .map(|i| {
                let t = i as f64 * 0.137;
                let axis = Vector::<3>::new(0.3 * math::sin(t), 0.2 * math::cos(t), 1.0);
                Pose {
                    tip: Vector::<3>::new(25.0 * math::cos(t), -3.0 + math::sin(t) / 3.0, 1e-3 * t),
                    axis: geometry::unit(&axis).unwrap(),
                }
            })
            .collect();
        let mut text = String::from("PARTNO/ROUND TRIP\nMULTAX\nFEDRAT/MMPM,1200\n");
        for (i, p) in poses.iter().enumerate() {
            let [x, y, z]: [f64; 3] = p.tip.into();
            let [a, b, c]: [f64; 3] = p.axis.into();
            if i % 7 == 3 {
                text += &format!("GOTO/{x},{y},{z},$\n{a},{b},{c} $$ split\n");
            } else {
                text += &format!("GOTO/{x},{y},{z},{a},{b},{c}\n");
            }
        }
        text += "FINI\n";
        let data = parse_cl(&text, "trip.cl").unwrap();
        assert_eq!(data.poses(), poses);
        assert!(data.warnings.is_empty(), "{:?}", data.warnings);
    }

    #[test]
    fn malformed_records_name_file_and_line() {
        let cases = [
            (
                "GOTO/1,2,3\nGOTO/1,2,x,0,0,1\n",
                2,
                "'x' is not a finite number",
            ),
            ("GOTO/1,2,3\nGOTO/1,2,3,4\n", 2, "got 4 numbers"),
            (
                "GOTO/1,2,3\n\nGOTO/1,2,3,0,0,0\n",
                3,
                "tool axis i,j,k is zero",
            ),
            (
                "GOTO/1,2,3\nGOTO/1,2,inf\n",
                2,
                "'inf' is not a finite number",
            ),
            ("GOTO/1,2,3\nGOTO/1,2,$\n", 2, "continuation"),
            ("PARTNO/X\nGOTO/1,2,3\n", 0, "at least two GOTO points"),
        ];
        for (text, line, message) in cases {
            let e = parse_cl(text, "part.cl").unwrap_err();
            match &e {
                PathError::File { file, line: l, .. } => {
                    assert_eq!((file.as_str(), *l), ("part.cl", line), "{text:?}: {e}");
                }
                other => panic!("{other:?}"),
            }
            assert!(e.to_string().contains(message), "{text:?}: {e}");
        }
        let e = load_cl("/nonexistent/part.cl").unwrap_err().to_string();
        assert!(
            e.contains("/nonexistent/part.cl") && e.contains("cannot read"),
            "{e}"
        );
    }
}
