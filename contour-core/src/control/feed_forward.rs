//! Feed-forward of the reference's velocity and acceleration onto a held velocity command
//! (docs/design/two-axis.md §4.12, §4.12b).
//!
//! A drive whose velocity loop is first order with time constant τ follows the command
//! v + τ·a exactly in continuous time. The controller's command is held over its period
//! Ts, so what counts is the acceleration over the hold: the command that brings the
//! drive to the reference's velocity at the end of the hold is v + a·Ts/(1 − e^(−Ts/τ))
//! with `a` the acceleration at the middle of the hold. The acceleration time T_a =
//! Ts/(1 − e^(−Ts/τ)) ≈ τ + Ts/2 is the parameter; the acceleration at the middle of
//! the hold is extrapolated from the last two communication points' `aref`, which the
//! reference's jerk moves by up to jerk·Ts between samples.

use serde::{Deserialize, Serialize};

use crate::geometry::Vector;

/// The feed-forward term of a controller with `D` axes and its memory of the inputs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FeedForward<const D: usize> {
    velocity_gain: f64,
    acceleration_time: f64,
    /// The reference's acceleration read at `input_time`.
    acceleration: Vector<D>,
    input_time: Option<f64>,
    /// How fast the acceleration input changed between the last two readings, per s.
    acceleration_slope: Vector<D>,
}

impl<const D: usize> FeedForward<D> {
    /// `velocity_gain` (1: the whole reference velocity) and `acceleration_time` (s), both
    /// finite and ≥ 0.
    pub fn new(velocity_gain: f64, acceleration_time: f64) -> Result<Self, String> {
        let feed_forward = FeedForward {
            velocity_gain,
            acceleration_time,
            acceleration: Vector::zeros(),
            input_time: None,
            acceleration_slope: Vector::zeros(),
        };
        feed_forward.validate()?;
        Ok(feed_forward)
    }

    /// The command to add for a sample taken at `at` and held for `hold` s, from the
    /// inputs of the communication point at `time`: the velocity gain times `velocity`,
    /// plus the acceleration time times `acceleration` extrapolated to the middle of the
    /// hold. The slope comes from the previous communication point that had a sample (the
    /// interpolator's outputs step once per Ts, so a shorter step between them would read
    /// a staircase); the samples of one step read the same point once.
    pub fn sample(
        &mut self,
        time: f64,
        velocity: Vector<D>,
        acceleration: Vector<D>,
        at: f64,
        hold: f64,
    ) -> Vector<D> {
        if let Some(before) = self.input_time.filter(|&t| t < time) {
            self.acceleration_slope = (acceleration - self.acceleration) / (time - before);
        }
        self.acceleration = acceleration;
        self.input_time = Some(time);
        let ahead = at + hold / 2.0 - time;
        velocity * self.velocity_gain
            + (acceleration + self.acceleration_slope * ahead) * self.acceleration_time
    }

    /// The command to add for a hold over which the reference's mean acceleration is
    /// known in advance (an interpolator's look-ahead, (v(t+Ts) − v(t))/Ts): the velocity
    /// gain times `velocity` plus the acceleration time times `mean_acceleration`. For a
    /// first-order velocity loop this lands on the reference's velocity at the end of the
    /// hold whatever the jerk does inside it; the memory is not used.
    pub fn over_hold(&self, velocity: Vector<D>, mean_acceleration: Vector<D>) -> Vector<D> {
        velocity * self.velocity_gain + mean_acceleration * self.acceleration_time
    }

    /// Checks the gains and the memory of a state restored at instance time `time`: the
    /// inputs were read before it. The error names the value.
    pub fn validate_at(&self, time: f64) -> Result<(), String> {
        self.validate()?;
        match self.input_time {
            Some(t) if t >= time => Err(format!(
                "inputs read at t = {t} s, not before the state's time {time} s"
            )),
            _ => Ok(()),
        }
    }

    /// Checks the gains (`feedForward`, `accelerationFeedForward`) and the memory; the
    /// error names the value.
    pub fn validate(&self) -> Result<(), String> {
        for (name, value) in [
            ("feedForward", self.velocity_gain),
            ("accelerationFeedForward", self.acceleration_time),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(format!("{name} = {value} must be finite and >= 0"));
            }
        }
        let memory = [&self.acceleration, &self.acceleration_slope];
        if memory.iter().any(|v| v.iter().any(|x| !x.is_finite()))
            || self.input_time.is_some_and(|t| !t.is_finite())
        {
            return Err("memory holds a value that is not finite".into());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    /// A first-order velocity loop dv/dt = (u − v)/τ with u held over Ts, integrated exactly,
    /// driven by the command for a reference whose acceleration ramps (constant jerk): the
    /// velocity at the end of every hold is the reference's (exactly: over a hold the ramp's
    /// velocity gains Ts times the acceleration at the hold's middle).
    #[test]
    fn the_acceleration_time_of_a_first_order_loop_reaches_the_reference_velocity() {
        let (tau, ts, jerk) = (1.0 / 314.0, 1e-3, 5e4);
        let time = ts / -crate::math::expm1(-ts / tau);
        let mut ff = FeedForward::<2>::new(1.0, time).unwrap();
        let decay = crate::math::exp(-ts / tau);
        let reference = |t: f64| (jerk * t * t / 2.0, jerk * t); // velocity, acceleration
        let (v_before, a_before) = reference(-ts);
        let at = |v: f64, a: f64| (Vector2::new(v, -v), Vector2::new(a, -a));
        let (vb, ab) = at(v_before, a_before);
        ff.sample(-ts, vb, ab, -ts, ts);
        let mut v = 0.0;
        let mut worst: f64 = 0.0;
        for k in 0..40 {
            let t = k as f64 * ts;
            let (vr, ar) = reference(t);
            let (velocity, acceleration) = at(vr, ar);
            let u = ff.sample(t, velocity, acceleration, t, ts);
            assert_eq!(u[1], -u[0]);
            v = u[0] + (v - u[0]) * decay;
            worst = worst.max((v - reference(t + ts).0).abs());
        }
        // Without the extrapolation every hold would end jerk·Ts²/2·T_a/Ts = 0.093 mm/s
        // short; with it only rounding is left.
        assert!(worst < 1e-12, "{worst}");
    }

    /// A jerk-limited reference whose jerk switches inside holds (every 2.5 samples):
    /// the look-ahead's mean acceleration over each hold lands the first-order loop on
    /// the reference velocity at the end of every hold; the acceleration extrapolated
    /// from the samples misses each switch.
    #[test]
    fn the_look_ahead_lands_on_the_reference_velocity_where_the_jerk_switches() {
        let (tau, ts, jerk) = (1.0 / 314.0, 1e-3, 5e4);
        let time = ts / -crate::math::expm1(-ts / tau);
        let decay = crate::math::exp(-ts / tau);
        // Jerk +j, −j, −j, +j repeating every 2.5 ms: velocity and acceleration at t.
        let reference = |t: f64| {
            let (period, mut v, mut a, mut at) = (2.5e-3, 0.0, 0.0, 0.0);
            let signs = [1.0, -1.0, -1.0, 1.0];
            let mut i = 0;
            while at < t {
                let dt = (t - at).min(period);
                let j = signs[i % 4] * jerk;
                v += a * dt + j * dt * dt / 2.0;
                a += j * dt;
                at += dt;
                i += 1;
            }
            (v, a)
        };
        let one = |v: f64| Vector2::new(v, 0.0);
        let mut worst = [0.0f64; 2];
        for (law, worst) in worst.iter_mut().enumerate() {
            let mut ff = FeedForward::<2>::new(1.0, time).unwrap();
            let mut v = 0.0;
            for k in 0..40 {
                let t = k as f64 * ts;
                let (vr, ar) = reference(t);
                let u = if law == 0 {
                    ff.over_hold(one(vr), one((reference(t + ts).0 - vr) / ts))[0]
                } else {
                    ff.sample(t, one(vr), one(ar), t, ts)[0]
                };
                v = u + (v - u) * decay;
                *worst = worst.max((v - reference(t + ts).0).abs());
            }
        }
        assert!(worst[0] < 1e-12, "{worst:?}");
        assert!(worst[1] > 0.01, "{worst:?}");
    }

    #[test]
    fn the_slope_scales_with_the_time_between_readings() {
        let mut ff = FeedForward::<2>::new(0.0, 1.0).unwrap();
        let (zero, one, three) = (
            Vector2::zeros(),
            Vector2::new(1.0, 0.0),
            Vector2::new(3.0, 0.0),
        );
        // No slope yet.
        assert_eq!(ff.sample(0.0, zero, one, 0.0, 0.002), one);
        // 500 /s² per s: at the middle of a 2 ms hold, 1 ms ahead: 3.5.
        assert_eq!(
            ff.sample(0.004, zero, three, 0.004, 0.002),
            Vector2::new(3.5, 0.0)
        );
        // A second sample inside the same communication step is 2 ms later: 4.5, and
        // reading the same point again keeps the slope.
        assert_eq!(
            ff.sample(0.004, zero, three, 0.006, 0.002),
            Vector2::new(4.5, 0.0)
        );
    }

    #[test]
    fn bad_gains_and_memory_are_refused() {
        assert!(FeedForward::<5>::new(-1.0, 0.0).is_err());
        assert!(FeedForward::<5>::new(1.0, f64::NAN)
            .unwrap_err()
            .contains("accelerationFeedForward = NaN"));
        let mut ff = FeedForward::<2>::new(1.0, 0.003).unwrap();
        ff.sample(0.002, Vector2::zeros(), Vector2::zeros(), 0.002, 0.001);
        assert!(ff.validate_at(0.003).is_ok());
        assert!(ff.validate_at(0.002).unwrap_err().contains("not before"));
        ff.acceleration_slope[1] = f64::INFINITY;
        assert!(ff.validate().is_err());
    }
}
