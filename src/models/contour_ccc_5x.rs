//! `ContourCCC5X`: the five-axis controller (docs/design/five-axis.md §5.4). Per joint a position
//! loop on the following error; the reference joints it receives, through the forward
//! kinematics, are its expected path (no path file), which the online HMM maps the
//! measured pose onto; tip and orientation contour errors there drive two fuzzy-PID laws
//! whose correction reaches the joints through the damped least-squares inverse of the
//! Jacobian. The control law runs every `Ts` inside `fmi2DoStep` on the inputs held over
//! the step, whatever the communication step.

use super::axis_variables::{
    COMMAND_OUT, FOLLOWING_ERROR_OUT, MEASURED_IN, REFERENCE_ACCELERATION_IN, REFERENCE_IN,
    REFERENCE_VELOCITY_IN,
};
use super::controller_parameters::{
    self, axis_gain, nonnegative, ControllerState, SavedController,
};
use super::{joint_limits_parameters, kinematics_parameters};
use crate::framework::model::{DefaultExperiment, Environment, Model, ModelInfo, ModelResult};
use crate::framework::sample_clock::{check_period, SampleClock};
use crate::framework::saved_state::StateLayout;
use crate::framework::variable_table::{axis_block, variable_table, Axis, AxisUnit, Int, XYZAC};
use crate::framework::variables::{Start, Values, Variable};
use contour_core::contour::five_axis::hmm::HmmParams;
use contour_core::control::{
    CccConfig, CccMode, ConfigError, FuzzyFactor, FuzzyFactors, Parameter, Pid, PidGains,
};
use contour_core::control::{FeedForward, FiveAxisConfig, FiveAxisController};
use contour_core::geometry::Vector;

/// Start values: the controller library's documented defaults.
const DEFAULT: FiveAxisConfig = FiveAxisConfig::DEFAULT;
const A: PidGains = DEFAULT.axis[0];
const TIP: CccConfig = DEFAULT.tip;
const TURN: CccConfig = DEFAULT.orientation;

const fn count(
    name: &'static str,
    start: usize,
    range: (f64, f64),
    what: &'static str,
) -> Variable {
    Variable::parameter(name, Start::Integer(start as i32), what)
        .min(range.0)
        .max(range.1)
}

variable_table! {
    static VARIABLES;
    REF: Reals<5> = axis_block(&XYZAC, &[REFERENCE_IN]);
    POS: Reals<5> = axis_block(&XYZAC, &[MEASURED_IN]);
    U: Reals<5> = axis_block(&XYZAC, &[COMMAND_OUT]);
    TIP_ERROR: Real = Variable::output(
        "contourError.tip",
        "Tool-tip contour error: distance from the measured tip to the foot point on the \
         reference segment the HMM maps it to (this sample)",
    )
    .unit("mm");
    ORIENTATION_ERROR: Real = Variable::output(
        "contourError.orientation",
        "Tool-orientation contour error: angle between the measured tool axis and the \
         reference axis at the foot point (this sample)",
    )
    .unit("rad");
    EVAL_TIP: Real = Variable::output(
        "evaluation.tip",
        "Evaluation-function estimate of the tip contour error at the newest reference \
         point it can be computed for; it describes the tool evaluation.delay seconds ago \
         (the decision lag hmm.lag plus up to hmm.maxSkip samples)",
    )
    .unit("mm");
    EVAL_ORIENTATION: Real = Variable::output(
        "evaluation.orientation",
        "Evaluation-function estimate of the orientation contour error, for the same \
         reference point and delay as evaluation.tip",
    )
    .unit("rad");
    EVAL_DELAY: Real = Variable::output(
        "evaluation.delay",
        "Age of the measured sample the evaluation estimates were fitted around (0 until \
         the first estimate)",
    )
    .unit("s");
    ERR: Reals<5> = axis_block(&XYZAC, &[FOLLOWING_ERROR_OUT]);
    TS: Real = Variable::parameter(
        "Ts",
        Start::Real(DEFAULT.ts),
        "Control period (at least 1 us)",
    )
    .unit("s");
    /// Kp, Ki, Kd of the X position loop, then of Y, Z, A, C.
    AXIS_GAINS: Reals<15> = axis_block(&XYZAC, &[
        axis_gain(".Kp", A.kp, " position loop, proportional gain", AxisUnit::Fixed("1/s")),
        axis_gain(".Ki", A.ki, " position loop, integral gain", AxisUnit::Fixed("1/s2")),
        axis_gain(".Kd", A.kd, " position loop, derivative gain", AxisUnit::None),
    ]);
    CCC_ENABLE: Bool = Variable::parameter(
        "ccc.enable",
        Start::Boolean(true),
        "Apply the cross-coupled tip and orientation corrections",
    );
    FUZZY_ENABLE: Bool = Variable::parameter(
        "fuzzy.enable",
        Start::Boolean(true),
        "Adapt the contour PID gains with the fuzzy system (else the fixed base gains)",
    );
    /// Kp0, Ki0, Kd0, limit, then ke, kde, kp, ki, kd of the tip law.
    TIP_LAW: Reals<9> = [
        nonnegative("tip.Kp0", TIP.gains0.kp, "Tip law: PID base gain Kp0").unit("1/s"),
        nonnegative("tip.Ki0", TIP.gains0.ki, "Tip law: PID base gain Ki0").unit("1/s2"),
        nonnegative("tip.Kd0", TIP.gains0.kd, "Tip law: PID base gain Kd0"),
        Variable::parameter(
            "tip.limit",
            Start::Real(100.0),
            "Tip law: bound on each component of the correction (> 0), with anti-windup",
        )
        .unit("mm/s"),
        nonnegative("tip.fuzzy.ke", TIP.fuzzy.ke, "Tip law: error quantisation factor (per um)"),
        nonnegative("tip.fuzzy.kde", TIP.fuzzy.kde, "Tip law: error change factor (per um/sample)"),
        nonnegative("tip.fuzzy.kp", TIP.fuzzy.kpf, "Tip law: scale of the fuzzy Kp adjustment")
            .unit("1/s"),
        nonnegative("tip.fuzzy.ki", TIP.fuzzy.kif, "Tip law: scale of the fuzzy Ki adjustment")
            .unit("1/s2"),
        nonnegative("tip.fuzzy.kd", TIP.fuzzy.kdf, "Tip law: scale of the fuzzy Kd adjustment"),
    ];
    /// The same for the orientation law (errors in rad, read by the fuzzy inputs in mrad).
    ORIENTATION_LAW: Reals<9> = [
        nonnegative("orientation.Kp0", TURN.gains0.kp, "Orientation law: PID base gain Kp0")
            .unit("1/s"),
        nonnegative("orientation.Ki0", TURN.gains0.ki, "Orientation law: PID base gain Ki0")
            .unit("1/s2"),
        nonnegative("orientation.Kd0", TURN.gains0.kd, "Orientation law: PID base gain Kd0"),
        Variable::parameter(
            "orientation.limit",
            Start::Real(100.0),
            "Orientation law: bound on each component of the angular correction (> 0), \
             with anti-windup",
        )
        .unit("rad/s"),
        nonnegative("orientation.fuzzy.ke", TURN.fuzzy.ke,
            "Orientation law: error quantisation factor (per mrad)"),
        nonnegative("orientation.fuzzy.kde", TURN.fuzzy.kde,
            "Orientation law: error change factor (per mrad/sample)"),
        nonnegative("orientation.fuzzy.kp", TURN.fuzzy.kpf,
            "Orientation law: scale of the fuzzy Kp adjustment").unit("1/s"),
        nonnegative("orientation.fuzzy.ki", TURN.fuzzy.kif,
            "Orientation law: scale of the fuzzy Ki adjustment").unit("1/s2"),
        nonnegative("orientation.fuzzy.kd", TURN.fuzzy.kdf,
            "Orientation law: scale of the fuzzy Kd adjustment"),
    ];
    DAMPING: Real = Variable::parameter(
        "damping",
        Start::Real(DEFAULT.damping),
        "Damping of the least-squares inverse of the Jacobian (> 0): bounds the joint \
         correction near the A = 0 singularity",
    );
    TOOL_LENGTH: Real = Variable::parameter(
        "toolLength",
        Start::Real(DEFAULT.tool_length),
        "Tool length L of the mapping's second point up the tool axis (> 0)",
    )
    .unit("mm");
    MAX_SKIP: Int = count(
        "hmm.maxSkip",
        DEFAULT.hmm.max_skip,
        (1.0, 64.0),
        "Largest number of reference segments the mapping moves forward per sample",
    );
    ANGLE_WEIGHT: Real = Variable::parameter(
        "hmm.angleWeight",
        Start::Real(DEFAULT.hmm.angle_weight),
        "Weight of the angle between measured motion and segment direction in the mapping \
         cost (>= 0)",
    )
    .unit("mm/rad")
    .min(0.0);
    BAND: Int = count(
        "hmm.band",
        DEFAULT.band,
        (2.0, 4096.0),
        "Newest reference segments the online mapping considers (must exceed the tool's \
         lag behind the reference, in samples)",
    );
    LAG: Int = count(
        "hmm.lag",
        DEFAULT.lag,
        (0.0, 4096.0),
        "Decision lag of the mapping read back for the evaluation estimate, samples",
    );
    BEAM: Real = Variable::parameter(
        "hmm.beam",
        Start::Real(DEFAULT.beam),
        "The mapping keeps the states within this summed cost of the best (> 0)",
    )
    .unit("mm");
    EVALUATION_ENABLE: Bool = Variable::parameter(
        "evaluation.enable",
        Start::Boolean(true),
        "Compute the evaluation-function estimate (evaluation.*): a diagnostic the control \
         law does not use, about 40 % of a sample's cost",
    );
    MACHINE: Reals<{ kinematics_parameters::COUNT }> = kinematics_parameters::VARIABLES;
    LIMITS: Reals<{ joint_limits_parameters::COUNT }> = joint_limits_parameters::VARIABLES;
    CORRECTION_SHARE: Real = Variable::parameter(
        "correctionShare",
        Start::Real(DEFAULT.correction_share),
        "Largest share of each joint's speed (<axis>.vmax) the correction may use, in (0, 1]",
    )
    .min(0.0)
    .max(1.0);
    RECOVERY: Real = Variable::parameter(
        "recovery",
        Start::Real(DEFAULT.recovery),
        "Time the correction takes to come back to full weight once the machine follows \
         its reference again (>= 0)",
    )
    .unit("s")
    .min(0.0);
    POLE_DAMPING: Real = Variable::parameter(
        "poleDamping",
        Start::Real(DEFAULT.pole_damping),
        "Growth of the damping on the C axis: within poleCone of it, damping^2 + \
         poleDamping^2 * (1 - sin^2 A / sin^2 poleCone) (>= 0)",
    )
    .min(0.0);
    POLE_CONE: Real = Variable::parameter(
        "poleCone",
        Start::Real(DEFAULT.pole_cone),
        "Half-angle of the cone about the C axis within which the damping grows",
    )
    .unit("rad")
    .min(0.0);
    WEIGHT: Real = Variable::output(
        "ccc.weight",
        "Weight of the correction this sample: 1 at full weight, 0 while it stands aside \
         (a reference beyond the joints' limits, a position loop far beyond its joint's \
         speed, a joint falling short of its commands, a mapping that lost the tool), \
         rising over `recovery` when none holds",
    );
    VREF: Reals<5> = axis_block(&XYZAC, &[REFERENCE_VELOCITY_IN]);
    FEED_FORWARD: Real = controller_parameters::FEED_FORWARD;
    AREF: Reals<5> = axis_block(&XYZAC, &[REFERENCE_ACCELERATION_IN]);
    ACCELERATION_FEED_FORWARD: Real = controller_parameters::ACCELERATION_FEED_FORWARD;
    LAGGING: Bool = Variable::discrete_output(
        "ccc.lagging",
        Start::Boolean(false),
        "A joint falls short of its commands by more than its velocity loop explains (held \
         by friction, stuck): the contour laws do not integrate this sample",
    );
}

pub static INFO: ModelInfo = ModelInfo {
    identifier: "ContourCCC5X",
    description: "Five-axis cross-coupled contour controller: position loops plus tool-tip \
                  and tool-orientation corrections (fuzzy-adapted PID gains) from an online \
                  HMM mapping of the measured pose onto the reference, through the damped \
                  least-squares inverse of the kinematic Jacobian",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment {
        start_time: 0.0,
        stop_time: 5.5,
        step_size: 1e-3,
    },
    // Every output starts at 0: the control law first runs in fmi2DoStep.
    initial_dependencies: &[],
    initial_dependencies_on_some_paths: &[],
    create: |environment: &Environment| {
        Box::new(ContourCCC5X {
            environment: environment.clone(),
            state: None,
        })
    },
};

/// Version 1: `Option<State>` as below. Version 2: the controller carries the machine's
/// limits and the guard of its correction. Version 3: the guard also remembers the
/// commands sent and the joints' shortfall of travel. Version 4: the feed-forward gains;
/// the guard averages the joints' speeds and commands (`lagging`). Version 5: the
/// feed-forward remembers its inputs (the acceleration at the middle of the hold).
const LAYOUT: StateLayout = StateLayout {
    model: "ContourCCC5X",
    version: 5,
};

type State = ControllerState<FiveAxisController, 5>;

impl SavedController<5> for FiveAxisController {
    const AXES: &'static [Axis] = &XYZAC;

    fn ts(&self) -> f64 {
        self.config().ts
    }

    fn check_config(&self) -> Result<(), String> {
        self.config().validate().map_err(config_message)
    }

    fn position_loops(&self) -> &[Pid] {
        self.axes()
    }

    /// The tip and orientation laws with their components, and the controller's memory.
    fn check_rest(state: &State) -> Result<(), String> {
        let controller = &state.controller;
        let ts = controller.ts();
        for (name, law) in ["tip", "orientation"].iter().zip(controller.laws()) {
            controller_parameters::check_pid(&format!("{name} law"), law.law().pid(), ts)?;
            for (axis, pid) in ["x", "y", "z"].iter().zip(law.components()) {
                controller_parameters::check_pid(
                    &format!("{name} law, {axis} component"),
                    pid,
                    ts,
                )?;
            }
        }
        controller.check_memory()
    }
}

pub struct ContourCCC5X {
    /// For the check of a restored state (`sampled_state_methods!`).
    environment: Environment,
    state: Option<State>,
}

fn law(mode: CccMode, values: [f64; 9]) -> CccConfig {
    let [kp, ki, kd, limit, ke, kde, kpf, kif, kdf] = values;
    CccConfig {
        mode,
        gains0: PidGains::new(kp, ki, kd),
        fuzzy: FuzzyFactors {
            ke,
            kde,
            kpf,
            kif,
            kdf,
        },
        limit: Some(limit),
    }
}

fn config(values: &Values) -> Result<FiveAxisConfig, String> {
    let mode = controller_parameters::mode(CCC_ENABLE.get(values), FUZZY_ENABLE.get(values));
    let g = AXIS_GAINS.get(values);
    // Integer parameters are within their bounds (checked on every set), so ≥ 0.
    let whole = |v: Int| v.get(values).max(0) as usize;
    Ok(FiveAxisConfig {
        ts: TS.get(values),
        axis: std::array::from_fn(|i| PidGains::new(g[3 * i], g[3 * i + 1], g[3 * i + 2])),
        limits: joint_limits_parameters::joint_limits(values, LIMITS)?,
        correction_share: CORRECTION_SHARE.get(values),
        recovery: RECOVERY.get(values),
        tip: law(mode, TIP_LAW.get(values)),
        orientation: law(mode, ORIENTATION_LAW.get(values)),
        damping: DAMPING.get(values),
        pole_damping: POLE_DAMPING.get(values),
        pole_cone: POLE_CONE.get(values),
        tool_length: TOOL_LENGTH.get(values),
        hmm: HmmParams {
            max_skip: whole(MAX_SKIP),
            angle_weight: ANGLE_WEIGHT.get(values),
        },
        band: whole(BAND),
        lag: whole(LAG),
        beam: BEAM.get(values),
        evaluate: EVALUATION_ENABLE.get(values),
        machine: kinematics_parameters::machine(values, MACHINE),
    })
}

/// The variable that sets a configuration value, if one does.
fn variable_of(parameter: Parameter) -> Option<&'static Variable> {
    let gain = controller_parameters::gain_index;
    let factor = |f: FuzzyFactor| match f {
        FuzzyFactor::Ke => 4,
        FuzzyFactor::Kde => 5,
        FuzzyFactor::Kpf => 6,
        FuzzyFactor::Kif => 7,
        FuzzyFactor::Kdf => 8,
    };
    let vr = match parameter {
        Parameter::Ts => TS.vr(),
        Parameter::AxisGain(axis, g) => AXIS_GAINS.at(3 * axis + gain(g)).vr(),
        Parameter::ContourGain(g) => TIP_LAW.at(gain(g)).vr(),
        Parameter::ContourLimit => TIP_LAW.at(3).vr(),
        Parameter::Fuzzy(f) => TIP_LAW.at(factor(f)).vr(),
        Parameter::OrientationGain(g) => ORIENTATION_LAW.at(gain(g)).vr(),
        Parameter::OrientationLimit => ORIENTATION_LAW.at(3).vr(),
        Parameter::OrientationFuzzy(f) => ORIENTATION_LAW.at(factor(f)).vr(),
        Parameter::Damping => DAMPING.vr(),
        Parameter::ToolLength => TOOL_LENGTH.vr(),
        Parameter::MaxSkip => MAX_SKIP.vr(),
        Parameter::AngleWeight => ANGLE_WEIGHT.vr(),
        Parameter::Band => BAND.vr(),
        Parameter::Lag => LAG.vr(),
        Parameter::Beam => BEAM.vr(),
        Parameter::Pivot(0, 1) => MACHINE.at(0).vr(),
        Parameter::Pivot(0, 2) => MACHINE.at(1).vr(),
        Parameter::Pivot(1, 0) => MACHINE.at(2).vr(),
        Parameter::Pivot(1, 1) => MACHINE.at(3).vr(),
        Parameter::TravelMin(3) => LIMITS.at(0).vr(),
        Parameter::TravelMax(3) => LIMITS.at(1).vr(),
        Parameter::TravelMin(4) => LIMITS.at(2).vr(),
        Parameter::TravelMax(4) => LIMITS.at(3).vr(),
        Parameter::JointSpeed(i) => LIMITS.at(4 + i).vr(),
        Parameter::JointAcceleration(i) => LIMITS.at(9 + i).vr(),
        Parameter::CorrectionShare => CORRECTION_SHARE.vr(),
        Parameter::Recovery => RECOVERY.vr(),
        Parameter::PoleDamping => POLE_DAMPING.vr(),
        Parameter::PoleCone => POLE_CONE.vr(),
        // The axis limit and the pivots' coordinates along their own axes: no variable.
        _ => return None,
    };
    Some(&VARIABLES[vr])
}

/// A configuration error in the FMU's own parameter names.
fn config_message(e: ConfigError) -> String {
    match variable_of(e.parameter) {
        Some(v) => e.message_for(&v.name.to_string()),
        None => e.to_string(),
    }
}

impl ContourCCC5X {
    fn write_zero_outputs(values: &mut Values) {
        U.set(values, &Vector::<5>::zeros());
        ERR.set(values, &Vector::<5>::zeros());
        for output in [
            TIP_ERROR,
            ORIENTATION_ERROR,
            EVAL_TIP,
            EVAL_ORIENTATION,
            EVAL_DELAY,
            WEIGHT,
        ] {
            output.set(values, 0.0);
        }
        LAGGING.set(values, false);
    }
}

impl Model for ContourCCC5X {
    fn initialize(&mut self, values: &mut Values, start_time: f64) -> ModelResult {
        check_period("Ts", TS.get(values))?;
        let config = config(values)?;
        let controller = FiveAxisController::new(config).map_err(config_message)?;
        self.state = Some(State {
            controller,
            clock: SampleClock::new(start_time, config.ts),
            feed_forward: FeedForward::new(
                FEED_FORWARD.get(values),
                ACCELERATION_FEED_FORWARD.get(values),
            )?,
        });
        Self::write_zero_outputs(values);
        Ok(())
    }

    fn do_step(&mut self, values: &mut Values, time: f64, step: f64) -> ModelResult {
        let state = self.state.as_mut().ok_or("not initialized")?;
        let reference = REF.vector(values);
        let actual = POS.vector(values);
        let (velocity, acceleration) = (VREF.vector(values), AREF.vector(values));
        let ts = state.controller.config().ts;
        while state.clock.take_before(time + step) {
            let feed_forward =
                state
                    .feed_forward
                    .sample(time, velocity, acceleration, state.clock.latest(), ts);
            // Inputs are finite (fmi2SetReal refuses others), so a sample cannot fail.
            // The inputs were set at this communication point and are held over it.
            let out = state
                .controller
                .sample_with_feed_forward(&reference, time, &actual, &feed_forward)
                .map_err(|e| format!("sample at t = {time}: {e}"))?;
            U.set(values, &out.u);
            ERR.set(values, &out.following_error);
            let (tip, orientation) = out.error.map_or((0.0, 0.0), |e| {
                (contour_core::geometry::norm(&e.tip), e.orientation)
            });
            TIP_ERROR.set(values, tip);
            WEIGHT.set(values, out.weight);
            LAGGING.set(values, out.lagging);
            ORIENTATION_ERROR.set(values, orientation);
            if let Some(e) = out.evaluation {
                EVAL_TIP.set(values, e.tip);
                EVAL_ORIENTATION.set(values, e.orientation);
                let newest = state.controller.samples().saturating_sub(1);
                EVAL_DELAY.set(values, newest.saturating_sub(e.sample) as f64 * ts);
            }
        }
        Ok(())
    }

    crate::framework::saved_state::sampled_state_methods!(State, LAYOUT);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn start_values_are_the_controller_library_defaults() {
        let values = Values::from_table(&VARIABLES);
        assert_eq!(config(&values).unwrap(), FiveAxisConfig::DEFAULT);
    }

    #[test]
    fn configuration_errors_use_the_fmu_parameter_names() {
        let mut values = Values::from_table(&VARIABLES);
        values.set_real(AXIS_GAINS.at(13).vr(), -1.0);
        let e = FiveAxisController::new(config(&values).unwrap()).unwrap_err();
        assert_eq!(
            config_message(e),
            "parameter axis.C.Ki = -1 is invalid: must be finite and >= 0"
        );
        let mut values = Values::from_table(&VARIABLES);
        values.set_real(ORIENTATION_LAW.at(7).vr(), -2.0);
        let e = config(&values).unwrap().validate().unwrap_err();
        assert!(config_message(e).starts_with("parameter orientation.fuzzy.ki = -2"));
        let mut values = Values::from_table(&VARIABLES);
        values.set_real(DAMPING.vr(), 0.0);
        let e = config(&values).unwrap().validate().unwrap_err();
        assert!(config_message(e).starts_with("parameter damping = 0"));
    }
}
