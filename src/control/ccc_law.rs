//! The scalar contour law ε → U_c = Kp·ε + Ki·Σε·Ts + Kd·Δε/Ts, with the gains fixed or
//! scheduled every sample by the fuzzy system from ε and Δε (docs/design.md §4.3). It
//! knows nothing of axes: the two-axis and N-axis controllers (and a five-axis one, one
//! law per contour error) apply its output along their own directions.

use serde::{Deserialize, Serialize};

use super::config::ConfigError;
use super::config::{check, CccConfig, CccMode, FuzzyFactors, Parameter};
use super::fuzzy::{FuzzyEngine, FuzzyOutput};
use super::pid::{Pid, PidGains};

/// The normalised fuzzy inputs (E′, EC′) for contour error `error` (mm) and its change
/// `delta` (mm per sample), before the engine's ±3 clamp:
/// E′ = −|kε·ε|, EC′ = −s·kΔε·Δε with ε, Δε in µm and s = sgn(ε) (sgn(Δε) when ε = 0).
///
/// The rule tables are not odd in (E, EC); read at the signed ε they would give a path
/// and its mirror image different gains. Folded, the gains depend only on |ε| and on
/// whether |ε| grows (EC′ < 0) or shrinks (EC′ > 0), read from the half of the tables
/// where Kp grows and Ki shrinks as |ε| grows. The increments stay unsigned: the PID's
/// product with ε carries the sign of the correction (docs/design.md §4.3).
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
    /// control (docs/design.md §4.3, direction symmetry).
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
        if self.config.mode == CccMode::Off || !error.is_finite() {
            return CccStep::default();
        }
        let (gains, fuzzy) = self.schedule(error, self.pid.difference(error));
        self.pid.set_gains(gains);
        CccStep {
            correction: self.pid.update(error),
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
