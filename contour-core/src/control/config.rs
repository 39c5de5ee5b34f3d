//! Controller configuration: the contour law's (mode, base gains, fuzzy factors, limit)
//! and the N-axis controller's (sample period, one position loop per axis), with the
//! checks that refuse values turning the feedback unstable or meaningless.
//!
//! A rejected value is named by its place in the configuration ([`Parameter`]); the FMU
//! models translate that into their own variable names.

use std::fmt;

use serde::{Deserialize, Serialize};
use serde_big_array::BigArray;

use super::pid::PidGains;

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
    /// Kp0 (1/s), Ki0 (1/s²), Kd0 (–). Default (100, 5000, 0): the PI CCC that docs/design/two-axis.md §4.2
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

/// Configuration of an N-axis controller (two axes unless said otherwise).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ControllerConfig<const D: usize = 2> {
    /// Sample period, s. Default 1 ms.
    pub ts: f64,
    /// Position controllers G, one per axis in axis order (output mm/s per mm, or rad/s
    /// per rad). Default P with Kpp = 28.5 1/s (docs/design/two-axis.md §4.2).
    #[serde(with = "BigArray")]
    pub axis: [PidGains; D],
    /// |G| bound in mm/s (enables the axis anti-windup). Default `None`: the plant has no
    /// limit by default.
    pub axis_limit: Option<f64>,
    /// The contour law.
    pub ccc: CccConfig,
}

impl<const D: usize> ControllerConfig<D> {
    /// The defaults documented on the fields (a constant, so FMU variable tables can use
    /// it for their start values).
    pub const DEFAULT: Self = ControllerConfig {
        ts: 1e-3,
        axis: [PidGains {
            kp: 28.5,
            ki: 0.0,
            kd: 0.0,
        }; D],
        axis_limit: None,
        ccc: CccConfig::DEFAULT,
    };
}

impl<const D: usize> Default for ControllerConfig<D> {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// One of the three PID gains.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Gain {
    /// Proportional.
    Kp,
    /// Integral.
    Ki,
    /// Derivative.
    Kd,
}

/// One of the five fuzzy factors (the fields of [`FuzzyFactors`], in order).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FuzzyFactor {
    /// Input scaling of the contour error E.
    Ke,
    /// Input scaling of its change ΔE.
    Kde,
    /// Output scaling of ΔKp.
    Kpf,
    /// Output scaling of ΔKi.
    Kif,
    /// Output scaling of ΔKd.
    Kdf,
}

/// Where a configuration value lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Parameter {
    /// `ControllerConfig::ts` (also the law's own period).
    Ts,
    /// A gain of the position loop of axis `.0` (0-based, in axis order).
    AxisGain(usize, Gain),
    /// `ControllerConfig::axis_limit`.
    AxisLimit,
    /// A base gain of the contour law, `CccConfig::gains0`.
    ContourGain(Gain),
    /// `CccConfig::limit`.
    ContourLimit,
    /// A fuzzy factor, `CccConfig::fuzzy`.
    Fuzzy(FuzzyFactor),
    /// Five-axis: a base gain of the orientation law.
    OrientationGain(Gain),
    /// Five-axis: the orientation law's limit.
    OrientationLimit,
    /// Five-axis: a fuzzy factor of the orientation law.
    OrientationFuzzy(FuzzyFactor),
    /// Five-axis: μ of the damped least squares.
    Damping,
    /// Five-axis: the tool length of the mapping.
    ToolLength,
    /// Five-axis: the mapping's largest skip per sample.
    MaxSkip,
    /// Five-axis: the mapping's weight of the motion angle.
    AngleWeight,
    /// Five-axis: segments in the online mapping's band.
    Band,
    /// Five-axis: samples the online mapping can read back.
    Lag,
    /// Five-axis: the online mapping's beam.
    Beam,
    /// Five-axis: coordinate `.1` (x, y, z) of pivot `.0` (0 = A axis, 1 = C axis).
    Pivot(usize, usize),
    /// Five-axis: the least position of joint `.0` (X Y Z A C).
    TravelMin(usize),
    /// Five-axis: the greatest position of joint `.0`.
    TravelMax(usize),
    /// Five-axis: the greatest speed of joint `.0`.
    JointSpeed(usize),
    /// Five-axis: the greatest acceleration of joint `.0`.
    JointAcceleration(usize),
    /// Five-axis: the correction's share of each joint's speed.
    CorrectionShare,
    /// Five-axis: the correction's recovery time.
    Recovery,
    /// Five-axis: the damping's growth at the singular pose.
    PoleDamping,
    /// Five-axis: the cone where the damping grows.
    PoleCone,
}

impl Parameter {
    /// The orientation law's counterpart of a contour-law parameter (others unchanged).
    pub fn orientation(self) -> Parameter {
        match self {
            Parameter::ContourGain(g) => Parameter::OrientationGain(g),
            Parameter::ContourLimit => Parameter::OrientationLimit,
            Parameter::Fuzzy(k) => Parameter::OrientationFuzzy(k),
            other => other,
        }
    }
}

impl fmt::Display for Parameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let gain = |g: &Gain| match g {
            Gain::Kp => "kp",
            Gain::Ki => "ki",
            Gain::Kd => "kd",
        };
        let factor = |k: &FuzzyFactor| match k {
            FuzzyFactor::Ke => "ke",
            FuzzyFactor::Kde => "kde",
            FuzzyFactor::Kpf => "kpf",
            FuzzyFactor::Kif => "kif",
            FuzzyFactor::Kdf => "kdf",
        };
        match self {
            Parameter::Ts => write!(f, "ts"),
            Parameter::AxisGain(i, g) => write!(f, "axis[{i}].{}", gain(g)),
            Parameter::AxisLimit => write!(f, "axis_limit"),
            Parameter::ContourGain(g) => write!(f, "ccc.gains0.{}", gain(g)),
            Parameter::ContourLimit => write!(f, "ccc.limit"),
            Parameter::Fuzzy(k) => write!(f, "ccc.fuzzy.{}", factor(k)),
            Parameter::OrientationGain(g) => write!(f, "orientation.gains0.{}", gain(g)),
            Parameter::OrientationLimit => write!(f, "orientation.limit"),
            Parameter::OrientationFuzzy(k) => write!(f, "orientation.fuzzy.{}", factor(k)),
            Parameter::Damping => write!(f, "damping"),
            Parameter::ToolLength => write!(f, "tool_length"),
            Parameter::MaxSkip => write!(f, "hmm.max_skip"),
            Parameter::AngleWeight => write!(f, "hmm.angle_weight"),
            Parameter::Band => write!(f, "band"),
            Parameter::Lag => write!(f, "lag"),
            Parameter::Beam => write!(f, "beam"),
            Parameter::Pivot(i, k) => {
                write!(f, "{}_pivot.{}", ["a", "c"][*i], ["x", "y", "z"][*k])
            }
            Parameter::TravelMin(i) => write!(f, "limits.min[{i}]"),
            Parameter::TravelMax(i) => write!(f, "limits.max[{i}]"),
            Parameter::JointSpeed(i) => write!(f, "limits.velocity[{i}]"),
            Parameter::JointAcceleration(i) => write!(f, "limits.acceleration[{i}]"),
            Parameter::CorrectionShare => write!(f, "correction_share"),
            Parameter::Recovery => write!(f, "recovery"),
            Parameter::PoleDamping => write!(f, "pole_damping"),
            Parameter::PoleCone => write!(f, "pole_cone"),
        }
    }
}

/// A rejected configuration value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConfigError {
    /// Which value.
    pub parameter: Parameter,
    /// Its value.
    pub value: f64,
    /// What it must satisfy.
    pub requirement: &'static str,
}

impl ConfigError {
    /// The same error, said of `parameter`.
    pub fn with_parameter(self, parameter: Parameter) -> ConfigError {
        ConfigError { parameter, ..self }
    }

    /// The message with the parameter called `name` (an FMU's variable name, say).
    pub fn message_for(&self, name: &str) -> String {
        format!(
            "parameter {name} = {} is invalid: {}",
            self.value, self.requirement
        )
    }
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message_for(&self.parameter.to_string()))
    }
}

impl std::error::Error for ConfigError {}

/// `Ok` when `value` is finite and `ok`; otherwise the error naming `parameter`.
pub(crate) fn check(
    parameter: Parameter,
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

fn non_negative(parameter: Parameter, value: f64) -> Result<(), ConfigError> {
    check(parameter, value, value >= 0.0, "must be finite and >= 0")
}

fn limit(parameter: Parameter, value: Option<f64>) -> Result<(), ConfigError> {
    match value {
        Some(v) => check(parameter, v, v > 0.0, "must be finite and > 0 when set"),
        None => Ok(()),
    }
}

fn gains(place: impl Fn(Gain) -> Parameter, g: &PidGains) -> Result<(), ConfigError> {
    non_negative(place(Gain::Kp), g.kp)?;
    non_negative(place(Gain::Ki), g.ki)?;
    non_negative(place(Gain::Kd), g.kd)
}

impl CccConfig {
    /// Checks every value; the error names the first offending parameter.
    pub fn validate(&self) -> Result<(), ConfigError> {
        gains(Parameter::ContourGain, &self.gains0)?;
        let f = &self.fuzzy;
        non_negative(Parameter::Fuzzy(FuzzyFactor::Ke), f.ke)?;
        non_negative(Parameter::Fuzzy(FuzzyFactor::Kde), f.kde)?;
        non_negative(Parameter::Fuzzy(FuzzyFactor::Kpf), f.kpf)?;
        non_negative(Parameter::Fuzzy(FuzzyFactor::Kif), f.kif)?;
        non_negative(Parameter::Fuzzy(FuzzyFactor::Kdf), f.kdf)?;
        limit(Parameter::ContourLimit, self.limit)
    }
}

impl<const D: usize> ControllerConfig<D> {
    /// Checks every value; the error names the first offending parameter. Negative gains
    /// are refused because they turn the negative feedback into positive feedback.
    pub fn validate(&self) -> Result<(), ConfigError> {
        check(
            Parameter::Ts,
            self.ts,
            self.ts > 0.0,
            "must be finite and > 0",
        )?;
        for (i, g) in self.axis.iter().enumerate() {
            gains(|gain| Parameter::AxisGain(i, gain), g)?;
        }
        limit(Parameter::AxisLimit, self.axis_limit)?;
        self.ccc.validate()
    }
}
