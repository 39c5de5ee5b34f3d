//! The limits of a five-axis feed plan at the nodes of its joint path
//! (docs/design/five-axis.md §5.3b): every joint's velocity and acceleration, and the tip's
//! feed and acceleration, mapped onto the path's arc length as the jerk filter will see
//! them.

use std::cell::Cell;

use super::joint_path::JointPath;
use crate::geometry::{self, Vector};
use crate::kinematics::Joints;
use crate::limits::{JointLimits, PathLimits};
use crate::path::FeedConstraints;

/// The limits of the feed plan at the nodes of a joint path.
///
/// Between nodes every joint moves linearly in s. A sample's acceleration after the two
/// moving averages (T1 = m1·Ts, then T2 = m2·Ts) is exactly
/// [(r_k − r_{k−m2})/T2 − (r_{k−m1} − r_{k−m1−m2})/T2]/T1 of the raw samples r: the
/// change, over T1, of the raw velocity averaged over T2. At a speed v that is the
/// second difference of the joint's path over the stretches ℓ1 = v·T1 and ℓ2 = v·T2,
/// times v²/(ℓ1·ℓ2): v²·q'' on a smooth path, v·Δg/T1 at a lone kink, and at a jog
/// shorter than ℓ2 (two kinks close together, which a difference of slopes across ℓ1
/// does not see) v·δ/(T1·T2). That difference is piecewise linear in the window's
/// place, so its extremes are where a window's edge meets a node: each node is judged
/// at the places where its own kink meets an edge. The tip's acceleration is the same
/// vector difference of its positions. Without the filter (the optimum the plan is
/// compared with) T2 is the samples' own Ts.
pub(super) struct Constraints<'a> {
    path: &'a JointPath,
    joints: &'a JointLimits,
    limits: &'a PathLimits,
    /// The filter's first average T1, s (Ts without a filter).
    spread: f64,
    /// The filter's second average T2, s (Ts without it).
    spread2: f64,
    /// The sum of the two averages' lengths squared, s² (0 without a filter): a curve
    /// of curvature κ is drawn in by v²·κ·Σ T²/24.
    smoothing2: f64,
    /// How far, as a time, the filter's samples reach on average beyond a corner
    /// (E|τ| of its kernel: T1/4 + T2²/(12·T1); 0 without a filter): at speed v a
    /// lone kink of angle θ is cut by v·E|τ|·sin θ/2.
    corner_reach: f64,
    /// Per node: the sine of the tip path's turn there.
    kink: Vec<f64>,
    /// Per piece between nodes: each joint's slope.
    slope: Vec<Joints>,
    /// Per node: how much of the speed squared and of the acceleration the samples
    /// allowed.
    speed_scale: &'a [f64],
    accel_scale: &'a [f64],
    /// Per node: the largest speed at its acceleration scale, once found (NaN before);
    /// kept from round to round, since a round changes few nodes' scales.
    top_speed: &'a [Cell<f64>],
    /// The last node, speed and bends found.
    last_bends: Cell<Option<(usize, f64, Bends)>>,
    /// The evaluations of the limits the plan may still make (`WORK_PER_SAMPLE`); at 0
    /// the rest of this feed plan sees only the slopes, and the plan is refused.
    work: &'a Cell<u64>,
}

impl<'a> Constraints<'a> {
    pub(super) fn new(
        path: &'a JointPath,
        joints: &'a JointLimits,
        limits: &'a PathLimits,
        filter: (usize, usize, f64),
        scales: (&'a [f64], &'a [f64]),
        top_speed: &'a [Cell<f64>],
        work: &'a Cell<u64>,
    ) -> Self {
        let (m1, m2, ts) = filter;
        let count = path.s.len();
        // m2 = 0: the same spread without the filter's deviation (and a 1 + 1 filter is
        // no filter).
        let smooths = m2 > 0 && m1 + m2 > 2;
        let (t1, t2) = (m1 as f64 * ts, m2 as f64 * ts);
        Constraints {
            path,
            joints,
            limits,
            spread: m1 as f64 * ts,
            spread2: m2.max(1) as f64 * ts,
            smoothing2: if smooths {
                ((m1 * m1 + m2 * m2) as f64) * ts * ts
            } else {
                0.0
            },
            corner_reach: if smooths {
                t1 / 4.0 + t2 * t2 / (12.0 * t1)
            } else {
                0.0
            },
            kink: (0..count)
                .map(|n| tip_turn(path, n).map_or(0.0, |(b, a)| geometry::norm(&b.cross(&a))))
                .collect(),
            slope: (0..count - 1)
                .map(|n| (path.joints[n + 1] - path.joints[n]) / (path.s[n + 1] - path.s[n]))
                .collect(),
            speed_scale: scales.0,
            accel_scale: scales.1,
            top_speed,
            last_bends: Cell::new(None),
            work,
        }
    }

    /// The joints and the tip at `s` (mm along the path), linear between nodes and
    /// beyond the ends: a window reaching past an end sees no kink there (the speed,
    /// not the path, comes to rest, and the tangential term holds the acceleration).
    /// Searched outwards from node `near`: a window is a few nodes wide, so this costs
    /// O(log of the nodes it spans) however long the path.
    fn at(&self, s: f64, near: usize) -> (Joints, Vector<3>) {
        let nodes = &self.path.s;
        let last = nodes.len() - 1;
        let near = near.min(last);
        // The last node at or before s (0 before the path).
        let below = if nodes[near] <= s {
            let (mut lo, mut step) = (near, 1);
            loop {
                let hi = (lo + step).min(last);
                if hi == lo || nodes[hi] > s {
                    break lo + nodes[lo..=hi].partition_point(|&x| x <= s) - 1;
                }
                lo = hi;
                step *= 2;
            }
        } else {
            let (mut hi, mut step) = (near, 1);
            loop {
                let lo = hi.saturating_sub(step);
                if lo == hi || nodes[lo] <= s {
                    break (lo + nodes[lo..=hi].partition_point(|&x| x <= s)).saturating_sub(1);
                }
                hi = lo;
                step *= 2;
            }
        };
        let m = below.min(last - 1);
        let (joints, poses) = (&self.path.joints, &self.path.poses);
        let f = (s - nodes[m]) / (nodes[m + 1] - nodes[m]);
        (
            joints[m] + (joints[m + 1] - joints[m]) * f,
            poses[m].tip + (poses[m + 1].tip - poses[m].tip) * f,
        )
    }

    /// At node `n` and speed `v`: each joint's slope (the larger of the pieces beside
    /// it); the least and greatest of its accelerations per speed squared over the
    /// windows that meet the node (see the type's text); and the largest such
    /// acceleration of the tip, its curvature as the samples see it (none at rest).
    fn bends(&self, n: usize, v: f64) -> Bends {
        // The feed planner asks a node again at the speed it just settled on.
        if let Some((m, w, bends)) = self.last_bends.get() {
            if (m, w) == (n, v) {
                return bends;
            }
        }
        let bends = self.bends_now(n, v);
        self.last_bends.set(Some((n, v, bends)));
        bends
    }

    /// [`Constraints::bends`] without the cache.
    fn bends_now(&self, n: usize, v: f64) -> Bends {
        let last = self.slope.len() - 1;
        let (g_in, g_out) = (
            self.slope[n.saturating_sub(1).min(last)],
            self.slope[n.min(last)],
        );
        let slope = g_in.zip_map(&g_out, |a, b| if a.abs() > b.abs() { a } else { b });
        let (l1, l2) = (v * self.spread, v * self.spread2);
        let mut bends = Bends {
            slope,
            least: Joints::zeros(),
            greatest: Joints::zeros(),
            curvature: 0.0,
        };
        if n == 0 || n > last || l1.is_nan() || l1 <= 0.0 || l2 <= 0.0 || self.work.get() == 0 {
            return bends;
        }
        self.work.set(self.work.get() - 1);
        let (a, b) = (0.5 * l1, 0.5 * l2);
        let (centre, area) = (self.path.s[n], l1 * l2);
        for place in [0.0, a - b, b - a, a + b, -a - b] {
            let c = centre + place;
            let (q1, t1) = self.at(c + a + b, n);
            let (q2, t2) = self.at(c + a - b, n);
            let (q3, t3) = self.at(c - a + b, n);
            let (q4, t4) = self.at(c - a - b, n);
            let bend = (q1 - q2 - q3 + q4) / area;
            bends.least = bends.least.inf(&bend);
            bends.greatest = bends.greatest.sup(&bend);
            let tip = (t1 - t2 - t3 + t4) / area;
            bends.curvature = bends.curvature.max(geometry::norm(&tip));
        }
        bends
    }

    /// The largest speed at node `n` (mm/s) its limits allow at zero path acceleration.
    fn top_speed_at(&self, n: usize) -> f64 {
        // The node is on both pieces beside it.
        let feed = &self.path.feed;
        let mut top = feed[n].min(feed[n.saturating_sub(1)]);
        // The slopes on both sides: the speed is the same at the node.
        let slope = self.bends(n, 0.0).slope;
        for i in 0..5 {
            if slope[i] != 0.0 {
                top = top.min(self.joints.velocity[i] / slope[i].abs());
            }
        }
        let scale = self.accel_scale[n];
        let accel = self.limits.accel * scale;
        let tolerance = self.limits.tolerance;
        Self::largest_speed(top, |v| {
            let bends = self.bends(n, v);
            let x = v * v;
            let joints_ok = (0..5).all(|i| {
                let bend = bends.least[i].abs().max(bends.greatest[i].abs());
                bend * x <= self.joints.acceleration[i] * scale
            });
            let turn = bends.curvature;
            // A curve drawn in, or a corner cut.
            let deviation =
                (x * turn * self.smoothing2 / 24.0).max(v * self.corner_reach * self.kink[n] / 2.0);
            joints_ok && turn * x <= accel && deviation <= tolerance
        })
    }

    /// The largest speed at node `n` (mm/s) at which `limit(v) ≥ 0` holds, by bisection
    /// below `top` (the constraints of a node grow with the speed).
    fn largest_speed(top: f64, ok: impl Fn(f64) -> bool) -> f64 {
        if ok(top) {
            return top;
        }
        let (mut lo, mut hi) = (0.0, top);
        // To 2⁻²⁴ of the top speed: well inside what the samples are checked to.
        for _ in 0..24 {
            let mid = 0.5 * (lo + hi);
            if ok(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }
}

impl FeedConstraints for Constraints<'_> {
    fn nodes(&self) -> &[f64] {
        &self.path.s
    }

    fn speed2_max(&self, n: usize) -> f64 {
        let known = self.top_speed[n].get();
        let v = if known.is_nan() {
            let v = self.top_speed_at(n);
            self.top_speed[n].set(v);
            v
        } else {
            known
        };
        v * v * self.speed_scale[n]
    }

    fn accel_range(&self, n: usize, x: f64) -> (f64, f64) {
        let v = x.max(0.0).sqrt();
        let bends = self.bends(n, v);
        let scale = self.accel_scale[n];
        let accel = self.limits.accel * scale;
        let normal = bends.curvature * x;
        let tangential = (accel * accel - normal * normal).max(0.0).sqrt();
        let (mut lo, mut hi) = (-tangential, tangential);
        for i in 0..5 {
            let g = bends.slope[i];
            if g.abs() < 1e-12 {
                continue;
            }
            let amax = self.joints.acceleration[i] * scale;
            // g·s̈ + bend·x within ±amax for every bend the windows saw.
            let (a, b) = (
                (-amax - bends.least[i] * x) / g,
                (amax - bends.greatest[i] * x) / g,
            );
            lo = lo.max(a.min(b));
            hi = hi.min(a.max(b));
        }
        (lo, hi)
    }
}

/// The tip's unit directions before and after node `n` (none at the ends or beside a
/// zero-length piece).
pub(super) fn tip_turn(path: &JointPath, n: usize) -> Option<(Vector<3>, Vector<3>)> {
    let poses = &path.poses;
    if n == 0 || n + 1 >= poses.len() {
        return None;
    }
    let before = geometry::unit(&(poses[n].tip - poses[n - 1].tip))?;
    let after = geometry::unit(&(poses[n + 1].tip - poses[n].tip))?;
    Some((before, after))
}

/// What [`Constraints::bends`] finds at a node.
#[derive(Clone, Copy)]
pub(super) struct Bends {
    slope: Joints,
    least: Joints,
    greatest: Joints,
    curvature: f64,
}
