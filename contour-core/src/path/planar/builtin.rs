//! The built-in test paths, chosen by name by the path-interpolator FMU (docs/design/two-axis.md §4.6).
//!
//! - `circle`: the paper's x = 10 cos πt − 10, y = 10 sin πt, t ∈ [0, 2], as an analytic
//!   [`Arc`] (centre (−10, 0), r = 10, start angle 0, CCW full turn). Analytic rather than
//!   rational NURBS because its parameter speed is constant: at F = 10π mm/s the
//!   interpolator reproduces the paper's x(t), y(t) exactly (parameter u = t/2).
//! - `line`: (0, 0) → (40, 30), 50 mm.
//! - `arc`: clockwise half circle from (0, 0) about (−20, 0), r = 20, ending at (−40, 0).
//! - `infinity`, `trident`: the cubic NURBS fitted for this project, weights 1, clamped
//!   uniform knots, control points exactly as listed in docs/design/two-axis.md §4.6.

use std::f64::consts::{FRAC_1_SQRT_2, PI};

use super::{CircularArc, Line, Nurbs, Path, PathError};

/// Names accepted by [`by_name`].
pub const NAMES: [&str; 5] = ["circle", "line", "arc", "infinity", "trident"];

/// The built-in path called `name` (case-insensitive, surrounding blanks ignored).
pub fn by_name(name: &str) -> Result<Path, PathError> {
    match name.trim().to_ascii_lowercase().as_str() {
        "circle" => Ok(Path::Arc(circle())),
        "line" => Ok(Path::Line(line())),
        "arc" => Ok(Path::Arc(arc())),
        "infinity" => Ok(Path::Nurbs(infinity())),
        "trident" => Ok(Path::Nurbs(trident())),
        _ => Err(PathError::UnknownName(name.to_string())),
    }
}

/// The paper's circle, x = 10 cos πt − 10, y = 10 sin πt (starts and ends at the origin).
pub fn circle() -> CircularArc {
    CircularArc::new([-10.0, 0.0], 10.0, 0.0, 2.0 * PI).expect("constant arc is valid")
}

/// The ends of [`line()`], mm: the two-axis FMUs' `line.*` defaults too, so that `line`
/// names one path everywhere unless those parameters say otherwise.
pub const LINE_ENDS: [[f64; 2]; 2] = [[0.0, 0.0], [40.0, 30.0]];

/// [`arc()`] as its centre (mm), radius (mm), start angle and sweep (rad): the two-axis
/// FMUs' `arc.*` defaults too.
pub const ARC: ([f64; 2], f64, f64, f64) = ([-20.0, 0.0], 20.0, 0.0, -PI);

/// A 50 mm straight line (0, 0) → (40, 30).
pub fn line() -> Line {
    Line::new(LINE_ENDS[0], LINE_ENDS[1]).expect("constant line is valid")
}

/// A clockwise half circle (0, 0) → (−40, 0) about (−20, 0).
pub fn arc() -> CircularArc {
    let (centre, radius, start, sweep) = ARC;
    CircularArc::new(centre, radius, start, sweep).expect("constant arc is valid")
}

/// The "∞" path: cubic, 13 control points, knots 0,0,0,0,0.1,…,0.9,1,1,1,1.
pub fn infinity() -> Nurbs {
    const P: [[f64; 2]; 13] = [
        [0.0, 0.0],
        [4.5, 4.5],
        [18.1, 21.5],
        [41.5, 19.0],
        [42.1, -19.4],
        [17.2, -20.1],
        [0.0, 0.0],
        [-17.2, 20.1],
        [-42.1, 19.4],
        [-41.5, -19.0],
        [-18.1, -21.5],
        [-4.5, -4.5],
        [0.0, 0.0],
    ];
    cubic_uniform(&P)
}

/// The "trident" (three-leaf rose) path: cubic, 25 control points, interior knots k/22.
pub fn trident() -> Nurbs {
    const P: [[f64; 2]; 25] = [
        [40.2, -0.1],
        [39.2, 4.5],
        [30.9, 7.7],
        [19.0, 7.5],
        [7.0, 3.7],
        [-3.5, -1.3],
        [-13.4, -10.5],
        [-19.9, -17.8],
        [-25.5, -34.2],
        [-11.3, -36.1],
        [-4.8, -22.6],
        [-0.7, -12.6],
        [0.3, 0.0],
        [-0.7, 12.6],
        [-4.8, 22.6],
        [-11.3, 36.1],
        [-25.5, 34.2],
        [-19.9, 17.8],
        [-13.4, 10.5],
        [-3.5, 1.3],
        [7.0, -3.7],
        [19.0, -7.5],
        [30.9, -7.7],
        [39.2, -4.5],
        [40.2, 0.1],
    ];
    cubic_uniform(&P)
}

/// The exact unit circle of docs/design/two-axis.md §4.6 (degree 2, 9 control points on a square's corners
/// and edge midpoints, weights 1, √2/2, …; knots 0,0,0,¼,¼,½,½,¾,¾,1,1,1): the reference
/// case for the rational evaluator.
pub fn rational_unit_circle() -> Nurbs {
    let s = FRAC_1_SQRT_2;
    Nurbs::new(
        2,
        vec![0., 0., 0., 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1., 1., 1.],
        vec![
            [1., 0.],
            [1., 1.],
            [0., 1.],
            [-1., 1.],
            [-1., 0.],
            [-1., -1.],
            [0., -1.],
            [1., -1.],
            [1., 0.],
        ],
        Some(vec![1., s, 1., s, 1., s, 1., s, 1.]),
    )
    .expect("constant NURBS is valid")
}

fn cubic_uniform(p: &[[f64; 2]]) -> Nurbs {
    Nurbs::new(
        3,
        crate::path::clamped_uniform_knots(p.len(), 3),
        p.to_vec(),
        None,
    )
    .expect("constant NURBS is valid")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math;
    use crate::path::Curve;

    #[test]
    fn knots_as_designed() {
        let k = infinity().knots().to_vec();
        assert_eq!(k.len(), 17);
        assert_eq!(&k[..5], &[0.0, 0.0, 0.0, 0.0, 0.1]);
        assert!((k[12] - 0.9).abs() < 1e-15);
        let k = trident().knots().to_vec();
        assert_eq!(k.len(), 29);
        assert_eq!(k[4], 1.0 / 22.0);
    }

    #[test]
    fn shapes_have_designed_size() {
        // docs/design/two-axis.md §4.6: infinity length ≈ 241 mm, crosses itself at the origin.
        let inf = infinity();
        let l = inf.length();
        assert!((l - 241.0).abs() < 2.0, "infinity length {l}");
        assert!(inf.point(0.5)[0].abs() < 1e-14 && inf.point(0.5)[1].abs() < 1e-14);
        let c = circle();
        assert!((c.length() - 20.0 * PI).abs() < 1e-12);
        // Paper's circle at t = 0.5 (u = 0.25): (−10, 10).
        let p = c.point(0.25);
        assert!((p[0] + 10.0).abs() < 1e-12 && (p[1] - 10.0).abs() < 1e-12);
        assert!(by_name(" Trident ").is_ok());
        assert!(matches!(by_name("square"), Err(PathError::UnknownName(_))));
    }

    #[test]
    fn trident_min_radius_about_4_2() {
        let t = trident();
        let mut rmin = f64::INFINITY;
        for k in 0..=20000 {
            let e = t.eval(k as f64 / 20000.0);
            let sp = math::hypot(e.d1[0], e.d1[1]);
            let cr = (e.d1[0] * e.d2[1] - e.d1[1] * e.d2[0]).abs();
            rmin = rmin.min(sp.powi(3) / cr);
        }
        assert!((rmin - 4.2).abs() < 0.3, "trident min radius {rmin}");
    }
}
