//! Five-axis cross-coupled contour controller (docs/design/five-axis.md §5.4).
//!
//! Per sample, with joint reference q_r and measured joints q (X, Y, Z mm; A, C rad):
//! 1. the axis position loops give u = G(q_r − q), per joint;
//! 2. the forward kinematics turn q_r into the next reference pose, appended to the
//!    online HMM mapper's reference, and q into the actual pose, which the mapper assigns
//!    to a reference segment (docs/design/five-axis.md §5.2);
//! 3. on that segment the foot point gives the tip error vector ε_t (to the foot, mm) and
//!    the orientation error as a rotation vector ε_o (axis × angle turning the actual tool
//!    axis onto the slerped reference axis, rad);
//! 4. one contour law per error ([`VectorLaw`]: gains scheduled from |ε|, one PID per
//!    component) gives a tip velocity v (mm/s) and an angular velocity ω (rad/s);
//! 5. the workpiece-frame correction (v, ω × o) — the change of the unit tool axis o that
//!    ω causes — becomes joint velocities through the damped least-squares inverse of the
//!    kinematic Jacobian, added to u.
//!
//! ω × o is orthogonal to o like every column of ∂o/∂q, so where the Jacobian has full
//! rank the six equations are consistent and the least-squares solution meets both the
//! tip and the orientation correction exactly; near A = 0 the damping keeps it bounded.
//!
//! Fixed-size state apart from the mapper's rings (sized once at construction), so
//! `sample` never allocates.

use serde::{Deserialize, Serialize};

use super::ccc_law::{CccStep, VectorLaw};
use super::config::{check, CccConfig, CccMode, ConfigError, Parameter};
use super::pid::{Pid, PidGains};
use crate::contour::five_axis::evaluation_online::{OnlineEvaluation, PointEvaluation};
use crate::contour::five_axis::hmm::HmmParams;
use crate::contour::five_axis::hmm_online::OnlineMapper;
use crate::contour::five_axis::pose_error::{foot_near, PoseError};
use crate::geometry::{self, Vector};
use crate::kinematics::{damped_least_squares, Joints, Pose, TableTiltingAc};

/// Configuration of the five-axis controller.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FiveAxisConfig {
    /// Sample period, s. Default 1 ms.
    pub ts: f64,
    /// Position loops of X, Y, Z (mm/s per mm) and A, C (rad/s per rad). Default P with
    /// Kpp = 28.5 1/s on every joint, as the two-axis controller.
    pub axis: [PidGains; 5],
    /// Bound on each position loop's output (mm/s or rad/s), `None`: unbounded.
    pub axis_limit: Option<f64>,
    /// The law on the tip error (mm → mm/s). Default: the two-axis CCC's defaults.
    pub tip: CccConfig,
    /// The law on the orientation error (rad → rad/s); the fuzzy inputs read the error in
    /// mrad where the tip law reads µm. Default: the same gains as the tip law.
    pub orientation: CccConfig,
    /// μ of the damped least squares (docs/design/five-axis.md §5.4). Default 0.01: below 1e-4
    /// relative change of the correction wherever the Jacobian's singular values exceed 1
    /// (mm per mm, or per rad), and |Δq| ≤ |e|/(2μ) at A = 0.
    pub damping: f64,
    /// Tool length L of the mapping's second point, mm. Default 100.
    pub tool_length: f64,
    /// The mapping's costs and largest skip per sample.
    pub hmm: HmmParams,
    /// Segments the online mapping considers (the newest ones). Default 64: the measured
    /// tool trails the reference by 1/(Kpp·Ts) ≈ 35 samples with the default loops,
    /// whatever the feed.
    pub band: usize,
    /// How many samples back a mapping can be read (for the lagging estimates). Default 16.
    pub lag: usize,
    /// The online mapping keeps the states within this much summed cost (mm) of the best.
    /// Default 5 mm: a state that far behind gains about its distance from the tool every
    /// sample and does not come back, while the live ones — a few segments around the
    /// tool — are kept; the work per sample drops from the band to those (a third of the
    /// instructions of the full band, the same mapping on both built-ins).
    pub beam: f64,
    /// Compute the evaluation-function estimate online (docs/design/five-axis.md §5.6). Default on;
    /// it is a diagnostic the control law does not use, and about 40 % of a sample's cost.
    pub evaluate: bool,
    /// The machine.
    pub machine: TableTiltingAc,
}

impl FiveAxisConfig {
    /// The defaults documented on the fields.
    pub const DEFAULT: FiveAxisConfig = FiveAxisConfig {
        ts: 1e-3,
        axis: [PidGains::p(28.5); 5],
        axis_limit: None,
        tip: CccConfig::DEFAULT,
        orientation: CccConfig::DEFAULT,
        damping: 0.01,
        tool_length: 100.0,
        hmm: HmmParams {
            max_skip: 3,
            angle_weight: 0.5,
        },
        band: 128,
        lag: 16,
        beam: 5.0,
        evaluate: true,
        machine: TableTiltingAc::ORIGIN,
    };

    /// Both laws in `mode`.
    pub fn with_mode(mut self, mode: CccMode) -> Self {
        self.tip.mode = mode;
        self.orientation.mode = mode;
        self
    }

    /// Checks every value; the error names the first offending parameter.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let axes = super::config::ControllerConfig::<5> {
            ts: self.ts,
            axis: self.axis,
            axis_limit: self.axis_limit,
            ccc: self.tip,
        };
        axes.validate()?;
        self.orientation
            .validate()
            .map_err(|e| e.with_parameter(Parameter::orientation(e.parameter)))?;
        check(
            Parameter::Damping,
            self.damping,
            self.damping > 0.0,
            "must be finite and > 0",
        )?;
        check(
            Parameter::ToolLength,
            self.tool_length,
            self.tool_length > 0.0,
            "must be finite and > 0 mm",
        )?;
        check(
            Parameter::Beam,
            self.beam,
            self.beam > 0.0,
            "must be finite and > 0 mm",
        )?;
        check(
            Parameter::AngleWeight,
            self.hmm.angle_weight,
            self.hmm.angle_weight >= 0.0,
            "must be finite and >= 0 mm/rad",
        )?;
        let count = |parameter, value: usize, range: std::ops::RangeInclusive<usize>| {
            check(
                parameter,
                value as f64,
                range.contains(&value),
                "must be a whole number in its documented range",
            )
        };
        count(Parameter::MaxSkip, self.hmm.max_skip, 1..=64)?;
        count(Parameter::Band, self.band, 2..=4096)?;
        count(Parameter::Lag, self.lag, 0..=4096)?;
        for (i, v) in [self.machine.a_pivot, self.machine.c_pivot]
            .iter()
            .enumerate()
        {
            for (k, x) in v.iter().enumerate() {
                check(Parameter::Pivot(i, k), *x, true, "must be finite")?;
            }
        }
        Ok(())
    }
}

/// The online mapping `config` asks for.
fn mapper(config: &FiveAxisConfig) -> OnlineMapper {
    OnlineMapper::new(config.hmm, config.tool_length, config.band, config.lag)
        .with_beam(config.beam)
}

impl Default for FiveAxisConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What the controller produces each sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FiveAxisOutput {
    /// Joint velocity commands (mm/s, rad/s).
    pub u: Joints,
    /// q_r − q.
    pub following_error: Joints,
    /// The reference segment the actual pose is mapped to, once the reference has one.
    pub segment: Option<usize>,
    /// Tip and orientation errors on that segment (`None` before there is one).
    pub error: Option<PoseError>,
    /// The joint-velocity correction added to the position loops.
    pub correction: Joints,
    /// The tip law's step.
    pub tip_step: CccStep,
    /// The orientation law's step.
    pub orientation_step: CccStep,
    /// The newest evaluation-function estimate (docs/design/five-axis.md §5.3), for a reference
    /// point the settled mapping has passed: it describes the tool `lag` or more samples
    /// ago ([`PointEvaluation::sample`]).
    pub evaluation: Option<PointEvaluation>,
}

/// Why a sample was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleError {
    /// A reference joint is NaN or infinite.
    NonFiniteReference,
    /// A measured joint is NaN or infinite.
    NonFiniteActual,
}

impl std::fmt::Display for SampleError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SampleError::NonFiniteReference => "a reference joint is not finite",
            SampleError::NonFiniteActual => "a measured joint is not finite",
        })
    }
}

/// The five-axis controller. It serialises whole (FMU state save/restore); bytes from
/// elsewhere go through [`FiveAxisController::check`] before use.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FiveAxisController {
    config: FiveAxisConfig,
    axes: [Pid; 5],
    tip: VectorLaw<3>,
    orientation: VectorLaw<3>,
    mapper: OnlineMapper,
    evaluation: OnlineEvaluation,
    /// The last reference pose given to the mapper.
    last_reference: LastReference,
}

/// The last reference pose given to the mapper, if any; saved as an `Option<Pose>`.
///
/// Not held as an `Option<Pose>`: the optimised `last != Some(wanted)` compares the
/// payload before the tag, and the payload of a `None` is uninitialised bytes, so the
/// first sample branched on them (valgrind's memcheck reported it). Here every byte
/// compared is written.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(from = "Option<Pose>", into = "Option<Pose>")]
struct LastReference {
    /// Zero while `held` is false.
    pose: Pose,
    held: bool,
}

impl LastReference {
    fn none() -> Self {
        LastReference {
            pose: Pose {
                tip: Vector::zeros(),
                axis: Vector::zeros(),
            },
            held: false,
        }
    }

    fn get(&self) -> Option<&Pose> {
        self.held.then_some(&self.pose)
    }
}

impl From<Option<Pose>> for LastReference {
    fn from(pose: Option<Pose>) -> Self {
        pose.map_or_else(LastReference::none, |pose| LastReference {
            pose,
            held: true,
        })
    }
}

impl From<LastReference> for Option<Pose> {
    fn from(last: LastReference) -> Self {
        last.get().copied()
    }
}

impl FiveAxisController {
    /// Validates `config` and builds the controller (the only allocation: the mapper's
    /// rings).
    pub fn new(config: FiveAxisConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        Ok(FiveAxisController {
            axes: config
                .axis
                .map(|gains| Pid::new(gains, config.ts, config.axis_limit)),
            tip: VectorLaw::new(config.tip, config.ts)?,
            orientation: VectorLaw::new(config.orientation, config.ts)
                .map_err(|e| e.with_parameter(Parameter::orientation(e.parameter)))?,
            mapper: mapper(&config),
            evaluation: OnlineEvaluation::new(config.hmm.max_skip, config.lag),
            last_reference: LastReference::none(),
            config,
        })
    }

    /// The configuration in use.
    pub fn config(&self) -> &FiveAxisConfig {
        &self.config
    }

    /// The online mapping (to read back lagged decisions).
    pub fn mapper(&self) -> &OnlineMapper {
        &self.mapper
    }

    /// One control sample with reference joints `reference` and measured joints
    /// `actual`. A non-finite input is refused and leaves the state as it was.
    pub fn sample(
        &mut self,
        reference: &Joints,
        actual: &Joints,
    ) -> Result<FiveAxisOutput, SampleError> {
        if !geometry::is_finite(reference) {
            return Err(SampleError::NonFiniteReference);
        }
        if !geometry::is_finite(actual) {
            return Err(SampleError::NonFiniteActual);
        }
        let following_error = reference - actual;
        let axes = &mut self.axes;
        let mut u = Joints::from_fn(|i, _| axes[i].update(following_error[i]));

        let machine = &self.config.machine;
        let wanted = machine.forward(reference);
        // A reference that stands still (before the start, after the end, in a dwell)
        // adds no segment: zero-length segments would crowd the band and pull the
        // mapping onto the standing point.
        if self.last_reference.get() != Some(&wanted) {
            self.mapper.push_reference(wanted.tip, wanted.axis);
            self.last_reference = Some(wanted).into();
        }
        let pose = machine.forward(actual);
        let segment = self.mapper.push_sample(pose.tip, pose.axis);
        let mapper = &self.mapper;
        // The foot may lie past the newest reference point: the reference is continued
        // there (docs/design/five-axis.md §5.3).
        let foot = segment
            .and_then(|j| foot_near(|i| mapper.extended_segment(i), j, &pose))
            .map(|(_, e, tangent)| (e, tangent));
        let error = foot.map(|(e, _)| e);
        let evaluation = if self.config.evaluate {
            self.evaluation
                .push(machine, &self.mapper, self.config.lag, actual, &pose.tip)
        } else {
            None
        };
        let mut output = FiveAxisOutput {
            u,
            following_error,
            segment,
            error,
            correction: Joints::zeros(),
            tip_step: CccStep::default(),
            orientation_step: CccStep::default(),
            evaluation,
        };
        if let Some((e, tangent)) = &foot {
            let (v, tip_step) = self
                .tip
                .update_normal_to(geometry::norm(&e.tip), &e.tip, tangent);
            let (omega, orientation_step) =
                self.orientation
                    .update_normal_to(e.orientation, &e.rotation, &pose.axis);
            output.tip_step = tip_step;
            output.orientation_step = orientation_step;
            output.correction = self.joint_correction(actual, &pose, &v, &omega);
            u += output.correction;
            output.u = u;
        }
        Ok(output)
    }

    /// Joint velocities giving tip velocity `v` and tool-axis angular velocity `omega`
    /// (workpiece frame) at joints `q` with pose `pose`.
    fn joint_correction(
        &self,
        q: &Joints,
        pose: &Pose,
        v: &Vector<3>,
        omega: &Vector<3>,
    ) -> Joints {
        if v.iter().chain(omega.iter()).all(|x| *x == 0.0) {
            return Joints::zeros();
        }
        let turn = omega.cross(&pose.axis);
        let target = Vector::<6>::new(v[0], v[1], v[2], turn[0], turn[1], turn[2]);
        let jacobian = self.config.machine.jacobian(q);
        damped_least_squares(&jacobian, &target, self.config.damping).unwrap_or_else(Joints::zeros)
    }

    /// Samples taken so far.
    pub fn samples(&self) -> u64 {
        self.evaluation.samples()
    }

    /// The position loops' PIDs (X, Y, Z, A, C).
    pub fn axes(&self) -> &[Pid; 5] {
        &self.axes
    }

    /// The tip and the orientation laws.
    pub fn laws(&self) -> [&VectorLaw<3>; 2] {
        [&self.tip, &self.orientation]
    }

    /// Checks the memories of a controller restored from bytes against its own
    /// configuration: the mapping and the evaluation built for these settings, finite
    /// poses. (The configuration and the PIDs are checked by the caller, which knows the
    /// parameters' names.)
    pub fn check_memory(&self) -> Result<(), String> {
        let c = &self.config;
        if self.mapper.settings() != mapper(c).settings() {
            return Err("the mapping's settings differ from the configuration".into());
        }
        self.mapper.check().map_err(|e| format!("mapping: {e}"))?;
        self.evaluation
            .check(c.hmm.max_skip, c.lag)
            .map_err(|e| format!("evaluation: {e}"))?;
        if let Some(p) = self.last_reference.get() {
            if !(geometry::is_finite(&p.tip) && geometry::is_finite(&p.axis)) {
                return Err("the last reference pose is not finite".into());
            }
        }
        Ok(())
    }

    /// Back to the initial state (the mapping forgets its reference too); the
    /// configuration is kept.
    pub fn reset(&mut self) {
        self.axes.iter_mut().for_each(Pid::reset);
        self.tip.reset();
        self.orientation.reset();
        self.mapper = mapper(&self.config);
        self.evaluation = OnlineEvaluation::new(self.config.hmm.max_skip, self.config.lag);
        self.last_reference = LastReference::none();
    }
}
