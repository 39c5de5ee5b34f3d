//! The planned geometry of a program: its corners between lines rounded by
//! [`CornerBlend`]s within the corner's tolerance (docs/design/two-axis.md §4.9). It
//! depends only on the program and the `tolerance` parameter, so the interpolator and
//! the controller's `program` estimator build the same path.

use super::{CornerBlend, Move, Program, Shape};
use crate::part_program::Corner;
use crate::path::{Curve, Line};
use crate::{geometry, math};

/// Turns below this (rad) are not rounded: a reference passes them at speed within its
/// limits (v·θ within the acceleration and jerk of one sample), and rounding them would
/// bend long stretches of nearly straight path.
pub const MIN_BLEND_TURN: f64 = 1e-3;

/// Share of each line a blend may take at either of its ends: what is left of a line
/// blended at both ends is a fifth of it.
const REACH: f64 = 0.4;

/// The program with every blended corner between two lines rounded: at the end of a
/// move whose corner is `Blend(P)` within P, `BlendDefault` within `tolerance` (none
/// when it is 0); `ExactStop` corners, corners into or out of arcs and turns below
/// [`MIN_BLEND_TURN`] stay as programmed.
pub fn blended(program: &Program, tolerance: f64) -> Program {
    let moves = program.moves();
    let last = moves.len() - 1;
    // The blend at the end of each move, and how much it takes from either side.
    let blends: Vec<Option<(CornerBlend, f64)>> = (0..moves.len())
        .map(|i| {
            let next = if i < last { i + 1 } else { return None };
            let within = match moves[i].corner {
                Corner::Blend(p) => p,
                Corner::BlendDefault => tolerance,
                Corner::ExactStop => 0.0,
            };
            let (Shape::Line(a), Shape::Line(b)) = (&moves[i].shape, &moves[next].shape) else {
                return None;
            };
            let (t1, t2) = (a.direction(), b.direction());
            let turn = math::atan2(geometry::cross(&t1, &t2), t1.dot(&t2)).abs();
            if !(within > 0.0 && turn >= MIN_BLEND_TURN) {
                return None;
            }
            let reach = REACH * a.length().min(b.length());
            // Lines of a few rounding units, or a blend narrower than the corner's
            // coordinates resolve: not rounded (what a blend would leave of the lines could
            // round to nothing, and its ends would not meet them).
            let resolution = 1e-9 * (1.0 + a.end().amax());
            if reach <= resolution || within <= resolution {
                return None;
            }
            CornerBlend::at_corner(a.end(), t1, t2, within, reach)
        })
        .collect();
    let mut out = Vec::with_capacity(moves.len() + blends.iter().flatten().count());
    for (i, m) in moves.iter().enumerate() {
        let before = if i > 0 { blends[i - 1].as_ref() } else { None };
        let after = blends[i].as_ref();
        let shape = match (&m.shape, before, after) {
            (Shape::Line(l), _, _) if before.is_some() || after.is_some() => {
                let t = l.direction();
                let from = l.start() + t * before.map_or(0.0, |b| b.1);
                let to = l.end() - t * after.map_or(0.0, |b| b.1);
                Shape::Line(Line::new(from, to).expect("a blend leaves a fifth of its line"))
            }
            _ => m.shape.clone(),
        };
        out.push(Move { shape, ..m.clone() });
        if let Some((blend, _)) = after {
            out.push(Move {
                shape: Shape::Blend(blend.clone()),
                ..m.clone()
            });
        }
    }
    // Blends join the lines they round; should rounding still part them somewhere (at
    // coordinates far beyond any machine's), the program stays as programmed.
    Program::new(out).unwrap_or_else(|_| program.clone())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A program the fuzzer wrote (fuzz target gcode_program): a move to Y = 6.7e22 mm and
    /// back home (G28 in the YZ plane), blended within 0.01 mm, far below what coordinates
    /// that large resolve. Planned, it stays sharp there instead of panicking.
    #[test]
    fn a_corner_beyond_the_coordinates_resolution_stays_sharp() {
        use crate::part_program::gcode::{parse_gcode, GcodeOptions};
        use crate::path::planar::{Path, XyLimits, XyReference};
        let text = "%\nO1001 (BRACKET)\nN15. H2\nG1 Z-1. F30\rG0 Z5.00 \rY66666666666666666666660.166666666666660\nG28 G19 X0. Y0.\nG90\nG53 G0 Z0.\nM30\n%\n";
        let options = GcodeOptions {
            dialect: crate::part_program::gcode::Dialect::Fanuc,
            home: crate::geometry::Vector::<3>::new(-12.0, 10.0, 50.0),
            ..GcodeOptions::default()
        };
        let part = parse_gcode(text, "far.ngc", &options).unwrap();
        let program = Program::from_part_program(&part).unwrap();
        let limits = XyLimits::example();
        let planned = blended(&program, limits.tolerance);
        assert!(Program::new(planned.moves().to_vec()).is_ok());
        // Planning it may refuse it (its length), never panic.
        let _ = XyReference::new(Path::Program(program), limits);
    }
}
