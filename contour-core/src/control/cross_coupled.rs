//! N-axis cross-coupled contour controller (docs/design/two-axis.md §4.2) with optional fuzzy gain
//! adaptation (docs/design/two-axis.md §4.3).
//!
//! Per sample: following errors `e = R − P`; per-axis position controllers give velocity
//! commands `G(e)` (mm/s); the contour estimator gives the contour error ε and the unit
//! direction n along which ε·n points to the path (in the plane: ε signed, n the left
//! normal). The fuzzy mode schedules (Kp, Ki, Kd) from ε and Δε every sample.
//!
//! In the plane the contour law runs on the scalar ε, `U_c = Kp·ε + Ki·Σε·Ts + Kd·Δε/Ts`,
//! and `u = G(e) + n·U_c`: the normal space is one line that turns with the path, so the
//! integral of ε is what holds a steady correction on a curve. In space the normal space
//! is a plane (or more) in which the error vector can turn, and an integral of ε along
//! whatever direction the error has now mixes up directions and chatters; there the law
//! runs per axis on the error vector ε·n (same scheduled gains, one PID per axis), which
//! holds any steady correction vector.
//!
//! Everything lives in fixed-size fields, so `sample` never allocates (it runs inside
//! `fmi2DoStep`) and the whole controller serialises with serde for FMU state saving.

use serde::{Deserialize, Serialize};
use serde_big_array::BigArray;

use super::ccc_law::{CccLaw, CccStep, VectorLaw};
use super::config::{CccMode, ConfigError, ControllerConfig};
use super::pid::Pid;
use crate::contour::{ContourEstimate, ContourEstimator};
use crate::geometry::{self, Vector};

/// What the controller produces each sample.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ControlOutput<const D: usize = 2> {
    /// Velocity commands to the drives, in axis order, mm/s (rad/s for rotary axes).
    pub u: Vector<D>,
    /// Following errors R − P, mm.
    pub following_error: Vector<D>,
    /// The estimator's contour error and normal this sample.
    pub contour: ContourEstimate<D>,
    /// CCC gains (Kp, Ki, Kd) used this sample; all 0 when the CCC is off.
    pub gains: (f64, f64, f64),
}

impl<const D: usize> Default for ControlOutput<D> {
    fn default() -> Self {
        ControlOutput {
            u: Vector::zeros(),
            following_error: Vector::zeros(),
            contour: ContourEstimate::default(),
            gains: (0.0, 0.0, 0.0),
        }
    }
}

/// Position control of `D` axes (two unless said otherwise) with cross-coupled contour
/// correction, generic over the contour estimator. Serialisable (for FMU state) whenever
/// the estimator is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CrossCoupledController<E, const D: usize = 2> {
    config: ControllerConfig<D>,
    #[serde(with = "BigArray")]
    axes: [Pid; D],
    /// The scalar law (D ≤ 2) and, for D ≥ 3, its per-axis form on the error vector (see
    /// the module docs).
    law: VectorLaw<D>,
    estimator: E,
}

impl<E, const D: usize> CrossCoupledController<E, D> {
    /// The same controller around the estimator `f` makes of this one: a restored state
    /// read with its estimator as saved ([`SavedEstimator`](crate::contour::planar::SavedEstimator)),
    /// resumed.
    pub fn map_estimator<F, Error>(
        self,
        f: impl FnOnce(E) -> Result<F, Error>,
    ) -> Result<CrossCoupledController<F, D>, Error> {
        Ok(CrossCoupledController {
            config: self.config,
            axes: self.axes,
            law: self.law,
            estimator: f(self.estimator)?,
        })
    }
}

impl<E: ContourEstimator<D>, const D: usize> CrossCoupledController<E, D> {
    /// Validates `config` and builds the controller around `estimator`.
    pub fn new(config: ControllerConfig<D>, estimator: E) -> Result<Self, ConfigError> {
        config.validate()?;
        Ok(Self {
            axes: config
                .axis
                .map(|gains| Pid::new(gains, config.ts, config.axis_limit)),
            law: VectorLaw::new(config.ccc, config.ts)?,
            estimator,
            config,
        })
    }

    /// The configuration in use.
    pub fn config(&self) -> &ControllerConfig<D> {
        &self.config
    }

    /// The contour estimator.
    pub fn estimator(&self) -> &E {
        &self.estimator
    }

    /// Mutable access to the contour estimator (e.g. to load a path).
    pub fn estimator_mut(&mut self) -> &mut E {
        &mut self.estimator
    }

    /// The contour law (state inspection).
    pub fn law(&self) -> &CccLaw {
        self.law.law()
    }

    /// The per-axis contour PIDs, used for D ≥ 3 (state inspection).
    pub fn contour_axes(&self) -> &[Pid; D] {
        self.law.components()
    }

    /// The position controllers, in axis order (state inspection).
    pub fn axes(&self) -> &[Pid; D] {
        &self.axes
    }

    /// One control sample: `reference` is the command point R, `actual` the measured
    /// point P (both mm). The estimator runs every sample, also with the CCC off, so its
    /// history and the reported contour error stay valid.
    pub fn sample(&mut self, reference: Vector<D>, actual: Vector<D>) -> ControlOutput<D> {
        let following_error = reference - actual;
        let axes = &mut self.axes;
        let mut u = Vector::from_fn(|i, _| axes[i].update(following_error[i]));
        let contour = self.estimator.estimate(reference, actual);
        let n = contour.normal;
        // A non-finite normal gets the same treatment as a non-finite error (see
        // `CccLaw::update`): no correction, CCC state untouched.
        let mut step = CccStep::default();
        if geometry::is_finite(&n) {
            if D <= 2 {
                step = self.law.update_scalar(contour.error);
                if self.law.law().config().mode != CccMode::Off {
                    u += n * step.correction;
                }
            } else {
                let correction;
                (correction, step) = self.law.update(contour.error, &contour.vector());
                u += correction;
            }
        }
        ControlOutput {
            u,
            following_error,
            contour,
            gains: step.gains.as_tuple(),
        }
    }

    /// [`CrossCoupledController::sample`] with a velocity feed-forward `feed_forward`
    /// (mm/s, the gain applied) added to the commands: the reference's velocity that a
    /// position loop alone only follows with a lag.
    pub fn sample_with(
        &mut self,
        reference: Vector<D>,
        actual: Vector<D>,
        feed_forward: Vector<D>,
    ) -> ControlOutput<D> {
        let mut out = self.sample(reference, actual);
        out.u += feed_forward;
        out
    }

    /// Back to the initial state: axis and contour integrators, previous errors and the
    /// estimator's history are cleared; the configuration is kept.
    pub fn reset(&mut self) {
        self.axes.iter_mut().for_each(Pid::reset);
        self.law.reset();
        self.estimator.reset();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contour::SpatialLineEstimator;
    use crate::path::Line;

    type V3 = Vector<3>;

    /// An estimator that replays given (error, normal) pairs.
    #[derive(Clone, Debug)]
    struct Replay(Vec<ContourEstimate<3>>, usize);

    impl ContourEstimator<3> for Replay {
        fn estimate(&mut self, _r: V3, _p: V3) -> ContourEstimate<3> {
            self.1 += 1;
            self.0[self.1 - 1]
        }
        fn reset(&mut self) {
            self.1 = 0;
        }
    }

    fn fixed_config() -> ControllerConfig<3> {
        let mut config = ControllerConfig::<3>::DEFAULT;
        config.ccc.mode = CccMode::Fixed;
        config
    }

    #[test]
    fn in_space_the_correction_is_a_pid_per_axis_on_the_error_vector() {
        // Kp0 = 100, Ki0 = 5000, Kd0 = 0, Ts = 1 ms, axis Kp = 28.5: with R = P the
        // position loops give 0, and the correction is Kp·e + Ki·Σe·Ts per axis.
        let e = |error, n: [f64; 3]| ContourEstimate {
            error,
            normal: V3::from(n),
        };
        let samples = vec![e(0.01, [0.0, 0.6, 0.8]), e(-0.02, [0.0, 0.6, 0.8])];
        let mut c = CrossCoupledController::new(fixed_config(), Replay(samples, 0)).unwrap();
        let p = V3::new(1.0, 2.0, 3.0);
        let u1 = c.sample(p, p).u;
        let v1 = V3::new(0.0, 0.006, 0.008);
        let expected1 = v1 * 100.0 + v1 * (5000.0 * 1e-3);
        assert!((u1 - expected1).amax() < 1e-12, "{u1:?} vs {expected1:?}");
        let u2 = c.sample(p, p).u;
        let v2 = V3::new(0.0, -0.012, -0.016);
        let expected2 = v2 * 100.0 + (v1 + v2) * (5000.0 * 1e-3);
        assert!((u2 - expected2).amax() < 1e-12, "{u2:?} vs {expected2:?}");
    }

    #[test]
    fn in_space_a_non_finite_error_gives_no_correction_and_keeps_state() {
        let e = |error| ContourEstimate {
            error,
            normal: V3::new(1.0, 0.0, 0.0),
        };
        let samples = vec![e(0.01), e(f64::NAN), e(f64::INFINITY), e(0.01)];
        let mut c = CrossCoupledController::new(fixed_config(), Replay(samples, 0)).unwrap();
        let p = V3::zeros();
        let first = c.sample(p, p).u;
        let integrals = c.contour_axes().each_ref().map(|pid| pid.integral());
        for _ in 0..2 {
            let out = c.sample(p, p);
            assert_eq!(out.u, V3::zeros());
            assert_eq!(
                c.contour_axes().each_ref().map(|pid| pid.integral()),
                integrals
            );
        }
        let last = c.sample(p, p).u;
        assert!(last[0].is_finite() && last[0] > first[0]);
        c.reset();
        assert!(c.contour_axes().iter().all(|pid| pid.integral() == 0.0));
    }

    #[test]
    fn one_axis_has_no_contour_error_and_no_correction() {
        let line = Line::<1>::new([0.0], [10.0]).unwrap();
        let mut c = CrossCoupledController::new(
            ControllerConfig::<1>::DEFAULT,
            SpatialLineEstimator::new(&line),
        )
        .unwrap();
        let out = c.sample(Vector::<1>::new(2.0), Vector::<1>::new(1.5));
        assert_eq!(out.contour.error, 0.0);
        assert_eq!(out.u[0], 28.5 * 0.5);
    }
}
