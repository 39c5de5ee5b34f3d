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
//! The correction does no harm (docs/design/five-axis.md §5.4b): every command stays
//! within its joint's speed (the position loops' integrals hold at it), the correction
//! within `correction_share` of it, the laws' integrals hold while a command saturates,
//! the damping grows inside `pole_cone` of the C axis, and the [`CorrectionGuard`] steps
//! the correction aside while the machine cannot follow its reference or the mapping has
//! lost the tool (which then restarts on the tool's nearest segment).
//!
//! Fixed-size state apart from the mapper's rings (sized once at construction), so
//! `sample` never allocates.

use crate::math;
use serde::{Deserialize, Serialize};

use super::ccc_law::{CccStep, VectorLaw};
use super::config::{check, CccConfig, CccMode, ConfigError, Parameter};
use super::correction_guard::{CorrectionGuard, Hold};
use super::pid::{Pid, PidGains};
use crate::contour::five_axis::evaluation_online::{OnlineEvaluation, PointEvaluation};
use crate::contour::five_axis::hmm::HmmParams;
use crate::contour::five_axis::hmm_online::OnlineMapper;
use crate::contour::five_axis::pose_error::{foot_near, PoseError};
use crate::geometry::{self, Vector};
use crate::kinematics::{damped_least_squares_per_joint, Joints, Pose, TableTiltingAc};
use crate::limits::JointLimits;

/// Configuration of the five-axis controller.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FiveAxisConfig {
    /// Sample period, s. Default 1 ms.
    pub ts: f64,
    /// Position loops of X, Y, Z (mm/s per mm) and A, C (rad/s per rad). Default P with
    /// Kpp = 28.5 1/s on every joint, as the two-axis controller.
    pub axis: [PidGains; 5],
    /// The machine's limits: every command stays within its joint's speed, and a
    /// reference beyond them makes the correction stand aside (docs/design/five-axis.md
    /// §5.4b). Default: the trunnion table's ([`JointLimits::DEFAULT`]).
    pub limits: JointLimits,
    /// The largest share of each joint's speed the correction may use. Default 0.25.
    pub correction_share: f64,
    /// Seconds the correction takes to come back to full weight once the machine follows
    /// its reference again. Default 0.05 s.
    pub recovery: f64,
    /// The law on the tip error (mm → mm/s). Default: the two-axis CCC's defaults.
    pub tip: CccConfig,
    /// The law on the orientation error (rad → rad/s); the fuzzy inputs read the error in
    /// mrad where the tip law reads µm. Default: the same gains as the tip law.
    pub orientation: CccConfig,
    /// μ of the damped least squares (docs/design/five-axis.md §5.4). Default 0.01: below 1e-4
    /// relative change of the correction wherever the Jacobian's singular values exceed 1
    /// (mm per mm, or per rad), and |Δq| ≤ |e|/(2μ) at A = 0.
    pub damping: f64,
    /// The growth of C's damping at the singular pose: inside `pole_cone` of the C axis,
    /// μ_C² = damping² + pole_damping²·(1 − sin²A / sin²pole_cone). Default 0.3: on the C
    /// axis an angular correction ω turns C at most L·|ω|/(2μ_C) ≈ 170·|ω| (L = 100 mm),
    /// and beside it the orientation correction loses under 2 % (3 would lose 2 %, 30 a
    /// quarter).
    pub pole_damping: f64,
    /// Half-angle of the cone about the C axis where the damping grows, rad. Default 2°,
    /// the planner's pole cone.
    pub pole_cone: f64,
    /// Tool length L, mm: the mapping's second point, and the weight of a tool-axis error
    /// in the least squares (the displacement it makes at L). Default 100.
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
        limits: JointLimits::DEFAULT,
        correction_share: 0.25,
        recovery: 0.05,
        tip: CccConfig::DEFAULT,
        orientation: CccConfig::DEFAULT,
        damping: 0.01,
        pole_damping: 0.3,
        pole_cone: 2.0 * std::f64::consts::PI / 180.0,
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
            axis_limit: None,
            ccc: self.tip,
        };
        axes.validate()?;
        let l = &self.limits;
        for i in 0..5 {
            check(Parameter::TravelMax(i), l.max[i], true, "must be finite")?;
            check(
                Parameter::TravelMin(i),
                l.min[i],
                l.min[i] < l.max[i],
                "must be finite and below the greatest position",
            )?;
            check(
                Parameter::JointSpeed(i),
                l.velocity[i],
                l.velocity[i] > 0.0,
                "must be finite and > 0",
            )?;
            check(
                Parameter::JointAcceleration(i),
                l.acceleration[i],
                l.acceleration[i] > 0.0,
                "must be finite and > 0",
            )?;
        }
        check(
            Parameter::CorrectionShare,
            self.correction_share,
            self.correction_share > 0.0 && self.correction_share <= 1.0,
            "must be in (0, 1]",
        )?;
        check(
            Parameter::Recovery,
            self.recovery,
            self.recovery >= 0.0,
            "must be finite and >= 0 s",
        )?;
        check(
            Parameter::PoleDamping,
            self.pole_damping,
            self.pole_damping >= 0.0,
            "must be finite and >= 0",
        )?;
        check(
            Parameter::PoleCone,
            self.pole_cone,
            self.pole_cone >= 0.0 && self.pole_cone < std::f64::consts::FRAC_PI_2,
            "must be in [0, pi/2) rad",
        )?;
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

/// The guard `config` asks for.
fn guard(config: &FiveAxisConfig) -> CorrectionGuard {
    CorrectionGuard::new(config.limits, config.ts, config.recovery)
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
    /// The correction's weight (1: full; 0: stood aside, see `hold`).
    pub weight: f64,
    /// Why the correction stands aside, if it does.
    pub hold: Hold,
    /// Whether a joint lags its commands beyond what its velocity loop explains, so the
    /// laws did not integrate ([`CorrectionGuard::lagging`]).
    pub lagging: bool,
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
    /// A feed-forward command is NaN or infinite.
    NonFiniteFeedForward,
}

impl std::fmt::Display for SampleError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SampleError::NonFiniteReference => "a reference joint is not finite",
            SampleError::NonFiniteActual => "a measured joint is not finite",
            SampleError::NonFiniteFeedForward => "a feed-forward command is not finite",
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
    guard: CorrectionGuard,
    /// Samples taken so far.
    taken: u64,
    /// Whether the correction was scaled down the sample before to keep a command within
    /// its joint's speed (the laws' integrals hold).
    clamped: bool,
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
            axes: std::array::from_fn(|i| {
                Pid::new(config.axis[i], config.ts, Some(config.limits.velocity[i]))
            }),
            tip: VectorLaw::new(config.tip, config.ts)?,
            orientation: VectorLaw::new(config.orientation, config.ts)
                .map_err(|e| e.with_parameter(Parameter::orientation(e.parameter)))?,
            mapper: mapper(&config),
            evaluation: OnlineEvaluation::new(config.hmm.max_skip, config.lag),
            last_reference: LastReference::none(),
            guard: guard(&config),
            taken: 0,
            clamped: false,
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

    /// One control sample with reference joints `reference` (a new one every sample) and
    /// measured joints `actual`. A non-finite input is refused and leaves the state as it
    /// was.
    pub fn sample(
        &mut self,
        reference: &Joints,
        actual: &Joints,
    ) -> Result<FiveAxisOutput, SampleError> {
        let now = self.taken as f64 * self.config.ts;
        self.sample_held(reference, now, actual)
    }

    /// [`FiveAxisController::sample`] with a reference set at time `set_at` (s; only
    /// differences count) and held since: an FMU's input, set at its communication point
    /// and held over the step. The guard measures the reference's speed over the time
    /// between its values.
    pub fn sample_held(
        &mut self,
        reference: &Joints,
        set_at: f64,
        actual: &Joints,
    ) -> Result<FiveAxisOutput, SampleError> {
        self.sample_with_feed_forward(reference, set_at, actual, &Joints::zeros())
    }

    /// [`FiveAxisController::sample_held`] with a feed-forward command `feed_forward`
    /// (mm/s, rad/s: the reference's velocity and acceleration terms, gains applied)
    /// added to the position loops' commands, the sum within each joint's speed (the
    /// loops' anti-windup judges the sum): what position loops alone follow with a lag.
    /// The guard and the correction's room judge the sum too.
    pub fn sample_with_feed_forward(
        &mut self,
        reference: &Joints,
        set_at: f64,
        actual: &Joints,
        feed_forward: &Joints,
    ) -> Result<FiveAxisOutput, SampleError> {
        if !geometry::is_finite(reference) {
            return Err(SampleError::NonFiniteReference);
        }
        if !geometry::is_finite(actual) {
            return Err(SampleError::NonFiniteActual);
        }
        if !geometry::is_finite(feed_forward) {
            return Err(SampleError::NonFiniteFeedForward);
        }
        let following_error = reference - actual;
        let axes = &mut self.axes;
        let mut asked = Joints::zeros();
        // The loops' limits are the joints' speeds: the sum is within them, and the
        // anti-windup judges the sum.
        let loops = Joints::from_fn(|i, _| {
            let (u, unclamped) =
                axes[i].update_unclamped(following_error[i], true, feed_forward[i]);
            asked[i] = unclamped;
            u
        });
        let mut hold = Hold {
            beyond_limits: self.guard.beyond_limits(reference, set_at),
            saturated: self.guard.saturated(&asked),
            lost: false,
            disobeyed: self.guard.disobeyed(actual, set_at),
        };

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
        // While the machine cannot follow, the tool may move along the reference faster
        // than the mapping's `max_skip` segments per sample: it is mapped afresh (to its
        // nearest segment) every such sample, so the mapping is on the tool's segment
        // when the correction comes back. A joint short of its commands moves slower,
        // not faster: the mapping keeps its history (the evaluation needs it).
        if hold.beyond_limits || hold.saturated {
            self.mapper.restart();
        }
        let segment = self.mapper.push_sample(pose.tip, pose.axis);
        hold.lost = segment.is_some_and(|j| self.lost(j));
        if hold.lost {
            self.mapper.restart();
        }
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
        let (weight, dropped) = self.guard.update(hold);
        if dropped {
            self.tip.reset();
            self.orientation.reset();
        }
        let mut output = FiveAxisOutput {
            u: loops,
            following_error,
            segment,
            error,
            correction: Joints::zeros(),
            weight,
            hold,
            lagging: self.guard.lagging(),
            tip_step: CccStep::default(),
            orientation_step: CccStep::default(),
            evaluation,
        };
        let mut clamped = false;
        if let (Some((e, tangent)), true) = (&foot, weight > 0.0) {
            // Integrals run at full weight only, and hold while a command saturates.
            let integrate = weight == 1.0 && !self.clamped && !self.guard.lagging();
            let (v, tip_step) =
                self.tip
                    .update_normal_to(geometry::norm(&e.tip), &e.tip, tangent, integrate);
            let (omega, orientation_step) = self.orientation.update_normal_to(
                e.orientation,
                &e.rotation,
                &pose.axis,
                integrate,
            );
            output.tip_step = tip_step;
            output.orientation_step = orientation_step;
            let (correction, limited) =
                self.joint_correction(actual, &pose, &(v * weight), &(omega * weight), &loops);
            output.correction = correction;
            output.u = loops + correction;
            clamped = limited;
        }
        self.clamped = clamped;
        self.guard.commanded(&output.u);
        self.taken += 1;
        Ok(output)
    }

    /// Whether the mapping has lost the tool this sample: left at the band's tail, where
    /// the tool's own segment may have left the band.
    fn lost(&self, segment: usize) -> bool {
        self.mapper.band_is_full() && segment == self.mapper.oldest_segment()
    }

    /// Joint velocities giving tip velocity `v` and tool-axis angular velocity `omega`
    /// (workpiece frame) at joints `q` with pose `pose`, the damping growing inside the
    /// pole cone, bounded twice; also whether a bound acted.
    ///
    /// 1. Scaled as a whole to within `correction_share` of every joint's speed: the
    ///    correction keeps its direction, so a large one (mm of error after a limit hit)
    ///    is slowed, not turned.
    /// 2. Within what the position loops leave of each joint's speed: a joint without that
    ///    room is held at its bound and the others solve for what it leaves undone
    ///    (saturation in the null space, the joint furthest beyond first; a linear joint's
    ///    part goes to the linear joints alone). Scaled as a whole instead, one joint at
    ///    its speed (C through a turn near the pole) would stop the whole correction.
    fn joint_correction(
        &self,
        q: &Joints,
        pose: &Pose,
        v: &Vector<3>,
        omega: &Vector<3>,
        loops: &Joints,
    ) -> (Joints, bool) {
        if v.iter().chain(omega.iter()).all(|x| *x == 0.0) {
            return (Joints::zeros(), false);
        }
        // A tool-axis error weighs as the displacement it makes at the tool length L (the
        // mapping's second point): unweighted, rad against mm, the damping finds turning
        // the table cheaper than moving X and Y for a tip far from its axes, and tilts the
        // tool to move the tip (docs/design/five-axis.md §5.4).
        let w = self.config.tool_length;
        let turn = omega.cross(&pose.axis) * w;
        let mut target = Vector::<6>::new(v[0], v[1], v[2], turn[0], turn[1], turn[2]);
        let mut jacobian = self.config.machine.jacobian(q);
        jacobian.fixed_rows_mut::<3>(3).scale_mut(w);
        let mut damping = self.damping_at(pose);
        let Some(mut free) = damped_least_squares_per_joint(&jacobian, &target, &damping) else {
            return (Joints::zeros(), true);
        };
        let speed = &self.config.limits.velocity;
        let share = self.config.correction_share;
        let scale = (0..5).fold(1.0f64, |scale, i| {
            scale.min(share * speed[i] / free[i].abs().max(f64::MIN_POSITIVE))
        });
        let mut limited = scale < 1.0;
        if limited {
            target *= scale;
            free *= scale;
        }
        // The room is the same both ways: a joint the correction slows must catch up
        // later, and it can only by what its speed leaves (a joint at its speed behind a
        // reference at that speed never makes up a lag the correction gave it).
        let room =
            Joints::from_fn(|i, _| (share * speed[i]).min(speed[i] - loops[i].abs()).max(0.0));
        let (low, high) = (-room, room);
        let mut held = Joints::zeros();
        for _ in 0..5 {
            let beyond = |i: usize| {
                let bound = if free[i] > 0.0 { high[i] } else { -low[i] };
                (free[i].abs() - bound) / free[i].abs().max(f64::MIN_POSITIVE)
            };
            let worst = (0..5).max_by(|&a, &b| beyond(a).total_cmp(&beyond(b)));
            let Some(i) = worst.filter(|&i| beyond(i) > 1e-12) else {
                return (held + free, limited);
            };
            held[i] = free[i].clamp(low[i], high[i]);
            // What a linear joint leaves undone only the other linear joints make up: the
            // rotary ones would tilt the tool to move its tip. The held joints' part is
            // done; their columns leave the solve (zero column, unit damping: their
            // shares come out 0).
            let hold: &[usize] = if i < 3 { &[i, 3, 4] } else { &[i] };
            for &h in hold {
                if h != i {
                    held[h] = free[h];
                }
                jacobian.column_mut(h).fill(0.0);
                damping[h] = 1.0;
            }
            limited = true;
            let rest = target - jacobian * held;
            match damped_least_squares_per_joint(&jacobian, &rest, &damping) {
                Some(next) => free = next,
                None => return (held, true),
            }
        }
        (held + free, limited)
    }

    /// Each joint's μ at `pose`: `damping`, C's growing inside the pole cone to
    /// √(damping² + pole_damping²) on the C axis (sin A is the tool axis's distance from
    /// it, the C column's share of the orientation rows; C alone is what the inverse
    /// drives without bound there).
    fn damping_at(&self, pose: &Pose) -> Joints {
        let c = &self.config;
        let mu = c.damping;
        let mut damping = Joints::repeat(mu);
        let sin_a2 = pose.axis[0] * pose.axis[0] + pose.axis[1] * pose.axis[1];
        let cone2 = math::sin(c.pole_cone).powi(2);
        if sin_a2 < cone2 && c.pole_damping > 0.0 {
            damping[4] =
                (mu * mu + c.pole_damping * c.pole_damping * (1.0 - sin_a2 / cone2)).sqrt();
        }
        damping
    }

    /// Samples taken so far.
    pub fn samples(&self) -> u64 {
        self.taken
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
        if self.guard.settings() != guard(c).settings() {
            return Err("the guard's limits differ from the configuration".into());
        }
        self.guard.check()?;
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
        self.guard = guard(&self.config);
        self.taken = 0;
        self.clamped = false;
    }
}
