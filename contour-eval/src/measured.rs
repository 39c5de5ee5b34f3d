//! The measured run: a CSV file with a header row. Its columns say what it is: `time,X,Y`
//! and none of `Z`, `A`, `C` is a run of the XY table; otherwise it is a five-axis run
//! and needs all of `time,X,Y,Z,A,C`. Other columns are ignored, the order is free.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use contour_core::geometry::Vector2;
use contour_core::kinematics::Joints;

/// What kind of machine a run comes from, by its columns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `time,X,Y`, no `Z`, `A`, `C`: the XY table.
    Planar,
    /// `time,X,Y,Z,A,C`: a table-tilting A–C machine.
    FiveAxis,
}

impl Kind {
    /// The run's columns, as messages name them.
    pub fn columns(self) -> &'static str {
        match self {
            Kind::Planar => "the XY table's columns time,X,Y (no Z, A, C)",
            Kind::FiveAxis => "five-axis columns time,X,Y,Z,A,C",
        }
    }
}

/// The samples of a run.
pub enum Samples {
    /// Positions of the XY table, mm.
    Planar(Vec<Vector2>),
    /// Joints X, Y, Z (mm), A, C (rad).
    FiveAxis(Vec<Joints>),
}

/// A measured run: a time and a sample per row.
pub struct Measured {
    pub times: Vec<f64>,
    pub samples: Samples,
}

const PLANAR: [&str; 3] = ["time", "X", "Y"];
const FIVE_AXIS: [&str; 6] = ["time", "X", "Y", "Z", "A", "C"];

/// The kind of run a header describes and the positions of its columns (in the order of
/// [`PLANAR`] or [`FIVE_AXIS`]).
fn columns(header: &str, name: &str) -> Result<(Kind, Vec<usize>), String> {
    let columns: Vec<&str> = header.split(',').map(str::trim).collect();
    let at = |w: &str| columns.iter().position(|c| *c == w);
    let rotary_or_z = ["Z", "A", "C"].iter().any(|w| at(w).is_some());
    let (kind, wanted, need) = if rotary_or_z {
        (
            Kind::FiveAxis,
            &FIVE_AXIS[..],
            "need time,X,Y,Z,A,C; a run of the XY table has time,X,Y and none of Z, A, C",
        )
    } else {
        (
            Kind::Planar,
            &PLANAR[..],
            "need time,X,Y for the XY table or time,X,Y,Z,A,C for five axes",
        )
    };
    let index = wanted
        .iter()
        .map(|w| at(w).ok_or_else(|| format!("{name}:1: no column '{w}' in the header ({need})")))
        .collect::<Result<Vec<usize>, String>>()?;
    Ok((kind, index))
}

/// Bytes read at a time; each block's lines are parsed by two threads.
const BLOCK: usize = 16 << 20;

/// Samples parsed from some lines of the run.
#[derive(Default)]
struct Rows {
    times: Vec<f64>,
    planar: Vec<Vector2>,
    joints: Vec<Joints>,
}

impl Rows {
    /// Room for `rows` rows in all, in the columns of the kind read so far.
    fn reserve(&mut self, rows: usize) {
        let more = rows.saturating_sub(self.times.len());
        self.times.reserve(more);
        if self.joints.is_empty() {
            self.planar.reserve(more);
        } else {
            self.joints.reserve(more);
        }
    }

    fn append(&mut self, mut other: Rows) {
        self.times.append(&mut other.times);
        self.planar.append(&mut other.planar);
        self.joints.append(&mut other.joints);
    }
}

/// The layout of the run's rows, from its header.
struct Layout {
    kind: Kind,
    /// The column of each wanted value (the order of [`PLANAR`] or [`FIVE_AXIS`]).
    index: Vec<usize>,
    /// Fields a row needs.
    needed: usize,
}

/// Why a line cannot be read: the line (counted from the text's first, 0) and what is
/// wrong, to be prefixed with the file and the line number.
type LineError = (usize, String);

impl Layout {
    /// Parses the complete lines of `text` (each ending in a newline, the file's last
    /// perhaps not) into `rows`; the lines read.
    fn parse(&self, text: &[u8], rows: &mut Rows) -> Result<usize, LineError> {
        let wanted = match self.kind {
            Kind::Planar => &PLANAR[..],
            Kind::FiveAxis => &FIVE_AXIS[..],
        };
        let mut values = [0.0; 6];
        let body = text.strip_suffix(b"\n").unwrap_or(text);
        if text.is_empty() {
            return Ok(0);
        }
        let mut lines = 0;
        for (at, line) in body.split(|&b| b == b'\n').enumerate() {
            lines = at + 1;
            // As BufRead::lines reads a line: without its CR LF.
            let line = line.strip_suffix(b"\r").unwrap_or(line);
            let line = std::str::from_utf8(line).map_err(|_| {
                (
                    at,
                    "cannot read: stream did not contain valid UTF-8".to_string(),
                )
            })?;
            if line.trim().is_empty() {
                continue;
            }
            let mut fields = [""; 6];
            let mut count = 0;
            for (column, field) in line.split(',').enumerate() {
                count = column + 1;
                for (slot, &i) in fields.iter_mut().zip(&self.index) {
                    if i == column {
                        *slot = field;
                    }
                }
            }
            if count < self.needed {
                let needed = self.needed;
                return Err((
                    at,
                    format!("{count} fields, the header needs at least {needed}"),
                ));
            }
            for ((slot, field), w) in values.iter_mut().zip(fields).zip(wanted) {
                let text = field.trim();
                let v: f64 = text
                    .parse()
                    .map_err(|_| (at, format!("column '{w}': '{text}' is not a number")))?;
                if !v.is_finite() {
                    return Err((at, format!("column '{w}': '{text}' is not finite")));
                }
                *slot = v;
            }
            rows.times.push(values[0]);
            match self.kind {
                Kind::Planar => rows.planar.push(Vector2::new(values[1], values[2])),
                Kind::FiveAxis => rows.joints.push(Joints::new(
                    values[1], values[2], values[3], values[4], values[5],
                )),
            }
        }
        Ok(lines)
    }

    /// [`Layout::parse`] with the second half of a large `text` parsed by a thread of
    /// its own (the lines' order, and the first error in it, as one pass gives them).
    fn parse_halves(&self, text: &[u8], rows: &mut Rows) -> Result<usize, LineError> {
        let middle = text.len() / 2;
        let split = match text[middle..].iter().position(|&b| b == b'\n') {
            Some(i) if text.len() > 1 << 16 => middle + i + 1,
            _ => return self.parse(text, rows),
        };
        let (head, tail) = text.split_at(split);
        std::thread::scope(|scope| {
            let later = scope.spawn(|| {
                let mut rows = Rows::default();
                self.parse(tail, &mut rows).map(|lines| (lines, rows))
            });
            let head_lines = self.parse(head, rows)?;
            let (tail_lines, tail_rows) = later
                .join()
                .expect("the parsing thread does not panic")
                .map_err(|(at, message)| (head_lines + at, message))?;
            rows.append(tail_rows);
            Ok(head_lines + tail_lines)
        })
    }
}

/// Threads by default: as many as the machine runs at once.
pub fn default_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Reads the run in `file`, with two threads where `threads` > 1; errors name the file
/// and the line.
pub fn read(file: &Path, threads: usize) -> Result<Measured, String> {
    read_blocks(file, threads, BLOCK)
}

/// [`read`], `block` bytes at a time.
fn read_blocks(file: &Path, threads: usize, block: usize) -> Result<Measured, String> {
    let name = file.display().to_string();
    let mut reader =
        BufReader::new(File::open(file).map_err(|e| format!("{name}: cannot read: {e}"))?);
    let mut header = String::new();
    match reader.read_line(&mut header) {
        Ok(0) => return Err(format!("{name}: empty file, expected a header row")),
        Ok(_) => {}
        Err(e) => return Err(format!("{name}:1: cannot read: {e}")),
    }
    let (kind, index) = columns(header.trim_end_matches(['\n', '\r']), &name)?;
    let needed = index.iter().max().map_or(0, |&i| i + 1);
    let layout = Layout {
        kind,
        index,
        needed,
    };
    let mut rows = Rows::default();
    let size = reader.get_ref().metadata().map_or(0, |m| m.len() as usize);
    // Whole lines of up to BLOCK bytes at a time; a line cut by the block waits for the next.
    let (mut buffer, mut line, mut read) = (Vec::new(), 2, 0);
    loop {
        let got = (&mut reader)
            .take(block as u64)
            .read_to_end(&mut buffer)
            .map_err(|e| format!("{name}:{line}: cannot read: {e}"))?;
        let end = if got == 0 {
            buffer.len()
        } else {
            match buffer.iter().rposition(|&b| b == b'\n') {
                Some(i) => i + 1,
                None => continue,
            }
        };
        let text = &buffer[..end];
        let parsed = if threads > 1 {
            layout.parse_halves(text, &mut rows)
        } else {
            layout.parse(text, &mut rows)
        };
        line += parsed.map_err(|(at, message)| format!("{name}:{}: {message}", line + at))?;
        if read == 0 && end > 0 {
            // Room for the whole run at the first block's bytes a row, so that a long
            // run's columns are not copied as they grow.
            rows.reserve(size / end * rows.times.len() + rows.times.len());
        }
        read += end;
        buffer.drain(..end);
        if got == 0 {
            break;
        }
    }
    if rows.times.is_empty() {
        return Err(format!("{name}: no measured samples after the header"));
    }
    let samples = match kind {
        Kind::Planar => Samples::Planar(rows.planar),
        Kind::FiveAxis => Samples::FiveAxis(rows.joints),
    };
    Ok(Measured {
        times: rows.times,
        samples,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_columns_decide_the_kind() {
        let kind = |h: &str| columns(h, "run.csv");
        assert_eq!(kind("time,X,Y").unwrap(), (Kind::Planar, vec![0, 1, 2]));
        assert_eq!(
            kind(" Y , note, X ,time").unwrap(),
            (Kind::Planar, vec![3, 2, 0])
        );
        assert_eq!(
            kind("C,time,X,Y,Z,A").unwrap(),
            (Kind::FiveAxis, vec![1, 2, 3, 4, 5, 0])
        );
        // One of Z, A, C makes it a five-axis run, which needs all of them.
        let e = kind("time,X,Y,Z").unwrap_err();
        assert!(e.contains("run.csv:1: no column 'A'"), "{e}");
        let e = kind("time,X,Y,C").unwrap_err();
        assert!(e.contains("no column 'Z'"), "{e}");
        // Lower-case names are other columns.
        let e = kind("time,x,y").unwrap_err();
        assert!(
            e.contains("no column 'X'") && e.contains("time,X,Y for"),
            "{e}"
        );
    }

    fn scratch(name: &str, text: &[u8]) -> std::path::PathBuf {
        let path = std::env::temp_dir().join(format!("measured-{}-{name}", std::process::id()));
        std::fs::write(&path, text).unwrap();
        path
    }

    /// A five-axis run of `rows` rows (CR LF and blank lines among them, the last
    /// without a newline), and its values as one plain pass over the lines reads them.
    fn five_axis_file(rows: usize) -> (Vec<u8>, Vec<f64>, Vec<[f64; 5]>) {
        let mut text = String::from("C, note ,time,X,Y,Z,A\r\n");
        let (mut times, mut joints) = (Vec::new(), Vec::new());
        for k in 0..rows {
            let t = k as f64 * 0.001;
            let q = [
                1.0 + k as f64 * 1e-3 / 3.0,
                -2.5e-7 * k as f64,
                k as f64,
                0.1 / (k + 1) as f64,
                -1e300 / (k + 1) as f64,
            ];
            let c = q[4];
            text += &format!("{c}, x ,{t},{},{},{},{}", q[0], q[1], q[2], q[3]);
            text += match k % 7 {
                0 => "\r\n",
                3 => "\n\n  \n",
                _ => "\n",
            };
            times.push(t);
            joints.push(q);
        }
        text.pop();
        (text.into_bytes(), times, joints)
    }

    #[test]
    fn blocks_and_halves_read_what_one_pass_reads() {
        let (text, times, joints) = five_axis_file(5000);
        let path = scratch("blocks.csv", &text);
        for (threads, block) in [(1, 1 << 20), (2, 1 << 20), (2, 70_000), (2, 999), (1, 37)] {
            let run = read_blocks(&path, threads, block).unwrap();
            assert_eq!(run.times, times, "{threads} threads, blocks of {block}");
            let Samples::FiveAxis(read) = run.samples else {
                panic!("a five-axis run")
            };
            let read: Vec<[f64; 5]> = read
                .iter()
                .map(|q| [q[0], q[1], q[2], q[3], q[4]])
                .collect();
            assert_eq!(read, joints, "{threads} threads, blocks of {block}");
        }
        std::fs::remove_file(path).unwrap();
    }

    #[test]
    fn a_bad_line_is_named_by_its_number_wherever_it_falls() {
        let (text, _, _) = five_axis_file(5000);
        let lines: Vec<&[u8]> = text.split(|&b| b == b'\n').collect();
        // Line numbers count every line, blank ones too (1: the header).
        for (at, bad, expected) in [
            (
                4321,
                &b"1,2,3"[..],
                "3 fields, the header needs at least 7".to_string(),
            ),
            (
                6000,
                &b"0,x,0.5,1,2,zwei,4"[..],
                "column 'Z': 'zwei' is not a number".to_string(),
            ),
            (
                17,
                &b"0,x,0.5,1,2,3,inf"[..],
                "column 'A': 'inf' is not finite".to_string(),
            ),
            (
                5555,
                &b"0,\xff,0.5,1,2,3,4"[..],
                "cannot read: stream did not contain valid UTF-8".to_string(),
            ),
        ] {
            let mut broken = lines.clone();
            broken[at - 1] = bad;
            let path = scratch("bad.csv", &broken.join(&b'\n'));
            for (threads, block) in [(1, 1 << 20), (2, 1 << 20), (2, 5000), (1, 100)] {
                let message = read_blocks(&path, threads, block).err().unwrap();
                assert!(
                    message.ends_with(&format!(":{at}: {expected}")),
                    "{threads} threads, blocks of {block}: {message}"
                );
            }
            std::fs::remove_file(path).unwrap();
        }
    }
}
