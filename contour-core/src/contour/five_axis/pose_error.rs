//! The per-sample five-axis contour errors used for control (docs/design/five-axis.md §5.3): the
//! actual tool tip against its mapped reference segment — the error vector to the foot
//! point — and the actual tool axis against the reference axis at that foot point,
//! slerped between the segment's end axes.

use crate::geometry::{self, Vector};
use crate::kinematics::Pose;

use super::hmm::segment_fraction;
use crate::geometry::{angle_between, slerp};

/// Contour errors of one pose against one reference segment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseError {
    /// From the actual tip to the foot point on the segment, mm.
    pub tip: Vector<3>,
    /// Angle from the actual tool axis to the reference axis at the foot point, rad.
    pub orientation: f64,
    /// Rotation axis (unit) turning the actual axis onto the reference one, times the
    /// angle: the orientation part of the error 6-vector (zero when aligned).
    pub rotation: Vector<3>,
    /// Where the foot point lies on the segment, 0 … 1.
    pub fraction: f64,
}

/// The errors of `actual` against the segment from pose `r0` to pose `r1` (tips joined
/// by a straight line, axes by slerp). `None` when the segment's axes are opposite or an
/// input is not finite.
pub fn foot_point_error(r0: &Pose, r1: &Pose, actual: &Pose) -> Option<PoseError> {
    let finite = [r0.tip, r0.axis, r1.tip, r1.axis, actual.tip, actual.axis]
        .iter()
        .all(geometry::is_finite);
    if !finite {
        return None;
    }
    errors_at(
        r0,
        r1,
        segment_fraction(&actual.tip, &r0.tip, &r1.tip),
        actual,
    )
}

/// The errors of `actual` against the point a `fraction` of the way along the segment.
fn errors_at(r0: &Pose, r1: &Pose, fraction: f64, actual: &Pose) -> Option<PoseError> {
    let foot = r0.tip + (r1.tip - r0.tip) * fraction;
    let reference_axis = slerp(&r0.axis, &r1.axis, fraction)?;
    let actual_axis = geometry::unit(&actual.axis)?;
    let orientation = angle_between(&actual_axis, &reference_axis);
    let rotation = geometry::unit(&actual_axis.cross(&reference_axis))
        .map_or(Vector::zeros(), |axis| axis * orientation);
    Some(PoseError {
        tip: foot - actual.tip,
        orientation,
        rotation,
        fraction,
    })
}

/// [`foot_point_error`] with the foot placed by the path's tangents at the segment's ends
/// rather than by the chord alone: `before` and `after` are the reference poses next to
/// the segment (`None` at an end of the reference).
///
/// A reference sampled every Ts is a chord polygon of the path. Projected onto a chord, a
/// point off a bend lands up to d·θ/2 away from its foot on the curve (d its distance, θ
/// the chord's turn), and the slerped orientation there is off by that much travel — at
/// a 0.3 mm error on a 5 mm radius with 0.05 mm chords, about 20 µrad. Here the normal
/// plane is swept from the one at r0 to the one at r1 (tangents estimated from the
/// neighbours): the foot is where it passes through the actual tip, which on a circular
/// arc is the true foot. Falls back to the chord projection when no such place lies on
/// the segment.
pub fn foot_point_error_between(
    before: Option<&Pose>,
    r0: &Pose,
    r1: &Pose,
    after: Option<&Pose>,
    actual: &Pose,
) -> Option<PoseError> {
    let chord = foot_point_error(r0, r1, actual)?;
    match swept_fraction(before, r0, r1, after, &actual.tip) {
        Some(fraction) if (0.0..=1.0).contains(&fraction) => errors_at(r0, r1, fraction, actual),
        _ => Some(chord),
    }
}

/// Where the normal plane swept from r0 to r1 passes through `tip`, as a fraction of the
/// segment — unclamped: below 0 or above 1 the foot lies on a neighbouring segment.
/// `None` when a tangent is undefined or the plane never passes through the tip.
fn swept_fraction(
    before: Option<&Pose>,
    r0: &Pose,
    r1: &Pose,
    after: Option<&Pose>,
    tip: &Vector<3>,
) -> Option<f64> {
    let d = r1.tip - r0.tip;
    let t0 = geometry::unit(&before.map_or(d, |b| r1.tip - b.tip))?;
    let t1 = geometry::unit(&after.map_or(d, |a| a.tip - r0.tip))?;
    // g(f) = (P − r0 − f·d)·(t0 + f·(t1 − t0)) = c + b·f + a·f², zero at the foot.
    let w = tip - r0.tip;
    let dt = t1 - t0;
    let (a, b, c) = (-d.dot(&dt), w.dot(&dt) - d.dot(&t0), w.dot(&t0));
    let fraction = if a.abs() <= 1e-12 * b.abs() {
        -c / b
    } else {
        // The root that tends to −c/b as the bend vanishes (a → 0).
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            return None;
        }
        2.0 * c / (-b - b.signum() * disc.sqrt())
    };
    fraction.is_finite().then_some(fraction)
}

/// The per-sample errors of `actual` for control (docs/design/five-axis.md §5.3): from the
/// mapped segment `mapped`, the segment under the tip ([`nearest_segment_near`]) and on it
/// the foot of the swept normal plane ([`foot_point_error_between`], tangents from the
/// neighbouring points). Returns the segment, its errors and its unit chord direction;
/// `None` when `mapped` is not held or an input is not finite.
///
/// Off a bend, the tip may lie where the two chords meeting at a vertex are equally near
/// (both feet clamped to the vertex): the walk keeps whichever it reached first, and the
/// swept plane may pass through the tip on the other one. Its fraction then falls outside
/// 0 … 1, and the foot is taken on the neighbour it points to rather than at the vertex:
/// clamped there it would lie up to d·θ/2 off (d the error, θ the chord's turn), and the
/// orientation at it off by that much travel.
pub fn foot_near(
    segment: impl Fn(usize) -> Option<(Pose, Pose)>,
    mapped: usize,
    actual: &Pose,
) -> Option<(usize, PoseError, Vector<3>)> {
    // Segment i's errors at its swept foot, if the plane passes through the tip on it;
    // else the fraction where it does.
    let on = |i: usize| -> Option<Result<(PoseError, Vector<3>), f64>> {
        let (r0, r1) = segment(i)?;
        let before = i.checked_sub(1).and_then(&segment).map(|s| s.0);
        let after = i.checked_add(1).and_then(&segment).map(|s| s.1);
        let f = swept_fraction(before.as_ref(), &r0, &r1, after.as_ref(), &actual.tip)?;
        if !(0.0..=1.0).contains(&f) {
            return Some(Err(f));
        }
        errors_at(&r0, &r1, f, actual).map(|e| Ok((e, chord_direction(&r0, &r1))))
    };
    let j = nearest_segment_near(&segment, mapped, &actual.tip);
    let (r0, r1) = segment(j)?;
    // The chord's errors: the finiteness check, and the fallback.
    let chord = foot_point_error(&r0, &r1, actual)?;
    let neighbour = match on(j) {
        Some(Ok((e, tangent))) => return Some((j, e, tangent)),
        Some(Err(f)) if f < 0.0 => j.checked_sub(1),
        Some(Err(_)) => j.checked_add(1),
        None => None,
    };
    if let Some((i, Some(Ok((e, tangent))))) = neighbour.map(|i| (i, on(i))) {
        return Some((i, e, tangent));
    }
    Some((j, chord, chord_direction(&r0, &r1)))
}

/// The unit direction from r0's tip to r1's (zero for a point segment).
fn chord_direction(r0: &Pose, r1: &Pose) -> Vector<3> {
    geometry::unit(&(r1.tip - r0.tip)).unwrap_or_else(Vector::zeros)
}

/// The segment nearest the tip `tip` among the neighbours of the mapped segment
/// `mapped`: walks from it toward decreasing tip distance while the distance decreases
/// (`segment(i)` gives segment i's end poses, `None` outside what is held).
///
/// The mapping weighs the second point and the motion direction too, so with an
/// orientation error it may settle a few segments beside the one under the tip; the foot
/// point on that segment would be clamped to its end and overstate the tip error. The
/// mapping picks the branch, this picks the foot on it.
pub fn nearest_segment_near(
    segment: impl Fn(usize) -> Option<(Pose, Pose)>,
    mapped: usize,
    tip: &Vector<3>,
) -> usize {
    let distance = |i: usize| {
        segment(i).map_or(f64::INFINITY, |(a, b)| {
            super::hmm::segment_distance(tip, &a.tip, &b.tip)
        })
    };
    let (mut best, mut d) = (mapped, distance(mapped));
    for step in [1isize, -1] {
        while let Some(next) = best.checked_add_signed(step) {
            let dn = distance(next);
            if dn >= d {
                break;
            }
            (best, d) = (next, dn);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math;

    type V3 = Vector<3>;

    #[test]
    fn tip_and_orientation_errors_by_hand() {
        // Segment along x from the origin to (10, 0, 0), the axis turning from +z to +x.
        let r0 = Pose {
            tip: V3::zeros(),
            axis: V3::z(),
        };
        let r1 = Pose {
            tip: V3::new(10.0, 0.0, 0.0),
            axis: V3::x(),
        };
        // Actual tip above x = 2.5 by (0, 3, 4): foot at 1/4, tip error (0, −3, −4).
        // The reference axis there is 22.5° from z toward x; the actual axis is z.
        let actual = Pose {
            tip: V3::new(2.5, 3.0, 4.0),
            axis: V3::z(),
        };
        let e = foot_point_error(&r0, &r1, &actual).unwrap();
        assert!((e.fraction - 0.25).abs() < 1e-15);
        assert!((e.tip - V3::new(0.0, -3.0, -4.0)).amax() < 1e-15);
        let expected = std::f64::consts::FRAC_PI_8;
        assert!((e.orientation - expected).abs() < 1e-15);
        // Turning z toward x is a rotation about +y.
        assert!((e.rotation - V3::new(0.0, expected, 0.0)).amax() < 1e-15);
        // Beyond the segment's end the foot is the end point.
        let past = Pose {
            tip: V3::new(14.0, 0.0, 0.0),
            axis: V3::x(),
        };
        let e = foot_point_error(&r0, &r1, &past).unwrap();
        assert_eq!(
            (e.fraction, e.orientation, e.rotation),
            (1.0, 0.0, V3::zeros())
        );
        assert!((e.tip - V3::new(-4.0, 0.0, 0.0)).amax() < 1e-15);
        let nan = Pose {
            tip: V3::new(f64::NAN, 0.0, 0.0),
            axis: V3::z(),
        };
        assert!(foot_point_error(&r0, &r1, &nan).is_none());
    }

    #[test]
    fn on_a_circle_the_swept_normal_plane_finds_the_true_foot() {
        // Chords of 0.05 mm on a circle of radius 5 mm about the origin in z = 0, the tool
        // axis tilting in proportion to the arc angle; a point 0.3 mm inside or outside
        // the circle has its true foot on the radius through it.
        let (radius, step) = (5.0, 0.01);
        let pose = |phi: f64| Pose {
            tip: V3::new(radius * math::cos(phi), radius * math::sin(phi), 0.0),
            axis: V3::new(math::sin(0.5 * phi), 0.0, math::cos(0.5 * phi)),
        };
        let mut worst: (f64, f64) = (0.0, 0.0);
        for k in 1..=9 {
            let phi = step * (1.0 + k as f64 / 10.0);
            for offset in [-0.3, 0.3] {
                let actual = Pose {
                    tip: V3::new(math::cos(phi), math::sin(phi), 0.0) * (radius + offset),
                    axis: V3::z(),
                };
                let e = foot_point_error_between(
                    Some(&pose(0.0)),
                    &pose(step),
                    &pose(2.0 * step),
                    Some(&pose(3.0 * step)),
                    &actual,
                )
                .unwrap();
                let chord = foot_point_error(&pose(step), &pose(2.0 * step), &actual).unwrap();
                let true_orientation = angle_between(&V3::z(), &pose(phi).axis);
                worst.0 = worst.0.max((e.orientation - true_orientation).abs());
                worst.1 = worst.1.max((chord.orientation - true_orientation).abs());
                // The tip error is the distance to the chord point (within the chord's
                // sagitta of the true one).
                assert!((geometry::norm(&e.tip) - offset.abs()).abs() < 1e-4);
            }
        }
        // Exact up to the chord's own slerp vs the arc's angle (second order): 3e-8 rad,
        // where the chord projection is off by up to 0.5·0.3 mm·0.01 rad of travel.
        assert!(worst.0 < 1e-7, "{worst:?}");
        assert!(worst.1 > 1e-6, "{worst:?}");
    }

    #[test]
    fn beside_a_vertex_the_foot_is_taken_where_the_swept_plane_meets_the_tip() {
        // Chords of 0.03 rad on a circle of radius 1 mm, the tool axis tilting by half the
        // arc angle; tips 0.06 mm outside, across the vertex between segments 10 and 11
        // where both chords' nearest points are the vertex. Mapped from either side the
        // walk may stop on the chord the swept plane does not cross at the tip: clamped to
        // the vertex there, the foot is off by the tip's angle from it (up to 7.5·10⁻⁴ rad
        // here) and the orientation by half that; taken on the neighbour it is the true
        // foot.
        let (radius, step, offset) = (1.0, 0.03, 0.06);
        let pose = |phi: f64| Pose {
            tip: V3::new(math::cos(phi), math::sin(phi), 0.0) * radius,
            axis: V3::new(math::sin(0.5 * phi), 0.0, math::cos(0.5 * phi)),
        };
        let segment =
            |i: usize| (i < 30).then(|| (pose(step * i as f64), pose(step * (i + 1) as f64)));
        let (mut worst, mut worst_before) = (0.0f64, 0.0f64);
        for k in -50..=50 {
            let phi = step * (11.0 + k as f64 / 2000.0);
            let actual = Pose {
                tip: V3::new(math::cos(phi), math::sin(phi), 0.0) * (radius + offset),
                axis: V3::z(),
            };
            let truth = 0.5 * phi;
            for mapped in [8, 13] {
                let (_, e, _) = foot_near(segment, mapped, &actual).unwrap();
                worst = worst.max((e.orientation - truth).abs());
                assert!((geometry::norm(&e.tip) - offset).abs() < 2e-4);
                // The walk and the swept plane alone, as before.
                let j = nearest_segment_near(segment, mapped, &actual.tip);
                let (r0, r1) = segment(j).unwrap();
                let (before, after) = (segment(j - 1).unwrap().0, segment(j + 1).unwrap().1);
                let e = foot_point_error_between(Some(&before), &r0, &r1, Some(&after), &actual)
                    .unwrap();
                worst_before = worst_before.max((e.orientation - truth).abs());
            }
        }
        assert!(worst < 1e-7, "{worst}");
        assert!(worst_before > 2e-4, "{worst_before}");
    }

    #[test]
    fn the_foot_moves_to_the_segment_under_the_tip() {
        // Unit segments along x; a tip above x = 7.3 mapped to segment 3 (or 11) walks to
        // segment 7; segments outside 2 … 12 are not held.
        let pose = |x: f64| Pose {
            tip: V3::new(x, 0.0, 0.0),
            axis: V3::z(),
        };
        let held = |i: usize| {
            (2..=12)
                .contains(&i)
                .then(|| (pose(i as f64), pose(i as f64 + 1.0)))
        };
        let tip = V3::new(7.3, 0.2, 0.0);
        assert_eq!(nearest_segment_near(held, 3, &tip), 7);
        assert_eq!(nearest_segment_near(held, 11, &tip), 7);
        assert_eq!(nearest_segment_near(held, 7, &tip), 7);
        // Beyond what is held it stops at the edge.
        assert_eq!(nearest_segment_near(held, 10, &V3::new(15.0, 0.0, 0.0)), 12);
        assert_eq!(nearest_segment_near(held, 4, &V3::new(-3.0, 0.0, 0.0)), 2);
    }
}
