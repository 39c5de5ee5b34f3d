//! Reading a G-code program into a [`PartProgram`] (docs/design/two-axis.md §4.7): the
//! RS-274/NGC subset LinuxCNC reads, arcs in the XY plane. The `g-code` crate reads the syntax
//! (words with exact decimals, comments, line by line); the modal state, the units and the
//! arc geometry are this file's. Every refusal names the file, line and column.

use std::collections::BTreeSet;

use g_code::emit::{Field, Value};
use g_code::parse::ast::Spanned;
use g_code::parse::snippet_parser;

use super::arc_words::{self, Circle};
use super::{Corner, Motion, PartMove, PartProgram, Place, Speed, Warning};
use crate::geometry::{Vector, Vector2};
use crate::path::nurbs_file::read_path_file;
use crate::path::PathError;

/// Reads a G-code file (see the module docs).
pub fn load_gcode(file: impl AsRef<std::path::Path>) -> Result<PartProgram, PathError> {
    let (name, text) = read_path_file(file.as_ref())?;
    parse_gcode(&text, &name)
}

/// Reads the text of a G-code program; `name` is used in messages.
pub fn parse_gcode(text: &str, name: &str) -> Result<PartProgram, PathError> {
    let mut reader = Reader::new(name);
    let mut percents = 0;
    for (index, line) in text.lines().enumerate() {
        let number = index + 1;
        if line.trim() == "%" {
            percents += 1;
            if percents == 2 {
                break;
            }
            continue;
        }
        if !reader.block(line, number)? {
            break;
        }
    }
    Ok(PartProgram {
        file: name.to_string(),
        start: Vector::<3>::zeros(),
        moves: reader.moves,
        warnings: reader.warnings,
    })
}

/// The motion modes (modal group 1).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Mode {
    Rapid,
    Linear,
    Clockwise,
    CounterClockwise,
}

/// One word of a block: its letter, value and 1-based column.
struct Word {
    letter: char,
    value: f64,
    column: usize,
}

/// The modal state and what has been read so far.
struct Reader<'a> {
    name: &'a str,
    /// mm per program unit: 1 (G21) or 25.4 (G20).
    scale: f64,
    absolute: bool,
    arc_absolute: bool,
    motion: Option<Mode>,
    feed: Option<f64>,
    corner: Corner,
    position: Vector2,
    /// The tip's z, mm: 0 until programmed (the program's origin).
    z: f64,
    moves: Vec<PartMove>,
    skipped: BTreeSet<&'static str>,
    warnings: Vec<Warning>,
}

impl<'a> Reader<'a> {
    fn new(name: &'a str) -> Self {
        Reader {
            name,
            scale: 1.0,
            absolute: true,
            arc_absolute: false,
            motion: None,
            feed: None,
            corner: Corner::BlendDefault,
            position: Vector2::zeros(),
            z: 0.0,
            moves: Vec::new(),
            skipped: BTreeSet::new(),
            warnings: Vec::new(),
        }
    }

    fn error(&self, line: usize, column: usize, message: impl Into<String>) -> PathError {
        PathError::File {
            file: self.name.to_string(),
            line,
            column: column.max(1),
            message: message.into(),
        }
    }

    /// Notes a skipped kind of word, with one warning per kind.
    fn skip(&mut self, kind: &'static str, place: Place) {
        if self.skipped.insert(kind) {
            self.warnings.push(Warning {
                file: self.name.to_string(),
                place,
                message: format!(
                    "{kind} skipped (not part of the XY contour); further ones are skipped silently"
                ),
            });
        }
    }

    /// The words of one line, letters upper-cased.
    fn words(&self, text: &str, line: usize) -> Result<Vec<Word>, PathError> {
        if let Some(column) = two_signs(text) {
            return Err(self.error(line, column, "a number takes one sign, not '+-'"));
        }
        let snippet = snippet_parser(text).map_err(|e| {
            self.error(
                line,
                e.location.column,
                format!("G-code syntax: expected {}", e.expected),
            )
        })?;
        let mut words = Vec::new();
        for field in snippet.iter_fields() {
            let column = field.span().0 + 1;
            let Field { letters, value } = Field::from(field);
            let mut chars = letters.chars();
            let (Some(letter), None) = (chars.next(), chars.next()) else {
                return Err(self.error(line, column, format!("unknown word '{letters}'")));
            };
            let value = match value {
                Value::Integer(i) => i as f64,
                Value::Rational(d) => d.to_string().parse::<f64>().unwrap_or(f64::NAN),
                Value::Float(f) => f,
                Value::String(_) => {
                    return Err(self.error(line, column, "a word's value must be a number"))
                }
            };
            words.push(Word {
                letter: letter.to_ascii_uppercase(),
                value,
                column,
            });
        }
        if let Some(flag) = snippet.iter_flags().next() {
            return Err(self.error(line, flag.span().0 + 1, "a letter without a number"));
        }
        Ok(words)
    }

    /// Reads one block; `false` at the program's end (M2, M30).
    fn block(&mut self, text: &str, line: usize) -> Result<bool, PathError> {
        let words = self.words(text, line)?;
        let mut motion: Option<(Mode, usize)> = None;
        let mut end = false;
        let (mut axes, mut z, mut centre, mut radius) = ([None; 2], None, [None; 2], None);
        let (mut p, mut feed) = (None, None);
        let mut corner_word: Option<(u32, usize)> = None;
        for w in &words {
            let column = w.column;
            let code = || -> Result<u32, PathError> {
                let tenths = w.value * 10.0;
                if tenths.fract() == 0.0 && (0.0..=9999.0).contains(&tenths) {
                    Ok(tenths as u32)
                } else {
                    Err(self.error(
                        line,
                        column,
                        format!("unknown code {}{}", w.letter, w.value),
                    ))
                }
            };
            match w.letter {
                'G' => match code()? {
                    c @ (0 | 10 | 20 | 30) => {
                        if motion.is_some() {
                            return Err(self.error(line, column, "two motion codes in one block"));
                        }
                        let m = [
                            Mode::Rapid,
                            Mode::Linear,
                            Mode::Clockwise,
                            Mode::CounterClockwise,
                        ][c as usize / 10];
                        motion = Some((m, column));
                    }
                    170 => {}
                    180 | 190 => {
                        return Err(self.error(
                            line,
                            column,
                            "only the XY plane (G17) is supported: the table has two axes",
                        ))
                    }
                    200 => self.scale = 25.4,
                    210 => self.scale = 1.0,
                    900 => self.absolute = true,
                    910 => self.absolute = false,
                    901 => self.arc_absolute = true,
                    911 => self.arc_absolute = false,
                    c @ (610 | 611 | 640) => corner_word = Some((c, column)),
                    400 => self.skip("G40 (cutter compensation off)", Place { line, column }),
                    490 => self.skip("G49 (tool length offset off)", Place { line, column }),
                    800 => self.skip("G80 (canned cycle off)", Place { line, column }),
                    940 => self.skip(
                        "G94 (feed per minute, the only feed mode here)",
                        Place { line, column },
                    ),
                    540..=590 if w.value.fract() == 0.0 => self.skip(
                        "G54-G59 (work offsets: coordinates are taken as programmed)",
                        Place { line, column },
                    ),
                    _ => {
                        return Err(self.error(
                            line,
                            column,
                            format!("G{} is not supported", w.value),
                        ))
                    }
                },
                'M' => match code()? {
                    20 | 300 => end = true,
                    30..=50 => self.skip("M3-M5 (spindle)", Place { line, column }),
                    60 => self.skip("M6 (tool change)", Place { line, column }),
                    70..=90 => self.skip("M7-M9 (coolant)", Place { line, column }),
                    _ => {
                        return Err(self.error(
                            line,
                            column,
                            format!("M{} is not supported", w.value),
                        ))
                    }
                },
                'X' => axes[0] = Some((w.value, column)),
                'Y' => axes[1] = Some((w.value, column)),
                'Z' => z = Some((w.value, column)),
                'I' => centre[0] = Some((w.value, column)),
                'J' => centre[1] = Some((w.value, column)),
                'R' => radius = Some((w.value, column)),
                'F' => feed = Some((w.value, column)),
                'P' => p = Some((w.value, column)),
                'N' => {}
                'S' => self.skip("S (spindle speed)", Place { line, column }),
                'T' => self.skip("T (tool number)", Place { line, column }),
                'Q' => self.skip("Q (G64's naive-CAM tolerance)", Place { line, column }),
                'K' => {
                    return Err(self.error(line, column, "K is not an XY-plane arc word"));
                }
                other => {
                    return Err(self.error(
                        line,
                        column,
                        format!("the word {other} is not supported (axes X, Y and Z only)"),
                    ))
                }
            }
        }
        if let Some((f, column)) = feed {
            if !(f.is_finite() && f > 0.0) {
                return Err(self.error(line, column, format!("feed F{f} must be > 0")));
            }
            self.feed = Some(f * self.scale / 60.0);
        }
        let mut p_used = false;
        if let Some((c, _)) = corner_word {
            self.corner = match (c, p) {
                (640, Some((tol, column))) => {
                    p_used = true;
                    if !(tol.is_finite() && tol >= 0.0) {
                        return Err(self.error(line, column, "G64's P must be >= 0"));
                    }
                    if tol == 0.0 {
                        // LinuxCNC: no limit on the blend; here the `tolerance` parameter's.
                        Corner::BlendDefault
                    } else {
                        Corner::Blend(tol * self.scale)
                    }
                }
                (640, None) => Corner::BlendDefault,
                _ => Corner::ExactStop,
            };
        }
        if let Some((m, _)) = motion {
            self.motion = Some(m);
        }
        let moves_axes = axes.iter().any(Option::is_some);
        let arc_words = centre.iter().chain([&radius]).find_map(|w| *w);
        if !moves_axes && z.is_none() {
            if let Some((_, column)) = arc_words.filter(|_| motion.is_some()) {
                return Err(self.error(line, column, "an arc needs its end point (X, Y)"));
            }
            if let Some((_, column)) = arc_words.or(p.filter(|_| !p_used)) {
                return Err(self.error(line, column, "this word belongs to a move"));
            }
            return Ok(!end);
        }
        let Some(mode) = self.motion else {
            let column = axes.iter().chain([&z]).find_map(|w| w.map(|(_, c)| c));
            return Err(self.error(
                line,
                column.unwrap_or(1),
                "axis words without a motion code (G0, G1, G2, G3) in force",
            ));
        };
        // The programmed end.
        let mut end_point = self.position;
        for (k, word) in axes.iter().enumerate() {
            if let Some((v, _)) = word {
                let v = v * self.scale;
                end_point[k] = if self.absolute { v } else { end_point[k] + v };
            }
        }
        let mut end_z = self.z;
        let z_place = z.map(|(v, column)| {
            let v = v * self.scale;
            end_z = if self.absolute { v } else { self.z + v };
            Place { line, column }
        });
        let speed = match mode {
            Mode::Rapid => Speed::Rapid,
            _ => self.feed.map_or(Speed::Default, Speed::Feed),
        };
        let shape = match mode {
            Mode::Rapid | Mode::Linear => {
                if let Some((_, column)) = arc_words.or(p.filter(|_| !p_used)) {
                    return Err(self.error(line, column, "I, J, R and P belong to arcs"));
                }
                if end_point == self.position && end_z == self.z {
                    return Ok(!end);
                }
                Motion::Line
            }
            Mode::Clockwise | Mode::CounterClockwise => {
                let motion_column = motion.map_or(1, |(_, c)| c);
                if let Some((turns, column)) = p.filter(|_| !p_used) {
                    if turns != 1.0 {
                        return Err(self.error(
                            line,
                            column,
                            "arcs of more than one turn (P) are not supported",
                        ));
                    }
                }
                let circle = match (centre, radius) {
                    ([None, None], None) => {
                        return Err(self.error(line, motion_column, "an arc needs I and J, or R"))
                    }
                    ([Some((_, column)), _] | [_, Some((_, column))], Some(_)) => {
                        return Err(self.error(
                            line,
                            column,
                            "an arc takes I and J, or R, not both",
                        ))
                    }
                    (_, Some((r, _))) => Circle::Radius(r * self.scale),
                    ([i, j], None) => {
                        let offset =
                            |w: Option<(f64, usize)>, k: usize| -> Result<f64, PathError> {
                                match (w, self.arc_absolute) {
                                    (Some((v, _)), true) => Ok(v * self.scale),
                                    (Some((v, _)), false) => Ok(self.position[k] + v * self.scale),
                                    (None, false) => Ok(self.position[k]),
                                    (None, true) => Err(self.error(
                                        line,
                                        motion_column,
                                        "with G90.1 an arc needs both I and J",
                                    )),
                                }
                            };
                        Circle::Centre(Vector2::new(offset(i, 0)?, offset(j, 1)?))
                    }
                };
                let clockwise = mode == Mode::Clockwise;
                let arc = arc_words::arc(self.position, end_point, circle, clockwise)
                    .map_err(|m| self.error(line, motion_column, m))?;
                Motion::Arc(arc)
            }
        };
        self.moves.push(PartMove {
            motion: shape,
            speed,
            end: Vector::<3>::new(end_point[0], end_point[1], end_z),
            tool_axis: None,
            corner: self.corner,
            place: Place { line, column: 1 },
            z_place,
        });
        self.position = end_point;
        self.z = end_z;
        Ok(!end)
    }
}

/// The 1-based column of a word's value signed twice (`X+-1.5`) outside comments, which
/// the `g-code` crate's parser (0.6.0) meets with `unreachable!` instead of an error.
fn two_signs(text: &str) -> Option<usize> {
    let bytes = text.as_bytes();
    let mut depth = 0usize;
    for (i, &b) in bytes.iter().enumerate() {
        match b {
            b'(' => depth += 1,
            b')' => depth = depth.saturating_sub(1),
            b';' if depth == 0 => return None,
            b'+' if depth == 0
                && bytes.get(i + 1) == Some(&b'-')
                && i > 0
                && (bytes[i - 1].is_ascii_alphabetic() || bytes[i - 1] == b'$') =>
            {
                return Some(i + 1)
            }
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::planar::{Program, Shape};
    use crate::path::Curve;
    use std::f64::consts::PI;

    fn read(text: &str) -> Program {
        Program::parse_gcode(text, "t.ngc").unwrap_or_else(|e| panic!("{e}"))
    }

    fn refused(text: &str) -> String {
        Program::parse_gcode(text, "t.ngc").unwrap_err().to_string()
    }

    #[test]
    fn a_value_signed_twice_is_refused_where_it_stands() {
        // Found by fuzz/gcode_program: the g-code crate's parser panics on it.
        assert_eq!(
            refused("G1 X1\nt+-1.\0r"),
            "t.ngc:2:2: a number takes one sign, not '+-'"
        );
        assert!(refused("G1 X+-.5").starts_with("t.ngc:1:5: a number takes one sign"));
        let found = String::from_utf8_lossy(b"t+-1.\0r\xcb%\0\0");
        assert!(refused(&found).starts_with("t.ngc:1:2: a number takes one sign"));
        // In a comment it is text.
        let p = Program::parse_gcode("G1 X1 (tolerance +-0.01)\nG1 X2 ; X+-1.\n", "t.ngc");
        assert!(p.is_ok(), "{p:?}");
    }

    #[test]
    fn a_square_with_a_rounded_corner_in_inches_and_incremental_moves() {
        let p = read(
            "%\n(square)\nG20 G17 G90 G64 P0.001\nG0 X0 Y0\nG1 X1 F60 ; 1 in/s\n\
             G91 Y0.5\nG3 X-0.5 Y0.5 R0.5\nG90 G61 G1 X0 Y1\nG1 Y0\nM30\n%\nG1 X9\n",
        );
        let moves = p.moves();
        assert_eq!(moves.len(), 5);
        assert!((p.point(0.0) - Vector2::zeros()).amax() < 1e-15);
        assert_eq!(moves[0].speed, Speed::Feed(25.4));
        assert_eq!(moves[0].corner, Corner::Blend(0.0254));
        assert_eq!(moves[3].corner, Corner::ExactStop);
        assert_eq!(moves[4].corner, Corner::ExactStop);
        assert_eq!(moves[2].line, 7);
        let Shape::Arc(a) = &moves[2].shape else {
            panic!("{:?}", moves[2].shape)
        };
        assert!((a.center() - Vector2::new(12.7, 12.7)).amax() < 1e-12);
        assert!((a.sweep() - PI / 2.0).abs() < 1e-12);
        let want = 25.4 + 12.7 + 12.7 * PI / 2.0 + 12.7 + 25.4;
        assert!((p.length() - want).abs() < 1e-12, "{}", p.length());
        assert!(p.warnings.is_empty(), "{:?}", p.warnings);
    }

    #[test]
    fn the_cam_preamble_is_skipped_with_one_warning_per_kind() {
        let p = read(
            "G21 G40 G49 G80 G94\nG54\nT1 M6\nS12000 M3 M8\nG0 Z5\nG0 X10 Y10\nG1 Z-1 F100\n\
             G1 X20 F600\nG2 X30 Y10 I5 J0\nG0 Z5\nG0 X0 Y0\nM5 M9\nM2\n",
        );
        assert_eq!(p.warnings.len(), 11, "{:#?}", p.warnings);
        assert!(p.warnings.iter().any(|w| w.starts_with("t.ngc:5: Z-only")));
        // A skipped word is named where it stands.
        assert!(
            p.warnings[0].starts_with("t.ngc:1:5: G40 "),
            "{}",
            p.warnings[0]
        );
        // The path starts at the first cut's start; the retract after the arc makes it an
        // exact stop; the last rapid is part of the path.
        assert_eq!(p.point(0.0), Vector2::new(10.0, 10.0));
        let moves = p.moves();
        assert_eq!(moves.len(), 3);
        assert_eq!(moves[1].corner, Corner::ExactStop);
        assert_eq!(moves[2].speed, Speed::Rapid);
        assert_eq!(moves[0].speed, Speed::Feed(10.0));
        assert_eq!(p.point(p.length()), Vector2::zeros());
    }

    #[test]
    fn full_circles_centres_and_the_default_feed() {
        let p = read("G1 X5 Y0\nG2 X5 I-5 J0\nG90.1 G3 X0 Y5 I0 J0\n");
        assert_eq!(p.moves()[0].speed, Speed::Default);
        assert!((p.length() - (5.0 + 10.0 * PI + 2.5 * PI)).abs() < 1e-12);
        let Shape::Arc(a) = &p.moves()[1].shape else {
            panic!()
        };
        assert_eq!(a.sweep(), -2.0 * PI);
    }

    #[test]
    fn g64_p_on_a_move_line_p0_and_rapids_with_z() {
        let p = read("G64 P0.01 G1 X1 F60\nG64 P0 G1 X2\nG0 X5 Y5 Z3\nG1 X6\n");
        let moves = p.moves();
        assert_eq!(moves[0].corner, Corner::Blend(0.01));
        assert_eq!(moves[1].corner, Corner::BlendDefault);
        assert_eq!((moves[2].speed, moves.len()), (Speed::Rapid, 4));
        assert!(
            p.warnings.iter().any(|w| w.contains("Z in rapids")),
            "{:?}",
            p.warnings
        );
    }

    #[test]
    fn wrong_programs_are_refused_with_their_line_and_column() {
        for (text, want) in [
            ("G1 X1\nG18\n", "t.ngc:2:1: only the XY plane"),
            ("G1 X1 A3\n", "t.ngc:1:7: the word A"),
            ("X1\n", "t.ngc:1:1: axis words without a motion"),
            (
                "G0 Z1\nG1 X2 Z2\n",
                "t.ngc:2:7: a move of X or Y together with Z",
            ),
            (
                "G1 X10\nG2 X0 Y10 I0 J5\n",
                "t.ngc:2:1: the arc's end is not on its circle",
            ),
            (
                "G1 X10\nG3 Y5 I-5 R3\n",
                "t.ngc:2:7: an arc takes I and J, or R",
            ),
            ("G1 X10\nG3 Y5\n", "t.ngc:2:1: an arc needs I and J, or R"),
            ("G1 X1 F0\n", "t.ngc:1:7: feed F0 must be > 0"),
            ("G1 X1 G0 Y1\n", "t.ngc:1:7: two motion codes"),
            ("G1 X[1+2]\n", "t.ngc:1:5: G-code syntax"),
            ("#1 = 2\n", "t.ngc:1:1: G-code syntax"),
            ("G1 X1e3\n", "t.ngc:1:6: the word E"),
            ("G4 P1\n", "t.ngc:1:1: G4 is not supported"),
            ("G1 X1\nM0\n", "t.ngc:2:1: M0 is not supported"),
            ("G1 X1 I2\n", "t.ngc:1:7: I, J, R and P belong to arcs"),
            ("G1 X1 Y2 G\n", "t.ngc:1:10: a letter without a number"),
            ("G21\nG0 X1\n", "t.ngc: the program has no XY motion"),
            (
                "G1 X5\nG2 X-5 I-5 P2\n",
                "t.ngc:2:12: arcs of more than one turn",
            ),
            ("G54.1 P1\n", "t.ngc:1:1: G54.1 is not supported"),
            (
                "G1 X5\nG2 Z-1 I-5\n",
                "t.ngc:2:4: a move of X or Y together with Z",
            ),
        ] {
            let e = refused(text);
            assert!(e.starts_with(want), "{text:?}: {e}");
        }
    }
}
