//! Exact contour error of a straight line (docs/design/two-axis.md §4.1, Koren's coupling gains):
//! ε = −ex·sin θ + ey·cos θ, n = (−sin θ, cos θ), with ex, ey the following errors
//! against a point of the line and θ the direction of travel. Positive right of travel.
//!
//! The error is measured to the infinite line (not the finite segment): a point that lags
//! behind the segment start or overshoots its end still gets the perpendicular error the
//! cross-coupled controller should correct.

use crate::math;
use serde::{Deserialize, Serialize};

use crate::contour::{ContourEstimate, ContourEstimator};
use crate::geometry::{self, Vector2};
use crate::path::Line;

/// How the line is known.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
enum LineMode {
    /// A fixed line through `point` with unit direction `dir`.
    Fixed { point: Vector2, dir: Vector2 },
    /// The line through the newest reference with the direction of the last reference
    /// move (for paths that are not a single line); `dir` is zero until the first move.
    Tracking { prev: Option<Vector2>, dir: Vector2 },
}

/// Line contour-error estimator.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LineEstimator {
    mode: LineMode,
}

/// Reference moves shorter than this (mm) do not redefine the tracking direction.
const MIN_MOVE: f64 = 1e-9;

/// Signed error of `p` against the line through `a` with unit direction `dir`.
pub fn line_error(p: Vector2, a: Vector2, dir: Vector2) -> ContourEstimate {
    ContourEstimate {
        error: -geometry::cross(&dir, &(p - a)),
        normal: geometry::perp(&dir),
    }
}

impl LineEstimator {
    /// Exact error against the given line.
    pub fn new(line: &Line) -> Self {
        LineEstimator {
            mode: LineMode::Fixed {
                point: line.start(),
                dir: line.direction(),
            },
        }
    }

    /// Exact error against the line through `point` at direction angle `theta` (rad).
    pub fn from_angle(point: Vector2, theta: f64) -> Self {
        let (s, c) = math::sincos(theta);
        LineEstimator {
            mode: LineMode::Fixed {
                point,
                dir: Vector2::new(c, s),
            },
        }
    }

    /// Line through the newest reference along the direction of the last reference move;
    /// zero error until the reference has moved once.
    pub fn tracking() -> Self {
        LineEstimator {
            mode: LineMode::Tracking {
                prev: None,
                dir: Vector2::zeros(),
            },
        }
    }
}

impl ContourEstimator for LineEstimator {
    fn estimate(&mut self, reference: Vector2, actual: Vector2) -> ContourEstimate {
        match &mut self.mode {
            LineMode::Fixed { point, dir } => line_error(actual, *point, *dir),
            LineMode::Tracking { prev, dir } => {
                if let Some(p) = *prev {
                    let d = reference - p;
                    let l = geometry::norm(&d);
                    if l > MIN_MOVE {
                        *dir = d * (1.0 / l);
                        *prev = Some(reference);
                    }
                } else {
                    *prev = Some(reference);
                }
                if *dir == Vector2::zeros() {
                    ContourEstimate::default()
                } else {
                    line_error(actual, reference, *dir)
                }
            }
        }
    }

    fn reset(&mut self) {
        if let LineMode::Tracking { prev, dir } = &mut self.mode {
            *prev = None;
            *dir = Vector2::zeros();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_computed_cases() {
        // 3-4-5 line from (1, 1) towards (4, 5): θ = atan2(4, 3), n = (−0.8, 0.6).
        let l = Line::new(Vector2::new(1.0, 1.0), Vector2::new(4.0, 5.0)).unwrap();
        let mut e = LineEstimator::new(&l);
        // P = (1,1) + 2·(0.8, −0.6): 2 mm right of travel.
        let r = e.estimate(Vector2::new(2.5, 3.0), Vector2::new(2.6, -0.2));
        assert!((r.error - 2.0).abs() < 1e-14, "{}", r.error);
        assert!((r.normal[0] + 0.8).abs() < 1e-15 && (r.normal[1] - 0.6).abs() < 1e-15);
        // Left of travel, beyond the end of the segment: still the perpendicular distance.
        let r = e.estimate(Vector2::new(4.0, 5.0), Vector2::new(7.0 - 0.8, 9.0 + 0.6));
        assert!((r.error + 1.0).abs() < 1e-14);
        // The formula of docs/design/two-axis.md §4.1 with following errors ex = xr − xp, ey = yr − yp.
        let (th, rr, p) = (0.3f64, Vector2::new(2.0, 1.0), Vector2::new(2.5, 0.2));
        let mut f = LineEstimator::from_angle(
            Vector2::new(2.0 - 3.0 * math::cos(th), 1.0 - 3.0 * math::sin(th)),
            th,
        );
        let (ex, ey) = (rr[0] - p[0], rr[1] - p[1]);
        let koren = -ex * math::sin(th) + ey * math::cos(th);
        assert!((f.estimate(rr, p).error - koren).abs() < 1e-14);
    }

    #[test]
    fn tracking_follows_reference_direction() {
        let mut e = LineEstimator::tracking();
        assert_eq!(
            e.estimate(Vector2::new(0.0, 0.0), Vector2::new(0.0, -1.0)),
            ContourEstimate::default()
        );
        // Moving −x: right of travel is +y.
        let r = e.estimate(Vector2::new(-0.1, 0.0), Vector2::new(-0.2, 0.5));
        assert!((r.error - 0.5).abs() < 1e-15 && r.normal == Vector2::new(0.0, -1.0));
        // Holding still keeps the direction.
        let r = e.estimate(Vector2::new(-0.1, 0.0), Vector2::new(-0.2, 0.5));
        assert!((r.error - 0.5).abs() < 1e-15);
        e.reset();
        assert_eq!(
            e.estimate(Vector2::new(0.0, 0.0), Vector2::new(0.0, -1.0))
                .error,
            0.0
        );
    }
}
