//! Exact contour error of a circular arc (docs/design/two-axis.md §4.1): counter-clockwise
//! ε = ‖P − O‖ − r, n = −(P − O)/‖P − O‖; clockwise both signs flip. Positive right of
//! travel. Koren–Lo's variable gains are the second-order expansion of this.
//!
//! Measured to the full circle, not the finite arc: a point lagging behind the arc start
//! or past its end still gets the radial error the controller should correct (the finite
//! arc distance is [`crate::contour::planar::true_error`]'s job). At the centre the error is −r
//! (CCW) and the normal is taken toward the reference point, so it is never NaN.

use crate::math;
use serde::{Deserialize, Serialize};

use super::local_circle;
use crate::contour::{ContourEstimate, ContourEstimator};
use crate::geometry::{self, Vector2};
use crate::path::CircularArc;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
enum ArcMode {
    /// Known circle.
    Fixed {
        center: Vector2,
        radius: f64,
        ccw: bool,
        /// Unit vector from the centre used when P and the reference are both at it.
        fallback: Vector2,
    },
    /// Circle through the last three distinct reference points (for non-arc paths).
    Tracking { pts: [Vector2; 3], count: u8 },
}

/// Arc/circle contour-error estimator.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ArcEstimator {
    mode: ArcMode,
}

/// Reference moves shorter than this (mm) are not new tracking points.
const MIN_MOVE: f64 = 1e-9;

/// Exact signed error of `p` against the circle (`center`, `radius`, direction `ccw`);
/// `toward` gives the normal's direction if `p` is exactly at the centre.
pub fn arc_error(
    p: Vector2,
    center: Vector2,
    radius: f64,
    ccw: bool,
    toward: Vector2,
) -> ContourEstimate {
    let d = p - center;
    let dist = geometry::norm(&d);
    let outward = if dist > 0.0 { d * (1.0 / dist) } else { toward };
    if ccw {
        ContourEstimate {
            error: dist - radius,
            normal: (outward * (-1.0)),
        }
    } else {
        ContourEstimate {
            error: radius - dist,
            normal: outward,
        }
    }
}

impl ArcEstimator {
    /// Exact error against the circle of `arc`.
    pub fn new(arc: &CircularArc) -> Self {
        let (s, c) = math::sincos(arc.start_angle());
        ArcEstimator {
            mode: ArcMode::Fixed {
                center: arc.center(),
                radius: arc.radius(),
                ccw: arc.is_ccw(),
                fallback: Vector2::new(c, s),
            },
        }
    }

    /// Circle through the last three distinct reference points, anchored at the newest
    /// (a straight reference gives the line error); zero until two points are known.
    pub fn tracking() -> Self {
        ArcEstimator {
            mode: ArcMode::Tracking {
                pts: [Vector2::zeros(); 3],
                count: 0,
            },
        }
    }
}

impl ContourEstimator for ArcEstimator {
    fn estimate(&mut self, reference: Vector2, actual: Vector2) -> ContourEstimate {
        match &mut self.mode {
            ArcMode::Fixed {
                center,
                radius,
                ccw,
                fallback,
            } => {
                let r = reference - (*center);
                let rl = geometry::norm(&r);
                let toward = if rl > 0.0 { r * (1.0 / rl) } else { *fallback };
                arc_error(actual, *center, *radius, *ccw, toward)
            }
            ArcMode::Tracking { pts, count } => {
                let n = usize::from(*count).min(3);
                if n == 0 || geometry::dist(&reference, &(pts[n - 1])) > MIN_MOVE {
                    if n == 3 {
                        pts.rotate_left(1);
                        pts[2] = reference;
                    } else {
                        pts[n] = reference;
                        *count = (n + 1) as u8;
                    }
                }
                match *count {
                    3 => local_circle::triple_error(actual, *pts, 2),
                    2 => {
                        let d = pts[1] - pts[0];
                        let dir = d * (1.0 / geometry::norm(&d));
                        super::line::line_error(actual, pts[1], dir)
                    }
                    _ => ContourEstimate::default(),
                }
            }
        }
    }

    fn reset(&mut self) {
        if let ArcMode::Tracking { count, .. } = &mut self.mode {
            *count = 0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn ccw_hand_cases() {
        // Centre (1, 2), r = 5, CCW quarter from angle 0 to π/2.
        let arc = CircularArc::new(Vector2::new(1.0, 2.0), 5.0, 0.0, PI / 2.0).unwrap();
        let mut e = ArcEstimator::new(&arc);
        let r = e.estimate(
            Vector2::new(6.0, 2.0),
            Vector2::new(1.0 + 3.0 * 0.6 * 2.0, 2.0 + 3.0 * 0.8 * 2.0),
        );
        // ‖P − O‖ = 6 → outside, right of CCW travel → +1; n points inward.
        assert!((r.error - 1.0).abs() < 1e-14);
        assert!((r.normal[0] + 0.6).abs() < 1e-15 && (r.normal[1] + 0.8).abs() < 1e-15);
        // Beyond the arc end (angle π): radial error to the full circle, −2.
        let r = e.estimate(Vector2::new(1.0, 7.0), Vector2::new(-2.0, 2.0));
        assert!((r.error + 2.0).abs() < 1e-14 && (r.normal[0] - 1.0).abs() < 1e-15);
        // Before the start (angle −π/2), on the circle: 0.
        let r = e.estimate(Vector2::new(6.0, 2.0), Vector2::new(1.0, -3.0));
        assert!(r.error.abs() < 1e-14);
        // At the centre: −r, normal from the reference direction, no NaN.
        let r = e.estimate(Vector2::new(1.0, 7.0), Vector2::new(1.0, 2.0));
        assert_eq!(r.error, -5.0);
        assert_eq!(r.normal, Vector2::new(0.0, -1.0));
        // Centre and reference both at the centre: start-angle direction.
        let r = e.estimate(Vector2::new(1.0, 2.0), Vector2::new(1.0, 2.0));
        assert_eq!(r.normal, Vector2::new(-1.0, 0.0));
    }

    #[test]
    fn cw_flips_signs() {
        let arc = CircularArc::new(Vector2::new(0.0, 0.0), 2.0, PI / 2.0, -PI).unwrap();
        let mut e = ArcEstimator::new(&arc);
        // Inside (1.5 from centre): right of clockwise travel → +0.5, n outward.
        let r = e.estimate(Vector2::new(0.0, 2.0), Vector2::new(0.0, 1.5));
        assert!((r.error - 0.5).abs() < 1e-15 && r.normal == Vector2::new(0.0, 1.0));
        let r = e.estimate(Vector2::new(0.0, 2.0), Vector2::new(3.0, 0.0));
        assert!((r.error + 1.0).abs() < 1e-15 && r.normal == Vector2::new(1.0, 0.0));
        let r = e.estimate(Vector2::new(2.0, 0.0), Vector2::new(0.0, 0.0));
        assert!((r.error - 2.0).abs() < 1e-15 && r.normal == Vector2::new(1.0, 0.0));
    }

    #[test]
    fn tracking_recovers_circle() {
        let mut e = ArcEstimator::tracking();
        let c = |t: f64| Vector2::new(10.0 * math::cos(t), 10.0 * math::sin(t));
        assert_eq!(e.estimate(c(0.0), Vector2::new(11.0, 0.0)).error, 0.0);
        e.estimate(c(0.01), Vector2::new(11.0, 0.0));
        let r = e.estimate(
            c(0.02),
            Vector2::new(11.0 * math::cos(0.02f64), 11.0 * math::sin(0.02f64)),
        );
        assert!((r.error - 1.0).abs() < 1e-9, "{}", r.error);
    }
}
