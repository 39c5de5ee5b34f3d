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

use crate::math;
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
    /// A position loop (with its feed-forward) asks for more than [`LIMIT_SLACK`] times
    /// its joint's speed: the machine is behind, catching up.
    pub saturated: bool,
    /// The mapping has lost the tool (at the tail of its band).
    pub lost: bool,
    /// A joint does not do what it was told: its travel falls short of its commands by
    /// more than a velocity loop's lag explains (a drive at its current limit, an axis
    /// stuck in friction).
    pub disobeyed: bool,
}

impl Hold {
    /// Whether any reason holds.
    pub fn any(&self) -> bool {
        self.beyond_limits || self.saturated || self.lost || self.disobeyed
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
    /// The joints measured last (`measured`), and when: travel is measured between
    /// distinct measurements (an FMU's input is held over a communication step).
    from: Joints,
    measured_at: f64,
    measured: bool,
    /// The command sent last (what a plant holds over a communication step), and whether
    /// one was sent since that measurement.
    sent: Joints,
    sent_since: bool,
    /// Each joint's travel short of its commands, forgotten over [`OBEY_WINDOW`].
    shortfall: Joints,
    /// Whether a joint fell short at the last measurement.
    short: bool,
    /// Each joint's measured speed and its commands, averaged over [`OBEY_WINDOW`] as
    /// the shortfall is forgotten.
    mean_speed: Joints,
    mean_sent: Joints,
    /// Whether a joint fell short of its commands by more than its lag behind their
    /// change explains, at the last measurement (see [`CorrectionGuard::lagging`]).
    lagging: bool,
}

/// How long a shortfall of travel is remembered, s: long against a velocity loop's lag,
/// short against a path's features.
pub const OBEY_WINDOW: f64 = 0.02;

/// The slowest velocity loop the guard expects, s (its time constant). A first-order
/// loop of lag τ travels ∫v = ∫u − τ·Δv: it falls short of its commands by τ·(v − v̄)
/// with v̄ the speed averaged over the window, at most τ·amax·window within the limits.
/// The guard allows τ plus the time between measurements: which command a plant held
/// over that time depends on the master (Gauss-Seidel: the last one sent; Jacobi: the one
/// before), so it is known to within one such interval of command change.
pub const OBEY_LAG: f64 = 0.01;

/// How far below 1 a velocity loop's steady gain may be before its joint counts as lagging:
/// a loop that runs at (1 − δ) of its command falls short by δ·ū over the window's
/// memory W, ū the commands' average (a drive without integral action on the test
/// plant's axes: δ = 0.2). A joint stuck under steady commands falls short by ū·W.
pub const GAIN_SHORTFALL: f64 = 0.25;

/// The shortfall every joint is allowed before it counts as lagging, as a time at its
/// speed limit, s: above the rounding of long runs, below a joint stuck for a few ms.
pub const LAG_FLOOR: f64 = 1e-6;

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
            from: Joints::zeros(),
            measured_at: 0.0,
            measured: false,
            sent: Joints::zeros(),
            sent_since: false,
            short: false,
            shortfall: Joints::zeros(),
            mean_speed: Joints::zeros(),
            mean_sent: Joints::zeros(),
            lagging: false,
        }
    }

    /// Records the command sent this sample.
    pub fn commanded(&mut self, command: &Joints) {
        self.sent = *command;
        self.sent_since = true;
    }

    /// Whether a joint has fallen short of its commands by more than a velocity loop of
    /// lag [`OBEY_LAG`] would (a drive at its current limit, an axis held by friction),
    /// given the joints `actual` measured at `at` (s). Travel between distinct
    /// measurements Δt apart is compared with the last command sent over Δt (a measurement
    /// held over several samples is judged once), and the allowance grows by Δt (see
    /// [`OBEY_LAG`]).
    pub fn disobeyed(&mut self, actual: &Joints, at: f64) -> bool {
        if self.measured && at == self.measured_at {
            return self.short;
        }
        let dt = at - self.measured_at;
        if self.measured && self.sent_since && dt > 0.0 {
            let keep = math::exp(-dt / OBEY_WINDOW);
            let l = &self.limits;
            self.short = false;
            self.lagging = false;
            for i in 0..5 {
                let short = self.sent[i] * dt - (actual[i] - self.from[i]);
                self.shortfall[i] = keep * self.shortfall[i] + short;
                let speed = (actual[i] - self.from[i]) / dt;
                self.mean_speed[i] = keep * self.mean_speed[i] + (1.0 - keep) * speed;
                self.mean_sent[i] = keep * self.mean_sent[i] + (1.0 - keep) * self.sent[i];
                let allowed =
                    (OBEY_LAG + dt) * (l.acceleration[i] * OBEY_WINDOW).min(2.0 * l.velocity[i]);
                self.short |= self.shortfall[i].abs() > allowed;
                let change =
                    (speed - self.mean_speed[i]).abs() + (self.sent[i] - self.mean_sent[i]).abs();
                let explained = (OBEY_LAG + dt) * change
                    + GAIN_SHORTFALL * OBEY_WINDOW * self.mean_sent[i].abs()
                    + LAG_FLOOR * l.velocity[i];
                self.lagging |= self.shortfall[i].abs() > explained;
            }
        }
        (self.from, self.measured_at, self.measured) = (*actual, at, true);
        self.sent_since = false;
        self.short
    }

    /// Whether a joint fell short of its commands, at the last measurement, by more than
    /// a velocity loop of lag [`OBEY_LAG`] explains by the commands' own change (a loop
    /// of lag τ falls short by τ·(v − v̄), v̄ the average over the window): a joint held
    /// by friction for a moment, far below what `disobeyed` holds the correction for. The
    /// laws do not integrate then (anti-windup against a joint that does not move).
    pub fn lagging(&self) -> bool {
        self.lagging
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

    /// Whether the machine is behind: a position loop (`loops`: with its feed-forward,
    /// before any clamp) asks for more than [`LIMIT_SLACK`] times its joint's speed.
    /// Tracking a reference within the speeds, a position loop's lag never asks more (a P
    /// loop's lag is the speed a little while ago over Kp; with feed-forward, the
    /// reference's own speed plus a smaller lag); a loop at its joint's speed behind a
    /// reference at that speed (a plan at the limit) asks exactly the speed.
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
        let memories = [
            self.from,
            self.sent,
            self.shortfall,
            self.mean_speed,
            self.mean_sent,
        ];
        if !(memories.iter().all(|m| m.iter().all(|x| x.is_finite()))
            && self.measured_at.is_finite())
        {
            return Err(
                "the guard's last measurement, commands, shortfall or averaged speeds and \
                 commands are not finite"
                    .into(),
            );
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

    /// X's commands and measurements for 0.3 s: a command of up to `peak` mm/s
    /// changing at up to 4000 mm/s² (within X's 5000), a first-order velocity loop of lag
    /// `lag` whose speed the drive caps at `cap`, measured every `every` samples as an
    /// FMU's input held over a communication step of that many samples, the plant holding
    /// over each step the last command of the step before (a Jacobi master: the largest
    /// delay). Which samples were judged disobeyed.
    fn disobedience(peak: f64, lag: f64, cap: f64, every: usize) -> Vec<usize> {
        judged(peak, 4000.0, lag, 1.0, cap, every, 0.0).0
    }

    /// [`disobedience`] with commands changing at up to `accel`, a velocity loop whose
    /// steady gain is `gain`, and an axis that sticks while its command is below `stick`
    /// in size (friction it breaks away from): the samples judged disobeyed, and lagging.
    #[allow(clippy::too_many_arguments)]
    fn judged(
        peak: f64,
        accel: f64,
        lag: f64,
        gain: f64,
        cap: f64,
        every: usize,
        stick: f64,
    ) -> (Vec<usize>, Vec<usize>) {
        let mut g = guard();
        let (ts, substeps) = (1e-3, 100);
        let (mut x, mut v) = (0.0, 0.0);
        let (mut measured, mut at) = (0.0, 0.0);
        let (mut held, mut last) = (0.0, 0.0);
        let (mut short, mut lagging) = (Vec::new(), Vec::new());
        for k in 0..300 {
            if k % every == 0 {
                (measured, at) = (x, k as f64 * ts);
                held = last;
            }
            if g.disobeyed(&Joints::new(measured, 0.0, 0.0, 0.0, 0.0), at) {
                short.push(k);
            }
            if g.lagging() {
                lagging.push(k);
            }
            let t = k as f64 * ts;
            last = peak * math::sin(accel / peak * t);
            g.commanded(&Joints::new(last, 0.0, 0.0, 0.0, 0.0));
            let u = if every == 1 { last } else { held };
            for _ in 0..substeps {
                let h = ts / substeps as f64;
                v = (v + h / lag * (gain * u - v)).clamp(-cap, cap);
                if u.abs() < stick {
                    v = 0.0;
                }
                x += v * h;
            }
        }
        (short, lagging)
    }

    #[test]
    fn a_velocity_loop_that_lags_within_the_limits_obeys() {
        // Lags of 3.2 ms (the test plant's 50 Hz loop) and 10 ms, every sample or through
        // a Jacobi master with communication steps of 3, 5 and 10 samples (judged once per
        // measurement).
        for lag in [0.0032, 0.01] {
            for every in [1, 3, 5, 10] {
                let (short, lagging) = judged(450.0, 4000.0, lag, 1.0, f64::INFINITY, every, 0.0);
                assert!(short.is_empty() && lagging.is_empty(), "{lag}, {every}");
                // A steady gain of 0.8, a drive without integral action (the test plant's
                // axes at Kvi = 0), 20 % slow at every speed, is not lagging. (At 450 mm/s
                // it falls 1.8 mm short over the window, which `disobeyed` holds for.)
                let (_, lagging) = judged(450.0, 4000.0, lag, 0.8, f64::INFINITY, every, 0.0);
                assert!(lagging.is_empty(), "{lag}, {every}");
            }
        }
    }

    #[test]
    fn an_axis_its_drive_cannot_move_as_told_disobeys() {
        // The drive tops out at 150 mm/s (a current limit) against commands of 450: not
        // judged short before the command passes the cap (at t = asin(1/3)·450/4000 =
        // 38 ms), then once the shortfall ∫(u − 150) ≈ 2000 mm/s²·Δt² (less what the
        // window forgets) passes X's 1 mm (0.01 s · 5000 mm/s² · 0.02 s): Δt ≈ 25 ms.
        for every in [1, 3] {
            let short = disobedience(450.0, 0.0032, 150.0, every);
            let first = *short.first().expect("never judged short");
            assert!((58..75).contains(&first), "{first}");
            // The command stays above the cap to the end (450·sin(2.67) = 203 mm/s).
            assert_eq!(short, (first..300).collect::<Vec<_>>());
        }
    }

    #[test]
    fn an_axis_stuck_for_a_moment_lags_but_is_not_held() {
        // From rest, commands rising at 1000 mm/s² on an axis that sticks until they pass
        // 30 mm/s (friction it breaks away from at t = asin(0.3)/10 = 30.5 ms). The stuck
        // axis falls short by a·t²/2. A loop of lag τ behind a ramp explains τ·(u − ū)
        // (ū the commands' average over the window W, a·t²/2W early on) and one 25 %
        // slow explains 0.25·W·ū = 0.25·a·t²/2: lagging once 0.75·a·t²/2 > (OBEY_LAG +
        // Ts)·a·t·(1 − t/2W), from t ≈ 29 ms·(1 − t/2W), about 22 ms. Its 0.45 mm at
        // breakaway is below `disobeyed`'s 1.1 mm, which would hold the correction only
        // from t ≈ 47 ms.
        for every in [1, 3] {
            let (short, lagging) = judged(100.0, 1000.0, 0.0032, 1.0, f64::INFINITY, every, 30.0);
            assert!(short.is_empty(), "{short:?}");
            let first = *lagging.first().expect("never lagging");
            assert!((18..=28).contains(&first), "{first}");
            // Not after the axis breaks away and follows.
            assert!(lagging.iter().all(|&k| k < 40), "{lagging:?}");
        }
    }
}
