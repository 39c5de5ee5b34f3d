//! One piece of a planned XY path as a time-optimal jerk-limited motion along its arc
//! length (docs/design/two-axis.md §4.9): from a given speed to a given speed, both at
//! zero tangential acceleration, within the piece's speed, acceleration and jerk. Ruckig
//! solves each exactly (`rsruckig`); its up to seven phases of constant jerk are kept,
//! and a sample is a cubic in time within one of them.

use rsruckig::prelude::*;

use crate::path::PathError;

/// What a piece allows along its arc length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PieceLimits {
    /// Speed, mm/s (> 0).
    pub speed: f64,
    /// Tangential acceleration, mm/s² (> 0).
    pub accel: f64,
    /// Tangential jerk, mm/s³ (> 0; infinite: no jerk limit).
    pub jerk: f64,
}

/// A stretch of constant jerk: from `time` on, s = s₀ + v·τ + a·τ²/2 + j·τ³/6 with
/// τ = t − `time`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phase {
    /// Start, s from the plan's start.
    pub time: f64,
    /// Arc length at the start, mm from the path's start.
    pub s: f64,
    /// Speed, acceleration and jerk at the start.
    pub speed: f64,
    pub accel: f64,
    pub jerk: f64,
}

impl Phase {
    /// Arc length, speed and acceleration `tau` s after the phase's start.
    pub fn at(&self, tau: f64) -> (f64, f64, f64) {
        let (v, a, j) = (self.speed, self.accel, self.jerk);
        (
            self.s + tau * (v + tau * (0.5 * a + tau * j / 6.0)),
            v + tau * (a + 0.5 * j * tau),
            a + j * tau,
        )
    }
}

/// The distance a change of speed from `v0` to `v1` takes with zero acceleration at
/// both ends: the S-curve of jerk `j` that reaches `a` when the change is large enough
/// (the classic closed forms; `j` infinite: the trapezoid's (v1² − v0²)/2a).
pub fn change_distance(v0: f64, v1: f64, a: f64, j: f64) -> f64 {
    let dv = (v1 - v0).abs();
    let mean = 0.5 * (v0 + v1);
    if j.is_infinite() {
        mean * dv / a
    } else if dv >= a * a / j {
        mean * (dv / a + a / j)
    } else {
        2.0 * mean * (dv / j).sqrt()
    }
}

/// The greatest speed reachable from `v0` (or from which `v0` is reachable) within
/// `length`, at most `cap`: bisection on [`change_distance`], which grows with the
/// change.
pub fn reachable(v0: f64, length: f64, cap: f64, limits: &PieceLimits) -> f64 {
    if cap <= v0 || change_distance(v0, cap, limits.accel, limits.jerk) <= length {
        return cap;
    }
    let (mut lo, mut hi) = (v0, cap);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if change_distance(v0, mid, limits.accel, limits.jerk) <= length {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi {
            break;
        }
    }
    lo
}

/// The time-optimal motion over `length` mm from speed `v0` to `v1` (zero acceleration
/// at both ends) within `limits`, as phases starting at `time` and arc length `s0`
/// (appended to `out`); returns its duration.
pub fn plan_piece(
    length: f64,
    (v0, v1): (f64, f64),
    limits: &PieceLimits,
    (time, s0): (f64, f64),
    out: &mut Vec<Phase>,
) -> Result<f64, PathError> {
    let mut otg = Ruckig::<1, ThrowErrorHandler>::new(None, 1e-3);
    let mut input = InputParameter::new(None);
    input.current_velocity[0] = v0;
    input.target_position[0] = length;
    input.target_velocity[0] = v1;
    input.max_velocity[0] = limits.speed;
    input.max_acceleration[0] = limits.accel;
    input.max_jerk[0] = limits.jerk;
    let mut trajectory = Trajectory::new(None);
    otg.calculate(&input, &mut trajectory).map_err(|e| {
        PathError::invalid(format!(
            "no motion over {length} mm from {v0} to {v1} mm/s within {limits:?}: {e}"
        ))
    })?;
    let profile = &trajectory.get_profiles()[0][0];
    let mut start = 0.0;
    for k in 0..7 {
        let duration = profile.t[k];
        if duration > 0.0 {
            out.push(Phase {
                time: time + start,
                s: s0 + profile.p[k],
                speed: profile.v[k],
                accel: profile.a[k],
                jerk: profile.j[k],
            });
        }
        start += duration;
    }
    Ok(trajectory.get_duration())
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIMITS: PieceLimits = PieceLimits {
        speed: 50.0,
        accel: 2000.0,
        jerk: 1e5,
    };

    #[test]
    fn a_long_line_from_rest_to_rest_takes_the_closed_form_time() {
        // Speed and acceleration both reached: L/v + v/a + a/j.
        let mut phases = Vec::new();
        let t = plan_piece(100.0, (0.0, 0.0), &LIMITS, (0.0, 0.0), &mut phases).unwrap();
        let want = 100.0 / 50.0 + 50.0 / 2000.0 + 2000.0 / 1e5;
        assert!((t - want).abs() < 1e-9, "{t} vs {want}");
        // The phases end where the line ends, at rest.
        let last = phases.last().unwrap();
        let (s, v, a) = last.at(t - last.time);
        assert!((s - 100.0).abs() < 1e-9 && v.abs() < 1e-9 && a.abs() < 1e-6);
        // The change distance of the ramps is what the closed form says.
        let ramp = change_distance(0.0, 50.0, 2000.0, 1e5);
        let cruise_start = phases
            .iter()
            .find(|p| p.accel == 0.0 && p.jerk == 0.0)
            .unwrap();
        assert!((cruise_start.s - ramp).abs() < 1e-9);
    }

    #[test]
    fn reachable_speeds_invert_the_change_distance() {
        for &(v0, length) in &[(0.0, 0.1), (10.0, 0.5), (0.0, 0.001), (30.0, 3.0)] {
            let v = reachable(v0, length, 1e9, &LIMITS);
            assert!((change_distance(v0, v, 2000.0, 1e5) - length).abs() < 1e-9 * length.max(1.0));
            let trapezoid = PieceLimits {
                jerk: f64::INFINITY,
                ..LIMITS
            };
            let v = reachable(v0, length, 1e9, &trapezoid);
            assert!(((v * v - v0 * v0) / 4000.0 - length).abs() < 1e-9 * length.max(1.0));
        }
        assert_eq!(reachable(5.0, 100.0, 50.0, &LIMITS), 50.0);
    }
}
