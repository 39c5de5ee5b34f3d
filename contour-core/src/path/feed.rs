//! The time-optimal feed along a path parameter s (arc length, mm) under speed and
//! acceleration limits that vary along s (docs/design/five-axis.md §5.3b): the classic
//! forward–backward integration of the phase plane, on the speed squared x = ṡ² at a
//! grid of nodes, with the path acceleration u = s̈ = ½·dx/ds constant between nodes.
//!
//! What the limits are is the caller's ([`FeedConstraints`]): the five-axis reference
//! maps the joints' velocity and acceleration limits onto s; a planar program would give
//! the programmed feed and the path's acceleration. The plan starts and ends at rest.

use crate::path::PathError;

/// The limits a plan obeys, node by node.
pub trait FeedConstraints {
    /// The nodes' path parameters, increasing (mm).
    fn nodes(&self) -> &[f64];
    /// The largest speed squared at node `n` ((mm/s)²), at which a zero path acceleration
    /// is still allowed.
    fn speed2_max(&self, n: usize) -> f64;
    /// The path accelerations s̈ (mm/s²) allowed at node `n` at speed squared `x`, as
    /// (least, greatest); for `x ≤ speed2_max(n)` the range holds 0.
    fn accel_range(&self, n: usize, x: f64) -> (f64, f64);
}

/// A planned feed: the speed at every node, and the time the plan passes it.
#[derive(Clone, Debug, PartialEq)]
pub struct FeedProfile {
    s: Vec<f64>,
    speed: Vec<f64>,
    time: Vec<f64>,
}

/// Where a plan stands at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeedPoint {
    /// Path parameter, mm.
    pub s: f64,
    /// Path speed, mm/s.
    pub speed: f64,
    /// The node interval holding `s` (a hint for the next lookup).
    pub interval: usize,
}

impl FeedProfile {
    /// The fastest profile that keeps, node by node, the speed within
    /// `speed2_max` and the path acceleration within `accel_range` (both evaluated at the
    /// interval's ends), starting and ending at rest.
    pub fn plan(constraints: &impl FeedConstraints) -> Result<Self, PathError> {
        let s = constraints.nodes();
        let count = s.len();
        if count < 2 {
            return Err(PathError::invalid("a feed plan needs at least two nodes"));
        }
        if let Some(n) = s
            .windows(2)
            .position(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
        {
            return Err(PathError::invalid(format!(
                "feed-plan nodes {n} and {} are not increasing",
                n + 1
            )));
        }
        let mut x: Vec<f64> = (0..count)
            .map(|n| constraints.speed2_max(n).max(0.0))
            .collect();
        if let Some(n) = x.iter().position(|v| v.is_nan()) {
            return Err(PathError::invalid(format!(
                "the speed limit at s = {} mm is not a number",
                s[n]
            )));
        }
        x[0] = 0.0;
        x[count - 1] = 0.0;
        // Backward: the speed from which the plan can still brake to every later limit.
        for n in (0..count - 1).rev() {
            let h = s[n + 1] - s[n];
            let least = |node: usize, at: f64| constraints.accel_range(node, at).0.min(0.0);
            let reach = x[n + 1] - 2.0 * h * least(n + 1, x[n + 1]);
            // The braking allowed at the interval's start, at the speed just found.
            let reach = reach.min(x[n + 1] - 2.0 * h * least(n, reach.min(x[n])));
            x[n] = x[n].min(reach.max(0.0));
        }
        // Forward: the speed the plan can reach from rest.
        for n in 0..count - 1 {
            let h = s[n + 1] - s[n];
            let most = |node: usize, at: f64| constraints.accel_range(node, at).1.max(0.0);
            let reach = x[n] + 2.0 * h * most(n, x[n]);
            let reach = reach.min(x[n] + 2.0 * h * most(n + 1, reach.min(x[n + 1])));
            x[n + 1] = x[n + 1].min(reach);
        }
        let speed: Vec<f64> = x.iter().map(|v| v.sqrt()).collect();
        let mut time = Vec::with_capacity(count);
        time.push(0.0);
        for n in 0..count - 1 {
            let mean = speed[n] + speed[n + 1];
            if mean.is_nan() || mean <= 0.0 {
                return Err(PathError::invalid(format!(
                    "the limits allow no motion between s = {} and {} mm",
                    s[n],
                    s[n + 1]
                )));
            }
            time.push(time[n] + 2.0 * (s[n + 1] - s[n]) / mean);
        }
        if !time[count - 1].is_finite() {
            return Err(PathError::invalid("the planned duration is not finite"));
        }
        Ok(FeedProfile {
            s: s.to_vec(),
            speed,
            time,
        })
    }

    /// The planned duration, s.
    pub fn duration(&self) -> f64 {
        self.time[self.time.len() - 1]
    }

    /// The path length, mm.
    pub fn length(&self) -> f64 {
        self.s[self.s.len() - 1] - self.s[0]
    }

    /// The planned speed at every node, mm/s.
    pub fn speeds(&self) -> &[f64] {
        &self.speed
    }

    /// The nodes' path parameters, mm.
    pub fn nodes(&self) -> &[f64] {
        &self.s
    }

    /// Where the plan stands at time `t` (s; clamped to the plan), searching forward from
    /// the node interval `hint`: a run of increasing times costs O(1) per call, however
    /// long the path.
    pub fn at(&self, t: f64, hint: usize) -> FeedPoint {
        let last = self.s.len() - 1;
        let t = t.clamp(0.0, self.duration());
        let mut n = hint.min(last - 1);
        if self.time[n] > t {
            n = self.time.partition_point(|&tn| tn <= t).saturating_sub(1);
        }
        while n + 1 < last && self.time[n + 1] <= t {
            n += 1;
        }
        let n = n.min(last - 1);
        let h = self.s[n + 1] - self.s[n];
        let (v0, v1) = (self.speed[n], self.speed[n + 1]);
        let accel = (v1 * v1 - v0 * v0) / (2.0 * h);
        let tau = t - self.time[n];
        let s = (self.s[n] + v0 * tau + 0.5 * accel * tau * tau).clamp(self.s[n], self.s[n + 1]);
        FeedPoint {
            s,
            speed: (v0 + accel * tau).clamp(v0.min(v1), v0.max(v1)),
            interval: n,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A straight move with a speed cap and symmetric acceleration limits, optionally a
    /// slower stretch.
    struct Straight {
        nodes: Vec<f64>,
        vmax: Box<dyn Fn(f64) -> f64>,
        amax: f64,
    }

    impl FeedConstraints for Straight {
        fn nodes(&self) -> &[f64] {
            &self.nodes
        }
        fn speed2_max(&self, n: usize) -> f64 {
            (self.vmax)(self.nodes[n]).powi(2)
        }
        fn accel_range(&self, _: usize, _: f64) -> (f64, f64) {
            (-self.amax, self.amax)
        }
    }

    fn grid(length: f64, count: usize) -> Vec<f64> {
        (0..=count)
            .map(|i| length * i as f64 / count as f64)
            .collect()
    }

    #[test]
    fn a_straight_move_is_the_analytic_trapezoid_and_triangle() {
        // Trapezoid: T = L/v + v/a. Triangle (too short to reach v): T = 2·√(L/a).
        for (length, v, a) in [(100.0, 50.0, 500.0), (2.0, 50.0, 500.0)] {
            let plan = FeedProfile::plan(&Straight {
                nodes: grid(length, 20_000),
                vmax: Box::new(move |_| v),
                amax: a,
            })
            .unwrap();
            let exact = if length > v * v / a {
                length / v + v / a
            } else {
                2.0 * (length / a).sqrt()
            };
            // The grid's discretisation: the speed is exact at nodes; time to 1e-4.
            assert!(
                (plan.duration() / exact - 1.0).abs() < 1e-4,
                "{} vs {exact}",
                plan.duration()
            );
            let mid = plan.at(plan.duration() / 2.0, 0);
            assert!((mid.s - length / 2.0).abs() < 1e-3 * length);
        }
    }

    #[test]
    fn a_slow_stretch_is_reached_in_time_and_left_at_once() {
        // 0–40 mm at 50, 40–60 at 10, 60–100 at 50, a = 500: decelerating from 50 to 10
        // takes (50² − 10²)/(2a) = 2.4 mm, which must end at s = 40.
        let plan = FeedProfile::plan(&Straight {
            nodes: grid(100.0, 10_000),
            vmax: Box::new(|s| {
                if (40.0..=60.0).contains(&s) {
                    10.0
                } else {
                    50.0
                }
            }),
            amax: 500.0,
        })
        .unwrap();
        let speed_at = |s: f64| {
            let i = plan.nodes().partition_point(|&x| x < s);
            plan.speeds()[i]
        };
        assert!((speed_at(37.6) - 50.0).abs() < 0.1, "{}", speed_at(37.6));
        assert!((speed_at(40.0) - 10.0).abs() < 1e-9);
        assert!((speed_at(50.0) - 10.0).abs() < 1e-9);
        assert!((speed_at(62.4) - 50.0).abs() < 0.1);
        // Time: two ramps to 50 and back (0.1 s, 2.5 mm each), two 50↔10 ramps (0.08 s,
        // 2.4 mm each), 20 mm at 10, the rest at 50.
        let cruise = (100.0 - 2.0 * 2.5 - 2.0 * 2.4 - 20.0) / 50.0;
        let exact = 2.0 * 0.1 + 2.0 * 0.08 + 2.0 + cruise;
        assert!(
            (plan.duration() / exact - 1.0).abs() < 1e-3,
            "{}",
            plan.duration()
        );
        // Lookups forward from a hint and from scratch agree.
        let mut hint = 0;
        for k in 0..=100 {
            let t = plan.duration() * k as f64 / 100.0;
            let p = plan.at(t, hint);
            assert_eq!(p, plan.at(t, 0));
            hint = p.interval;
        }
    }

    #[test]
    fn nodes_that_do_not_increase_or_allow_no_motion_are_refused() {
        let bad = Straight {
            nodes: vec![0.0, 1.0, 1.0, 2.0],
            vmax: Box::new(|_| 1.0),
            amax: 1.0,
        };
        assert!(FeedProfile::plan(&bad).is_err());
        let stuck = Straight {
            nodes: grid(10.0, 10),
            vmax: Box::new(|s| if s > 4.5 && s < 6.5 { 0.0 } else { 1.0 }),
            amax: 1.0,
        };
        let e = FeedProfile::plan(&stuck).unwrap_err().to_string();
        assert!(e.contains("no motion between s = 5"), "{e}");
    }
}
