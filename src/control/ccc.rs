//! Two-axis cross-coupled contour controller (docs/design.md §4.2) with optional fuzzy gain
//! adaptation (docs/design.md §4.3).
//!
//! Per sample: following errors `e = R − P`; per-axis position controllers give velocity
//! commands `G(e)` (mm/s); the contour estimator gives the signed contour error ε and the
//! left unit normal n; the CCC law gives `U_c = Kp·ε + Ki·Σε·Ts + Kd·Δε/Ts`, and
//! `u = G(e) + n·U_c`. The fuzzy mode schedules (Kp, Ki, Kd) from ε and Δε every sample.
//!
//! Everything lives in fixed-size fields, so `sample` never allocates (it runs inside
//! `fmi2DoStep`) and the whole controller serialises with serde for FMU state saving.

use std::fmt;

use serde::{Deserialize, Serialize};

use super::fuzzy::{FuzzyEngine, FuzzyOutput};
use super::pid::{Pid, PidGains};
use crate::contour::{ContourEstimate, ContourEstimator};

/// How the contour correction `U_c` is produced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum CccMode {
    /// No cross-coupling: `U_c = 0`, pure independent axis loops (the baseline).
    Off,
    /// PID on ε with the fixed gains `gains0`.
    Fixed,
    /// PID on ε with gains `gains0 + (kpf·ΔKp′, kif·ΔKi′, kdf·ΔKd′)` from the fuzzy engine.
    #[default]
    Fuzzy,
}

/// Quantisation factors (inputs) and scale factors (outputs) of the fuzzy adaptation.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FuzzyFactors {
    /// kε: E = clamp(kε·ε, ±3) with ε in µm.
    pub ke: f64,
    /// kΔε: EC = clamp(kΔε·Δε, ±3) with Δε in µm per sample.
    pub kde: f64,
    /// kpf: ΔKp = kpf·ΔKp′ (1/s per unit of ΔKp′).
    pub kpf: f64,
    /// kif: ΔKi = kif·ΔKi′ (1/s² per unit).
    pub kif: f64,
    /// kdf: ΔKd = kdf·ΔKd′ (dimensionless per unit).
    pub kdf: f64,
}

impl FuzzyFactors {
    /// The paper's PSO optimum (kε, kΔε, kpf, kif, kdf) = (1, 1.2, 87, 8.5, 4).
    pub const PAPER: FuzzyFactors = FuzzyFactors {
        ke: 1.0,
        kde: 1.2,
        kpf: 87.0,
        kif: 8.5,
        kdf: 4.0,
    };
}

impl Default for FuzzyFactors {
    fn default() -> Self {
        Self::PAPER
    }
}

/// Configuration of the contour law (the part shared by every CCC, whatever the axes).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CccConfig {
    /// Off / fixed gains / fuzzy-adapted gains. Default: `Fuzzy`.
    pub mode: CccMode,
    /// Kp0 (1/s), Ki0 (1/s²), Kd0 (–). Default (100, 5000, 0): the PI CCC that docs/design.md §4.2
    /// measured at 0.08 µm on the paper's circle; near ε = 0 the fuzzy adjustments of Kp
    /// and Ki are zero, so the fuzzy mode keeps that accuracy in steady state.
    pub gains0: PidGains,
    /// Fuzzy quantisation/scale factors. Default: the paper's.
    pub fuzzy: FuzzyFactors,
    /// |U_c| bound in mm/s, enabling the anti-windup. Default 100 mm/s: far above the
    /// ≈ 1.4 mm/s the paper's circle needs, so it acts only on faults and large transients.
    /// `None`: unbounded (and no anti-windup).
    pub limit: Option<f64>,
}

impl CccConfig {
    /// The defaults documented on the fields (a constant, so FMU variable tables can use
    /// it for their start values).
    pub const DEFAULT: CccConfig = CccConfig {
        mode: CccMode::Fuzzy,
        gains0: PidGains {
            kp: 100.0,
            ki: 5000.0,
            kd: 0.0,
        },
        fuzzy: FuzzyFactors::PAPER,
        limit: Some(100.0),
    };
}

impl Default for CccConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Configuration of the two-axis controller.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ControllerConfig {
    /// Sample period, s. Default 1 ms.
    pub ts: f64,
    /// Position controllers G of X and Y (output mm/s per mm). Default P with
    /// Kpp = 28.5 1/s (docs/design.md §4.2).
    pub axis: [PidGains; 2],
    /// |G| bound in mm/s (enables the axis anti-windup). Default `None`: the plant has no
    /// limit by default.
    pub axis_limit: Option<f64>,
    /// The contour law.
    pub ccc: CccConfig,
}

impl ControllerConfig {
    /// The defaults documented on the fields (a constant, so FMU variable tables can use
    /// it for their start values).
    pub const DEFAULT: ControllerConfig = ControllerConfig {
        ts: 1e-3,
        axis: [PidGains {
            kp: 28.5,
            ki: 0.0,
            kd: 0.0,
        }; 2],
        axis_limit: None,
        ccc: CccConfig::DEFAULT,
    };
}

impl Default for ControllerConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// A rejected configuration value. `parameter` uses the FMI parameter names of docs/design.md §1
/// (`Ts`, `ccc.Kp0`, `fuzzy.ke`, …) so the FMU can report it verbatim.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConfigError {
    /// Name of the offending parameter.
    pub parameter: &'static str,
    /// Its value.
    pub value: f64,
    /// What it must satisfy.
    pub requirement: &'static str,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "parameter {} = {} is invalid: {}",
            self.parameter, self.value, self.requirement
        )
    }
}

impl std::error::Error for ConfigError {}

fn check(
    parameter: &'static str,
    value: f64,
    ok: bool,
    requirement: &'static str,
) -> Result<(), ConfigError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(ConfigError {
            parameter,
            value,
            requirement,
        })
    }
}

fn non_negative(parameter: &'static str, value: f64) -> Result<(), ConfigError> {
    check(parameter, value, value >= 0.0, "must be finite and >= 0")
}

fn limit(parameter: &'static str, value: Option<f64>) -> Result<(), ConfigError> {
    match value {
        Some(v) => check(parameter, v, v > 0.0, "must be finite and > 0 when set"),
        None => Ok(()),
    }
}

fn gains(names: [&'static str; 3], g: &PidGains) -> Result<(), ConfigError> {
    non_negative(names[0], g.kp)?;
    non_negative(names[1], g.ki)?;
    non_negative(names[2], g.kd)
}

impl CccConfig {
    /// Checks every value; the error names the first offending parameter.
    pub fn validate(&self) -> Result<(), ConfigError> {
        gains(["ccc.Kp0", "ccc.Ki0", "ccc.Kd0"], &self.gains0)?;
        let f = &self.fuzzy;
        non_negative("fuzzy.ke", f.ke)?;
        non_negative("fuzzy.kde", f.kde)?;
        non_negative("fuzzy.kp", f.kpf)?;
        non_negative("fuzzy.ki", f.kif)?;
        non_negative("fuzzy.kd", f.kdf)?;
        limit("ccc.limit", self.limit)
    }
}

impl ControllerConfig {
    /// Checks every value; the error names the first offending parameter. Negative gains
    /// are refused because they turn the negative feedback into positive feedback.
    pub fn validate(&self) -> Result<(), ConfigError> {
        check("Ts", self.ts, self.ts > 0.0, "must be finite and > 0")?;
        gains(["axis.x.Kp", "axis.x.Ki", "axis.x.Kd"], &self.axis[0])?;
        gains(["axis.y.Kp", "axis.y.Ki", "axis.y.Kd"], &self.axis[1])?;
        limit("axis.limit", self.axis_limit)?;
        self.ccc.validate()
    }
}

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
        check("Ts", ts, ts > 0.0, "must be finite and > 0")?;
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

/// What the controller produces each sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ControlOutput {
    /// Velocity commands to the X and Y drives, mm/s.
    pub u: [f64; 2],
    /// Following errors (ex, ey) = R − P, mm.
    pub following_error: [f64; 2],
    /// The estimator's contour error and normal this sample.
    pub contour: ContourEstimate,
    /// CCC gains (Kp, Ki, Kd) used this sample; all 0 when the CCC is off.
    pub gains: (f64, f64, f64),
}

/// Two-axis position control with cross-coupled contour correction, generic over the
/// contour estimator. Serialisable (for FMU state) whenever the estimator is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CrossCoupledController<E> {
    config: ControllerConfig,
    axes: [Pid; 2],
    law: CccLaw,
    estimator: E,
}

impl<E: ContourEstimator> CrossCoupledController<E> {
    /// Validates `config` and builds the controller around `estimator`.
    pub fn new(config: ControllerConfig, estimator: E) -> Result<Self, ConfigError> {
        config.validate()?;
        Ok(Self {
            axes: [
                Pid::new(config.axis[0], config.ts, config.axis_limit),
                Pid::new(config.axis[1], config.ts, config.axis_limit),
            ],
            law: CccLaw::new(config.ccc, config.ts)?,
            estimator,
            config,
        })
    }

    /// The configuration in use.
    pub fn config(&self) -> &ControllerConfig {
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
        &self.law
    }

    /// The X and Y position controllers (state inspection).
    pub fn axes(&self) -> &[Pid; 2] {
        &self.axes
    }

    /// One control sample: `reference` is the command point R, `actual` the measured
    /// point P (both mm). The estimator runs every sample, also with the CCC off, so its
    /// history and the reported contour error stay valid.
    pub fn sample(&mut self, reference: [f64; 2], actual: [f64; 2]) -> ControlOutput {
        let following_error = [reference[0] - actual[0], reference[1] - actual[1]];
        let mut u = [
            self.axes[0].update(following_error[0]),
            self.axes[1].update(following_error[1]),
        ];
        let contour = self.estimator.estimate(reference, actual);
        let n = contour.normal;
        // A non-finite normal gets the same treatment as a non-finite error (see
        // `CccLaw::update`): no correction, CCC state untouched.
        let mut step = CccStep::default();
        if n[0].is_finite() && n[1].is_finite() {
            step = self.law.update(contour.error);
            if self.law.config.mode != CccMode::Off {
                u[0] += n[0] * step.correction;
                u[1] += n[1] * step.correction;
            }
        }
        ControlOutput {
            u,
            following_error,
            contour,
            gains: step.gains.as_tuple(),
        }
    }

    /// Back to the initial state: axis and contour integrators, previous errors and the
    /// estimator's history are cleared; the configuration is kept.
    pub fn reset(&mut self) {
        self.axes[0].reset();
        self.axes[1].reset();
        self.law.reset();
        self.estimator.reset();
    }
}
