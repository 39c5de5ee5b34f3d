//! Mapping measured five-axis samples to reference segments with a hidden Markov model
//! solved by Viterbi (docs/design/five-axis.md §5.2) — the model's costs, the offline form over a
//! whole run, and the nearest-segment mapping it is compared with (the online form:
//! `hmm_online`; the windowed offline form: `run_evaluation`). The recursion, the
//! back-pointer table and the backtrack of all three forms are the shared core's
//! ([`viterbi`]); the offline form keeps every segment and sample.
//!
//! The reference is a polyline of tool tips R_j with a second polyline S_j = R_j + L·O_j
//! (the point L mm up the tool axis), so the tool orientation takes part in the match.
//! States are the segments j = [R_j, R_j+1] (and [S_j, S_j+1]); an observation is a
//! measured tip P_k and its second point Q_k. The cost of being in segment j at sample k
//! is
//!   c(k, j) = d(P_k, [R_j, R_j+1]) + d(Q_k, [S_j, S_j+1]) + w·∠(P_k − P_k−1, R_j+1 − R_j)
//! (distances to the segments, and how far the measured motion turns away from the
//! segment's direction, weighted by w mm/rad; no angle term while the tip stands still).
//! The mapping only moves forward, by at most `max_skip` segments per sample, and the
//! decoded mapping minimises the summed cost:
//!   C(k, j) = c(k, j) + min over j − max_skip ≤ i ≤ j of C(k − 1, i).

use super::viterbi::{self, BackTable};
use crate::geometry::Vector;
use crate::math;

/// Distance from `p` to the segment a–b. (A plain square root of the squared distance:
/// this runs band × samples times per mapping, and coordinates in mm are far from
/// where `hypot`'s care about overflow would matter.)
pub fn segment_distance(p: &Vector<3>, a: &Vector<3>, b: &Vector<3>) -> f64 {
    let off = a + (b - a) * segment_fraction(p, a, b) - p;
    off.dot(&off).sqrt()
}

/// Where the point of the segment a–b nearest `p` lies, 0 … 1 (0 for a point segment).
pub fn segment_fraction(p: &Vector<3>, a: &Vector<3>, b: &Vector<3>) -> f64 {
    let d = b - a;
    let len2 = d.dot(&d);
    if len2 > 0.0 {
        ((p - a).dot(&d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// The reference as the mapping sees it.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferencePolyline {
    /// Tool tips R_j, mm.
    pub tips: Vec<Vector<3>>,
    /// Second points S_j = R_j + L·O_j, mm.
    pub seconds: Vec<Vector<3>>,
}

impl ReferencePolyline {
    /// From tips and unit tool axes, with tool length `length` (mm).
    pub fn new(tips: &[Vector<3>], axes: &[Vector<3>], length: f64) -> Self {
        ReferencePolyline {
            tips: tips.to_vec(),
            seconds: tips.iter().zip(axes).map(|(p, o)| p + o * length).collect(),
        }
    }

    /// Number of segments.
    pub fn segments(&self) -> usize {
        self.tips.len().saturating_sub(1)
    }
}

/// Parameters of the mapping.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HmmParams {
    /// Largest forward move per sample, in segments (the paper's K = 1).
    pub max_skip: usize,
    /// Weight of the motion-direction angle, mm per rad.
    pub angle_weight: f64,
}

/// The cost of the segment with tips `r` and second points `s` for the observation
/// (`tip`, `second`) that moved by `motion` since the previous sample.
#[allow(clippy::too_many_arguments)]
pub fn segment_cost(
    params: &HmmParams,
    r: [&Vector<3>; 2],
    s: [&Vector<3>; 2],
    tip: &Vector<3>,
    second: &Vector<3>,
    motion: &Vector<3>,
) -> f64 {
    let turn = if *motion == Vector::<3>::zeros() {
        0.0
    } else {
        // angle_between with a plain square root (see segment_distance).
        let (direction, cross) = (r[1] - r[0], motion.cross(&(r[1] - r[0])));
        math::atan2(cross.dot(&cross).sqrt(), motion.dot(&direction))
    };
    segment_distance(tip, r[0], r[1])
        + segment_distance(second, s[0], s[1])
        + params.angle_weight * turn
}

/// The cost c(k, j) of segment `j` of `reference`.
pub fn state_cost(
    reference: &ReferencePolyline,
    params: &HmmParams,
    j: usize,
    tip: &Vector<3>,
    second: &Vector<3>,
    motion: &Vector<3>,
) -> f64 {
    let (r, s) = (&reference.tips, &reference.seconds);
    segment_cost(
        params,
        [&r[j], &r[j + 1]],
        [&s[j], &s[j + 1]],
        tip,
        second,
        motion,
    )
}

/// The nearest segment of every sample (tip plus second-point distance), for comparison.
pub fn nearest_segments(
    reference: &ReferencePolyline,
    tips: &[Vector<3>],
    seconds: &[Vector<3>],
) -> Vec<usize> {
    let none = HmmParams {
        max_skip: 0,
        angle_weight: 0.0,
    };
    tips.iter()
        .zip(seconds)
        .map(|(p, q)| {
            (0..reference.segments())
                .map(|j| (state_cost(reference, &none, j, p, q, &Vector::zeros()), j))
                .fold(
                    (f64::INFINITY, 0),
                    |best, c| if c.0 < best.0 { c } else { best },
                )
                .1
        })
        .collect()
}

/// The Viterbi mapping of a whole run: one segment per sample, nondecreasing, moving by
/// at most `max_skip` per sample, of least summed cost (ties to the lower segment). The
/// first sample may be in any segment. Empty for an empty run or a reference of fewer
/// than two points.
pub fn viterbi_offline(
    reference: &ReferencePolyline,
    params: &HmmParams,
    tips: &[Vector<3>],
    seconds: &[Vector<3>],
) -> Vec<usize> {
    let m = reference.segments();
    let n = tips.len().min(seconds.len());
    if m == 0 || n == 0 {
        return Vec::new();
    }
    let mut cost = vec![0.0; m];
    let mut next = vec![0.0; m];
    // Full indices: the offline form allows any skip.
    let mut back = BackTable::<usize>::with_capacity(m, n);
    for k in 0..n {
        let motion = if k == 0 {
            Vector::zeros()
        } else {
            tips[k] - tips[k - 1]
        };
        let c = |j| state_cost(reference, params, j, &tips[k], &seconds[k], &motion);
        let mut row = back.push_row(0);
        if k == 0 {
            viterbi::start(0..m, c, |j, cj, _| next[j] = cj);
        } else {
            let previous = |i: usize| cost[i];
            let score = |j, best| best + c(j);
            viterbi::step(params.max_skip, 0..m, 0..m, previous, score, |j, cj, i| {
                next[j] = cj;
                row.set(j, i);
            });
        }
        std::mem::swap(&mut cost, &mut next);
    }
    let last = viterbi::best_state(0..m, |j| cost[j]);
    let mut path = vec![0; n];
    let predecessor = |k, j| back.predecessor(k, j);
    viterbi::backtrack(n - 1, last, 0, predecessor, |k, j| path[k] = j);
    path
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{self, angle_between};

    type V3 = Vector<3>;

    /// Every admissible mapping of a small run, with its summed cost (the brute force the
    /// Viterbi recursion must agree with).
    fn brute_force(
        reference: &ReferencePolyline,
        params: &HmmParams,
        tips: &[V3],
        seconds: &[V3],
    ) -> (f64, Vec<usize>) {
        let m = reference.segments();
        let mut best = (f64::INFINITY, Vec::new());
        let mut path = vec![0; tips.len()];
        fn walk(
            k: usize,
            path: &mut Vec<usize>,
            total: f64,
            ctx: &(&ReferencePolyline, &HmmParams, &[V3], &[V3], usize),
            best: &mut (f64, Vec<usize>),
        ) {
            let (reference, params, tips, seconds, m) = *ctx;
            if k == tips.len() {
                if total < best.0 {
                    *best = (total, path.clone());
                }
                return;
            }
            let (lo, hi) = if k == 0 {
                (0, m - 1)
            } else {
                (path[k - 1], (path[k - 1] + params.max_skip).min(m - 1))
            };
            let motion = if k == 0 {
                V3::zeros()
            } else {
                tips[k] - tips[k - 1]
            };
            for j in lo..=hi {
                path[k] = j;
                let c = state_cost(reference, params, j, &tips[k], &seconds[k], &motion);
                walk(k + 1, path, total + c, ctx, best);
            }
        }
        walk(
            0,
            &mut path,
            0.0,
            &(reference, params, tips, seconds, m),
            &mut best,
        );
        best
    }

    fn total(
        reference: &ReferencePolyline,
        params: &HmmParams,
        tips: &[V3],
        seconds: &[V3],
        path: &[usize],
    ) -> f64 {
        (0..tips.len())
            .map(|k| {
                let motion = if k == 0 {
                    V3::zeros()
                } else {
                    tips[k] - tips[k - 1]
                };
                state_cost(reference, params, path[k], &tips[k], &seconds[k], &motion)
            })
            .sum()
    }

    #[test]
    fn distances_and_angles_by_hand() {
        let (a, b) = (V3::new(0.0, 0.0, 0.0), V3::new(10.0, 0.0, 0.0));
        assert_eq!(segment_distance(&V3::new(5.0, 3.0, 4.0), &a, &b), 5.0);
        assert_eq!(segment_distance(&V3::new(13.0, 4.0, 0.0), &a, &b), 5.0);
        assert_eq!(segment_distance(&V3::new(-3.0, 0.0, 4.0), &a, &a), 5.0);
        let right = angle_between(&V3::x(), &V3::y());
        assert!((right - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert_eq!(angle_between(&V3::x(), &V3::zeros()), 0.0);
    }

    #[test]
    fn viterbi_equals_the_brute_force_optimum() {
        // A zig-zag reference, a run that wanders near it; every mapping of 7 samples over
        // 6 segments with skips up to 2 is tried.
        let tips: Vec<V3> = (0..7)
            .map(|j| V3::new(j as f64 * 2.0, if j % 2 == 0 { 0.0 } else { 1.5 }, 0.0))
            .collect();
        let axes = vec![V3::z(); tips.len()];
        let reference = ReferencePolyline::new(&tips, &axes, 100.0);
        let run: Vec<V3> = [0.2, 1.1, 2.9, 4.2, 6.8, 8.1, 11.7]
            .iter()
            .enumerate()
            .map(|(k, &x)| V3::new(x, 0.7 + 0.1 * k as f64, 0.3))
            .collect();
        let seconds: Vec<V3> = run.iter().map(|p| p + V3::new(0.05, 0.0, 100.0)).collect();
        for params in [
            HmmParams {
                max_skip: 1,
                angle_weight: 0.0,
            },
            HmmParams {
                max_skip: 2,
                angle_weight: 0.5,
            },
            HmmParams {
                max_skip: 1,
                angle_weight: 3.0,
            },
        ] {
            let decoded = viterbi_offline(&reference, &params, &run, &seconds);
            let (best, _) = brute_force(&reference, &params, &run, &seconds);
            let got = total(&reference, &params, &run, &seconds, &decoded);
            assert!((got - best).abs() < 1e-12, "{params:?}: {got} vs {best}");
            assert!(decoded
                .windows(2)
                .all(|w| w[0] <= w[1] && w[1] - w[0] <= params.max_skip));
        }
    }

    #[test]
    fn at_a_crossing_orientation_and_order_pick_the_right_branch() {
        // A figure eight whose two branches cross at the origin (samples 0 and 20) with
        // different tool axes: the tool leans +x on the first loop and −x on the second.
        let lean = |j: usize| if j < 20 { 0.3 } else { -0.3 };
        let tips: Vec<V3> = (0..=40)
            .map(|j| {
                let t = j as f64 / 40.0 * std::f64::consts::TAU;
                V3::new(20.0 * math::sin(t), 10.0 * math::sin(2.0 * t), 0.0)
            })
            .collect();
        let axes: Vec<V3> = (0..=40)
            .map(|j| geometry::unit(&V3::new(lean(j), 0.0, 1.0)).unwrap())
            .collect();
        let run: Vec<V3> = tips.iter().map(|p| p + V3::new(0.0, 0.05, 0.0)).collect();
        let seconds: Vec<V3> = run.iter().zip(&axes).map(|(p, o)| p + o * 100.0).collect();
        let crossing = 20;

        // The tip alone: at the crossing the first segment is as near as the right one,
        // and the nearest-segment mapping takes the wrong branch.
        let tip_only = ReferencePolyline::new(&tips, &axes, 0.0);
        let nearest = nearest_segments(&tip_only, &run[..40], &run[..40]);
        assert!(
            nearest[crossing] < 2,
            "tip-only nearest: {}",
            nearest[crossing]
        );

        // With the second point the nearest segment is right, and the Viterbi mapping
        // (order of travel, max_skip 1) is right everywhere.
        let reference = ReferencePolyline::new(&tips, &axes, 100.0);
        let nearest = nearest_segments(&reference, &run[..40], &seconds[..40]);
        assert!(
            (19..=20).contains(&nearest[crossing]),
            "{}",
            nearest[crossing]
        );
        let params = HmmParams {
            max_skip: 1,
            angle_weight: 1.0,
        };
        let decoded = viterbi_offline(&reference, &params, &run[..40], &seconds[..40]);
        for (k, &j) in decoded.iter().enumerate() {
            assert!(j == k || j + 1 == k, "sample {k} -> segment {j}");
        }
        // Order alone also resolves it: the tip-only Viterbi mapping cannot jump back.
        let decoded = viterbi_offline(&tip_only, &params, &run[..40], &run[..40]);
        assert!(
            (19..=20).contains(&decoded[crossing]),
            "{}",
            decoded[crossing]
        );
    }
}
