//! APT cutter-location (CL) data, the format five-axis CAM post-processors read: each
//! `GOTO/x,y,z,i,j,k` record gives the tool tip and the tool-axis vector, both in the
//! workpiece frame (docs/design/five-axis.md §5.3a). Siemens NX writes it as `.cls`, CATIA
//! as `.aptsource`, Creo as `.ncl`; others as `.cl` or `.apt`.
//!
//! Read:
//! - `GOTO` with six numbers, or three (the tool axis then stays as it was, +Z at the
//!   start, or as `TLAXIS` set it); `GODLTA/dx,dy,dz` (a move by that much); `FROM` (where
//!   the tool starts, a move at rapid from the origin like any first move).
//! - `UNITS/MM` or `UNITS/INCHES` (`UNIT/…` too); without it, a file whose first
//!   `FEDRAT` is in `IPM` or `IPR` is in inches from its first record (NX writes rapids
//!   before it), with a warning saying so. Inch data is read as inch: every length × 25.4.
//! - `FEDRAT/f`, `FEDRAT/MMPM,f`, `FEDRAT/IPM,f` (or the unit after the number): the feed
//!   of the moves after it, mm/min or in/min; `MMPR`/`IPR` per spindle turn, with the turns
//!   of the last `SPINDL` (refused without one). `RAPID`: the next move at rapid.
//! - `CIRCLE/xc,yc,zc,i,j,k,r,…`: the next `GOTO` goes there along the circle of centre
//!   (xc,yc,zc) and radius r about the axis (i,j,k), counter-clockwise about it (the
//!   right-hand rule, as NX and CATIA write it); it becomes chords whose sag is at most
//!   [`ClOptions::arc_sag`]. Both ends must lie on the circle within max(0.01 mm, 0.1 % of
//!   r); r is at most 10 m.
//! - `MSYS/x0,y0,z0,xi,xj,xk,yi,yj,yk` (NX): the frame the following records are written
//!   in (origin, X and Y axes in the part's coordinates). The first one is the frame of
//!   the whole reference; the records after a later, different one are carried into it.
//! - `TLAXIS/i,j,k`: the tool axis for the following three-number `GOTO`s.
//! - `NURBS/` with its `KNOT/…` and `CNTRL/x,y,z` records (NX's spline motion): a clamped
//!   cubic B-spline from the tool's position through the control points (see
//!   [`SplineBlock`]), as chords within [`ClOptions::arc_sag`] at the feed, the tool axis
//!   unchanged; a block that does not fit that reading (counts, knots, weights or axes in
//!   `CNTRL`) is refused.
//! - `FINI`: the end. `PARTNO`, `MULTAX`, `INTOL`, `OUTTOL`, `TOLER`, `END-OF-PATH`: read,
//!   nothing to do. `TOOL PATH`, `TLDATA`, `PAINT`, `LOAD`, `SELECT`, `COOLNT`, `PPRINT`
//!   and any other record that does not move the tool: skipped with one warning per kind.
//!   Lines that are no record at all (a listing's header): skipped with one warning.
//!
//! A `GOTO` to the pose the tool is already at moves nothing and is left out.
//!
//! Refused with the file and line: a malformed `GOTO` (wrong count, not a number,
//! non-finite, a zero axis), `CYCLE` (drilling cycles: their moves are the controller's),
//! `CUTCOM` on (compensation), a `CIRCLE` not followed by a `GOTO` on it, a feed per turn
//! without a spindle speed. `$$` starts a comment; a line ending in `$` continues on the
//! next one, a comment too. Axis vectors are normalised; one whose length is off 1 by
//! more than 1e-6 gets a warning.

use std::collections::BTreeSet;

use super::{Corner, Motion, PartMove, PartProgram, Place, Speed, Warning};
use crate::contour::five_axis::hmm::segment_distance;
use crate::geometry::{self, Vector};
use crate::math;
use crate::path::nurbs_file::read_path_file;
use crate::path::{Curve, Nurbs, PathError};

/// How far an axis vector's length may be off 1 before it is worth a warning.
const UNIT_TOLERANCE: f64 = 1e-6;
/// mm per inch.
const INCH: f64 = 25.4;
/// How far a `CIRCLE`'s ends may lie off it, mm (and this share of its radius).
const CIRCLE_END_TOLERANCE: f64 = 0.01;
const CIRCLE_END_SHARE: f64 = 1e-3;
/// The records written without '/': bare words, or words followed by free text.
const BARE_WORDS: [&str; 13] = [
    "RAPID",
    "FINI",
    "END-OF-PATH",
    "MULTAX",
    "PARTNO",
    "PPRINT",
    "INSERT",
    "STOP",
    "OPSTOP",
    "END",
    "NOPS",
    "GOHOME",
    "REWIND",
];
/// The largest `CIRCLE` radius read, mm: 10 m, beyond any machine's table; at the
/// default sag a full turn of it is 10 000 chords.
const MAX_RADIUS: f64 = 1e4;
/// The most moves a file becomes, `CIRCLE` chords included (2²⁴, the sampling budget of
/// a five-axis curve pair): a huge circle at a tiny sag is refused, not allocated.
const MAX_MOVES: usize = 1 << 24;
/// The most chords one `NURBS` block may become: 20 m of 10 mm radii at the default
/// sag, so no block of a few lines asks for millions of moves.
const MAX_SPLINE_CHORDS: usize = 100_000;

/// What the reader needs beyond the file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClOptions {
    /// The largest sag of the chords a `CIRCLE` record becomes, mm (> 0).
    pub arc_sag: f64,
}

impl Default for ClOptions {
    fn default() -> Self {
        ClOptions { arc_sag: 5e-4 }
    }
}

/// Reads a CL file.
pub fn load_cl(file: impl AsRef<std::path::Path>) -> Result<PartProgram, PathError> {
    load_cl_with(file, &ClOptions::default())
}

/// Reads a CL file with `options`.
pub fn load_cl_with(
    file: impl AsRef<std::path::Path>,
    options: &ClOptions,
) -> Result<PartProgram, PathError> {
    let (name, text) = read_path_file(file.as_ref())?;
    parse_cl_with(&text, &name, options)
}

/// Where a file without a `UNITS` record has its first `FEDRAT` in inches (`IPM`,
/// `IPR`): its line and unit.
fn inch_by_first_feed(text: &str) -> Option<(usize, String)> {
    let records = text
        .lines()
        .map(|l| l.split("$$").next().unwrap_or("").trim());
    let mut first_feed = None;
    for (index, record) in records.enumerate() {
        let upper = record.to_ascii_uppercase();
        if upper.starts_with("UNIT") {
            return None;
        }
        if first_feed.is_none() && upper.starts_with("FEDRAT") {
            let unit = ["IPM", "IPR", "MMPM", "MMPR"]
                .into_iter()
                .find(|u| upper.contains(u))
                .unwrap_or("MMPM");
            first_feed = Some((index + 1, unit.to_string()));
        }
    }
    first_feed.filter(|(_, unit)| unit.starts_with("IP"))
}

/// Parses the text of a CL file; `name` is used in messages.
pub fn parse_cl(text: &str, name: &str) -> Result<PartProgram, PathError> {
    parse_cl_with(text, name, &ClOptions::default())
}

/// Parses the text of a CL file with `options`; `name` is used in messages.
pub fn parse_cl_with(
    text: &str,
    name: &str,
    options: &ClOptions,
) -> Result<PartProgram, PathError> {
    if !(options.arc_sag.is_finite() && options.arc_sag > 0.0) {
        return Err(PathError::invalid(format!(
            "the chord sag for CIRCLE records must be finite and > 0 mm, got {}",
            options.arc_sag
        )));
    }
    let mut reader = Reader::new(name, *options);
    if let Some((line, unit)) = inch_by_first_feed(text) {
        // NX writes the first rapids before the first FEDRAT: the feed's unit is the
        // file's, from its first record.
        reader.scale = INCH;
        reader.warn(
            line,
            format!("no UNITS record and the first FEDRAT in {unit}: the file is read in inches"),
        );
    }
    let mut record = String::new();
    let mut first_line = 0;
    let mut comment_continues = false;
    for (index, raw) in text.lines().enumerate() {
        // A comment that ends in `$` goes on over the next line (Creo's `$$-> CSYS / …, $`).
        if comment_continues {
            comment_continues = raw.trim_end().ends_with('$');
            continue;
        }
        let (line, comment) = match raw.split_once("$$") {
            Some((code, comment)) => (code.trim(), Some(comment)),
            None => (raw.trim(), None),
        };
        comment_continues = comment.is_some_and(|c| c.trim_end().ends_with('$'));
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
        if !reader.record(whole.trim(), first_line)? {
            break;
        }
    }
    if !record.is_empty() {
        return Err(reader.fail(
            first_line,
            "the last record ends in a continuation '$'".into(),
        ));
    }
    reader.finish()
}

/// An NX `NURBS` block: a clamped cubic B-spline from the tool's position (its first
/// control point, not written) through the `CNTRL` points (the last one its end), whose
/// `KNOT` records list the interior knots on 0..1 and then 1. Its chords are moves at the
/// feed; the tool axis stays as it was. No document states the format: how it was
/// established is in docs/design/five-axis.md §5.3a.
#[derive(Clone, Debug)]
struct SplineBlock {
    line: usize,
    start: Vector<3>,
    knots: Vec<f64>,
    points: Vec<Vector<3>>,
}

impl SplineBlock {
    fn curve(&self) -> Result<Nurbs<3>, String> {
        let (m, n) = (self.knots.len(), self.points.len());
        if m == 0 || n != m + 2 {
            return Err(format!(
                "{m} knots and {n} control points: a cubic block has two control points more \
                 than knots (at least one knot, the last 1)"
            ));
        }
        if self.knots[m - 1] != 1.0 || self.knots.iter().any(|k| !(*k > 0.0 && *k <= 1.0)) {
            return Err("the knots must lie in (0, 1] and end with 1".into());
        }
        let mut knots = vec![0.0; 4];
        knots.extend_from_slice(&self.knots[..m - 1]);
        knots.extend_from_slice(&[1.0; 4]);
        let mut points = vec![self.start];
        points.extend_from_slice(&self.points);
        Nurbs::new(3, knots, points, None).map_err(|e| e.to_string())
    }
}

/// Points along `curve` (its end the last) whose chords leave it by at most `sag` mm,
/// judged at a quarter, half and three quarters of each chord's parameter span; `None`
/// beyond `room` points.
fn chords_within(curve: &Nurbs<3>, sag: f64, room: usize) -> Option<Vec<Vector<3>>> {
    let (u0, u1) = curve.param_range();
    let mut out = Vec::new();
    // Spans still to judge, the next one last; each with its end points.
    let mut spans = vec![(u0, u1, curve.point(u0), curve.point(u1))];
    while let Some((a, b, pa, pb)) = spans.pop() {
        let off = [0.25, 0.5, 0.75].iter().any(|t| {
            let p = curve.point(a + (b - a) * t);
            // NaN (lengths past f64) counts as off.
            let off = segment_distance(&p, &pa, &pb);
            off.is_nan() || off > sag
        });
        if off && b - a > 1e-9 * (u1 - u0) {
            let m = 0.5 * (a + b);
            let pm = curve.point(m);
            spans.push((m, b, pm, pb));
            spans.push((a, m, pa, pm));
            continue;
        }
        if out.len() >= room {
            return None;
        }
        out.push(pb);
    }
    Some(out)
}

/// A `CIRCLE` record waiting for the `GOTO` that ends it.
#[derive(Clone, Copy, Debug)]
struct Circle {
    centre: Vector<3>,
    axis: Vector<3>,
    radius: f64,
    line: usize,
}

/// A frame from `MSYS`: origin and the rotation whose columns are its X, Y, Z axes.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Frame {
    origin: Vector<3>,
    rotation: nalgebra::Matrix3<f64>,
}

impl Frame {
    fn point_in_part(self, p: &Vector<3>) -> Vector<3> {
        self.origin + self.rotation * p
    }
}

struct Reader<'a> {
    name: &'a str,
    options: ClOptions,
    data: PartProgram,
    /// mm per length unit of the file.
    scale: f64,
    axis: Vector<3>,
    tip: Vector<3>,
    feed: Option<f64>,
    rapid_next: bool,
    spindle_rpm: Option<f64>,
    circle: Option<Circle>,
    /// An NX `NURBS` block being read.
    spline: Option<SplineBlock>,
    /// The reference's frame (the first `MSYS`) and the frame records are written in now.
    first_frame: Option<Frame>,
    frame: Option<Frame>,
    skipped: BTreeSet<String>,
}

impl<'a> Reader<'a> {
    fn new(name: &'a str, options: ClOptions) -> Self {
        Reader {
            name,
            options,
            data: PartProgram {
                file: name.to_string(),
                start: Vector::<3>::zeros(),
                moves: Vec::new(),
                warnings: Vec::new(),
            },
            scale: 1.0,
            axis: Vector::<3>::z(),
            tip: Vector::<3>::zeros(),
            feed: None,
            rapid_next: false,
            spindle_rpm: None,
            circle: None,
            spline: None,
            first_frame: None,
            frame: None,
            skipped: BTreeSet::new(),
        }
    }

    fn fail(&self, line: usize, message: String) -> PathError {
        PathError::File {
            file: self.name.to_string(),
            line,
            column: 0,
            message,
        }
    }

    fn warn(&mut self, line: usize, message: String) {
        self.data.warnings.push(Warning {
            file: self.name.to_string(),
            place: Place { line, column: 0 },
            message,
        });
    }

    /// One warning per kind of skipped record.
    fn skip(&mut self, kind: &str, line: usize) {
        // A String only for a kind not seen yet: a program repeats its kinds.
        if !self.skipped.contains(kind) && self.skipped.insert(kind.to_owned()) {
            self.warn(
                line,
                format!(
                    "{kind} skipped (it does not move the tool); further ones are skipped \
                     silently"
                ),
            );
        }
    }

    /// Reads one record; `false` at `FINI`.
    fn record(&mut self, record: &str, line: usize) -> Result<bool, PathError> {
        if record.is_empty() {
            return Ok(true);
        }
        let (word, args) = match record.split_once('/') {
            Some((word, args)) => (word.trim().to_ascii_uppercase(), Some(args)),
            None => {
                // A record without '/' is a bare word, or one followed by free text
                // (`PARTNO BRACKET 7`); anything else is no record.
                let first = record.split_whitespace().next().unwrap_or("");
                let first = first.to_ascii_uppercase();
                if !BARE_WORDS.contains(&first.as_str()) {
                    self.skip("text that is not a CL record (a listing's header?)", line);
                    return Ok(true);
                }
                (first, None)
            }
        };
        // A record's word is letters, digits, '-', '_' and spaces (`TOOL PATH`).
        let is_word = !word.is_empty()
            && word.starts_with(|c: char| c.is_ascii_alphabetic())
            && word
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | ' '));
        if !is_word {
            self.skip("text that is not a CL record (a listing's header?)", line);
            return Ok(true);
        }
        let args = args.unwrap_or("");
        // A NURBS block ends at the first record that is not its own (PAINT may come
        // between its records).
        if !matches!(word.as_str(), "KNOT" | "CNTRL" | "PAINT") {
            self.end_spline()?;
        }
        match word.as_str() {
            "GOTO" => {
                let n = self.numbers(args, line, "GOTO")?;
                self.goto(&n, line)?;
            }
            "GODLTA" => {
                let n = self.numbers(args, line, "GODLTA")?;
                if n.len() != 3 {
                    return Err(self.fail(
                        line,
                        format!("GODLTA needs dx,dy,dz, got {} numbers", n.len()),
                    ));
                }
                let delta =
                    self.in_part_frame_vector(&Vector::<3>::new(n[0], n[1], n[2])) * self.scale;
                let to = self.tip + delta;
                self.push_move(to, line);
            }
            "FROM" => {
                let n = self.numbers(args, line, "FROM")?;
                self.rapid_next = true;
                self.goto(&n, line)?;
            }
            "RAPID" => self.rapid_next = true,
            "FEDRAT" => self.feed_rate(args, line)?,
            "SPINDL" => self.spindle(args),
            // CAMWorks writes `UNIT/MM`.
            "UNITS" | "UNIT" => {
                let unit = args.trim().to_ascii_uppercase();
                self.scale = match unit.as_str() {
                    "MM" | "MILLIMETERS" | "MILLIMETER" => 1.0,
                    "INCHES" | "INCH" | "IN" => INCH,
                    other => {
                        return Err(self.fail(line, format!("UNITS/{other}: expected MM or INCHES")))
                    }
                };
            }
            "CIRCLE" => {
                let n = self.numbers(args, line, "CIRCLE")?;
                if n.len() < 7 {
                    return Err(self.fail(
                        line,
                        format!(
                            "CIRCLE needs xc,yc,zc,i,j,k,r (and optional tolerances), got {} \
                             numbers",
                            n.len()
                        ),
                    ));
                }
                let centre = self.in_part_frame(&Vector::<3>::new(n[0], n[1], n[2]));
                let axis =
                    geometry::unit(&self.in_part_frame_vector(&Vector::<3>::new(n[3], n[4], n[5])))
                        .ok_or_else(|| self.fail(line, "CIRCLE: the axis i,j,k is zero".into()))?;
                let radius = n[6] * self.scale;
                if !(radius > 0.0 && radius <= MAX_RADIUS) {
                    return Err(self.fail(
                        line,
                        format!("CIRCLE: the radius {radius} mm is not in (0, {MAX_RADIUS}] mm"),
                    ));
                }
                self.circle = Some(Circle {
                    centre,
                    axis,
                    radius,
                    line,
                });
            }
            "MSYS" => self.msys(args, line)?,
            "TLAXIS" => {
                let n = self.numbers(args, line, "TLAXIS")?;
                if n.len() != 3 {
                    return Err(
                        self.fail(line, format!("TLAXIS needs i,j,k, got {} numbers", n.len()))
                    );
                }
                self.axis = self.unit_axis(Vector::<3>::new(n[0], n[1], n[2]), line, "TLAXIS")?;
            }
            "CYCLE" => {
                if !args.trim().eq_ignore_ascii_case("OFF") {
                    return Err(self.fail(
                        line,
                        format!(
                            "CYCLE/{}: drilling cycles are not supported (their moves are the \
                             controller's); output them as GOTO moves from the CAM system",
                            args.trim()
                        ),
                    ));
                }
            }
            "CUTCOM" => {
                if !args.trim().to_ascii_uppercase().starts_with("OFF") {
                    return Err(self.fail(
                        line,
                        "CUTCOM: cutter compensation is not supported; output the tool's \
                         centre (or tip) path from the CAM system"
                            .into(),
                    ));
                }
            }
            "NURBS" => {
                if self.data.moves.is_empty() {
                    return Err(self.fail(line, "NURBS before any GOTO: it has no start".into()));
                }
                self.spline = Some(SplineBlock {
                    line,
                    start: self.tip,
                    knots: Vec::new(),
                    points: Vec::new(),
                });
            }
            "KNOT" => {
                let n = self.numbers(args, line, "KNOT")?;
                match &mut self.spline {
                    Some(block) if block.points.is_empty() => block.knots.extend(n),
                    _ => return Err(self.fail(line, "KNOT outside a NURBS block's head".into())),
                }
            }
            "CNTRL" => {
                let n = self.numbers(args, line, "CNTRL")?;
                if n.len() != 3 {
                    return Err(self.fail(
                        line,
                        format!(
                            "CNTRL needs x,y,z, got {} numbers (weights and tool axes in NURBS \
                             blocks are not read)",
                            n.len()
                        ),
                    ));
                }
                let point = self.in_part_frame(&Vector::<3>::new(n[0], n[1], n[2]));
                match &mut self.spline {
                    Some(block) => block.points.push(point),
                    None => return Err(self.fail(line, "CNTRL outside a NURBS block".into())),
                }
            }
            "GOHOME" => {
                return Err(self.fail(
                    line,
                    "GOHOME moves to the machine's home, which the CL data does not give; \
                     output the move as a GOTO"
                        .into(),
                ))
            }
            "FINI" => return Ok(false),
            // Read, and nothing for the reference to do: the part's name, the multi-axis
            // mode (six-number GOTOs say it), the CAM's tolerances, an operation's end.
            "PARTNO" | "MULTAX" | "INTOL" | "OUTTOL" | "TOLER" | "END-OF-PATH" => {}
            other => {
                let kind = other.to_string();
                self.skip(&kind, line);
            }
        }
        Ok(true)
    }

    fn numbers(&self, args: &str, line: usize, word: &str) -> Result<Vec<f64>, PathError> {
        args.split(',')
            .map(|field| {
                let field = field.trim();
                field
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| {
                        self.fail(line, format!("{word}: '{field}' is not a finite number"))
                    })
            })
            .collect()
    }

    fn in_part_frame(&self, p: &Vector<3>) -> Vector<3> {
        self.to_first_frame(&(p * self.scale), true)
    }

    fn in_part_frame_vector(&self, v: &Vector<3>) -> Vector<3> {
        self.to_first_frame(v, false)
    }

    /// A point (or a direction) written in the current `MSYS` frame, in the first one's.
    fn to_first_frame(&self, v: &Vector<3>, point: bool) -> Vector<3> {
        match (self.first_frame, self.frame) {
            (Some(first), Some(now)) if first != now => {
                let in_part = if point {
                    now.point_in_part(v)
                } else {
                    now.rotation * v
                };
                let back = first.rotation.transpose();
                if point {
                    back * (in_part - first.origin)
                } else {
                    back * in_part
                }
            }
            _ => *v,
        }
    }

    fn unit_axis(
        &mut self,
        given: Vector<3>,
        line: usize,
        word: &str,
    ) -> Result<Vector<3>, PathError> {
        let length = geometry::norm(&given);
        if length == 0.0 {
            return Err(self.fail(line, format!("{word}: the tool axis i,j,k is zero")));
        }
        if (length - 1.0).abs() > UNIT_TOLERANCE {
            self.warn(line, format!("tool axis of length {length} normalised"));
        }
        // A length within a few ulps of 1 is unit already: dividing would only round (and a
        // written unit axis would not read back as written).
        let unit = if (length - 1.0).abs() <= 4.0 * f64::EPSILON {
            given
        } else {
            given / length
        };
        Ok(self.in_part_frame_vector(&unit))
    }

    fn goto(&mut self, numbers: &[f64], line: usize) -> Result<(), PathError> {
        let tip = match numbers.len() {
            3 | 6 => self.in_part_frame(&Vector::<3>::new(numbers[0], numbers[1], numbers[2])),
            n => {
                return Err(self.fail(
                    line,
                    format!("GOTO needs x,y,z or x,y,z,i,j,k, got {n} numbers"),
                ))
            }
        };
        if numbers.len() == 6 {
            self.axis = self.unit_axis(
                Vector::<3>::new(numbers[3], numbers[4], numbers[5]),
                line,
                "GOTO",
            )?;
        }
        if let Some(circle) = self.circle.take() {
            return self.arc(circle, tip, line);
        }
        self.push_move(tip, line);
        Ok(())
    }

    fn push_move(&mut self, tip: Vector<3>, line: usize) {
        // The first move is where the tool path starts.
        if self.data.moves.is_empty() {
            self.data.start = tip;
        }
        let speed = if std::mem::take(&mut self.rapid_next) {
            Speed::Rapid
        } else {
            self.feed.map_or(Speed::Default, Speed::Feed)
        };
        // A GOTO to the pose the tool is at (CAM systems repeat points) moves nothing.
        if let Some(last) = self.data.moves.last() {
            if last.end == tip && last.tool_axis == Some(self.axis) {
                return;
            }
        }
        self.data.moves.push(PartMove {
            motion: Motion::Line,
            speed,
            end: tip,
            tool_axis: Some(self.axis),
            corner: Corner::BlendDefault,
            place: Place { line, column: 0 },
            z_place: None,
            compensation: None,
        });
        self.tip = tip;
    }

    /// The chords of the NURBS block being read, if any (see [`SplineBlock`]).
    fn end_spline(&mut self) -> Result<(), PathError> {
        let Some(block) = self.spline.take() else {
            return Ok(());
        };
        let curve = block
            .curve()
            .map_err(|e| self.fail(block.line, format!("NURBS: {e}")))?;
        let room = MAX_MOVES
            .saturating_sub(self.data.moves.len())
            .min(MAX_SPLINE_CHORDS);
        let chords = chords_within(&curve, self.options.arc_sag, room).ok_or_else(|| {
            self.fail(
                block.line,
                format!(
                    "NURBS: more than {room} chords at a sag of {} mm (a block may have \
                     {MAX_SPLINE_CHORDS}, the file {MAX_MOVES} moves)",
                    self.options.arc_sag
                ),
            )
        })?;
        for point in chords {
            self.push_move(point, block.line);
            // Every chord at the feed: only the first one may follow a RAPID.
            self.rapid_next = false;
        }
        Ok(())
    }

    /// The chords of a `CIRCLE` from the tip to `end`, counter-clockwise about its axis.
    fn arc(&mut self, circle: Circle, end: Vector<3>, line: usize) -> Result<(), PathError> {
        if self.data.moves.is_empty() {
            return Err(self.fail(
                circle.line,
                "CIRCLE before any GOTO: the arc has no start".into(),
            ));
        }
        let start = self.tip;
        let (a, ra, ha) = polar(&circle, &start);
        let (b, rb, hb) = polar(&circle, &end);
        let allowed = CIRCLE_END_TOLERANCE.max(CIRCLE_END_SHARE * circle.radius);
        for (r, which) in [(ra, "start"), (rb, "end")] {
            if (r - circle.radius).abs() > allowed {
                return Err(self.fail(
                    line,
                    format!(
                        "the arc's {which} is {r:.4} mm from the axis of the CIRCLE on line {} \
                         (radius {:.4} mm, {allowed:.4} mm allowed)",
                        circle.line, circle.radius
                    ),
                ));
            }
        }
        let (u, v) = (a, circle.axis.cross(&a));
        let mut sweep = math::atan2(b.dot(&v), b.dot(&u));
        if sweep <= 1e-12 {
            sweep += std::f64::consts::TAU;
        }
        let step = super::chord_angle(circle.radius, self.options.arc_sag);
        let chords = ((sweep / step).ceil() as usize).max(1);
        if chords >= MAX_MOVES.saturating_sub(self.data.moves.len()) {
            return Err(self.fail(
                circle.line,
                format!(
                    "CIRCLE: {chords} chords at a sag of {} mm would make the file more than \
                     {MAX_MOVES} moves",
                    self.options.arc_sag
                ),
            ));
        }
        for k in 1..chords {
            let t = k as f64 / chords as f64;
            let angle = sweep * t;
            let radius = ra + (rb - ra) * t;
            let height = ha + (hb - ha) * t;
            let point = circle.centre
                + (u * math::cos(angle) + v * math::sin(angle)) * radius
                + circle.axis * height;
            self.push_move(point, line);
            // Every chord at the feed: only the first one may follow a RAPID.
            self.rapid_next = false;
        }
        self.push_move(end, line);
        Ok(())
    }

    fn feed_rate(&mut self, args: &str, line: usize) -> Result<(), PathError> {
        let mut value = None;
        let mut unit = None;
        for field in args.split(',').map(str::trim).filter(|f| !f.is_empty()) {
            match field.parse::<f64>() {
                Ok(v) => value = Some(v),
                Err(_) => unit = Some(field.to_ascii_uppercase()),
            }
        }
        let Some(value) = value.filter(|v| v.is_finite() && *v > 0.0) else {
            return Err(self.fail(line, format!("FEDRAT/{args}: no feed > 0")));
        };
        let unit = unit.unwrap_or_else(|| "MMPM".to_string());
        let inch = unit.starts_with("IP");
        let per_unit = if inch { INCH } else { 1.0 };
        let per_minute = match unit.as_str() {
            "MMPM" | "IPM" => value * per_unit,
            "MMPR" | "IPR" => {
                let Some(rpm) = self.spindle_rpm else {
                    return Err(self.fail(
                        line,
                        format!("FEDRAT/{unit}: a feed per turn needs a SPINDL speed before it"),
                    ));
                };
                value * per_unit * rpm
            }
            other => {
                return Err(self.fail(
                    line,
                    format!("FEDRAT unit {other}: expected MMPM, IPM, MMPR or IPR"),
                ))
            }
        };
        self.feed = Some(per_minute / 60.0);
        Ok(())
    }

    fn spindle(&mut self, args: &str) {
        // SPINDL/RPM,n,CLW or SPINDL/n,RPM,…: the turns per minute; OFF stops it.
        let fields: Vec<&str> = args.split(',').map(str::trim).collect();
        if fields.iter().any(|f| f.eq_ignore_ascii_case("OFF")) {
            self.spindle_rpm = None;
        } else if let Some(rpm) = fields.iter().find_map(|f| f.parse::<f64>().ok()) {
            if rpm.is_finite() && rpm > 0.0 {
                self.spindle_rpm = Some(rpm);
            }
        }
    }

    fn msys(&mut self, args: &str, line: usize) -> Result<(), PathError> {
        let n = self.numbers(args, line, "MSYS")?;
        if n.len() != 9 {
            return Err(self.fail(
                line,
                format!(
                    "MSYS needs x0,y0,z0 and the X and Y axes (9 numbers), got {}",
                    n.len()
                ),
            ));
        }
        let x = Vector::<3>::new(n[3], n[4], n[5]);
        let y = Vector::<3>::new(n[6], n[7], n[8]);
        let (Some(x), Some(y)) = (geometry::unit(&x), geometry::unit(&y)) else {
            return Err(self.fail(line, "MSYS: an axis is zero".into()));
        };
        if x.dot(&y).abs() > 1e-4 {
            return Err(self.fail(
                line,
                format!(
                    "MSYS: the X and Y axes are not perpendicular (cos {:.2e})",
                    x.dot(&y)
                ),
            ));
        }
        let y = geometry::unit(&(y - x * x.dot(&y))).unwrap_or(y);
        let z = x.cross(&y);
        let frame = Frame {
            origin: Vector::<3>::new(n[0], n[1], n[2]) * self.scale,
            rotation: nalgebra::Matrix3::from_columns(&[x, y, z]),
        };
        match self.first_frame {
            None => self.first_frame = Some(frame),
            Some(first) if first != frame && self.frame == Some(first) => self.warn(
                line,
                "a new MSYS frame: the records after it are carried into the first MSYS's \
                 frame"
                    .into(),
            ),
            _ => {}
        }
        self.frame = Some(frame);
        Ok(())
    }

    fn finish(mut self) -> Result<PartProgram, PathError> {
        self.end_spline()?;
        if let Some(circle) = self.circle {
            return Err(self.fail(circle.line, "a CIRCLE record with no GOTO after it".into()));
        }
        if self.data.moves.len() < 2 {
            return Err(self.fail(
                0,
                format!(
                    "a path needs at least two GOTO points, found {}",
                    self.data.moves.len()
                ),
            ));
        }
        Ok(self.data)
    }
}

/// A point's place about a circle's axis: the unit direction from the axis to it in the
/// circle's plane, its distance from the axis, and its height along the axis.
fn polar(circle: &Circle, p: &Vector<3>) -> (Vector<3>, f64, f64) {
    let offset = p - circle.centre;
    let height = offset.dot(&circle.axis);
    let radial = offset - circle.axis * height;
    let r = geometry::norm(&radial);
    let direction = geometry::unit(&radial).unwrap_or_else(|| any_normal(&circle.axis));
    (direction, r, height)
}

/// Some unit vector normal to `axis` (a unit vector).
fn any_normal(axis: &Vector<3>) -> Vector<3> {
    let helper = if axis[0].abs() < 0.9 {
        Vector::<3>::x()
    } else {
        Vector::<3>::y()
    };
    geometry::unit(&axis.cross(&helper)).unwrap_or(helper)
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
    fn a_goto_to_where_the_tool_is_moves_nothing() {
        let data = parse_cl(
            "GOTO/1,2,3,0,0,1\nGOTO/1,2,3,0,0,1\nRAPID\nGOTO/1,2,3\nGOTO/4,2,3\n\
             GOTO/4,2,3,0,0.6,0.8\n",
            "r.cls",
        )
        .unwrap();
        let lines: Vec<usize> = data.moves.iter().map(|m| m.place.line).collect();
        // The repeats (lines 2 and 4) are left out, the RAPID spent on its own repeat; a
        // turn on the spot (line 6) is a move of the tool axis.
        assert_eq!(lines, [1, 5, 6]);
        assert!(data.moves.iter().all(|m| m.speed == Speed::Default));
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
        assert_refused(&cases, "part.cl");
        let e = load_cl("/nonexistent/part.cl").unwrap_err().to_string();
        assert!(
            e.contains("/nonexistent/part.cl") && e.contains("cannot read"),
            "{e}"
        );
    }
    /// The tips of a program, mm.
    fn tips(data: &PartProgram) -> Vec<Vector<3>> {
        data.poses().iter().map(|p| p.tip).collect()
    }

    #[test]
    fn an_nx_inch_file_with_msys_rapid_feed_and_a_circle() {
        // NX's CLSF as it writes an inch program: no UNITS record, FEDRAT/IPM, an MSYS
        // record, paint and tool records, a rapid before the first FEDRAT (in inches too),
        // a CIRCLE before the GOTO that ends the arc.
        let text = "TOOL PATH/FINISH,TOOL,EM_250\n\
            TLDATA/MILL,0.2500,0.0000,2.0000,0.0000,0.0000\n\
            MSYS/0.0000,0.0000,0.0000,1.0000000,0.0000000,0.0000000,0.0000000,1.0000000,0.0000000\n\
            $$ centerline data\n\
            PAINT/PATH\n\
            PAINT/SPEED,10\n\
            RAPID\n\
            GOTO/1.0000,0.0000,0.5000,0.0000000,0.0000000,1.0000000\n\
            FEDRAT/IPM,20.0000\n\
            PAINT/COLOR,211\n\
            GOTO/1.0000,0.0000,0.0000\n\
            CIRCLE/0.0000,0.0000,0.0000,0.0000000,0.0000000,1.0000000,1.0000,0.0010,0.0500,0.2500,0.0000\n\
            GOTO/0.0000,1.0000,0.0000\n\
            CIRCLE/0.0000,0.0000,0.0000,0.0000000,0.0000000,-1.0000000,1.0000,0.0010,0.0500,0.2500,0.0000\n\
            GOTO/1.0000,0.0000,0.0000\n\
            END-OF-PATH\n";
        let data = parse_cl(text, "nx.cls").unwrap();
        let t = tips(&data);
        assert_eq!(t[0], Vector::<3>::new(25.4, 0.0, 12.7));
        assert_eq!(t[1], Vector::<3>::new(25.4, 0.0, 0.0));
        // Counter-clockwise about +Z from (1,0) to (0,1): a quarter; then clockwise (axis
        // -Z) back: the same quarter. Every chord end on the 1 in circle, each chord's
        // sag within the option, and the y of the first arc's points rising.
        let r = 25.4;
        let sag = ClOptions::default().arc_sag;
        let quarter = (2.0 * math::acos(1.0 - sag / r)).recip() * std::f64::consts::FRAC_PI_2;
        let n = quarter.ceil() as usize;
        assert_eq!(t.len(), 2 + 2 * n, "{}", t.len());
        for p in &t[2..] {
            assert!((geometry::norm(p) - r).abs() < 1e-9 && p[2] == 0.0, "{p:?}");
            assert!(p[0] >= -1e-9 && p[1] >= -1e-9, "{p:?}");
        }
        assert!(t[2..2 + n].windows(2).all(|w| w[1][1] > w[0][1]));
        assert!(t[2 + n..].windows(2).all(|w| w[1][1] < w[0][1]));
        assert_eq!(t[1 + n], Vector::<3>::new(0.0, 25.4, 0.0));
        for w in t[1..].windows(2) {
            let chord = geometry::dist(&w[0], &w[1]);
            assert!(r - (r * r - chord * chord / 4.0).sqrt() <= sag * (1.0 + 1e-9));
        }
        // Speeds: the first move at rapid, the rest at 20 in/min.
        assert_eq!(data.moves[0].speed, Speed::Rapid);
        for m in &data.moves[1..] {
            assert_eq!(m.speed, Speed::Feed(20.0 * 25.4 / 60.0));
        }
        // One warning for the inch reading and one per skipped kind, none for MSYS.
        assert_eq!(
            data.warning_lines(),
            [
                "nx.cls:9: no UNITS record and the first FEDRAT in IPM: the file is read in \
                 inches",
                "nx.cls:1: TOOL PATH skipped (it does not move the tool); further ones are \
                 skipped silently",
                "nx.cls:2: TLDATA skipped (it does not move the tool); further ones are \
                 skipped silently",
                "nx.cls:5: PAINT skipped (it does not move the tool); further ones are skipped \
                 silently",
            ]
        );
    }

    /// The test's own cubic B-spline (Cox–de Boor) at u.
    fn de_boor(knots: &[f64], points: &[Vector<3>], u: f64) -> Vector<3> {
        fn basis(k: &[f64], i: usize, p: usize, u: f64) -> f64 {
            if p == 0 {
                let last = u == k[k.len() - 1] && k[i] < k[i + 1] && k[i + 1] == u;
                return if (k[i] <= u && u < k[i + 1]) || last {
                    1.0
                } else {
                    0.0
                };
            }
            let left = if k[i + p] > k[i] {
                (u - k[i]) / (k[i + p] - k[i]) * basis(k, i, p - 1, u)
            } else {
                0.0
            };
            let right = if k[i + p + 1] > k[i + 1] {
                (k[i + p + 1] - u) / (k[i + p + 1] - k[i + 1]) * basis(k, i + 1, p - 1, u)
            } else {
                0.0
            };
            left + right
        }
        points
            .iter()
            .enumerate()
            .fold(Vector::<3>::zeros(), |sum, (i, q)| {
                sum + q * basis(knots, i, 3, u)
            })
    }

    #[test]
    fn nx_nurbs_blocks_are_read_as_cubic_splines_from_the_tool_position() {
        // As NX writes spline motion (TetraDecaPost's test_prt listing): the start is the
        // GOTO before the block, KNOT lists the interior knots and 1, the last CNTRL is
        // the end; a second block goes on from there, PAINT between records, KNOT values
        // over two lines.
        let text = "GOTO/-1.7710,1.5994,1.3538\nNURBS/\nKNOT/1.0000000\n\
            CNTRL/-1.6893,1.6898,1.3538\nPAINT/COLOR,37\nCNTRL/-1.6017,1.7730,1.3538\n\
            CNTRL/-1.5072,1.8500,1.3538\nNURBS/\nKNOT/0.1153846\nKNOT/0.8846154,1.0000000\n\
            CNTRL/-1.40,1.92,1.3538\nCNTRL/-1.10,2.05,1.35\nCNTRL/-0.80,2.10,1.34\n\
            CNTRL/-0.50,2.12,1.33\nCNTRL/-0.20,2.10,1.33\nGOTO/0.0,2.0,1.33\n";
        let data = parse_cl(text, "nx.cls").unwrap();
        assert!(data.warnings.len() == 1, "{:?}", data.warning_lines()); // PAINT
        let t = tips(&data);
        let v = |x: f64, y: f64, z: f64| Vector::<3>::new(x, y, z);
        let first = [
            v(-1.7710, 1.5994, 1.3538),
            v(-1.6893, 1.6898, 1.3538),
            v(-1.6017, 1.7730, 1.3538),
            v(-1.5072, 1.8500, 1.3538),
        ];
        let mut second = vec![first[3]];
        second.extend([
            v(-1.40, 1.92, 1.3538),
            v(-1.10, 2.05, 1.35),
            v(-0.80, 2.10, 1.34),
            v(-0.50, 2.12, 1.33),
            v(-0.20, 2.10, 1.33),
        ]);
        let k1 = [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
        let k2 = [0.0, 0.0, 0.0, 0.0, 0.1153846, 0.8846154, 1.0, 1.0, 1.0, 1.0];
        // Dense samples of the test's own curves.
        let dense: Vec<(usize, Vector<3>)> = (0..=20_000)
            .map(|i| (1, de_boor(&k1, &first, i as f64 / 20_000.0)))
            .chain((0..=20_000).map(|i| (2, de_boor(&k2, &second, i as f64 / 20_000.0))))
            .collect();
        let near = |p: &Vector<3>| {
            dense
                .iter()
                .map(|(_, q)| geometry::dist(p, q))
                .fold(f64::INFINITY, f64::min)
        };
        let sag = ClOptions::default().arc_sag;
        let ends = t.iter().position(|p| *p == first[3]).unwrap();
        assert!(ends > 2, "the first block in {ends} chords");
        // Every chord end on the curves (to the dense sampling's reach), every chord's
        // middle within the sag, the second block's end its last CNTRL, then the GOTO.
        assert_eq!(t[t.len() - 2], second[5]);
        assert_eq!(t[t.len() - 1], v(0.0, 2.0, 1.33));
        for w in t[..t.len() - 1].windows(2) {
            assert!(near(&w[1]) < 2e-5, "{:?}", w[1]);
            assert!(near(&((w[0] + w[1]) * 0.5)) <= sag + 2e-5);
        }
        assert!(t.len() > 12, "{} points", t.len());
    }

    #[test]
    fn a_creo_file_with_spaced_slashes_and_a_comment_continued() {
        // As Creo's Pro/CLfile writes it: a `$$->` comment continued with `$` over two
        // lines of numbers, spaced slashes, a record continued with `$`.
        let text = "$$*          Pro/CLfile  Version 8.0 - 8.0.3.0\nUNITS / MM\n\
            $$-> CSYS / 1.0, 0.0, 0.0, 0.0,  $\n            0.0, 1.0, 0.0, 0.0,  $\n\
            \x20           0.0, 0.0, 1.0, 0.0\nRAPID \nGOTO / 0.0, 1.5, 2.0\n\
            FEDRAT / 400.000000,  MMPM\nGOTO / 0.0, 1.5, -1.5\n\
            CIRCLE / 0.0, 0.0, -1.5,  $\n0.0, 0.0, -1.0,  1.5\nGOTO / 1.5, 0.0, -1.5\nFINI \n";
        let data = parse_cl(text, "creo.ncl").unwrap();
        assert!(data.warnings.is_empty(), "{:?}", data.warning_lines());
        let t = tips(&data);
        assert_eq!(t[0], Vector::<3>::new(0.0, 1.5, 2.0));
        // Clockwise about +Z (axis −Z) from (0, 1.5) to (1.5, 0): a quarter, x rising.
        assert_eq!(t[t.len() - 1], Vector::<3>::new(1.5, 0.0, -1.5));
        assert!(t[2..].windows(2).all(|w| w[1][0] > w[0][0]));
        for p in &t[2..] {
            assert!((math::hypot(p[0], p[1]) - 1.5).abs() < 1e-9, "{p:?}");
        }
    }

    #[test]
    fn a_catia_aptsource_in_mm_with_tlaxis_godlta_and_units() {
        let text = "$$ CATIA APT source\nPARTNO PART1\nUNITS/MM\nMULTAX/ON\n\
            FEDRAT/ 1000.0000,MMPM\nTLAXIS/0.0,0.6,0.8\nGOTO/ 10.0, 0.0, 5.0\n\
            GODLTA/1.0,2.0,-0.5\nSPINDL/RPM,2000,CLW\nFEDRAT/0.05,MMPR\n\
            GOTO/ 12.0, 2.0, 4.5, 0.0, 0.0, 1.0\nFINI\nGOTO/99,99,99\n";
        let data = parse_cl(text, "part.aptsource").unwrap();
        assert_eq!(
            tips(&data),
            [
                Vector::<3>::new(10.0, 0.0, 5.0),
                Vector::<3>::new(11.0, 2.0, 4.5),
                Vector::<3>::new(12.0, 2.0, 4.5)
            ]
        );
        let axes: Vec<_> = data.poses().iter().map(|p| p.axis).collect();
        assert_eq!(axes[0], Vector::<3>::new(0.0, 0.6, 0.8));
        assert_eq!(axes[2], Vector::<3>::z());
        // 1000 mm/min, then 0.05 mm/turn × 2000 turns/min = 100 mm/min.
        assert_eq!(data.moves[0].speed, Speed::Feed(1000.0 / 60.0));
        assert_eq!(data.moves[2].speed, Speed::Feed(100.0 / 60.0));
        assert!(data.warnings.is_empty(), "{:?}", data.warning_lines());
        // UNITS/INCHES scales every length after it.
        let inch = parse_cl("UNITS/INCHES\nGOTO/1,2,3\nGOTO/2,2,3\n", "i.apt").unwrap();
        assert!((tips(&inch)[0] - Vector::<3>::new(25.4, 50.8, 76.2)).amax() < 1e-12);
    }

    #[test]
    fn a_second_msys_frame_is_carried_into_the_first() {
        // The second frame: origin (100, 0, 0), X along the first frame's Y, Y along -X
        // (a quarter turn about Z). Its point (1, 0, 2) is (100, 1, 2) in the first frame,
        // its axis (1, 0, 0) the first frame's (0, 1, 0).
        let text = "MSYS/0,0,0,1,0,0,0,1,0\nGOTO/0,0,0\nGOTO/1,0,0\n\
            MSYS/100,0,0,0,1,0,-1,0,0\nGOTO/1,0,2,1,0,0\n";
        let data = parse_cl(text, "two.cls").unwrap();
        let last = data.poses()[2];
        assert!(
            (last.tip - Vector::<3>::new(100.0, 1.0, 2.0)).amax() < 1e-12,
            "{last:?}"
        );
        assert!((last.axis - Vector::<3>::y()).amax() < 1e-12, "{last:?}");
        assert_eq!(
            data.warning_lines(),
            [
                "two.cls:4: a new MSYS frame: the records after it are carried into the first \
              MSYS's frame"
            ]
        );
    }

    #[test]
    fn a_circle_back_to_its_start_is_a_full_turn_and_a_listing_header_is_skipped() {
        let text = "Siemens NX CLSF listing  page 1\n==========\nGOTO/5,0,0\n\
            CIRCLE/0,0,0,0,0,1,5,0.01\nGOTO/5,0,0\nGOTO/6,0,0\n";
        let data = parse_cl(text, "l.cls").unwrap();
        let t = tips(&data);
        let length: f64 = t.windows(2).map(|w| geometry::dist(&w[0], &w[1])).sum();
        // Chords of sag 0.5 µm are shorter than the arc by θ²/24 of it (θ ≈ 0.028 rad).
        assert!(
            (length - (std::f64::consts::TAU * 5.0 + 1.0)).abs() < 2e-3,
            "{length}"
        );
        assert_eq!(
            data.warning_lines(),
            [
                "l.cls:1: text that is not a CL record (a listing's header?) skipped (it does not \
              move the tool); further ones are skipped silently"
            ]
        );
    }

    #[test]
    fn records_that_change_the_motion_are_refused_with_their_line() {
        let cases = [
            (
                "GOTO/0,0,0\nCYCLE/DRILL,5,FEDTO,0\nGOTO/1,1,0\n",
                2,
                "drilling cycles",
            ),
            (
                "GOTO/0,0,0\nCUTCOM/LEFT\nGOTO/1,1,0\n",
                2,
                "cutter compensation",
            ),
            (
                "GOTO/0,0,0\nGOTO/1,0,0\nCIRCLE/0,0,0,0,0,1,1\n",
                3,
                "no GOTO after it",
            ),
            (
                "GOTO/0,0,0\nFEDRAT/0.1,MMPR\nGOTO/1,0,0\n",
                2,
                "needs a SPINDL",
            ),
            (
                "GOTO/1,0,0\nCIRCLE/0,0,0,0,0,1,1\nGOTO/0,1.5,0\n",
                3,
                "the arc's end is 1.5000 mm from the axis",
            ),
            (
                "CIRCLE/0,0,0,0,0,1,1\nGOTO/0,1,0\nGOTO/1,1,0\n",
                1,
                "no start",
            ),
            ("UNITS/FEET\nGOTO/0,0,0\n", 1, "expected MM or INCHES"),
            ("GOTO/0,0,0\nGOHOME\nGOTO/1,0,0\n", 2, "GOHOME"),
            ("NURBS/\nKNOT/1\nCNTRL/1,0,0\n", 1, "NURBS before any GOTO"),
            (
                "GOTO/0,0,0\nCNTRL/1,0,0\n",
                2,
                "CNTRL outside a NURBS block",
            ),
            (
                "GOTO/0,0,0\nNURBS/\nKNOT/1\nCNTRL/1,0,0\nCNTRL/2,0,0\nGOTO/3,0,0\n",
                2,
                "1 knots and 2 control points",
            ),
            (
                "GOTO/0,0,0\nNURBS/\nKNOT/0.5\nCNTRL/1,0,0\nCNTRL/2,0,0\nCNTRL/3,0,0\n",
                2,
                "end with 1",
            ),
            (
                "GOTO/0,0,0\nNURBS/\nKNOT/1\nCNTRL/1,0,0,0,0,1\n",
                4,
                "weights and tool axes in NURBS blocks are not read",
            ),
            (
                "GOTO/0,0,0\nNURBS/\nKNOT/1\nCNTRL/1e200,0,0\nCNTRL/0,1e200,0\n\
                 CNTRL/1,1,0\n",
                2,
                "NURBS: more than 100000 chords",
            ),
            (
                "GOTO/0,0,0\nNURBS/\nKNOT/1\nCNTRL/1,0,0\nKNOT/1\n",
                5,
                "KNOT outside a NURBS block's head",
            ),
            (
                "GOTO/1e11,0,0\nCIRCLE/0,0,0,0,0,1,1e11\nGOTO/1e11,0,0\n",
                2,
                "not in (0, 10000] mm",
            ),
            (
                "MSYS/0,0,0,1,0,0,1,0,0\nGOTO/0,0,0\n",
                1,
                "not perpendicular",
            ),
            ("GOTO/0,0,0\nFEDRAT/IPM\n", 2, "no feed > 0"),
        ];
        assert_refused(&cases, "bad.cls");
    }

    /// Each text refused naming `file`, its line and a message holding the given words.
    fn assert_refused(cases: &[(&str, usize, &str)], file: &str) {
        for &(text, line, message) in cases {
            let e = match parse_cl(text, file) {
                Err(e) => e,
                Ok(read) => panic!("{text:?} read, {} moves", read.moves.len()),
            };
            match &e {
                PathError::File {
                    file: f, line: l, ..
                } => {
                    assert_eq!((f.as_str(), *l), (file, line), "{text:?}: {e}");
                }
                other => panic!("{other:?}"),
            }
            assert!(e.to_string().contains(message), "{text:?}: {e}");
        }
    }
}
