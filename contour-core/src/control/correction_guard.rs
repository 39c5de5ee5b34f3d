//! When the five-axis CCC may act (docs/design/five-axis.md §5.4b): the correction's
//! weight, 1 while the machine follows a reference it can follow, 0 while it cannot.
//!
//! A contour correction helps a machine that tracks its reference with a small lag. It
//! harms one that cannot track it: a reference beyond the joints' limits (a user's own,
//! a plan for another machine, a branch flip of C by π in one sample), position loops
//! at their speed limit, or a mapping that has lost the tool. The correction then pulls
//! the tool toward the path while the position loops pull the joints toward the
//! reference, and the two end in a tug-of-war won by whichever saturates last. The guard
//! steps the correction aside in those samples (weight 0, the laws reset: nothing wound
//! up survives), and brings it back over `recovery` seconds once none holds.
//!
//! The reference's speed is that of its distinct values over the time between them: a
//! reference held over a communication step moves once per step, and is measured over the
//! step. Its acceleration is not judged: a corner at constant feed asks an infinite one
//! that the correction is made for, and a reference held over communication steps that
//! are not a whole number of samples reads as one; what the joints cannot do shows in the
//! position loops instead (`saturated`).

use serde::{Deserialize, Serialize};

use crate::kinematics::Joints;
use crate::limits::JointLimits;

/// How far a reference may exceed a joint's speed before the guard calls it beyond the
/// machine, and a position loop ask beyond it before the guard calls the machine behind:
/// room for another planner's rounding and for a sampling that differs from the one it
/// planned at.
pub const LIMIT_SLACK: f64 = 1.1;

/// Why the correction stands aside this sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Hold {
    /// The reference leaves a joint's travel, or exceeds its speed by more than
    /// [`LIMIT_SLACK`].
    pub beyond_limits: bool,
    /// A position loop alone asks for more than [`LIMIT_SLACK`] times its joint's speed:
    /// the machine is behind, catching up.
    pub saturated: bool,
    /// The mapping has lost the tool (at the tail of its band).
    pub lost: bool,
}

impl Hold {
    /// Whether any reason holds.
    pub fn any(&self) -> bool {
        self.beyond_limits || self.saturated || self.lost
    }
}

/// The guard's state: the reference's last distinct value and its time, and the weight.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CorrectionGuard {
    limits: JointLimits,
    ts: f64,
    /// Weight gained per sample on the way back (Ts / recovery).
    rise: f64,
    /// The last distinct reference, once there is one (`seen`), and when it came (s).
    last: Joints,
    seen: bool,
    since: f64,
    weight: f64,
}

impl CorrectionGuard {
    /// A guard for a machine with `limits`, sampled every `ts` s, that returns to full
    /// weight in `recovery` s (0: at once). Starts at full weight.
    pub fn new(limits: JointLimits, ts: f64, recovery: f64) -> Self {
        CorrectionGuard {
            limits,
            ts,
            rise: if recovery > 0.0 { ts / recovery } else { 1.0 },
            last: Joints::zeros(),
            seen: false,
            since: 0.0,
            weight: 1.0,
        }
    }

    /// What the guard was built with: the limits, the sample period and the rise per
    /// sample.
    pub fn settings(&self) -> (JointLimits, f64, f64) {
        (self.limits, self.ts, self.rise)
    }

    /// Whether reference sample `reference`, set at `time` (s), is beyond the limits:
    /// outside a travel, or (when it differs from the last) faster than allowed over the
    /// time since the last one came (at least a sample period).
    pub fn beyond_limits(&mut self, reference: &Joints, time: f64) -> bool {
        let l = &self.limits;
        let outside = (0..5).any(|i| reference[i] < l.min[i] || reference[i] > l.max[i]);
        if !self.seen {
            (self.last, self.seen, self.since) = (*reference, true, time);
            return outside;
        }
        if *reference == self.last {
            return outside;
        }
        let dt = (time - self.since).max(self.ts);
        let fast =
            (0..5).any(|i| (reference[i] - self.last[i]).abs() > LIMIT_SLACK * l.velocity[i] * dt);
        (self.last, self.since) = (*reference, time);
        outside || fast
    }

    /// Whether the machine is behind: a position loop (`loops`, before any clamp) asks
    /// for more than [`LIMIT_SLACK`] times its joint's speed. Tracking a reference within
    /// the speeds, a position loop's lag never asks more (a P loop's lag is the speed a
    /// little while ago over Kp); a loop at its joint's speed behind a reference at that
    /// speed (a plan at the limit) asks exactly the speed.
    pub fn saturated(&self, loops: &Joints) -> bool {
        (0..5).any(|i| loops[i].abs() > LIMIT_SLACK * self.limits.velocity[i])
    }

    /// The weight for this sample given why it would hold, and whether the correction was
    /// dropped this sample (it acted the sample before: the caller resets its laws).
    pub fn update(&mut self, hold: Hold) -> (f64, bool) {
        if hold.any() {
            let dropped = self.weight > 0.0;
            self.weight = 0.0;
            (0.0, dropped)
        } else {
            self.weight = (self.weight + self.rise).min(1.0);
            (self.weight, false)
        }
    }

    /// Checks a guard restored from bytes: finite memories, a weight in [0, 1].
    pub fn check(&self) -> Result<(), String> {
        if !(self.last.iter().all(|x| x.is_finite()) && self.since.is_finite()) {
            return Err("the guard's last reference or its time is not finite".into());
        }
        if !((0.0..=1.0).contains(&self.weight) && self.rise > 0.0 && self.rise <= 1.0) {
            return Err(format!(
                "the guard's weight {} or rise {} lies outside (0, 1]",
                self.weight, self.rise
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn guard() -> CorrectionGuard {
        CorrectionGuard::new(JointLimits::DEFAULT, 1e-3, 0.01)
    }

    /// Feeds `x(k)` at samples k (time k·Ts) and says which were beyond.
    fn beyond(g: &mut CorrectionGuard, samples: usize, x: impl Fn(usize) -> Joints) -> Vec<usize> {
        (0..samples)
            .filter(|&k| g.beyond_limits(&x(k), k as f64 * 1e-3))
            .collect()
    }

    #[test]
    fn a_reference_within_the_limits_is_not_beyond_them() {
        // X at up to 450 mm/s (under 500), from rest in one sample: the acceleration is
        // not judged.
        let x = |k: usize| Joints::new(0.45 * k as f64, 0.0, 0.0, 0.0, 0.0);
        assert!(beyond(&mut guard(), 200, x).is_empty());
        // C at 5.4 rad/s: within the 10 % of slack; at 5.6 not.
        let c = |w: f64| move |k: usize| Joints::new(0.0, 0.0, 0.0, 0.0, w * 1e-3 * k as f64);
        assert!(beyond(&mut guard(), 100, c(5.4)).is_empty());
        assert_eq!(beyond(&mut guard(), 100, c(5.6)).len(), 99);
    }

    #[test]
    fn a_jump_of_c_and_a_travel_are_beyond() {
        // C by π in one sample: 3142 rad/s.
        let flip = |k: usize| Joints::new(0.0, 0.0, 0.0, 0.0, if k < 5 { 0.0 } else { 3.1 });
        assert_eq!(beyond(&mut guard(), 10, flip), vec![5]);
        // A below its travel (−35°), at every sample it stays there.
        let low = |_| Joints::new(0.0, 0.0, 0.0, -0.7, 0.0);
        assert_eq!(beyond(&mut guard(), 3, low), vec![0, 1, 2]);
    }

    #[test]
    fn a_reference_held_over_a_communication_step_is_measured_over_the_step() {
        // 400 mm/s set every 2.5 ms (the communication step), sampled every 1 ms: the
        // values change after 2 or 3 samples, and per sample they would read 1000.
        let mut g = guard();
        for k in 0..100 {
            let step = (k as f64 / 2.5).floor();
            let (x, set_at) = (400.0 * 2.5e-3 * step, 2.5e-3 * step);
            let beyond = g.beyond_limits(&Joints::new(x, 0.0, 0.0, 0.0, 0.0), set_at);
            assert!(!beyond, "sample {k}");
        }
    }

    #[test]
    fn the_weight_drops_at_once_and_comes_back_over_the_recovery() {
        let mut g = guard();
        assert_eq!(g.update(Hold::default()), (1.0, false));
        let hold = Hold {
            saturated: true,
            ..Hold::default()
        };
        assert_eq!(g.update(hold), (0.0, true));
        assert_eq!(g.update(hold), (0.0, false));
        let mut last = 0.0;
        for k in 1..=10 {
            let (w, dropped) = g.update(Hold::default());
            assert!(!dropped && w > last, "{k}: {w}");
            last = w;
        }
        assert!((last - 1.0).abs() < 1e-12);
    }
}
