//! The measured run: a CSV file with a header row. Its columns say what it is: `time,X,Y`
//! and none of `Z`, `A`, `C` is a run of the XY table; otherwise it is a five-axis run
//! and needs all of `time,X,Y,Z,A,C`. Other columns are ignored, the order is free.

use std::fs::File;
use std::io::{BufRead, BufReader};
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

/// Reads the run in `file`; errors name the file and the line.
pub fn read(file: &Path) -> Result<Measured, String> {
    let name = file.display().to_string();
    let reader = BufReader::new(File::open(file).map_err(|e| format!("{name}: cannot read: {e}"))?);
    let mut lines = reader.lines();
    let header = match lines.next() {
        Some(line) => line.map_err(|e| format!("{name}:1: cannot read: {e}"))?,
        None => return Err(format!("{name}: empty file, expected a header row")),
    };
    let (kind, index) = columns(&header, &name)?;
    let wanted = match kind {
        Kind::Planar => &PLANAR[..],
        Kind::FiveAxis => &FIVE_AXIS[..],
    };
    let needed = index.iter().max().map_or(0, |&i| i + 1);
    let mut times = Vec::new();
    let mut planar = Vec::new();
    let mut joints = Vec::new();
    let mut values = [0.0; 6];
    for (number, line) in lines.enumerate() {
        let at = number + 2;
        let line = line.map_err(|e| format!("{name}:{at}: cannot read: {e}"))?;
        if line.trim().is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() < needed {
            return Err(format!(
                "{name}:{at}: {} fields, the header needs at least {needed}",
                fields.len()
            ));
        }
        for (slot, (&i, w)) in values.iter_mut().zip(index.iter().zip(wanted)) {
            let text = fields[i].trim();
            let v: f64 = text
                .parse()
                .map_err(|_| format!("{name}:{at}: column '{w}': '{text}' is not a number"))?;
            if !v.is_finite() {
                return Err(format!("{name}:{at}: column '{w}': '{text}' is not finite"));
            }
            *slot = v;
        }
        times.push(values[0]);
        match kind {
            Kind::Planar => planar.push(Vector2::new(values[1], values[2])),
            Kind::FiveAxis => joints.push(Joints::new(
                values[1], values[2], values[3], values[4], values[5],
            )),
        }
    }
    if times.is_empty() {
        return Err(format!("{name}: no measured samples after the header"));
    }
    let samples = match kind {
        Kind::Planar => Samples::Planar(planar),
        Kind::FiveAxis => Samples::FiveAxis(joints),
    };
    Ok(Measured { times, samples })
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
}
