//! Discrete PID with conditional-integration anti-windup and gains that may change every
//! sample (the fuzzy CCC adapts them).
//!
//! Law at sample k (docs/design/two-axis.md §4.2): `u = Kp·e + Ki·I + Kd·(e − e_prev)/Ts` with
//! `I = Σ e·Ts` including the current sample. The state keeps `I` itself rather than
//! `Ki·I`, exactly as the formula reads, so a gain change rescales the accumulated
//! integral action at once; that is the behaviour of the paper's fuzzy PID.
//!
//! Anti-windup (only when an output limit is set): the output is clamped to ±limit, and
//! the integrator is frozen for a sample when the unclamped output with the new integral
//! would exceed the limit *and* the new error term pushes further in that direction
//! (conditional integration). Integration resumes as soon as the error changes sign or
//! the output leaves saturation, so there is no wound-up integral to unwind.

use serde::{Deserialize, Serialize};

/// Proportional, integral and derivative gain.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PidGains {
    /// Proportional gain (output per unit error).
    pub kp: f64,
    /// Integral gain (output per unit error·s).
    pub ki: f64,
    /// Derivative gain (output per unit error/s).
    pub kd: f64,
}

impl PidGains {
    /// All three gains zero.
    pub const ZERO: PidGains = PidGains::new(0.0, 0.0, 0.0);

    /// Gains from their three values.
    pub const fn new(kp: f64, ki: f64, kd: f64) -> Self {
        Self { kp, ki, kd }
    }

    /// A pure proportional controller.
    pub const fn p(kp: f64) -> Self {
        Self::new(kp, 0.0, 0.0)
    }

    /// The gains as a tuple `(kp, ki, kd)`.
    pub const fn as_tuple(self) -> (f64, f64, f64) {
        (self.kp, self.ki, self.kd)
    }
}

/// Discrete PID controller with fixed sample period.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pid {
    gains: PidGains,
    ts: f64,
    limit: Option<f64>,
    /// Σ e·Ts over the samples that were integrated.
    integral: f64,
    /// Error of the previous sample; `None` until the first sample, so the first
    /// derivative is 0 instead of a kick from an arbitrary initial value.
    prev_error: Option<f64>,
}

impl Pid {
    /// A controller with sample period `ts` (s) and an optional symmetric output limit
    /// (|u| ≤ limit, which also enables the anti-windup).
    ///
    /// # Panics
    /// If `ts` is not finite and positive, or the limit is not finite and positive;
    /// configurations are validated before they get here (see `ControllerConfig`).
    pub fn new(gains: PidGains, ts: f64, limit: Option<f64>) -> Self {
        assert!(ts.is_finite() && ts > 0.0, "PID sample period must be > 0");
        if let Some(l) = limit {
            assert!(l.is_finite() && l > 0.0, "PID output limit must be > 0");
        }
        Self {
            gains,
            ts,
            limit,
            integral: 0.0,
            prev_error: None,
        }
    }

    /// The gains used by the next [`Pid::update`].
    pub fn gains(&self) -> PidGains {
        self.gains
    }

    /// Replaces the gains; takes effect at the next [`Pid::update`], keeps the state.
    pub fn set_gains(&mut self, gains: PidGains) {
        self.gains = gains;
    }

    /// Sample period, s.
    pub fn ts(&self) -> f64 {
        self.ts
    }

    /// Symmetric output limit, if any.
    pub fn limit(&self) -> Option<f64> {
        self.limit
    }

    /// Accumulated Σ e·Ts.
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// Replaces the accumulated Σ e·Ts (e.g. to re-express a vector of integrals in a
    /// turning frame); non-finite values are ignored.
    pub fn set_integral(&mut self, integral: f64) {
        if integral.is_finite() {
            self.integral = integral;
        }
    }

    /// The error of the previous sample, if there was one.
    pub fn previous_error(&self) -> Option<f64> {
        self.prev_error
    }

    /// The change `e − e_prev` the next update would use (0 on the first sample); lets
    /// callers feed the same Δe to a gain scheduler before updating.
    pub fn difference(&self, error: f64) -> f64 {
        match self.prev_error {
            Some(prev) => error - prev,
            None => 0.0,
        }
    }

    /// Advances one sample with error `error` and returns the (clamped) output.
    pub fn update(&mut self, error: f64) -> f64 {
        self.update_with(error, true)
    }

    /// [`Pid::update`], integrating only if `integrate` (and the anti-windup allows it):
    /// a caller that knows the output cannot act (its own consumer saturates) holds the
    /// integral.
    pub fn update_with(&mut self, error: f64, integrate: bool) -> f64 {
        self.update_unclamped(error, integrate, 0.0).0
    }

    /// [`Pid::update_with`] with `offset` added to the output before the clamp (a
    /// feed-forward the limit also bounds, so the anti-windup judges the sum), returning
    /// the output and what it was before the clamp (how far beyond its limit the loop
    /// asks to go).
    pub fn update_unclamped(&mut self, error: f64, integrate: bool, offset: f64) -> (f64, f64) {
        let g = self.gains;
        let p = g.kp * error + offset;
        let d = g.kd * self.difference(error) / self.ts;
        let candidate = self.integral + error * self.ts;
        let integrate = integrate
            && match self.limit {
                None => true,
                Some(l) => {
                    let unclamped = p + g.ki * candidate + d;
                    let push = g.ki * error;
                    !((unclamped > l && push > 0.0) || (unclamped < -l && push < 0.0))
                }
            };
        if integrate {
            self.integral = candidate;
        }
        self.prev_error = Some(error);
        let u = p + g.ki * self.integral + d;
        match self.limit {
            Some(l) => (u.clamp(-l, l), u),
            None => (u, u),
        }
    }

    /// Forgets the integral and the previous error; keeps gains, period and limit.
    pub fn reset(&mut self) {
        self.integral = 0.0;
        self.prev_error = None;
    }
}
