//! The circular test of ISO 230-4 (docs/design/two-axis.md §4.11): what a ballbar reports
//! of a machine's circle, computed from a run of the XY table.
//!
//! - **Least-squares circle (LSC)**: the centre c and radius R that minimise
//!   Σ (|pᵢ − c| − R)² over the measured points (the geometric fit; started from the
//!   algebraic one, then Gauss–Newton).
//! - **Circular deviation G**: the least radial separation of two circles about the LSC
//!   centre that enclose the path: max |pᵢ − c| − min |pᵢ − c|.
//! - **Bidirectional circular deviation G(b)**: the same for a clockwise and a
//!   counter-clockwise run together, about the LSC of both.
//! - **Radial deviation F**: the path's deviation from the nominal circle (programmed
//!   centre and radius, where a ballbar's pivots are set): F_max = max (|pᵢ − c₀| − R₀),
//!   F_min = min (|pᵢ − c₀| − R₀).

use contour_core::geometry::{norm, Vector2};
use contour_core::math;
use nalgebra::{Matrix3, Vector3};

/// A circle in the plane, mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle {
    pub centre: Vector2,
    pub radius: f64,
}

impl Circle {
    /// How far `p` lies outside the circle (< 0 inside), mm.
    pub fn deviation(&self, p: &Vector2) -> f64 {
        norm(&(p - self.centre)) - self.radius
    }

    /// The angle of `p` seen from the centre, rad.
    pub fn angle(&self, p: &Vector2) -> f64 {
        let d = p - self.centre;
        math::atan2(d.y, d.x)
    }
}

/// What ISO 230-4 reports of one run (or of two runs together), mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CircularFigures {
    /// The least-squares circle of the points.
    pub lsc: Circle,
    /// G: max − min distance from the LSC centre.
    pub circular_deviation: f64,
    /// F_min, F_max: the least and greatest distance from the nominal circle (outside > 0).
    pub radial_deviation: (f64, f64),
}

/// Solves the 3 × 3 system `a·x = b` by LU with partial pivoting; `None` when it is
/// singular (the points are collinear or too few).
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let matrix = Matrix3::from_fn(|i, j| a[i][j]);
    let scale = matrix.amax();
    let lu = matrix.lu();
    // A pivot this small against the entries: no unique solution in f64.
    let u = lu.u();
    if (0..3).any(|i| u[(i, i)].abs() <= 1e-14 * scale) {
        return None;
    }
    let x = lu.solve(&Vector3::from(b))?;
    Some([x[0], x[1], x[2]])
}

/// The least-squares circle of `points` (at least three, not on one line).
pub fn least_squares_circle(points: &[Vector2]) -> Result<Circle, String> {
    if points.len() < 3 {
        return Err(format!(
            "a circle needs at least 3 points, got {}",
            points.len()
        ));
    }
    // Work about the mean, for conditioning.
    let mean = points.iter().sum::<Vector2>() / points.len() as f64;
    // Algebraic fit: x² + y² = a·x + b·y + c in the least-squares sense.
    let (mut normal, mut rhs) = ([[0.0; 3]; 3], [0.0; 3]);
    for p in points {
        let q = p - mean;
        let row = [q.x, q.y, 1.0];
        let z = q.norm_squared();
        for i in 0..3 {
            for j in 0..3 {
                normal[i][j] += row[i] * row[j];
            }
            rhs[i] += row[i] * z;
        }
    }
    let [a, b, c] = solve3(normal, rhs).ok_or("the points lie on a line: no circle fits")?;
    let mut centre = Vector2::new(a / 2.0, b / 2.0);
    let mut radius = (c + centre.norm_squared()).sqrt();
    // Geometric fit: Gauss–Newton on rᵢ = |qᵢ − c| − R.
    for _ in 0..100 {
        let (mut jtj, mut jtr) = ([[0.0; 3]; 3], [0.0; 3]);
        for p in points {
            let d = p - mean - centre;
            let distance = norm(&d);
            if distance == 0.0 {
                continue;
            }
            let row = [-d.x / distance, -d.y / distance, -1.0];
            let residual = distance - radius;
            for i in 0..3 {
                for j in 0..3 {
                    jtj[i][j] += row[i] * row[j];
                }
                jtr[i] -= row[i] * residual;
            }
        }
        let Some(step) = solve3(jtj, jtr) else { break };
        centre += Vector2::new(step[0], step[1]);
        radius += step[2];
        if step.iter().all(|s| s.abs() <= 1e-15 * (1.0 + radius)) {
            break;
        }
    }
    if !(radius.is_finite() && radius > 0.0) {
        return Err("no circle fits the points".into());
    }
    Ok(Circle {
        centre: centre + mean,
        radius,
    })
}

/// G, F and the LSC of `points` (one run, or two runs' points together for G(b)).
pub fn figures(points: &[Vector2], nominal: &Circle) -> Result<CircularFigures, String> {
    let lsc = least_squares_circle(points)?;
    let extremes = |circle: &Circle| {
        points
            .iter()
            .map(|p| circle.deviation(p))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| {
                (lo.min(r), hi.max(r))
            })
    };
    let (lo, hi) = extremes(&lsc);
    Ok(CircularFigures {
        lsc,
        circular_deviation: hi - lo,
        radial_deviation: extremes(nominal),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn on(circle: &Circle, deviation: impl Fn(f64) -> f64, n: usize) -> Vec<Vector2> {
        (0..n)
            .map(|k| {
                let t = 2.0 * std::f64::consts::PI * k as f64 / n as f64;
                circle.centre
                    + (circle.radius + deviation(t)) * Vector2::new(math::cos(t), math::sin(t))
            })
            .collect()
    }

    #[test]
    fn an_exact_circle_is_its_own_least_squares_circle() {
        let circle = Circle {
            centre: Vector2::new(-10.003, 0.002),
            radius: 9.997,
        };
        let nominal = Circle {
            centre: Vector2::new(-10.0, 0.0),
            radius: 10.0,
        };
        let f = figures(&on(&circle, |_| 0.0, 3600), &nominal).unwrap();
        assert!(norm(&(f.lsc.centre - circle.centre)) < 1e-12);
        assert!((f.lsc.radius - circle.radius).abs() < 1e-12);
        assert!(f.circular_deviation < 1e-12);
        // About the nominal centre the offset circle swings by ±|offset| around
        // R − R₀ = −3 µm: |offset| = √(3² + 2²) µm (sampled every 0.1°: the extremes
        // missed by at most |offset|·(0.05°)²/2 = 1.4e-9 mm).
        let offset = (0.003f64.powi(2) + 0.002f64.powi(2)).sqrt();
        let (lo, hi) = f.radial_deviation;
        assert!((lo - (-0.003 - offset)).abs() < 1e-8, "{lo}");
        assert!((hi - (-0.003 + offset)).abs() < 1e-8, "{hi}");
    }

    #[test]
    fn an_oval_path_has_the_peak_to_valley_of_its_radius_as_g() {
        // r(θ) = R + 4 µm·cos 2θ (two axes with mismatched gains): the LSC keeps the
        // centre and radius, and G = 8 µm.
        let circle = Circle {
            centre: Vector2::new(1.0, 2.0),
            radius: 25.0,
        };
        let f = figures(&on(&circle, |t| 0.004 * math::cos(2.0 * t), 720), &circle).unwrap();
        assert!(norm(&(f.lsc.centre - circle.centre)) < 1e-9);
        assert!((f.lsc.radius - 25.0).abs() < 1e-9);
        assert!((f.circular_deviation - 0.008).abs() < 1e-9);
        assert!((f.radial_deviation.0 + 0.004).abs() < 1e-9);
        assert!((f.radial_deviation.1 - 0.004).abs() < 1e-9);
    }

    #[test]
    fn collinear_or_too_few_points_are_refused() {
        let line: Vec<Vector2> = (0..10).map(|k| Vector2::new(k as f64, 2.0)).collect();
        assert!(least_squares_circle(&line).unwrap_err().contains("line"));
        assert!(least_squares_circle(&line[..2])
            .unwrap_err()
            .contains("3 points"));
    }
}
