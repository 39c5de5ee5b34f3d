//! Which control samples fall inside a communication step.
//!
//! Sampled models (interpolator, controllers) run at their own period `Ts` whatever
//! communication step the importer uses: sample n is due at t0 + n·Ts. Counting samples
//! with an integer (instead of accumulating time) keeps the phase exact over any number
//! of steps, and a tolerance of 1e-6·Ts absorbs the rounding of importers' clocks.

use serde::{Deserialize, Serialize};

/// The shortest sample period a model accepts, s. A communication step costs one sample
/// per period, so a vanishing `Ts` would make a single `fmi2DoStep` run for hours.
pub const MIN_PERIOD: f64 = 1e-6;

/// The most samples one communication step may take: 10⁴ s of simulated time at the
/// usual 1 ms period, far beyond any sensible communication step.
pub const MAX_SAMPLES_PER_STEP: f64 = 1e7;

/// Checks a sample period parameter; the error names it.
pub fn check_period(name: &str, period: f64) -> Result<f64, String> {
    if period >= MIN_PERIOD && period.is_finite() {
        Ok(period)
    } else {
        Err(format!(
            "parameter '{name}' must be at least {MIN_PERIOD:e} s (got {period})"
        ))
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SampleClock {
    start: f64,
    period: f64,
    /// Samples taken so far; the next one is due at start + taken·period.
    taken: u64,
}

impl SampleClock {
    pub fn new(start: f64, period: f64) -> Self {
        SampleClock {
            start,
            period,
            taken: 0,
        }
    }

    fn due(&self, n: u64) -> f64 {
        self.start + n as f64 * self.period
    }

    fn tolerance(&self) -> f64 {
        1e-6 * self.period
    }

    /// Takes the next sample if it is due strictly before `end` (a controller acting at
    /// the start of its period on the inputs held over it). Returns whether it did.
    pub fn take_before(&mut self, end: f64) -> bool {
        let due = self.due(self.taken) < end - self.tolerance();
        self.taken += u64::from(due);
        due
    }

    /// Takes the next sample after the current one if it is due at or before `end` (an
    /// interpolator whose output at `end` is the latest sample). Returns whether it did.
    pub fn take_until(&mut self, end: f64) -> bool {
        let due = self.due(self.taken + 1) <= end + self.tolerance();
        self.taken += u64::from(due);
        due
    }

    /// When the latest sample [`SampleClock::take_before`] took was due (the start before
    /// the first; not for a clock advanced by `take_until`).
    pub fn latest(&self) -> f64 {
        self.due(self.taken.saturating_sub(1))
    }

    /// Samples taken so far.
    pub fn taken(&self) -> u64 {
        self.taken
    }

    /// The sample period, s.
    pub fn period(&self) -> f64 {
        self.period
    }

    /// Refuses a communication step to `end` that would take more than
    /// [`MAX_SAMPLES_PER_STEP`] samples: a step of 1e300 s is finite, so the FMI layer
    /// accepts it, but one `fmi2DoStep` would then never return.
    pub fn check_step(&self, end: f64) -> Result<(), String> {
        let samples = (end - self.due(self.taken)) / self.period;
        if samples > MAX_SAMPLES_PER_STEP {
            return Err(format!(
                "it would take {samples:e} samples of Ts = {} s (at most \
                 {MAX_SAMPLES_PER_STEP:e} per step)",
                self.period
            ));
        }
        Ok(())
    }

    /// Checks a clock restored from saved bytes at instance time `time` like the
    /// parameter it came from: a period below [`MIN_PERIOD`] (or ≤ 0) would make one
    /// `fmi2DoStep` loop for hours or forever, and so would a clock far behind the time
    /// (a start of −1e6 s is 10⁹ samples to catch up). Whichever way it is stepped, the
    /// next sample of a live clock is due within one period of the instance time.
    pub fn validate_at(&self, time: f64) -> Result<(), String> {
        if !self.start.is_finite() {
            return Err(format!(
                "sample clock start time {} is not finite",
                self.start
            ));
        }
        if !(self.period >= MIN_PERIOD && self.period.is_finite()) {
            return Err(format!(
                "sample clock period {} s must be at least {MIN_PERIOD:e} s",
                self.period
            ));
        }
        let next = self.due(self.taken);
        // False for a NaN time too.
        let within = (next - time).abs() <= self.period + self.tolerance();
        if !within {
            return Err(format!(
                "sample clock: the next sample is due at {next} s, more than one period \
                 ({} s) from the state's time {time} s",
                self.period
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fired_before(steps: &[f64], ts: f64) -> Vec<u64> {
        let mut clock = SampleClock::new(0.0, ts);
        let mut t = 0.0;
        let mut counts = Vec::new();
        for &h in steps {
            t += h;
            while clock.take_before(t) {}
            counts.push(clock.taken());
        }
        counts
    }

    #[test]
    fn a_controller_fires_at_every_multiple_of_its_period() {
        // 2.5 ms steps over a 1 ms period: samples at 0, 1, 2 | 3, 4 | 5, 6, 7 | …
        assert_eq!(fired_before(&[0.0025; 4], 0.001), vec![3, 5, 8, 10]);
        // Importer rounding (0.1 + 0.2 style) does not add or drop a sample.
        assert_eq!(fired_before(&[0.1, 0.2, 0.3], 0.1), vec![1, 3, 6]);
        let counts = fired_before(&[0.001; 1000], 0.001);
        assert_eq!(counts.last(), Some(&1000));
    }

    #[test]
    fn restored_clocks_are_checked_like_the_period_parameter() {
        assert_eq!(SampleClock::new(0.5, 1e-3).validate_at(0.5), Ok(()));
        for bad in [0.0, -1e-3, 1e-9, f64::NAN, f64::INFINITY] {
            let message = SampleClock::new(0.0, bad).validate_at(0.0).unwrap_err();
            assert!(message.starts_with("sample clock period"), "{message}");
        }
        assert!(SampleClock::new(f64::NAN, 1e-3).validate_at(0.0).is_err());
        // A clock far from the state's time would loop through the gap in one step.
        let message = SampleClock::new(-1e6, 1e-3).validate_at(0.0).unwrap_err();
        assert!(
            message.starts_with("sample clock: the next sample"),
            "{message}"
        );
        assert!(SampleClock::new(0.0, 1e-3).validate_at(0.5).is_err());
    }

    /// Every clock a run can produce passes: after any sequence of steps, controller-style
    /// and interpolator-style, the next sample is within one period of the time reached.
    #[test]
    fn every_reachable_clock_is_valid_at_its_time() {
        for ts in [1e-3, 2.5e-3, 0.1] {
            let (mut before, mut until) = (SampleClock::new(0.3, ts), SampleClock::new(0.3, ts));
            let mut t = 0.3;
            assert_eq!(before.validate_at(t), Ok(()));
            for k in 0..2000 {
                t += [0.001, 0.0025, 0.004, 0.0007][k % 4];
                while before.take_before(t) {}
                while until.take_until(t) {}
                assert_eq!(before.validate_at(t), Ok(()), "take_before at {t}");
                assert_eq!(until.validate_at(t), Ok(()), "take_until at {t}");
            }
        }
    }

    #[test]
    fn an_interpolator_holds_the_latest_sample() {
        let mut clock = SampleClock::new(0.0, 0.001);
        while clock.take_until(0.0025) {}
        assert_eq!(clock.taken(), 2);
        while clock.take_until(0.003 - 1e-15) {}
        assert_eq!(clock.taken(), 3);
    }
}
