//! What the offline evaluation measures a sample against (docs/design/five-axis.md §5.3a):
//! the CL points read as straight moves (the polyline, what CL data means) or as a smooth
//! curve through them. Either way the tip's foot is the nearest point of that one
//! reference and the tool axis is taken at the same point, so the tip and the orientation
//! error belong to one place.
//!
//! The controller's per-sample estimate (§5.3, [`foot_point_error_between`]) is neither:
//! it puts the foot on the chord at the fraction where the swept normal plane meets the
//! tip. Online that is cheap and good to 2 µrad; offline a CL file at 0.2 mm chords read
//! that way was off its own straight moves by tens of µrad.
//!
//! [`foot_point_error_between`]: super::pose_error::foot_point_error_between

use std::fmt;
use std::str::FromStr;

use super::pose_error::{foot_point_error, nearest_segment_near, PoseError};
use crate::geometry::{self, angle_between, slerp, Vector};
use crate::kinematics::Pose;

/// How the reference between consecutive poses is read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ReferenceShape {
    /// Straight tip moves between the points, the axis slerped along each by the fraction
    /// of its length (as `ToolPath` and the interpolators follow CL data).
    #[default]
    Straight,
    /// Per segment a cubic Hermite through its two points, tangent at each point to the
    /// chord between that point's neighbours (the chord itself at the reference's ends),
    /// each tangent as long as the segment's chord; the axis slerped by the same curve
    /// parameter. The tip curve is G1 through the points.
    Smooth,
}

impl ReferenceShape {
    /// The names `FromStr` takes.
    pub const NAMES: [&'static str; 2] = ["straight", "smooth"];

    /// The name of the shape.
    pub fn name(self) -> &'static str {
        match self {
            ReferenceShape::Straight => "straight",
            ReferenceShape::Smooth => "smooth",
        }
    }
}

impl fmt::Display for ReferenceShape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for ReferenceShape {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "straight" => Ok(ReferenceShape::Straight),
            "smooth" => Ok(ReferenceShape::Smooth),
            other => Err(format!(
                "unknown reference shape '{other}': expected {}",
                Self::NAMES.join(" or ")
            )),
        }
    }
}

/// The errors of `actual` against `reference` (unit axes, no two consecutive opposite)
/// read as `shape`, at the nearest point of the stretch around segment `mapped` (the
/// mapping picks the branch, this the foot on it). `None` for a non-finite pose or
/// fewer than two reference poses.
pub fn foot_error(
    shape: ReferenceShape,
    reference: &[Pose],
    mapped: usize,
    actual: &Pose,
) -> Option<PoseError> {
    let segments = reference.len().checked_sub(1).filter(|&m| m > 0)?;
    if !(geometry::is_finite(&actual.tip) && geometry::is_finite(&actual.axis)) {
        return None;
    }
    let segment = |i: usize| (i < segments).then(|| (reference[i], reference[i + 1]));
    let near = nearest_segment_near(segment, mapped.min(segments - 1), &actual.tip);
    match shape {
        // The nearest point of the polyline near the mapping is the projection on the
        // chord nearest the tip; foot_point_error slerps the axis at that fraction.
        ReferenceShape::Straight => {
            foot_point_error(&reference[near], &reference[near + 1], actual)
        }
        ReferenceShape::Smooth => {
            // The curve stays within its chords' sagitta (a µm at 0.2 mm chords): its
            // nearest piece is the chord's or a neighbour.
            let (j, s, point) = (near.saturating_sub(1)..=(near + 1).min(segments - 1))
                .map(|j| {
                    let piece = Piece::new(reference, j);
                    let (s, point) = piece.nearest(&actual.tip);
                    (j, s, point)
                })
                .min_by(|a, b| {
                    geometry::dist2(&a.2, &actual.tip)
                        .total_cmp(&geometry::dist2(&b.2, &actual.tip))
                })?;
            let reference_axis = slerp(&reference[j].axis, &reference[j + 1].axis, s)?;
            let actual_axis = geometry::unit(&actual.axis)?;
            let orientation = angle_between(&actual_axis, &reference_axis);
            let rotation = geometry::unit(&actual_axis.cross(&reference_axis))
                .map_or(Vector::zeros(), |axis| axis * orientation);
            Some(PoseError {
                tip: point - actual.tip,
                orientation,
                rotation,
                fraction: s,
            })
        }
    }
}

/// One segment of the smooth reference as a cubic a + b·s + c·s² + d·s³, s ∈ [0, 1].
struct Piece {
    a: Vector<3>,
    b: Vector<3>,
    c: Vector<3>,
    d: Vector<3>,
    /// The chord's projection of a point, for the start of the search.
    chord: (Vector<3>, Vector<3>),
}

impl Piece {
    /// Segment `j` of `reference` (j + 1 < len).
    fn new(reference: &[Pose], j: usize) -> Piece {
        let (p0, p1) = (reference[j].tip, reference[j + 1].tip);
        let chord = p1 - p0;
        let length = geometry::norm(&chord);
        let tangent = |i: usize| {
            let before = reference[i.saturating_sub(1)].tip;
            let after = reference[(i + 1).min(reference.len() - 1)].tip;
            geometry::unit(&(after - before)).map_or(chord, |t| t * length)
        };
        let (m0, m1) = (tangent(j), tangent(j + 1));
        Piece {
            a: p0,
            b: m0,
            c: (p1 - p0) * 3.0 - m0 * 2.0 - m1,
            d: (p0 - p1) * 2.0 + m0 + m1,
            chord: (p0, p1),
        }
    }

    /// Point, first and second derivative at `s`.
    fn eval(&self, s: f64) -> [Vector<3>; 3] {
        [
            self.a + (self.b + (self.c + self.d * s) * s) * s,
            self.b + (self.c * 2.0 + self.d * (3.0 * s)) * s,
            self.c * 2.0 + self.d * (6.0 * s),
        ]
    }

    /// The parameter and point of the piece nearest `p`: Newton on (C − p)·C' = 0 from
    /// the chord projection, kept in [0, 1], against both ends.
    fn nearest(&self, p: &Vector<3>) -> (f64, Vector<3>) {
        let mut s = super::hmm::segment_fraction(p, &self.chord.0, &self.chord.1);
        for _ in 0..50 {
            let [point, d1, d2] = self.eval(s);
            let w = point - p;
            let (g, h) = (w.dot(&d1), d1.dot(&d1) + w.dot(&d2));
            // Farther out than the curvature radius the distance is not convex here:
            // stop, the ends below still compete.
            if h.is_nan() || h <= 0.0 {
                break;
            }
            let next = (s - g / h).clamp(0.0, 1.0);
            let done = (next - s).abs() <= 1e-15;
            s = next;
            if done {
                break;
            }
        }
        [s, 0.0, 1.0]
            .into_iter()
            .map(|s| (s, self.eval(s)[0]))
            .min_by(|a, b| geometry::dist2(&a.1, p).total_cmp(&geometry::dist2(&b.1, p)))
            .expect("three candidates")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math;

    type V3 = Vector<3>;

    #[test]
    fn names_round_trip_and_straight_is_the_default() {
        for name in ReferenceShape::NAMES {
            assert_eq!(name.parse::<ReferenceShape>().unwrap().to_string(), name);
        }
        assert_eq!(ReferenceShape::default(), ReferenceShape::Straight);
        let e = "curved".parse::<ReferenceShape>().unwrap_err();
        assert_eq!(
            e,
            "unknown reference shape 'curved': expected straight or smooth"
        );
    }

    #[test]
    fn on_points_of_a_circle_the_smooth_piece_lies_on_the_circle_to_its_order() {
        // Points every 0.05 rad on a circle of radius 5 mm: the Hermite piece with tangents
        // from the neighbours and chord-long derivatives deviates from the circle by
        // O(θ⁴·r) (here 2.4e-7 mm), where the chord's sagitta is r·θ²/8 = 1.6 µm.
        let pose = |phi: f64| Pose {
            tip: V3::new(5.0 * math::cos(phi), 5.0 * math::sin(phi), 0.0),
            axis: V3::z(),
        };
        let reference: Vec<Pose> = (0..6).map(|i| pose(0.05 * i as f64)).collect();
        let piece = Piece::new(&reference, 2);
        let worst = (0..=100)
            .map(|k| (geometry::norm(&piece.eval(k as f64 / 100.0)[0]) - 5.0).abs())
            .fold(0.0, f64::max);
        assert!(worst < 3e-7, "{worst}");
        // A point 0.3 mm outside the circle above the piece's middle: its foot on the
        // piece is on the radius through it.
        let phi: f64 = 0.125;
        let outside = V3::new(math::cos(phi), math::sin(phi), 0.0) * 5.3;
        let (s, point) = piece.nearest(&outside);
        assert!((s - 0.5).abs() < 1e-6, "{s}");
        assert!((geometry::dist(&point, &outside) - 0.3).abs() < 3e-7);
        let e = foot_error(
            ReferenceShape::Smooth,
            &reference,
            2,
            &Pose {
                tip: outside,
                axis: V3::z(),
            },
        )
        .unwrap();
        assert!((geometry::norm(&e.tip) - 0.3).abs() < 3e-7);
        // The straight reading measures to the chord: 0.3 mm plus its sagitta there.
        let e = foot_error(
            ReferenceShape::Straight,
            &reference,
            2,
            &Pose {
                tip: outside,
                axis: V3::z(),
            },
        )
        .unwrap();
        let sagitta = 5.0 * (1.0 - math::cos(0.025f64));
        assert!((geometry::norm(&e.tip) - 0.3 - sagitta).abs() < 1e-9);
    }
}
