//! The circle of a G2/G3 block from its words (docs/design/two-axis.md §4.7): the start,
//! the programmed end and either the centre (I, J) or the radius R (negative: the arc
//! over 180°). Posts round every coordinate to their last decimal, so a programmed end
//! is rarely exactly as far from the centre as the start. An end off the circle by more
//! than [`end_tolerance`] is refused; within it, the centre moves to the nearest point
//! equally far from both ends, so the arc ends exactly at the programmed end and the next
//! move starts there, and that circle must stay within the same tolerance of the path a
//! controller cuts (the spiral from the start's radius to the end's about the programmed
//! centre): a near-full circle whose end misses its start would otherwise shrink to a
//! tiny one.

use crate::math;
use std::f64::consts::{PI, SQRT_2};

use crate::geometry::{self, Vector2};
use crate::path::CircularArc;

/// How far (mm) an arc's end may lie off its circle, and the arc as followed off the
/// path a controller cuts: max(`allowance` ([`allowance`]), [`LINUXCNC_RELATIVE`] of the
/// radius).
pub fn end_tolerance(radius: f64, allowance: f64) -> f64 {
    allowance.max(LINUXCNC_RELATIVE * radius)
}

/// The absolute part of the arc tolerance, mm: max(LinuxCNC's for the program's units,
/// what rounding every coordinate to `resolution` mm explains). Each of the start, the
/// end and I, J is within resolution/√2 of its exact value, so the two radii differ by
/// up to four of those, 2√2·resolution.
pub fn allowance(inch: bool, resolution: f64) -> f64 {
    let linuxcnc = if inch {
        LINUXCNC_ABSOLUTE_INCH * 25.4
    } else {
        LINUXCNC_ABSOLUTE_MM
    };
    linuxcnc.max(2.0 * SQRT_2 * resolution)
}

/// LinuxCNC's absolute arc-end tolerance in mm mode (`CENTER_ARC_RADIUS_TOLERANCE_MM`,
/// 2 · 0.01 · √2), mm.
pub const LINUXCNC_ABSOLUTE_MM: f64 = 2.0 * 0.01 * SQRT_2;

/// LinuxCNC's absolute arc-end tolerance in inch mode (`CENTER_ARC_RADIUS_TOLERANCE_INCH`,
/// 2 · 0.001 · √2), inches.
pub const LINUXCNC_ABSOLUTE_INCH: f64 = 2.0 * 0.001 * SQRT_2;

/// LinuxCNC's tolerance relative to the radius (`SPIRAL_RELATIVE_TOLERANCE`).
pub const LINUXCNC_RELATIVE: f64 = 0.001;

/// How far short of half the chord R may fall (LinuxCNC's 0.00005 in), mm.
pub const RADIUS_TOLERANCE: f64 = 0.00127;

/// How the circle was given.
#[derive(Clone, Copy, Debug)]
pub enum Circle {
    /// The centre (absolute, mm).
    Centre(Vector2),
    /// R, mm: > 0 for the arc up to 180°, < 0 for the one beyond.
    Radius(f64),
}

/// The arc from `start` to `end` about `circle`, clockwise when `clockwise` (G2);
/// `start == end` with a centre is a full circle. `allowance` is [`allowance`]'s. The
/// error says what is wrong.
pub fn arc(
    start: Vector2,
    end: Vector2,
    circle: Circle,
    clockwise: bool,
    allowance: f64,
) -> Result<CircularArc, String> {
    let centre = match circle {
        Circle::Centre(c) => fit_centre(start, end, c, clockwise, allowance)?,
        Circle::Radius(r) => radius_centre(start, end, r, clockwise)?,
    };
    let radius = geometry::dist(&start, &centre);
    let (a0, sweep) = sweep_about(centre, start, end, clockwise);
    CircularArc::new(centre, radius, a0, sweep).map_err(|e| e.to_string())
}

/// The start angle about `centre` and the signed sweep from `start` to `end` in the
/// arc's sense; a whole turn when they coincide.
fn sweep_about(centre: Vector2, start: Vector2, end: Vector2, clockwise: bool) -> (f64, f64) {
    let angle = |p: Vector2| math::atan2(p[1] - centre[1], p[0] - centre[0]);
    let (a0, a1) = (angle(start), angle(end));
    let turn = if clockwise { a0 - a1 } else { a1 - a0 };
    let mut sweep = turn.rem_euclid(2.0 * PI);
    if start == end || sweep == 0.0 {
        sweep = 2.0 * PI;
    }
    (a0, if clockwise { -sweep } else { sweep })
}

/// The centre nearest `c` that is equally far from `start` and `end`; refused when the
/// end is off the circle, or that circle off the programmed path, beyond the tolerance.
fn fit_centre(
    start: Vector2,
    end: Vector2,
    c: Vector2,
    clockwise: bool,
    allowance: f64,
) -> Result<Vector2, String> {
    let (r0, r1) = (geometry::dist(&start, &c), geometry::dist(&end, &c));
    if r0 == 0.0 {
        return Err("the arc's centre is its start point (radius 0)".into());
    }
    let tolerance = end_tolerance(r0, allowance);
    if (r1 - r0).abs() > tolerance || r1.is_nan() {
        return Err(format!(
            "the arc's end is not on its circle: {r0:.6} mm from the centre at the start, \
             {r1:.6} mm at the end (tolerance {tolerance:.4} mm)"
        ));
    }
    let chord = end - start;
    let length2 = chord.dot(&chord);
    if length2 == 0.0 {
        return Ok(c);
    }
    let fitted = nearest_on_bisector(start, end, c);
    let off = off_the_cut_path(start, end, c, fitted, clockwise);
    if off > tolerance || off.is_nan() {
        return Err(format!(
            "the arc's end is {:.6} mm off its circle, and the circle through both ends runs \
             up to {off:.6} mm from the programmed arc (the ends are {:.6} mm apart; \
             tolerance {tolerance:.4} mm)",
            (r1 - r0).abs(),
            length2.sqrt(),
        ));
    }
    Ok(fitted)
}

/// The point of the perpendicular bisector of `start`–`end` (two distinct points) nearest
/// `c`: the centre nearest `c` of a circle through both.
pub fn nearest_on_bisector(start: Vector2, end: Vector2, c: Vector2) -> Vector2 {
    let chord = end - start;
    let middle = (start + end) * 0.5;
    c - chord * ((c - middle).dot(&chord) / chord.dot(&chord))
}

/// How far the arc about `fitted` strays from the spiral a controller cuts about the
/// programmed centre `c` (its radius going from the start's to the end's), compared at
/// the same share of each one's sweep.
fn off_the_cut_path(
    start: Vector2,
    end: Vector2,
    c: Vector2,
    fitted: Vector2,
    clockwise: bool,
) -> f64 {
    const SAMPLES: usize = 64;
    let (r0, r1) = (geometry::dist(&start, &c), geometry::dist(&end, &c));
    let r = geometry::dist(&start, &fitted);
    let (b0, cut_sweep) = sweep_about(c, start, end, clockwise);
    let (a0, sweep) = sweep_about(fitted, start, end, clockwise);
    (0..=SAMPLES)
        .map(|k| {
            let t = k as f64 / SAMPLES as f64;
            let (sa, ca) = math::sincos(a0 + t * sweep);
            let (sb, cb) = math::sincos(b0 + t * cut_sweep);
            let ours = fitted + Vector2::new(ca, sa) * r;
            let cut = c + Vector2::new(cb, sb) * (r0 + t * (r1 - r0));
            geometry::dist(&ours, &cut)
        })
        .fold(0.0, f64::max)
}

/// The centre of the circle of radius |r| through `start` and `end` on the side R's sign
/// and the direction choose.
fn radius_centre(start: Vector2, end: Vector2, r: f64, clockwise: bool) -> Result<Vector2, String> {
    let chord = end - start;
    let length = geometry::norm(&chord);
    if length == 0.0 {
        return Err(
            "an arc given by R must end elsewhere than it starts (a full circle takes I and J)"
                .into(),
        );
    }
    let half = 0.5 * length;
    let radius = r.abs();
    if radius == 0.0 || radius < half - RADIUS_TOLERANCE || radius.is_nan() {
        return Err(format!(
            "R = {r} mm is too small for an arc whose ends are {length:.6} mm apart"
        ));
    }
    let rise = (radius * radius - half * half).max(0.0).sqrt();
    // Up to 180°, a counter-clockwise arc has its centre left of the chord, a clockwise
    // one right; beyond 180° (R < 0), the other side.
    let left = clockwise == (r < 0.0);
    let normal = geometry::perp(&(chord / length));
    let side = if left { 1.0 } else { -1.0 };
    Ok((start + end) * 0.5 + normal * (side * rise))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::Curve;

    fn close(a: Vector2, b: Vector2) -> bool {
        (a - b).amax() < 1e-12
    }

    #[test]
    fn quarter_circles_by_centre_and_by_radius() {
        let (s, e) = (Vector2::new(10.0, 0.0), Vector2::new(0.0, 10.0));
        // G3 from (10, 0) to (0, 10) about the origin: a quarter, counter-clockwise.
        let a = arc(
            s,
            e,
            Circle::Centre(Vector2::zeros()),
            false,
            allowance(false, 0.001),
        )
        .unwrap();
        assert!((a.sweep() - PI / 2.0).abs() < 1e-15 && a.radius() == 10.0);
        // G2 the same way round is the three-quarter circle.
        let b = arc(
            s,
            e,
            Circle::Centre(Vector2::zeros()),
            true,
            allowance(false, 0.001),
        )
        .unwrap();
        assert!((b.sweep() + 1.5 * PI).abs() < 1e-14);
        // R 10: the short arcs; R −10: the long ones, about (10, 10).
        let c = arc(s, e, Circle::Radius(10.0), false, allowance(false, 0.001)).unwrap();
        assert!(close(c.center(), Vector2::zeros()));
        let d = arc(s, e, Circle::Radius(-10.0), false, allowance(false, 0.001)).unwrap();
        assert!(close(d.center(), Vector2::new(10.0, 10.0)));
        assert!((d.sweep() - 1.5 * PI).abs() < 1e-14);
        let f = arc(s, e, Circle::Radius(10.0), true, allowance(false, 0.001)).unwrap();
        assert!(
            close(f.center(), Vector2::new(10.0, 10.0)) && (f.sweep() + PI / 2.0).abs() < 1e-14
        );
        for x in [a, b, c, d, f] {
            assert!(close(x.point(0.0), s) && close(x.point(1.0), e));
        }
    }

    #[test]
    fn full_circles_and_rounded_ends() {
        let s = Vector2::new(5.0, 0.0);
        let full = arc(
            s,
            s,
            Circle::Centre(Vector2::zeros()),
            true,
            allowance(false, 0.001),
        )
        .unwrap();
        assert_eq!(full.sweep(), -2.0 * PI);
        // An end rounded to 3 decimals: 0.0005 mm off the circle, accepted; the centre
        // moves so that the arc ends exactly there.
        let e = Vector2::new(0.0005, 5.0);
        let a = arc(
            s,
            e,
            Circle::Centre(Vector2::zeros()),
            false,
            allowance(false, 0.001),
        )
        .unwrap();
        assert!(close(a.point(1.0), e) && close(a.point(0.0), s));
        assert!(geometry::norm(&a.center()) < 1e-3);
        // 0.05 mm off: refused (LinuxCNC's 0.028 mm and 0.1 % of r, 0.005 mm, are less).
        let e = arc(
            s,
            Vector2::new(0.0, 5.05),
            Circle::Centre(Vector2::zeros()),
            false,
            allowance(false, 0.001),
        );
        assert!(e.unwrap_err().contains("not on its circle"));
        // A full circle whose end misses its start by 0.001 mm radially: on the circle
        // within the tolerance, yet the centre that fits both ends is 5 mm away (it would
        // be a 0.0005 mm circle). 0.001 mm along the circle instead is a near-full turn.
        let near = Vector2::new(5.001, 0.0);
        let e = arc(
            s,
            near,
            Circle::Centre(Vector2::zeros()),
            true,
            allowance(false, 0.001),
        )
        .unwrap_err();
        assert!(e.contains("the circle through both ends runs"), "{e}");
        let along = arc(
            s,
            Vector2::new(5.0, 0.001),
            Circle::Centre(Vector2::zeros()),
            true,
            allowance(false, 0.001),
        );
        let along = along.unwrap();
        assert!((along.sweep() + 2.0 * PI).abs() < 3e-4 && (along.radius() - 5.0).abs() < 1e-6);
        assert!(arc(s, s, Circle::Radius(5.0), false, allowance(false, 0.001)).is_err());
        assert!(
            arc(s, -s, Circle::Radius(4.0), false, allowance(false, 0.001))
                .unwrap_err()
                .contains("too small")
        );
        assert!(arc(s, s, Circle::Centre(s), false, allowance(false, 0.001)).is_err());
    }
}
