//! The scalar contour law ε → U_c = Kp·ε + Ki·Σε·Ts + Kd·Δε/Ts, with the gains fixed or
//! scheduled every sample by the fuzzy system from ε and Δε (docs/design/two-axis.md §4.3). It
//! knows nothing of axes: the two-axis and N-axis controllers (and a five-axis one, one
//! law per contour error) apply its output along their own directions.

use serde::{Deserialize, Serialize};
use serde_big_array::BigArray;

use super::config::ConfigError;
use super::config::{check, CccConfig, CccMode, FuzzyFactors, Parameter};
use super::fuzzy::{FuzzyEngine, FuzzyOutput};
use super::pid::{Pid, PidGains};
use crate::geometry::{self, Vector};

/// The normalised fuzzy inputs (E′, EC′) for contour error `error` (mm) and its change
/// `delta` (mm per sample), before the engine's ±3 clamp:
/// E′ = −|kε·ε|, EC′ = −s·kΔε·Δε with ε, Δε in µm and s = sgn(ε) (sgn(Δε) when ε = 0).
///
/// The rule tables are not odd in (E, EC); read at the signed ε they would give a path
/// and its mirror image different gains. Folded, the gains depend only on |ε| and on
/// whether |ε| grows (EC′ < 0) or shrinks (EC′ > 0), read from the half of the tables
/// where Kp grows and Ki shrinks as |ε| grows. The increments stay unsigned: the PID's
/// product with ε carries the sign of the correction (docs/design/two-axis.md §4.3).
pub fn folded_inputs(factors: &FuzzyFactors, error: f64, delta: f64) -> (f64, f64) {
    // Compare with 0 rather than use `signum`, which gives ±1 for ±0.
    let s = if error > 0.0 || (error == 0.0 && delta > 0.0) {
        1.0
    } else {
        -1.0
    };
    (
        -(factors.ke * error * 1e3).abs(),
        -s * factors.kde * delta * 1e3,
    )
}

/// The scalar contour law ε → U_c with optional fuzzy gain scheduling. Separate from the
/// two-axis controller so other CCCs (e.g. five-axis, one law per contour error) can
/// reuse it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CccLaw {
    config: CccConfig,
    pid: Pid,
    /// Constant rule tables: not part of the saved state, rebuilt on restore.
    #[serde(skip)]
    engine: FuzzyEngine,
}

/// One step of [`CccLaw`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CccStep {
    /// Correction U_c, mm/s (0 when off).
    pub correction: f64,
    /// Gains used this sample (all 0 when off).
    pub gains: PidGains,
    /// The fuzzy engine's raw outputs ΔKp′, ΔKi′, ΔKd′ (0 unless in fuzzy mode).
    pub fuzzy: FuzzyOutput,
}

impl CccLaw {
    /// A law with sample period `ts` (s).
    pub fn new(config: CccConfig, ts: f64) -> Result<Self, ConfigError> {
        check(Parameter::Ts, ts, ts > 0.0, "must be finite and > 0")?;
        config.validate()?;
        Ok(Self {
            pid: Pid::new(config.gains0, ts, config.limit),
            engine: FuzzyEngine::default(),
            config,
        })
    }

    /// The configuration in use.
    pub fn config(&self) -> &CccConfig {
        &self.config
    }

    /// The underlying PID (state inspection).
    pub fn pid(&self) -> &Pid {
        &self.pid
    }

    /// The fuzzy engine in use.
    pub fn engine(&self) -> &FuzzyEngine {
        &self.engine
    }

    /// Gains for contour error `error` (mm) and its change `delta` (mm per sample).
    ///
    /// Fixed mode returns `gains0`; fuzzy mode `gains0 + k·ΔK′` with the rule tables read
    /// at the folded inputs of [`folded_inputs`], each gain clamped at ≥ 0. The gains are
    /// the same for (ε, Δε) and (−ε, −Δε), so a path and its mirror image get the same
    /// control (docs/design/two-axis.md §4.3, direction symmetry).
    pub fn schedule(&self, error: f64, delta: f64) -> (PidGains, FuzzyOutput) {
        let g0 = self.config.gains0;
        match self.config.mode {
            CccMode::Off => (PidGains::ZERO, FuzzyOutput::default()),
            CccMode::Fixed => (g0, FuzzyOutput::default()),
            CccMode::Fuzzy => {
                let f = &self.config.fuzzy;
                let (e, ec) = folded_inputs(f, error, delta);
                // The engine clamps its inputs to ±3.
                let out = self.engine.evaluate(e, ec);
                let gains = PidGains::new(
                    (g0.kp + f.kpf * out.dkp).max(0.0),
                    (g0.ki + f.kif * out.dki).max(0.0),
                    (g0.kd + f.kdf * out.dkd).max(0.0),
                );
                (gains, out)
            }
        }
    }

    /// Advances one sample with contour error `error` (mm).
    ///
    /// Off mode, or a non-finite error, leaves the state untouched and returns a zero
    /// correction: a broken estimate must not poison the integrator for the rest of the
    /// run (the caller still sees the bad estimate it passed in).
    pub fn update(&mut self, error: f64) -> CccStep {
        self.update_with(error, true)
    }

    /// [`CccLaw::update`], integrating only if `integrate` (anti-windup from outside).
    pub fn update_with(&mut self, error: f64, integrate: bool) -> CccStep {
        if self.config.mode == CccMode::Off || !error.is_finite() {
            return CccStep::default();
        }
        let (gains, fuzzy) = self.schedule(error, self.pid.difference(error));
        self.pid.set_gains(gains);
        CccStep {
            correction: self.pid.update_with(error, integrate),
            gains,
            fuzzy,
        }
    }

    /// Forgets the integral and the previous error.
    pub fn reset(&mut self) {
        self.pid.reset();
        self.pid.set_gains(self.config.gains0);
    }
}

/// The contour law applied to an error vector: the scalar law schedules the gains from the
/// error's size (and keeps its own PID for callers that want the scalar correction), and
/// one PID per component, with those gains, gives the correction vector.
///
/// Why per component: in space the direction of the error turns (the normal space of a
/// curve is a plane, an orientation error has two directions), and an integral of the
/// magnitude along whatever direction the error has now mixes directions up and chatters;
/// per component the integrals hold any steady correction vector.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VectorLaw<const D: usize> {
    law: CccLaw,
    #[serde(with = "BigArray")]
    components: [Pid; D],
}

impl<const D: usize> VectorLaw<D> {
    /// A law with sample period `ts` (s).
    pub fn new(config: CccConfig, ts: f64) -> Result<Self, ConfigError> {
        let law = CccLaw::new(config, ts)?;
        Ok(Self {
            components: [(); D].map(|_| Pid::new(config.gains0, ts, config.limit)),
            law,
        })
    }

    /// The scalar law (scheduling state).
    pub fn law(&self) -> &CccLaw {
        &self.law
    }

    /// Advances the scalar law alone with the signed contour error `error` (its own
    /// correction is the scalar one; the components are left alone).
    pub fn update_scalar(&mut self, error: f64) -> CccStep {
        self.law.update(error)
    }

    /// The per-component PIDs (state inspection).
    pub fn components(&self) -> &[Pid; D] {
        &self.components
    }

    /// Advances one sample: gains scheduled from `size` (the error's magnitude, or the
    /// signed scalar the scheduling should see), correction per component of `error`.
    /// Off mode, or a non-finite size or vector, gives a zero correction and leaves the
    /// component integrals untouched.
    pub fn update(&mut self, size: f64, error: &Vector<D>) -> (Vector<D>, CccStep) {
        self.update_with(size, error, true)
    }

    /// [`VectorLaw::update`], integrating only if `integrate`: the caller holds the
    /// integrals while what it does with the correction saturates (anti-windup).
    pub fn update_with(
        &mut self,
        size: f64,
        error: &Vector<D>,
        integrate: bool,
    ) -> (Vector<D>, CccStep) {
        let step = self.law.update_with(size, integrate);
        if self.law.config().mode == CccMode::Off
            || !size.is_finite()
            || !geometry::is_finite(error)
        {
            return (Vector::zeros(), step);
        }
        let components = &mut self.components;
        let correction = Vector::from_fn(|i, _| {
            components[i].set_gains(step.gains);
            components[i].update_with(error[i], integrate)
        });
        (correction, step)
    }

    /// [`VectorLaw::update_with`] with the integrals held in the plane normal to the unit
    /// vector `along` (the path's tangent for a tip error, the tool axis for an
    /// orientation error): before the update their component along it is removed.
    ///
    /// The error has no component along `along`, but an integral of it does once the
    /// direction turns (the path bends, the tool tilts): kept, that stale part would
    /// push the tool along the path — the position loops' business — or spin it about
    /// its own axis. In the plane this is what the scalar law's integral along the
    /// turning normal does by construction.
    pub fn update_normal_to(
        &mut self,
        size: f64,
        error: &Vector<D>,
        along: &Vector<D>,
        integrate: bool,
    ) -> (Vector<D>, CccStep) {
        if geometry::is_finite(along) {
            let integral = Vector::<D>::from_fn(|i, _| self.components[i].integral());
            let normal = integral - along * integral.dot(along);
            for (pid, value) in self.components.iter_mut().zip(normal.iter()) {
                pid.set_integral(*value);
            }
        }
        self.update_with(size, error, integrate)
    }

    /// Forgets integrals and previous errors.
    pub fn reset(&mut self) {
        self.law.reset();
        self.components.iter_mut().for_each(Pid::reset);
    }
}
