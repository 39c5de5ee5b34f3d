//! Reading a G-code program into a [`PartProgram`] (docs/design/two-axis.md §4.7): the
//! RS-274/NGC words CAM posts write, as LinuxCNC reads them, or as Fanuc does where the two
//! differ ([`Dialect`]). The `g-code` crate reads the syntax (words with exact decimals,
//! comments, line by line); the modal state, the units, the arc geometry ([`arc_words`])
//! and the drilling cycles ([`drilling`]) are this module's. Every refusal names the file,
//! line and column.

use std::collections::BTreeSet;

use g_code::emit::{Field, Value};
use g_code::parse::ast::Spanned;
use g_code::parse::snippet_parser;

use super::arc_words::{self, Circle};
use super::cutter_compensation::ToolTable;
use super::drilling::{self, Cycle, CycleKind};
use super::{
    Compensation, Corner, Motion, PartMove, PartProgram, Place, Plane, Side, Speed, Warning,
};
use crate::geometry::{Vector, Vector2};
use crate::path::nurbs_file::read_path_file;
use crate::path::PathError;

/// Where two controllers read the same words differently, which one the program was
/// written for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Dialect {
    /// LinuxCNC (RS-274/NGC): `G4 P` in seconds.
    #[default]
    LinuxCnc,
    /// Fanuc (and Haas): `G4 P` in milliseconds.
    Fanuc,
}

/// How a program is read: what the file cannot say.
#[derive(Clone, Debug, PartialEq)]
pub struct GcodeOptions {
    /// The controller the program was written for.
    pub dialect: Dialect,
    /// Whether M1 stops (the operator's optional-stop switch); M0 always does.
    pub optional_stop: bool,
    /// The machine's home (its reference point) in the program's coordinates, mm: where
    /// G28 and G30 go and what G53's machine coordinates count from.
    pub home: Vector<3>,
    /// The tools' radii by D number, for cutter radius compensation (G41, G42).
    pub tools: ToolTable,
}

impl Default for GcodeOptions {
    fn default() -> Self {
        GcodeOptions {
            dialect: Dialect::LinuxCnc,
            optional_stop: false,
            home: Vector::<3>::zeros(),
            tools: ToolTable::default(),
        }
    }
}

/// Reads a G-code file (see the module docs).
pub fn load_gcode(
    file: impl AsRef<std::path::Path>,
    options: &GcodeOptions,
) -> Result<PartProgram, PathError> {
    let (name, text) = read_path_file(file.as_ref())?;
    parse_gcode(&text, &name, options)
}

/// Reads the text of a G-code program; `name` is used in messages.
pub fn parse_gcode(
    text: &str,
    name: &str,
    options: &GcodeOptions,
) -> Result<PartProgram, PathError> {
    let mut reader = Reader::new(name, options.clone());
    let blocks = reader.blocks(text)?;
    reader.decimals = blocks
        .iter()
        .flat_map(|(_, words)| words)
        .filter(|w| "XYZIJR".contains(w.letter))
        .map(|w| w.decimals)
        .max()
        .unwrap_or(0);
    for (line, words) in blocks {
        if !reader.block(line, words)? {
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
    /// A drilling cycle (G73, G81–G83, G85, G89).
    Drilling(CycleKind),
}

/// The one-block codes of modal group 0 that are read.
#[derive(Clone, Copy, Debug, PartialEq)]
enum OneBlock {
    /// G4.
    Dwell,
    /// G28 or G30: to home, through the point the axis words give.
    Home,
    /// G53: the axis words in machine coordinates (from [`GcodeOptions::home`]).
    MachineCoordinates,
    /// G92: the tip is where the axis words say (the coordinates' zero moves).
    SetPosition,
}

/// One word of a block: its letter, value, 1-based column and the decimals it was
/// written with.
#[derive(Clone, Copy, Debug)]
struct Word {
    letter: char,
    value: f64,
    column: usize,
    decimals: u32,
}

/// The words of a block other than G, M, N and O, by letter; each is taken by what uses
/// it, and one left over is refused.
struct Letters([Option<Word>; 26]);

impl Letters {
    fn slot(letter: char) -> usize {
        (letter as u8 - b'A') as usize
    }
    fn take(&mut self, letter: char) -> Option<Word> {
        self.0[Self::slot(letter)].take()
    }
    fn has(&self, letter: char) -> bool {
        self.0[Self::slot(letter)].is_some()
    }
    fn column(&self, letter: char) -> Option<usize> {
        self.0[Self::slot(letter)].map(|w| w.column)
    }
    /// The first word left, by column.
    fn left_over(&self) -> Option<Word> {
        self.0.iter().flatten().min_by_key(|w| w.column).copied()
    }
}

/// The modal state and what has been read so far.
struct Reader<'a> {
    name: &'a str,
    options: GcodeOptions,
    /// The most decimals any X, Y, Z, I, J or R word of the program has: the resolution
    /// its post rounds to (the arc rule's rounding allowance).
    decimals: u32,
    /// mm per program unit: 1 (G21) or 25.4 (G20).
    scale: f64,
    absolute: bool,
    arc_absolute: bool,
    motion: Option<Mode>,
    /// The drilling cycle's sticky words, from its first block to G80 or another motion.
    cycle: Option<Cycle>,
    /// G98 (the default): a cycle retracts to where Z was when it began; G99: to R.
    retract_to_start: bool,
    feed: Option<f64>,
    corner: Corner,
    /// The tip, mm: the program's origin until programmed.
    position: Vector<3>,
    /// Where the coordinates' zero is, mm: the program's origin until G92 moves it.
    origin: Vector<3>,
    /// G9 in the block: its move ends in an exact stop.
    stop_here: bool,
    /// The plane of arcs and of cutter compensation (G17, G18, G19).
    plane: Plane,
    /// Cutter radius compensation (G41, G42) until G40.
    compensation: Option<Compensation>,
    /// The G41 and G42 read so far.
    stretches: u32,
    /// The tool the last T word selected, and the one M6 loaded (G41 without D takes its
    /// radius).
    tool_selected: Option<f64>,
    tool_loaded: Option<f64>,
    /// The motion mode before a drilling cycle began: Fanuc's G80 returns to it (its
    /// cycles are a modal group of their own), LinuxCNC's G80 leaves none.
    before_cycle: Option<Mode>,
    moves: Vec<PartMove>,
    skipped: BTreeSet<String>,
    warnings: Vec<Warning>,
}

impl<'a> Reader<'a> {
    fn new(name: &'a str, options: GcodeOptions) -> Self {
        Reader {
            name,
            options,
            decimals: 0,
            scale: 1.0,
            absolute: true,
            arc_absolute: false,
            motion: None,
            cycle: None,
            retract_to_start: true,
            feed: None,
            corner: Corner::BlendDefault,
            position: Vector::<3>::zeros(),
            origin: Vector::<3>::zeros(),
            stop_here: false,
            plane: Plane::Xy,
            compensation: None,
            stretches: 0,
            tool_selected: None,
            tool_loaded: None,
            before_cycle: None,
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
    fn skip(&mut self, kind: &str, line: usize, column: usize) {
        // A String only for a kind not seen yet: a program repeats its kinds.
        if !self.skipped.contains(kind) && self.skipped.insert(kind.to_owned()) {
            self.warnings.push(Warning {
                file: self.name.to_string(),
                place: Place { line, column },
                message: format!(
                    "{kind} skipped (not part of the contour); further ones are skipped silently"
                ),
            });
        }
    }

    /// The words of every line up to the program's end (a second `%` line, M2, M30),
    /// with their line numbers: a byte-order mark and any line end (LF, CRLF, CR) read.
    fn blocks(&self, text: &str) -> Result<Vec<(usize, Vec<Word>)>, PathError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let mut blocks = Vec::new();
        let mut percents = 0;
        for (index, line) in lines(text).enumerate() {
            let number = index + 1;
            if line.trim() == "%" {
                percents += 1;
                if percents == 2 {
                    break;
                }
                continue;
            }
            let words = self.words(line, number)?;
            let ends = words
                .iter()
                .any(|w| w.letter == 'M' && (w.value == 2.0 || w.value == 30.0));
            blocks.push((number, words));
            if ends {
                break;
            }
        }
        Ok(blocks)
    }

    /// The words of one line, letters upper-cased.
    fn words(&self, original: &str, line: usize) -> Result<Vec<Word>, PathError> {
        let (text, columns) = plain(original);
        // The column in `original` of a 1-based column of `text`.
        let at = |column: usize| columns[column.clamp(1, columns.len()) - 1];
        if let Some(column) = two_signs(&text) {
            return Err(self.error(line, at(column), "a number takes one sign, not '+-'"));
        }
        if let Some(i) = outside_comments(&text, |b| matches!(b, b'#' | b'[')) {
            return Err(self.error(
                line,
                at(i + 1),
                "G-code syntax: '#' parameters and '[…]' expressions are not supported; have \
                 the CAM post write plain numbers",
            ));
        }
        if original.trim_start().starts_with('%') {
            return Err(self.error(
                line,
                at(1),
                "G-code syntax: a '%' line marks the program's start or end and holds nothing \
                 else",
            ));
        }
        let snippet = snippet_parser(&text).map_err(|e| {
            self.error(
                line,
                at(e.location.column),
                format!("G-code syntax: expected {}", e.expected),
            )
        })?;
        let mut words = Vec::new();
        for field in snippet.iter_fields() {
            let column = at(field.span().0 + 1);
            let Field { letters, value } = Field::from(field);
            let mut chars = letters.chars();
            let (Some(letter), None) = (chars.next(), chars.next()) else {
                return Err(self.error(line, column, format!("unknown word '{letters}'")));
            };
            let (value, decimals) = match value {
                Value::Integer(i) => (i as f64, 0),
                Value::Rational(d) => (d.to_string().parse::<f64>().unwrap_or(f64::NAN), d.scale()),
                Value::Float(f) => (f, 0),
                Value::String(_) => {
                    return Err(self.error(line, column, "a word's value must be a number"))
                }
            };
            let letter = letter.to_ascii_uppercase();
            if !letter.is_ascii_uppercase() {
                return Err(self.error(line, column, format!("unknown word '{letters}'")));
            }
            words.push(Word {
                letter,
                value,
                column,
                decimals,
            });
        }
        if let Some(flag) = snippet.iter_flags().next() {
            return Err(self.error(line, at(flag.span().0 + 1), "a letter without a number"));
        }
        Ok(words)
    }

    /// Reads one block; `false` at the program's end (M2, M30).
    fn block(&mut self, line: usize, words: Vec<Word>) -> Result<bool, PathError> {
        let mut letters = Letters([None; 26]);
        let (mut g_codes, mut m_codes) = (Vec::new(), Vec::new());
        for w in words {
            let code = || -> Result<u32, PathError> {
                let tenths = w.value * 10.0;
                if tenths.fract() == 0.0 && (0.0..=9999.0).contains(&tenths) {
                    Ok(tenths as u32)
                } else {
                    Err(self.error(
                        line,
                        w.column,
                        format!("unknown code {}{}", w.letter, w.value),
                    ))
                }
            };
            match w.letter {
                'G' => g_codes.push((code()?, w.column)),
                'M' => m_codes.push((code()?, w.column)),
                // Block and program numbers.
                'N' | 'O' => {}
                'A' | 'B' | 'C' | 'E' | 'V' | 'W' => {
                    return Err(self.error(
                        line,
                        w.column,
                        format!(
                            "the word {} is not supported (axes X, Y and Z only)",
                            w.letter
                        ),
                    ))
                }
                letter => {
                    let slot = &mut letters.0[Letters::slot(letter)];
                    if slot.is_some() {
                        return Err(self.error(
                            line,
                            w.column,
                            format!("two {letter} words in one block"),
                        ));
                    }
                    *slot = Some(w);
                }
            }
        }
        let mut motion: Option<(Option<Mode>, usize)> = None;
        let mut one_block: Option<(OneBlock, usize)> = None;
        let mut corner_word: Option<(u32, usize)> = None;
        let mut plane_word: Option<(Plane, usize)> = None;
        let mut compensation_word: Option<(u32, usize)> = None;
        let mut length_offset_word: Option<usize> = None;
        for &(code, column) in &g_codes {
            let set_motion = |motion: &mut Option<(Option<Mode>, usize)>, m: Option<Mode>| {
                if motion.is_some() {
                    return Err(self.error(line, column, "two motion codes in one block"));
                }
                *motion = Some((m, column));
                Ok(())
            };
            let set_one_block = |one: &mut Option<(OneBlock, usize)>, o: OneBlock| {
                if one.is_some() {
                    return Err(self.error(line, column, "two of G4, G28, G30, G53 in one block"));
                }
                *one = Some((o, column));
                Ok(())
            };
            match code {
                0 => set_motion(&mut motion, Some(Mode::Rapid))?,
                10 => set_motion(&mut motion, Some(Mode::Linear))?,
                20 => set_motion(&mut motion, Some(Mode::Clockwise))?,
                30 => set_motion(&mut motion, Some(Mode::CounterClockwise))?,
                800 => set_motion(&mut motion, None)?,
                c @ (730 | 740 | 810 | 820 | 830 | 840 | 850 | 890) => {
                    let kind = CycleKind::from_code(c / 10).expect("a cycle's code");
                    set_motion(&mut motion, Some(Mode::Drilling(kind)))?
                }
                40 => set_one_block(&mut one_block, OneBlock::Dwell)?,
                280 | 300 => set_one_block(&mut one_block, OneBlock::Home)?,
                530 => set_one_block(&mut one_block, OneBlock::MachineCoordinates)?,
                920 => set_one_block(&mut one_block, OneBlock::SetPosition)?,
                // G92.1, G92.2: the G92 offsets cleared (suspended: nothing restores them).
                921 | 922 => self.origin = Vector::<3>::zeros(),
                90 => self.stop_here = true,
                170 => plane_word = Some((Plane::Xy, column)),
                180 => plane_word = Some((Plane::Zx, column)),
                190 => plane_word = Some((Plane::Yz, column)),
                200 => self.scale = 25.4,
                210 => self.scale = 1.0,
                900 => self.absolute = true,
                910 => self.absolute = false,
                901 => self.arc_absolute = true,
                911 => self.arc_absolute = false,
                980 => self.retract_to_start = true,
                990 => self.retract_to_start = false,
                c @ (610 | 611 | 640) => corner_word = Some((c, column)),
                c @ (400 | 410 | 420 | 411 | 421) => {
                    if compensation_word.is_some() {
                        return Err(self.error(line, column, "two of G40, G41, G42 in one block"));
                    }
                    compensation_word = Some((c, column));
                }
                430 | 490 if length_offset_word.is_none() => {
                    length_offset_word = Some(column);
                    if code == 430 {
                        self.skip(
                            "G43 H (tool length offset: the program gives the tip)",
                            line,
                            column,
                        );
                        letters.take('H');
                    } else {
                        self.skip("G49 (tool length offset off)", line, column);
                    }
                }
                430 | 490 => {
                    return Err(self.error(line, column, "two of G43, G49 in one block"));
                }
                940 => self.skip(
                    "G94 (feed per minute, the only feed mode here)",
                    line,
                    column,
                ),
                540..=590 if code % 10 == 0 => self.skip(
                    "G54-G59 (work offsets: coordinates are taken as programmed)",
                    line,
                    column,
                ),
                _ => {
                    return Err(self.error(
                        line,
                        column,
                        format!("G{} is not supported", code as f64 / 10.0),
                    ))
                }
            }
        }
        let mut stop = false;
        let mut end = false;
        let mut machine_function = false;
        for &(code, column) in &m_codes {
            match code {
                0 => stop = true,
                10 => {
                    if self.options.optional_stop {
                        stop = true;
                    } else {
                        self.skip("M1 (optional stop, off)", line, column);
                    }
                }
                20 | 300 => end = true,
                30..=50 => self.skip("M3-M5 (spindle)", line, column),
                60 if self.compensation.is_some() => {
                    return Err(self.error(
                        line,
                        column,
                        "no tool change while cutter radius compensation is on (G40 first)",
                    ))
                }
                60 => {
                    // The T of this block, or the one selected before.
                    self.tool_loaded = letters.0[Letters::slot('T')]
                        .map(|w| w.value)
                        .or(self.tool_selected);
                    self.skip("M6 (tool change)", line, column)
                }
                70..=90 => self.skip("M7-M9 (coolant)", line, column),
                // Subprogram calls and returns, program repeats and the modal-state
                // save and restore change which moves run or how they read.
                470 | 700..=730 | 980 | 990 => {
                    return Err(self.error(
                        line,
                        column,
                        format!(
                            "M{} is not supported: it changes which blocks run or the modes \
                             they are read in; expand the program in the CAM post",
                            code as f64 / 10.0
                        ),
                    ))
                }
                // Every other M code is a machine function (I/O, vacuum, probing
                // set-up, waiting for the planner): the axes do not move for it.
                _ => {
                    machine_function = true;
                    self.skip(
                        &format!("M{} (a machine function)", code as f64 / 10.0),
                        line,
                        column,
                    );
                }
            }
        }
        if let Some(w) = letters.take('F') {
            if !(w.value.is_finite() && w.value > 0.0) {
                return Err(self.error(line, w.column, format!("feed F{} must be > 0", w.value)));
            }
            self.feed = Some(w.value * self.scale / 60.0);
        }
        for (letter, kind) in [('S', "S (spindle speed)"), ('T', "T (tool number)")] {
            if let Some(w) = letters.take(letter) {
                if letter == 'T' {
                    self.tool_selected = Some(w.value);
                }
                self.skip(kind, line, w.column);
            }
        }
        if let Some(w) = letters.take('H') {
            self.skip("H (tool length offset number)", line, w.column);
        }
        if let Some((c, _)) = corner_word {
            self.corner = self.corner_mode(c, &mut letters, line)?;
        }
        if let Some((plane, column)) = plane_word {
            if self.compensation.is_some() && plane != self.plane {
                return Err(self.error(
                    line,
                    column,
                    "the plane cannot change while cutter radius compensation is on (G40 first)",
                ));
            }
            self.plane = plane;
        }
        if let Some((code, column)) = compensation_word {
            self.compensation = self.compensation_mode(code, &mut letters, line, column)?;
        }
        // After the block's G40 (RS-274 applies compensation before the length offset).
        if let (Some(column), Some(_)) = (length_offset_word, self.compensation) {
            return Err(self.error(
                line,
                column,
                "the tool length offset cannot change while cutter radius compensation is on \
                 (G40 first)",
            ));
        }
        if let Some((m, _)) = motion {
            let drilling = |m: Option<Mode>| matches!(m, Some(Mode::Drilling(_)));
            if drilling(m) && !drilling(self.motion) {
                self.before_cycle = self.motion;
            }
            self.motion = match (m, self.options.dialect) {
                (None, Dialect::Fanuc) if drilling(self.motion) => self.before_cycle,
                _ => m,
            };
            if !drilling(m) {
                self.cycle = None;
            }
        }
        if let (Some(_), Some((code, column))) = (self.compensation, one_block) {
            if code != OneBlock::Dwell {
                return Err(self.error(
                    line,
                    column,
                    "G28, G30, G53 and G92 are not allowed while cutter radius compensation is \
                     on (G40 first)",
                ));
            }
        }
        match one_block {
            Some((OneBlock::Dwell, column)) => {
                self.dwell(&mut letters, motion, line, column)?;
            }
            Some((OneBlock::Home, column)) => {
                self.home(&mut letters, motion, line, column)?;
            }
            Some((OneBlock::MachineCoordinates, column)) => {
                self.machine_move(&mut letters, line, column)?;
            }
            Some((OneBlock::SetPosition, column)) => {
                self.set_position(&mut letters, motion, line, column)?;
            }
            None => self.motion(&mut letters, motion, line)?,
        }
        if machine_function {
            // What the motion left of P, Q and L are the machine function's arguments.
            for letter in ['P', 'Q', 'L'] {
                letters.take(letter);
            }
        }
        if let Some(w) = letters.left_over() {
            let message = match w.letter {
                'I' | 'J' | 'K' | 'R' | 'P' | 'Q' => format!(
                    "the word {} belongs to an arc, a dwell or a cycle, not to this block",
                    w.letter
                ),
                letter => format!("the word {letter} has no use in this block"),
            };
            return Err(self.error(line, w.column, message));
        }
        if stop {
            self.push(Motion::Dwell(0.0), Speed::Rapid, self.position, line, None);
        }
        self.stop_here = false;
        Ok(!end)
    }

    /// The corner mode of G61, G61.1 or G64 (with its P).
    fn corner_mode(
        &mut self,
        code: u32,
        letters: &mut Letters,
        line: usize,
    ) -> Result<Corner, PathError> {
        if code != 640 {
            return Ok(Corner::ExactStop);
        }
        if let Some(q) = letters.take('Q') {
            self.skip("Q (G64's naive-CAM tolerance)", line, q.column);
        }
        let Some(p) = letters.take('P') else {
            return Ok(Corner::BlendDefault);
        };
        if !(p.value.is_finite() && p.value >= 0.0) {
            return Err(self.error(line, p.column, "G64's P must be >= 0"));
        }
        // LinuxCNC's P0: no limit on the blend; here the `tolerance` parameter's.
        Ok(if p.value == 0.0 {
            Corner::BlendDefault
        } else {
            Corner::Blend(p.value * self.scale)
        })
    }

    /// Cutter radius compensation after G40, G41, G42 (D: the tool's number in the tool
    /// table) or G41.1, G42.1 (D: the tool's diameter); a negative radius puts the tool on
    /// the other side (LinuxCNC's reading).
    fn compensation_mode(
        &mut self,
        code: u32,
        letters: &mut Letters,
        line: usize,
        column: usize,
    ) -> Result<Option<Compensation>, PathError> {
        if code == 400 {
            if let Some(d) = letters.take('D') {
                return Err(self.error(line, d.column, "G40 takes no D"));
            }
            return Ok(None);
        }
        if self.compensation.is_some() {
            return Err(self.error(
                line,
                column,
                "cutter radius compensation is already on: turn it off (G40) before G41 or G42",
            ));
        }
        if self.plane == Plane::Yz {
            return Err(self.error(
                line,
                column,
                "cutter radius compensation is allowed only in the XY and XZ planes (G17, G18)",
            ));
        }
        // G41.1 and G42.1: D is the diameter.
        let diameter = matches!(code, 411 | 421);
        let d =
            match (letters.take('D'), self.tool_loaded) {
                (Some(d), _) => d,
                // LinuxCNC: without D, the loaded tool's radius.
                (None, Some(tool)) if !diameter => Word {
                    letter: 'D',
                    value: tool,
                    column,
                    decimals: 0,
                },
                (None, _) => return Err(self.error(
                    line,
                    column,
                    "G41 and G42 need D, the tool's number in the tool table, or a tool loaded \
                     (T M6); G41.1 and G42.1 need D, its diameter",
                )),
            };
        let radius = if diameter {
            if !d.value.is_finite() {
                return Err(self.error(line, d.column, "the tool's diameter D must be finite"));
            }
            0.5 * d.value * self.scale
        } else {
            self.options
                .tools
                .radius(d.value)
                .map_err(|m| self.error(line, d.column, m))?
        };
        let left = (code / 10 == 41) == (radius >= 0.0);
        self.stretches += 1;
        Ok(Some(Compensation {
            side: if left { Side::Left } else { Side::Right },
            radius: radius.abs(),
            plane: self.plane,
            stretch: self.stretches,
        }))
    }

    /// G4: the tool stands for P (seconds in LinuxCNC, milliseconds in Fanuc) or for X or
    /// U seconds (Fanuc's; LinuxCNC refuses them, so they conflict with nothing).
    fn dwell(
        &mut self,
        letters: &mut Letters,
        motion: Option<(Option<Mode>, usize)>,
        line: usize,
        column: usize,
    ) -> Result<(), PathError> {
        if let Some((_, c)) = motion {
            return Err(self.error(
                line,
                c,
                "G4 takes a block of its own, without a motion code",
            ));
        }
        let seconds = [letters.take('X'), letters.take('U')];
        let p = letters.take('P');
        let (time, word) = match (seconds, p) {
            ([Some(w), None] | [None, Some(w)], None) => (w.value, w),
            ([None, None], Some(w)) => (w.value * self.dwell_unit(), w),
            ([None, None], None) => {
                return Err(self.error(line, column, "G4 needs its time: P (or X or U seconds)"))
            }
            (_, _) => return Err(self.error(line, column, "G4 takes one time: P, X or U")),
        };
        if !(time.is_finite() && time >= 0.0) {
            return Err(self.error(line, word.column, "a dwell's time must be >= 0"));
        }
        self.push(Motion::Dwell(time), Speed::Rapid, self.position, line, None);
        Ok(())
    }

    /// G28 or G30: at rapid to the point the axis words give (only the axes named move),
    /// then those axes (all of them when none is named) to home.
    fn home(
        &mut self,
        letters: &mut Letters,
        motion: Option<(Option<Mode>, usize)>,
        line: usize,
        column: usize,
    ) -> Result<(), PathError> {
        if let Some((_, c)) = motion {
            return Err(self.error(line, c, "G28 and G30 take no motion code in their block"));
        }
        let (through, named, z_place) = self.axis_target(letters, line);
        self.push(Motion::Line, Speed::Rapid, through, line, z_place);
        let mut home = through;
        for k in 0..3 {
            if named[k] || named == [false; 3] {
                home[k] = self.options.home[k];
            }
        }
        let z_place = (home[2] != through[2]).then_some(Place { line, column });
        self.push(Motion::Line, Speed::Rapid, home, line, z_place);
        Ok(())
    }

    /// G92: the coordinates' zero moves so that the tip is where the axis words say.
    fn set_position(
        &mut self,
        letters: &mut Letters,
        motion: Option<(Option<Mode>, usize)>,
        line: usize,
        column: usize,
    ) -> Result<(), PathError> {
        if let Some((_, c)) = motion {
            return Err(self.error(line, c, "G92 takes no motion code in its block"));
        }
        let mut named = false;
        for (k, letter) in ['X', 'Y', 'Z'].into_iter().enumerate() {
            if let Some(w) = letters.take(letter) {
                self.origin[k] = self.position[k] - w.value * self.scale;
                named = true;
            }
        }
        if !named {
            return Err(self.error(line, column, "G92 needs an axis word"));
        }
        Ok(())
    }

    /// G53 with G0 or G1: the axis words are machine coordinates, counted from home.
    fn machine_move(
        &mut self,
        letters: &mut Letters,
        line: usize,
        column: usize,
    ) -> Result<(), PathError> {
        let speed = match self.motion {
            Some(Mode::Rapid) => Speed::Rapid,
            Some(Mode::Linear) => self.speed(),
            _ => {
                return Err(self.error(line, column, "G53 moves with G0 or G1 only"));
            }
        };
        let mut end = self.position;
        let mut z_place = None;
        for (k, letter) in ['X', 'Y', 'Z'].into_iter().enumerate() {
            if let Some(w) = letters.take(letter) {
                end[k] = self.options.home[k] + w.value * self.scale;
                if k == 2 {
                    z_place = Some(Place {
                        line,
                        column: w.column,
                    });
                }
            }
        }
        self.push(Motion::Line, speed, end, line, z_place);
        Ok(())
    }

    /// The point the block's X, Y and Z words name (in the distance mode in force), which
    /// axes they name and where its Z word is.
    fn axis_target(
        &self,
        letters: &mut Letters,
        line: usize,
    ) -> (Vector<3>, [bool; 3], Option<Place>) {
        let mut end = self.position;
        let mut named = [false; 3];
        let mut z_place = None;
        for (k, letter) in ['X', 'Y', 'Z'].into_iter().enumerate() {
            if let Some(w) = letters.take(letter) {
                let v = w.value * self.scale;
                end[k] = if self.absolute {
                    self.origin[k] + v
                } else {
                    end[k] + v
                };
                named[k] = true;
                if k == 2 {
                    z_place = Some(Place {
                        line,
                        column: w.column,
                    });
                }
            }
        }
        (end, named, z_place)
    }

    /// Seconds per unit of a dwell's P: LinuxCNC's seconds, Fanuc's milliseconds.
    fn dwell_unit(&self) -> f64 {
        match self.options.dialect {
            Dialect::LinuxCnc => 1.0,
            Dialect::Fanuc => 1e-3,
        }
    }

    /// The speed of a feed move now.
    fn speed(&self) -> Speed {
        self.feed.map_or(Speed::Default, Speed::Feed)
    }

    /// The block's move in the motion mode in force.
    fn motion(
        &mut self,
        letters: &mut Letters,
        motion: Option<(Option<Mode>, usize)>,
        line: usize,
    ) -> Result<(), PathError> {
        let names_axes = ['X', 'Y', 'Z'].iter().any(|&l| letters.has(l));
        let motion_column = motion.map_or(1, |(_, c)| c);
        let [u, v, _] = self.plane.axes();
        let arc_centre = letters.has(['I', 'J', 'K'][u]) || letters.has(['I', 'J', 'K'][v]);
        let Some(mode) = self.motion else {
            if let Some(column) = ['X', 'Y', 'Z'].iter().find_map(|&l| letters.column(l)) {
                return Err(self.error(
                    line,
                    column,
                    "axis words without a motion code (G0, G1, G2, G3, a cycle) in force",
                ));
            }
            return Ok(());
        };
        if let Mode::Drilling(kind) = mode {
            return self.drill(kind, letters, motion.is_some(), line, motion_column);
        }
        let arc = matches!(mode, Mode::Clockwise | Mode::CounterClockwise);
        // Fanuc's, Haas's and Siemens's full circle: I or J without X and Y (LinuxCNC
        // refuses it, so reading it conflicts with nothing).
        if !(names_axes || arc && arc_centre) {
            if let Some(column) = letters.column('R').filter(|_| arc) {
                return Err(self.error(
                    line,
                    column,
                    "an arc given by R must end elsewhere than it starts (a full circle takes \
                     I and J)",
                ));
            }
            return Ok(());
        }
        let (end, _, z_place) = self.axis_target(letters, line);
        let speed = match mode {
            Mode::Rapid => Speed::Rapid,
            _ => self.speed(),
        };
        let shape = if arc {
            let plane = self.plane;
            let circle = self.circle(letters, line, motion_column)?;
            let start = plane.in_plane(&self.position);
            let to = plane.in_plane(&end);
            let resolution = 10f64.powi(-(self.decimals.max(MIN_DECIMALS) as i32)) * self.scale;
            let allowance = arc_words::allowance(self.scale != 1.0, resolution);
            let arc = arc_words::arc(start, to, circle, mode == Mode::Clockwise, allowance)
                .map_err(|m| self.error(line, motion_column, m))?;
            Motion::Arc { arc, plane }
        } else {
            if end == self.position {
                return Ok(());
            }
            Motion::Line
        };
        self.push(shape, speed, end, line, z_place);
        Ok(())
    }

    /// The circle of a G2/G3 block in the plane: its two centre words (I and J in G17, K
    /// and I in G18, J and K in G19; the third must be 0), or R; P, the turns, must be 1.
    fn circle(
        &self,
        letters: &mut Letters,
        line: usize,
        motion_column: usize,
    ) -> Result<Circle, PathError> {
        const CENTRE_WORDS: [char; 3] = ['I', 'J', 'K'];
        let [u, v, w] = self.plane.axes();
        if let Some(k) = letters.take(CENTRE_WORDS[w]) {
            if k.value != 0.0 {
                return Err(self.error(
                    line,
                    k.column,
                    format!(
                        "a {} arc's {} must be 0: the arc's centre is given by {} and {}",
                        self.plane.code(),
                        CENTRE_WORDS[w],
                        CENTRE_WORDS[u],
                        CENTRE_WORDS[v]
                    ),
                ));
            }
        }
        if let Some(p) = letters.take('P') {
            if p.value != 1.0 {
                return Err(self.error(
                    line,
                    p.column,
                    "arcs of more than one turn (P) are not supported",
                ));
            }
        }
        let (i, j, r) = (
            letters.take(CENTRE_WORDS[u]),
            letters.take(CENTRE_WORDS[v]),
            letters.take('R'),
        );
        let pair = format!("{} and {}", CENTRE_WORDS[u], CENTRE_WORDS[v]);
        match (i, j, r) {
            (None, None, None) => Err(self.error(
                line,
                motion_column,
                format!("a {} arc needs {pair}, or R", self.plane.code()),
            )),
            (Some(w), _, Some(_)) | (_, Some(w), Some(_)) => Err(self.error(
                line,
                w.column,
                format!("an arc takes {pair}, or R, not both"),
            )),
            (None, None, Some(r)) => Ok(Circle::Radius(r.value * self.scale)),
            (i, j, None) => {
                let offset = |w: Option<Word>, k: usize| -> Result<f64, PathError> {
                    match (w, self.arc_absolute) {
                        (Some(w), true) => Ok(self.origin[k] + w.value * self.scale),
                        (Some(w), false) => Ok(self.position[k] + w.value * self.scale),
                        (None, false) => Ok(self.position[k]),
                        (None, true) => Err(self.error(
                            line,
                            motion_column,
                            format!("with G90.1 an arc needs both {pair}"),
                        )),
                    }
                };
                Ok(Circle::Centre(Vector2::new(offset(i, u)?, offset(j, v)?)))
            }
        }
    }

    /// A block in a drilling cycle's mode: its words update the cycle, and X or Y drill
    /// a hole there (so does the cycle's own block without them: at the tool's XY).
    fn drill(
        &mut self,
        kind: CycleKind,
        letters: &mut Letters,
        starts: bool,
        line: usize,
        column: usize,
    ) -> Result<(), PathError> {
        if !self.absolute {
            return Err(self.error(
                line,
                column,
                "drilling cycles in incremental mode (G91) are not supported: write them in G90",
            ));
        }
        if self.compensation.is_some() {
            return Err(self.error(
                line,
                column,
                "drilling cycles are not allowed while cutter radius compensation is on (G40 \
                 first)",
            ));
        }
        if self.plane != Plane::Xy {
            return Err(self.error(
                line,
                column,
                format!(
                    "drilling cycles drill along Z here: select G17, not {}",
                    self.plane.code()
                ),
            ));
        }
        let z = |w: Option<Word>| w.map(|w| (self.origin[2] + w.value * self.scale, w.column));
        let depth = z(letters.take('Z'));
        let retract = z(letters.take('R'));
        let dwell = letters
            .take('P')
            .map(|w| (w.value * self.dwell_unit(), w.column));
        let peck = letters.take('Q').map(|w| (w.value * self.scale, w.column));
        if let Some(l) = letters.take('L').or_else(|| letters.take('K')) {
            if l.value != 1.0 {
                return Err(self.error(line, l.column, "a cycle's repeats (L, K) must be 1"));
            }
        }
        let names_xy = letters.has('X') || letters.has('Y');
        // A series of cycles keeps its sticky words and where Z was when it began.
        let mut cycle = match self.cycle {
            Some(c) => c.with_kind(kind),
            None => Cycle::new(kind, self.position[2]),
        };
        cycle
            .update(depth, retract, dwell, peck)
            .map_err(|(column, m)| self.error(line, column, m))?;
        self.cycle = Some(cycle);
        if !(names_xy || starts || depth.is_some()) {
            return Ok(());
        }
        let (hole, _, _) = self.axis_target(letters, line);
        let moves = cycle
            .hole(
                self.position,
                Vector2::new(hole[0], hole[1]),
                self.retract_to_start,
            )
            .map_err(|m| self.error(line, column, m))?;
        for step in moves {
            let speed = match step.speed {
                drilling::StepSpeed::Rapid => Speed::Rapid,
                drilling::StepSpeed::Feed => self.speed(),
            };
            let z_place = (step.end[2] != self.position[2]).then_some(Place { line, column });
            self.push(step.motion, speed, step.end, line, z_place);
        }
        Ok(())
    }

    /// Appends a move from the tip to `end`.
    fn push(
        &mut self,
        motion: Motion,
        speed: Speed,
        end: Vector<3>,
        line: usize,
        z_place: Option<Place>,
    ) {
        if matches!(motion, Motion::Line) && end == self.position {
            return;
        }
        let corner = if std::mem::take(&mut self.stop_here) {
            Corner::ExactStop
        } else {
            self.corner
        };
        self.moves.push(PartMove {
            motion,
            speed,
            end,
            tool_axis: None,
            corner,
            place: Place { line, column: 1 },
            z_place,
            compensation: self.compensation,
        });
        self.position = end;
    }
}

/// The fewest decimals the arc rule assumes a program's coordinates were rounded to (a
/// program written with fewer, by hand, is taken as exact to 0.001 units).
const MIN_DECIMALS: u32 = 3;

/// The lines of `text`, ended by LF, CRLF or a lone CR.
fn lines(text: &str) -> impl Iterator<Item = &str> {
    let mut rest = text;
    std::iter::from_fn(move || {
        if rest.is_empty() {
            return None;
        }
        let end = rest.find(['\n', '\r']).unwrap_or(rest.len());
        let line = &rest[..end];
        let skip = if rest[end..].starts_with("\r\n") {
            2
        } else {
            usize::from(end < rest.len())
        };
        rest = &rest[end + skip..];
        Some(line)
    })
}

/// The 1-based column of a word's value signed twice (`X+-1.5`) outside comments, which
/// the `g-code` crate's parser (0.6.0) meets with `unreachable!` instead of an error.
/// A line as the syntax crate reads it: plain ASCII, with the 1-based column in the
/// original line of each of its bytes (and one past the end). Comments may hold any
/// character (a German or Portuguese post's header), so theirs become '_'; outside them a
/// character that is not ASCII becomes '?', which the crate then refuses at its column. A
/// space between a word's letter and its number (`X 45.`, as Inkscape's plug-ins write) is
/// dropped: RS-274 ignores spaces there.
fn plain(line: &str) -> (String, Vec<usize>) {
    let chars: Vec<char> = line.chars().collect();
    let mut text = String::with_capacity(chars.len());
    let mut columns = Vec::with_capacity(chars.len() + 1);
    let (mut in_parens, mut in_rest) = (false, false);
    for (i, &c) in chars.iter().enumerate() {
        let comment = in_parens || in_rest;
        if !comment && matches!(c, ' ' | '\t') {
            let after_letter = text.ends_with(|l: char| l.is_ascii_alphabetic());
            let number_next = chars[i..]
                .iter()
                .find(|n| !matches!(n, ' ' | '\t'))
                .is_some_and(|n| n.is_ascii_digit() || matches!(n, '+' | '-' | '.'));
            if after_letter && number_next {
                continue;
            }
        }
        let shown = match (c.is_ascii(), comment) {
            (true, _) => c,
            (false, true) => '_',
            (false, false) => '?',
        };
        match c {
            '(' if !comment => in_parens = true,
            ')' if in_parens => in_parens = false,
            ';' if !comment => in_rest = true,
            _ => {}
        }
        text.push(shown);
        columns.push(i + 1);
    }
    columns.push(chars.len() + 1);
    (text, columns)
}

/// The first byte of an ASCII line, outside its comments, that `wanted` picks.
fn outside_comments(text: &str, wanted: impl Fn(u8) -> bool) -> Option<usize> {
    let mut in_parens = false;
    for (i, b) in text.bytes().enumerate() {
        match b {
            b'(' if !in_parens => in_parens = true,
            b')' if in_parens => in_parens = false,
            b';' if !in_parens => return None,
            _ if !in_parens && wanted(b) => return Some(i),
            _ => {}
        }
    }
    None
}

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
    use crate::math;
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
    fn comments_in_any_language_and_spaces_inside_words() {
        // A Portuguese and a German header (UTF-8), Inkscape's "X 45." and a tab: read as
        // LinuxCNC reads them; a word's column still counts the characters before it.
        let text = "( Plano de segurança = 5 )\n(Fräsen/Balsaholz)\nG21 G90\nG0 X 0 Y\t0\n\
                    G1 X 45. F300. (Überfahrt ä)\nG1 Y 10 ; fim ç\n";
        let read = parse_gcode(text, "p.nc", &GcodeOptions::default()).unwrap();
        let plain = parse_gcode(
            "G21 G90\nG0 X0 Y0\nG1 X45. F300.\nG1 Y10\n",
            "p.nc",
            &GcodeOptions::default(),
        )
        .unwrap();
        assert_eq!(read.poses(), plain.poses());
        let cases = [
            // Outside a comment a character that is not ASCII is refused where it stands.
            ("G1 Xé5\n", "t.ngc:1:5: G-code syntax"),
            ("(ü) G1 X1 Y2 Q\n", "t.ngc:1:14: a letter without a number"),
            ("G1 X#1\n", "t.ngc:1:5: G-code syntax: '#' parameters"),
            (
                "(#1 is fine here)\n#1 = 2\n",
                "t.ngc:2:1: G-code syntax: '#' parameters",
            ),
            (
                "% vfd enable\nG1 X1\n",
                "t.ngc:1:1: G-code syntax: a '%' line",
            ),
        ];
        for (text, expected) in cases {
            let e = refused(text);
            assert!(e.starts_with(expected), "{text:?}: {e}");
        }
    }

    #[test]
    fn machine_m_codes_are_skipped_with_one_warning_per_code() {
        // Makera's Fusion post: M400 (wait for the planner), M851/M852 (probe set-up),
        // M62 (an output): none moves the axes; the path is the one without them.
        let with = parse_gcode(
            "G21 G90\nM400\nM851 S100\nG0 X1 Y1\nG1 X5 F600\nM62 P1\nM400\nG1 Y4\nM852\n",
            "m.nc",
            &GcodeOptions::default(),
        )
        .unwrap();
        let without = parse_gcode(
            "G21 G90\nG0 X1 Y1\nG1 X5 F600\nG1 Y4\n",
            "m.nc",
            &GcodeOptions::default(),
        )
        .unwrap();
        assert_eq!(with.poses(), without.poses());
        let warnings = with.warning_lines();
        for (code, line) in [("M400", 2), ("M851", 3), ("M62", 6), ("M852", 9)] {
            let found: Vec<_> = warnings
                .iter()
                .filter(|w| w.contains(&format!("{code} (a machine function)")))
                .collect();
            assert_eq!(found.len(), 1, "{code}: {warnings:?}");
            assert!(found[0].starts_with(&format!("m.nc:{line}:")), "{found:?}");
        }
    }

    #[test]
    fn the_cam_preamble_is_skipped_with_one_warning_per_kind() {
        let p = read(
            "G21 G40 G49 G80 G94\nG54\nT1 M6\nS12000 M3 M8\nG0 Z5\nG0 X10 Y10\nG1 Z-1 F100\n\
             G1 X20 F600\nG2 X30 Y10 I5 J0\nG0 Z5\nG0 X0 Y0\nM5 M9\nM2\n",
        );
        // G49, G94, G54, T, M6, S, M3-M5, M7-M9 (G80 is a motion code, G40 turns cutter
        // compensation off; a Z-only move is a standstill: the retract after the arc, 6 mm
        // at rapid).
        assert_eq!(p.warnings.len(), 8, "{:#?}", p.warnings);
        let standstill = p.moves()[1].standstill;
        assert_eq!((standstill.at_rapid, standstill.seconds), (6.0, 0.0));
        // A skipped word is named where it stands.
        assert!(
            p.warnings[0].starts_with("t.ngc:1:9: G49 "),
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
            (
                "G1 X1\nG18 G2 X0 Z1 I-1 K0\n",
                "t.ngc:2:1: G18 arcs are in a plane with the third axis",
            ),
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
            (
                "G1 X10\nG3 Y5\n",
                "t.ngc:2:1: a G17 arc needs I and J, or R",
            ),
            ("G1 X1 F0\n", "t.ngc:1:7: feed F0 must be > 0"),
            ("G1 X1\nM98 P100\n", "t.ngc:2:1: M98 is not supported"),
            ("G1 X1\nM99\n", "t.ngc:2:1: M99 is not supported"),
            ("G1 X1\nM72\n", "t.ngc:2:1: M72 is not supported"),
            ("G1 X1 G0 Y1\n", "t.ngc:1:7: two motion codes"),
            ("G1 X[1+2]\n", "t.ngc:1:5: G-code syntax"),
            ("#1 = 2\n", "t.ngc:1:1: G-code syntax"),
            ("G1 X1e3\n", "t.ngc:1:6: the word E"),
            ("G1 X1 I2\n", "t.ngc:1:7: the word I belongs to an arc"),
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

    fn part(text: &str, options: &GcodeOptions) -> PartProgram {
        parse_gcode(text, "t.ngc", options).unwrap_or_else(|e| panic!("{e}"))
    }

    fn dwells(p: &PartProgram) -> Vec<f64> {
        p.moves
            .iter()
            .filter_map(|m| match m.motion {
                Motion::Dwell(t) => Some(t),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn a_byte_order_mark_and_every_line_end_read_alike() {
        let body = [
            "(profile)",
            "G21 G90",
            "G1 X10 F600",
            "G2 X20 I5",
            "G1 Y5",
            "M30",
        ];
        let unix = Program::parse_gcode(&body.join("\n"), "t.ngc").unwrap();
        for (bom, end) in [("\u{feff}", "\r\n"), ("", "\r"), ("\u{feff}", "\n")] {
            let text = format!("{bom}{}{end}", body.join(end));
            let p = Program::parse_gcode(&text, "t.ngc").unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(p.moves(), unix.moves(), "{end:?}");
        }
        // Lines are counted at a lone CR too.
        let e = refused("G1 X1\rG1 A1\r");
        assert!(e.starts_with("t.ngc:2:4: the word A"), "{e}");
    }

    #[test]
    fn program_numbers_tool_length_offsets_and_k0_on_xy_arcs_are_read() {
        // FreeCAD writes K with I and J; Fanuc posts an O number and G43 H.
        let p = read(
            "O1001 (PART)\nG90 G17 G21\nT2 M6\nG0 G43 Z15. H2\nG0 X5 Y0\nG1 Z-1 F100\n\
             G2 X-5 Y0 I-5 J0 K0 F600\nG3 X5 Y0 I5.0 J0.0 K0.0\nM30\n",
        );
        assert_eq!(p.moves().len(), 2);
        assert!((p.length() - 10.0 * PI).abs() < 1e-12);
        assert!(p.warnings.iter().any(|w| w.contains("G43 H")));
        let e = refused("G1 X5\nG2 X-5 I-5 K1\n");
        assert!(e.starts_with("t.ngc:2:12: a G17 arc's K must be 0"), "{e}");
    }

    #[test]
    fn dwells_by_dialect_and_stops() {
        let text = "G1 X1 F60\nG4 P2.5\nG04 X1.5\nG4 U0.5\nM0\nM1\nG1 X2\nM01\n";
        let linuxcnc = part(text, &GcodeOptions::default());
        assert_eq!(dwells(&linuxcnc), [2.5, 1.5, 0.5, 0.0]);
        let fanuc = GcodeOptions {
            dialect: Dialect::Fanuc,
            optional_stop: true,
            ..GcodeOptions::default()
        };
        // Fanuc's P is in milliseconds; the optional stop is on: M1 stops too.
        assert_eq!(
            dwells(&part(text, &fanuc)),
            [0.0025, 1.5, 0.5, 0.0, 0.0, 0.0]
        );
        assert!(linuxcnc
            .warnings
            .iter()
            .any(|w| w.message.contains("M1 (optional stop")));
        for (text, want) in [
            ("G4\n", "t.ngc:1:1: G4 needs its time"),
            ("G4 P1 X2\n", "t.ngc:1:1: G4 takes one time"),
            ("G4 P-1\n", "t.ngc:1:4: a dwell's time must be >= 0"),
            ("G4 G1 X1 P1\n", "t.ngc:1:4: G4 takes a block of its own"),
            ("G4 P1 Y2\n", "t.ngc:1:7: the word Y has no use"),
        ] {
            let e = refused(text);
            assert!(e.starts_with(want), "{text:?}: {e}");
        }
    }

    #[test]
    fn home_moves_go_through_their_point_and_machine_coordinates_count_from_home() {
        let options = GcodeOptions {
            home: Vector::<3>::new(-100.0, -50.0, 80.0),
            ..GcodeOptions::default()
        };
        let end = |p: &PartProgram| p.moves.last().map(|m| m.end).unwrap();
        // Fanuc's retract: incremental G28 Z0 sends Z home alone.
        let p = part("G0 X10 Y20 Z5\nG28 G91 Z0.\nG90\n", &options);
        assert_eq!(end(&p), Vector::<3>::new(10.0, 20.0, 80.0));
        assert!(p.moves.iter().all(|m| m.speed == Speed::Rapid));
        // Through (30, 20, 5) (Y is not named: it stays), then X home.
        let p = part("G0 X10 Y20 Z5\nG28 X30\n", &options);
        let ends: Vec<_> = p.moves.iter().map(|m| m.end).collect();
        assert_eq!(
            ends[1..],
            [
                Vector::<3>::new(30.0, 20.0, 5.0),
                Vector::<3>::new(-100.0, 20.0, 5.0)
            ]
        );
        // G30 alone: every axis home; G53 G0 Z0: to home's Z.
        assert_eq!(end(&part("G0 X1 Y1\nG30\n", &options)), options.home);
        let p = part("G0 X1 Y1 Z1\nG53 G0 Z0\nG53 X2\n", &options);
        assert_eq!(end(&p), Vector::<3>::new(-98.0, 1.0, 80.0));
        assert!(refused("G2 X2 I1\nG53 X0\n").contains("G53 moves with G0 or G1 only"));
        assert!(refused("G28 G1 X1\n").contains("no motion code"));
    }

    #[test]
    fn tapping_the_loaded_tools_radius_and_g80_by_dialect() {
        // G84 at one hole: rapid to R, feed to Z, dwell P, feed back to R, rapid to Z10
        // (G98); then Fanuc's G80 returns to G0, in which `Z20` moves; LinuxCNC refuses it.
        let text = "G21 G90\nG0 X0 Y0 Z10\nG98 G84 X5 Y5 Z-6 R2 P200 F100\nG80\nZ20\nM30\n";
        let fanuc = GcodeOptions {
            dialect: Dialect::Fanuc,
            ..GcodeOptions::default()
        };
        let p = part(text, &fanuc);
        let steps: Vec<_> = p.moves.iter().map(|m| (m.end[2], m.speed)).collect();
        let feed = Speed::Feed(100.0 / 60.0);
        assert_eq!(
            steps,
            [
                (10.0, Speed::Rapid),
                (10.0, Speed::Rapid),
                (2.0, Speed::Rapid),
                (-6.0, feed),
                (-6.0, Speed::Rapid),
                (2.0, feed),
                (10.0, Speed::Rapid),
                (20.0, Speed::Rapid),
            ]
        );
        assert_eq!(dwells(&p), [0.2]);
        let e = parse_gcode(text, "t.ngc", &GcodeOptions::default()).unwrap_err();
        assert!(
            e.to_string().starts_with("t.ngc:5:1: axis words without"),
            "{e}"
        );
        // G41 without D: the radius of the tool M6 loaded (T on its block or before).
        let tools = GcodeOptions {
            tools: ToolTable::parse("3:1.5, 4:2").unwrap(),
            ..GcodeOptions::default()
        };
        for text in ["T3 M6\nG41 G1 X10 F60\n", "T3\nM6\nT4\nG41 G1 X10 F60\n"] {
            let p = part(text, &tools);
            let c = p.moves.last().unwrap().compensation.unwrap();
            assert_eq!((c.side, c.radius), (Side::Left, 1.5), "{text}");
        }
        let e = parse_gcode("G42 G1 X10 F60\n", "t.ngc", &tools).unwrap_err();
        assert!(e.to_string().contains("or a tool loaded (T M6)"), "{e}");
    }

    #[test]
    fn drilling_cycles_between_profiles() {
        let text = "G90 G21\nG0 Z10\nG0 X0 Y0\nG1 Z-1 F120\nG1 X10\nG0 Z10\n\
                    G98 G81 X20 Y0 Z-3 R2 F60\nX30\nG99 G82 X40 P0.5\nG83 X50 Z-4 Q1.5\nG80\n\
                    G0 X60 Y0\nG1 Z-1 F120\nG1 Y10\nM30\n";
        let p = part(text, &GcodeOptions::default());
        let holes: Vec<_> = p
            .moves
            .iter()
            .filter(|m| m.motion == Motion::Line && (m.end[2] == -3.0 || m.end[2] == -4.0))
            .map(|m| (m.end[0], m.speed))
            .collect();
        assert_eq!(
            holes,
            [
                (20.0, Speed::Feed(1.0)),
                (30.0, Speed::Feed(1.0)),
                (40.0, Speed::Feed(1.0)),
                (50.0, Speed::Feed(1.0))
            ]
        );
        assert_eq!(dwells(&p), [0.5]);
        // G98 back to Z10 after the first two holes, G99 to R after the others.
        let tops: Vec<_> = p
            .moves
            .windows(2)
            .filter(|w| w[0].end[2] < -2.0 && w[1].speed == Speed::Rapid)
            .filter(|w| w[1].motion == Motion::Line)
            .map(|w| w[1].end[2])
            .collect();
        // (G83's last two pecks start below −2: out to R after each.)
        assert_eq!(tops, [10.0, 10.0, 2.0, 2.0, 2.0]);
        // On the table: the holes are exact stops for the cycles' time, and the profiles
        // around them are read.
        let table = Program::from_part_program(&p).unwrap();
        let at_hole = |x: f64| {
            table
                .moves()
                .iter()
                .find(|m| m.shape.curve().point(1.0) == Vector2::new(x, 0.0))
                .map(|m| (m.corner, m.standstill))
                .unwrap()
        };
        let (corner, first) = at_hole(20.0);
        assert_eq!(corner, Corner::ExactStop);
        // Rapid 8 down to R, 5 mm at F60 (5 s), rapid 13 back up.
        assert_eq!((first.seconds, first.at_rapid), (5.0, 8.0 + 13.0));
        let (_, g82) = at_hole(40.0);
        assert_eq!((g82.seconds, g82.at_rapid), (5.0 + 0.5, 8.0 + 5.0));
        assert!(table.moves().last().unwrap().shape.curve().point(1.0) == Vector2::new(60.0, 10.0));
        for (text, want) in [
            ("G0 Z5\nG81 X1 Z-1\n", "t.ngc:2:1: a drilling cycle needs R"),
            (
                "G0 Z5\nG83 X1 Z-1 R1\n",
                "t.ngc:2:1: a peck cycle (G73, G83) needs Q",
            ),
            (
                "G91 G81 X1 Z-1 R1\n",
                "t.ngc:1:5: drilling cycles in incremental mode",
            ),
            ("G81 X1 Z1 R0 L2\n", "t.ngc:1:14: a cycle's repeats"),
            (
                "G81 X1 Z-1 R1\nG80 X2\n",
                "t.ngc:2:5: axis words without a motion code",
            ),
        ] {
            let e = refused(text);
            assert!(e.starts_with(want), "{text:?}: {e}");
        }
    }

    #[test]
    fn a_full_circle_without_x_and_y_in_every_dialect() {
        for dialect in [Dialect::LinuxCnc, Dialect::Fanuc] {
            let options = GcodeOptions {
                dialect,
                ..GcodeOptions::default()
            };
            let p = Program::parse_gcode_with("G1 X5 Y0 F600\nG2 I-5\nJ5 G3\n", "t.ngc", &options)
                .unwrap();
            let Shape::Arc(a) = &p.moves()[1].shape else {
                panic!()
            };
            assert_eq!((a.sweep(), a.center()), (-2.0 * PI, Vector2::zeros()));
            let Shape::Arc(b) = &p.moves()[2].shape else {
                panic!()
            };
            assert_eq!((b.sweep(), b.center()), (2.0 * PI, Vector2::new(5.0, 5.0)));
        }
        assert!(refused("G1 X5\nG2 R5\n").contains("full circle takes I and J"));
    }

    #[test]
    fn the_third_axis_is_refused_with_its_line_and_the_five_axis_machine_advised() {
        for (text, want) in [
            ("G1 X1\nG19 G2 Y1 Z1 J1\n", "t.ngc:2:1: G19 arcs"),
            (
                "G1 X1 F60\nG1 X2 Y1 Z-1\n",
                "t.ngc:2:10: a move of X or Y together with Z",
            ),
            (
                "G0 X1\nG3 X1 Y0 I1 Z-1 F60\n",
                "t.ngc:2:13: a move of X or Y together with Z",
            ),
        ] {
            let e = refused(text);
            assert!(
                e.starts_with(want) && e.contains("five-axis machine"),
                "{text:?}: {e}"
            );
        }
    }

    #[test]
    fn arcs_rounded_as_posts_round_them_are_read_and_ends_truly_off_are_refused() {
        // Arcs of radius 0.1 to 50 mm at many angles, their ends and centres rounded to
        // 3 and to 4 decimals as a post writes them.
        for decimals in [3, 4] {
            let round = |v: f64| format!("{v:.decimals$}");
            let mut text = String::from("G21 G90\nG0 X0 Y0\n");
            let mut position = Vector2::zeros();
            let mut count = 0;
            for (k, radius) in [0.1, 0.14, 0.3, 1.0, 5.0, 50.0].into_iter().enumerate() {
                for step in 0..24 {
                    let a0 = 0.37 * (step as f64) + k as f64;
                    let sweep = [0.05, 0.4, 1.3, 3.0, 6.0][step % 5]
                        * if step % 2 == 0 { 1.0 } else { -1.0 };
                    let centre = position - Vector2::new(math::cos(a0), math::sin(a0)) * radius;
                    let end = centre
                        + Vector2::new(math::cos(a0 + sweep), math::sin(a0 + sweep)) * radius;
                    let (x, y) = (round(end[0]), round(end[1]));
                    let (i, j) = (
                        round(centre[0] - position[0]),
                        round(centre[1] - position[1]),
                    );
                    let g = if sweep > 0.0 { "G3" } else { "G2" };
                    text += &format!("{g} X{x} Y{y} I{i} J{j} F600\n");
                    position = Vector2::new(x.parse().unwrap(), y.parse().unwrap());
                    count += 1;
                }
            }
            let p =
                Program::parse_gcode(&text, "t.ngc").unwrap_or_else(|e| panic!("{decimals}: {e}"));
            assert_eq!(p.moves().len(), count);
        }
        // A 2 mm arc whose end is 0.05 mm off its circle (no rounding explains it).
        let e = refused("G1 X2 F60\nG3 X0 Y2.05 I-2 J0\n");
        assert!(
            e.starts_with("t.ngc:2:1: the arc's end is not on its circle"),
            "{e}"
        );
    }

    #[test]
    fn g92_moves_the_coordinates_zero_and_g9_stops_one_move() {
        // CamBam's older posts set zero with G92 at the start; here after a move.
        let p = read("G0 X10 Y10\nG92 X0 Y0\nG1 X5 F600\nG90.1 G2 X10 Y0 I7.5 J0\nG92.1\nG1 X30\n");
        let ends: Vec<Vector2> = p
            .moves()
            .iter()
            .map(|m| m.shape.curve().point(1.0))
            .collect();
        let want = [(15.0, 10.0), (20.0, 10.0), (30.0, 10.0)].map(|(x, y)| Vector2::new(x, y));
        assert_eq!(ends, want);
        let Shape::Arc(a) = &p.moves()[1].shape else {
            panic!()
        };
        assert!((a.center() - Vector2::new(17.5, 10.0)).amax() < 1e-12);
        assert!(refused("G92\n").starts_with("t.ngc:1:1: G92 needs an axis word"));
        let p = read("G64\nG1 X10 F600\nG9 G1 Y10\nG1 X0\n");
        let corners: Vec<Corner> = p.moves().iter().map(|m| m.corner).collect();
        assert_eq!(
            corners,
            [
                Corner::BlendDefault,
                Corner::ExactStop,
                Corner::BlendDefault
            ]
        );
    }
}
