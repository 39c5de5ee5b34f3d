//! `ContourCCC2D`: the two-axis controller. Per axis a position loop on the following
//! error, plus the cross-coupled correction along the contour normal with fixed or
//! fuzzy-adapted PID gains (docs/design/two-axis.md §4.2, 4.3). The control law runs every `Ts` inside
//! `fmi2DoStep` on the inputs held over the step, whatever the communication step.

use super::axis_variables::{
    ACCELERATION_AHEAD_IN, COMMAND_OUT, FOLLOWING_ERROR_OUT, MEASURED_IN,
    REFERENCE_ACCELERATION_IN, REFERENCE_IN, REFERENCE_VELOCITY_IN,
};
use super::controller_parameters::{
    self, axis_gain, nonnegative, ControllerState, SavedController,
};
use super::line_arc_parameters;
use super::path_parameter;
use crate::framework::model::{DefaultExperiment, Environment, Model, ModelInfo, ModelResult};
use crate::framework::sample_clock::{check_period, SampleClock};
use crate::framework::saved_state::{self, RestoredState, SavedState, StateLayout};
use crate::framework::variable_table::{axis_block, variable_table, Axis, AxisUnit, XY};
use crate::framework::variables::{EnumItem, EnumType, Start, Values, Variable};
use contour_core::contour::planar::{
    Estimator, EstimatorKind, FreeCurveEstimator, SavedEstimator, ON_PATH,
};
use contour_core::control::{
    CccConfig, ConfigError, ControllerConfig, CrossCoupledController, FeedForward, FuzzyFactor,
    FuzzyFactors, Parameter, Pid, PidGains,
};
use contour_core::geometry::{Vector, Vector2};

/// The three contour gains in use, as one block.
type Vector3 = Vector<3>;

/// The `estimator` parameter's type: an FMI Enumeration (importers show a drop-down), in
/// the order of [`EstimatorKind::ALL`] (values 1, 2, 3, 4).
pub static ESTIMATOR_TYPE: EnumType = EnumType {
    name: "ContourEstimator",
    description: "How the controller estimates the contour error",
    items: &[
        EnumItem {
            name: "free_curve",
            description: "Free curve: two circles through the recent reference points (any path)",
        },
        EnumItem {
            name: "line",
            description: "Line: exact error to the line of the line.* parameters",
        },
        EnumItem {
            name: "arc",
            description: "Arc: exact error to the circle of the arc.* parameters",
        },
        EnumItem {
            name: "program",
            description: "Program: exact error along the whole path of the 'path' parameter \
                          (a G-code program, a NURBS file or a built-in), tracked with the reference",
        },
    ],
};

/// Start values: the controller library's documented defaults.
const DEFAULT: ControllerConfig = ControllerConfig::DEFAULT;
const A: PidGains = DEFAULT.axis[0];
const C: CccConfig = DEFAULT.ccc;

variable_table! {
    static VARIABLES;
    REF: Reals<2> = axis_block(&XY, &[REFERENCE_IN]);
    POS: Reals<2> = axis_block(&XY, &[MEASURED_IN]);
    U: Reals<2> = axis_block(&XY, &[COMMAND_OUT]);
    CONTOUR_ERROR: Real = Variable::output(
        "contourError",
        "Estimated contour error, > 0 when the tool is right of the direction of travel",
    )
    .unit("mm");
    ERR: Reals<2> = axis_block(&XY, &[FOLLOWING_ERROR_OUT]);
    CCC_GAINS: Reals<3> = [
        Variable::output("ccc.Kp", "Contour PID gain Kp in use").unit("1/s"),
        Variable::output("ccc.Ki", "Contour PID gain Ki in use").unit("1/s2"),
        Variable::output("ccc.Kd", "Contour PID gain Kd in use"),
    ];
    TS: Real = Variable::parameter(
        "Ts",
        Start::Real(DEFAULT.ts),
        "Control period (at least 1 us)",
    )
    .unit("s");
    /// Kp, Ki, Kd of the X position loop, then of Y.
    AXIS_GAINS: Reals<6> = axis_block(&XY, &[
        axis_gain(".Kp", A.kp, " position loop, proportional gain", AxisUnit::Fixed("1/s")),
        axis_gain(".Ki", A.ki, " position loop, integral gain", AxisUnit::Fixed("1/s2")),
        axis_gain(".Kd", A.kd, " position loop, derivative gain", AxisUnit::None),
    ]);
    CCC_ENABLE: Bool = Variable::parameter(
        "ccc.enable",
        Start::Boolean(true),
        "Apply the cross-coupled correction",
    );
    FUZZY_ENABLE: Bool = Variable::parameter(
        "fuzzy.enable",
        Start::Boolean(true),
        "Adapt the contour PID gains with the fuzzy system (else fixed Kp0, Ki0, Kd0)",
    );
    /// Kp0, Ki0, Kd0.
    CCC_GAINS0: Reals<3> = [
        nonnegative("ccc.Kp0", C.gains0.kp, "Contour PID base gain Kp0").unit("1/s"),
        nonnegative("ccc.Ki0", C.gains0.ki, "Contour PID base gain Ki0").unit("1/s2"),
        nonnegative("ccc.Kd0", C.gains0.kd, "Contour PID base gain Kd0"),
    ];
    CCC_LIMIT: Real = Variable::parameter(
        "ccc.limit",
        Start::Real(100.0),
        "Bound on the contour correction (> 0), with anti-windup",
    )
    .unit("mm/s");
    /// ke, kde, kp, ki, kd.
    FUZZY_FACTORS: Reals<5> = [
        nonnegative("fuzzy.ke", C.fuzzy.ke, "Contour error quantisation factor (per um)"),
        nonnegative("fuzzy.kde", C.fuzzy.kde, "Error change quantisation factor (per um/sample)"),
        nonnegative("fuzzy.kp", C.fuzzy.kpf, "Scale of the fuzzy Kp adjustment").unit("1/s"),
        nonnegative("fuzzy.ki", C.fuzzy.kif, "Scale of the fuzzy Ki adjustment").unit("1/s2"),
        nonnegative("fuzzy.kd", C.fuzzy.kdf, "Scale of the fuzzy Kd adjustment"),
    ];
    ESTIMATOR: Int = Variable::parameter(
        "estimator",
        Start::Integer(1),
        "Contour estimator: free_curve (two circles through recent references), line / arc \
         (exact, from the line.*/arc.* parameters) or program (exact, along 'path')",
    )
    .enumeration(&ESTIMATOR_TYPE);
    GEOMETRY: Reals<{ line_arc_parameters::COUNT }> = line_arc_parameters::VARIABLES;
    PATH: Str = Variable::parameter(
        "path",
        Start::String(path_parameter::DEFAULT),
        path_parameter::DESCRIPTION,
    );
    TOLERANCE: Real = path_parameter::TOLERANCE;
    VREF: Reals<2> = axis_block(&XY, &[REFERENCE_VELOCITY_IN]);
    FEED_FORWARD: Real = controller_parameters::FEED_FORWARD;
    AREF: Reals<2> = axis_block(&XY, &[REFERENCE_ACCELERATION_IN]);
    ACCELERATION_FEED_FORWARD: Real = controller_parameters::ACCELERATION_FEED_FORWARD;
    DIALECT: Int = path_parameter::DIALECT;
    OPTIONAL_STOP: Bool = path_parameter::OPTIONAL_STOP;
    HOME: Reals<3> = path_parameter::HOME;
    TOOL_RADII: Str = path_parameter::TOOL_RADII;
    AHEAD: Reals<2> = axis_block(&XY, &[ACCELERATION_AHEAD_IN]);
    LOOK_AHEAD: Bool = Variable::parameter(
        "feedForwardLookAhead",
        Start::Boolean(false),
        "Acceleration feed-forward from the interpolator's look-ahead: \
         accelerationFeedForward times ahead (the mean acceleration over the coming period, \
         exact over each hold whatever the jerk does) instead of aref extrapolated to the \
         middle of the hold; needs an interpolator that gives ahead",
    );
}

pub static INFO: ModelInfo = ModelInfo {
    identifier: "ContourCCC2D",
    description:
        "Two-axis cross-coupled contour controller: position loops plus a contour correction \
                  whose PID gains are adapted by a 7-set Mamdani fuzzy system",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment {
        start_time: 0.0,
        stop_time: 2.0,
        step_size: 1e-3,
    },
    // Every output starts at 0: the control law first runs in fmi2DoStep.
    initial_dependencies: &[],
    initial_dependencies_on_some_paths: &[],
    create: |environment: &Environment| {
        Box::new(ContourCCC2D {
            environment: environment.clone(),
            state: None,
            warnings: Vec::new(),
        })
    },
};

/// `Option<State>` as below. Version 2: the controller became N-axis (per-axis contour
/// PIDs, unused in the plane, joined its state). Version 3: the program estimator's track
/// keeps its last two foot points (its next search's guess). Version 4: the velocity
/// feed-forward gain. Version 5: the acceleration feed-forward time. Version 6: a program's
/// moves carry their standstill (dwells, stops, Z alone). Version 7: the feed-forward
/// remembers its inputs (the acceleration at the middle of the hold).
const LAYOUT: StateLayout = StateLayout {
    model: "ContourCCC2D",
    version: 7,
};

/// The G-code reader's parameters.
const READER: path_parameter::ReaderParameters = path_parameter::ReaderParameters {
    dialect: DIALECT,
    optional_stop: OPTIONAL_STOP,
    home: HOME,
    tools: TOOL_RADII,
};

/// The model's state, saved as the controller's [`ControllerState`] (the same bytes).
#[derive(Clone, serde::Serialize)]
#[serde(transparent)]
struct State(ControllerState<CrossCoupledController<Estimator>, 2>);

impl std::ops::Deref for State {
    type Target = ControllerState<CrossCoupledController<Estimator>, 2>;
    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

impl std::ops::DerefMut for State {
    fn deref_mut(&mut self) -> &mut Self::Target {
        &mut self.0
    }
}

/// A restore reads the estimator as saved and resumes it: a `program` estimator finds its
/// path's index in the environment's cache instead of building it (1.3 ms for the
/// infinity NURBS, more for a long program), then the state is checked as saved.
impl RestoredState for State {
    type Saved = ControllerState<CrossCoupledController<SavedEstimator>, 2>;

    fn restore(saved: Self::Saved, time: f64, environment: &Environment) -> Result<Self, String> {
        let ControllerState {
            controller,
            clock,
            feed_forward,
        } = saved;
        let controller = controller
            .map_estimator(|e| e.resume(&environment.indexes))
            .map_err(|e| format!("estimator: {e}"))?;
        let state = ControllerState {
            controller,
            clock,
            feed_forward,
        };
        state.validate(time, environment)?;
        Ok(State(state))
    }
}

impl SavedController<2> for CrossCoupledController<Estimator> {
    const AXES: &'static [Axis] = &XY;

    fn ts(&self) -> f64 {
        self.config().ts
    }

    fn check_config(&self) -> Result<(), String> {
        self.config().validate().map_err(config_message)
    }

    fn position_loops(&self) -> &[Pid] {
        self.axes()
    }

    /// The contour PID and the per-axis contour PIDs, the estimator's radii, and every
    /// number finite.
    fn check_rest(state: &ControllerState<Self, 2>) -> Result<(), String> {
        let controller = &state.controller;
        let ts = controller.ts();
        controller_parameters::check_pid("contour PID", controller.law().pid(), ts)?;
        for (axis, pid) in XY.iter().zip(controller.contour_axes()) {
            controller_parameters::check_pid(&format!("{} contour PID", axis.label), pid, ts)?;
        }
        saved_state::all_positive(state, "radius").map_err(|e| format!("estimator: {e}"))?;
        saved_state::all_finite(state)
    }
}

pub struct ContourCCC2D {
    environment: Environment,
    state: Option<State>,
    /// For the log: the path reader's warnings at initialization, and a reference off
    /// the `program` estimator's path once.
    warnings: Vec<String>,
}

fn gains([kp, ki, kd]: [f64; 3]) -> PidGains {
    PidGains::new(kp, ki, kd)
}

fn config(values: &Values) -> ControllerConfig {
    let [ke, kde, kpf, kif, kdf] = FUZZY_FACTORS.get(values);
    let mode = controller_parameters::mode(CCC_ENABLE.get(values), FUZZY_ENABLE.get(values));
    let [xp, xi, xd, yp, yi, yd] = AXIS_GAINS.get(values);
    ControllerConfig {
        ts: TS.get(values),
        axis: [gains([xp, xi, xd]), gains([yp, yi, yd])],
        axis_limit: None,
        ccc: CccConfig {
            mode,
            gains0: gains(CCC_GAINS0.get(values)),
            fuzzy: FuzzyFactors {
                ke,
                kde,
                kpf,
                kif,
                kdf,
            },
            limit: Some(CCC_LIMIT.get(values)),
        },
    }
}

/// The variable that sets a configuration value, if one does (the FMU never sets an
/// axis limit).
fn variable_of(parameter: Parameter) -> Option<&'static Variable> {
    let gain = controller_parameters::gain_index;
    let vr = match parameter {
        Parameter::Ts => TS.vr(),
        Parameter::AxisGain(axis, g) => AXIS_GAINS.at(3 * axis + gain(g)).vr(),
        Parameter::ContourLimit => CCC_LIMIT.vr(),
        Parameter::ContourGain(g) => CCC_GAINS0.at(gain(g)).vr(),
        Parameter::Fuzzy(f) => FUZZY_FACTORS
            .at(match f {
                FuzzyFactor::Ke => 0,
                FuzzyFactor::Kde => 1,
                FuzzyFactor::Kpf => 2,
                FuzzyFactor::Kif => 3,
                FuzzyFactor::Kdf => 4,
            })
            .vr(),
        // The five-axis values are not in this model's configuration.
        _ => return None,
    };
    Some(&VARIABLES[vr])
}

/// A configuration error in the FMU's own parameter names (the library's name for a value
/// no parameter sets).
fn config_message(e: ConfigError) -> String {
    match variable_of(e.parameter) {
        Some(v) => e.message_for(&v.name.to_string()),
        None => e.to_string(),
    }
}

/// The estimator kind the `estimator` value selects.
fn estimator_kind(values: &Values) -> Result<EstimatorKind, String> {
    let value = ESTIMATOR.get(values);
    usize::try_from(value)
        .ok()
        .and_then(|v| v.checked_sub(1))
        .and_then(|i| EstimatorKind::ALL.get(i).copied())
        .ok_or_else(|| {
            format!(
                "parameter 'estimator' = {value} is not one of {}",
                ESTIMATOR_TYPE.listing()
            )
        })
}

/// The estimator the parameters choose ([`Estimator::for_path`]), with the path reader's
/// warnings. The exact line and arc estimators measure against the paths named `line` and
/// `arc` (the `line.*` and `arc.*` parameters, whatever `path` says), the program
/// estimator against `path`, both as followed (blended); the free-curve one needs none.
fn estimator(
    values: &Values,
    environment: &Environment,
) -> Result<(Estimator, Vec<String>), String> {
    let kind = estimator_kind(values)?;
    let spec = match kind {
        EstimatorKind::FreeCurve => {
            return Ok((
                Estimator::FreeCurve(FreeCurveEstimator::default()),
                Vec::new(),
            ))
        }
        EstimatorKind::Line => "line",
        EstimatorKind::Arc => "arc",
        EstimatorKind::Program => PATH.get(values),
    };
    let mut path = path_parameter::path(spec, values, GEOMETRY, READER, environment)?;
    let warnings = path_parameter::reader_warnings(&mut path);
    let path = path.blended(TOLERANCE.get(values));
    Ok((
        Estimator::for_path_shared(kind, &path, &environment.indexes),
        warnings,
    ))
}

impl Model for ContourCCC2D {
    fn initialize(&mut self, values: &mut Values, start_time: f64) -> ModelResult {
        check_period("Ts", TS.get(values))?;
        let config = config(values);
        let (estimator, warnings) = estimator(values, &self.environment)?;
        let controller = CrossCoupledController::new(config, estimator).map_err(config_message)?;
        self.warnings = warnings;
        self.state = Some(State(ControllerState {
            controller,
            clock: SampleClock::new(start_time, config.ts),
            feed_forward: FeedForward::new(
                FEED_FORWARD.get(values),
                ACCELERATION_FEED_FORWARD.get(values),
            )?,
        }));
        U.set(values, &Vector2::zeros());
        CONTOUR_ERROR.set(values, 0.0);
        ERR.set(values, &Vector2::zeros());
        CCC_GAINS.set(values, &Vector3::zeros());
        Ok(())
    }

    fn do_step(&mut self, values: &mut Values, time: f64, step: f64) -> ModelResult {
        let state = &mut self.state.as_mut().ok_or("not initialized")?.0;
        let reference = REF.vector(values);
        let actual = POS.vector(values);
        let (velocity, acceleration) = (VREF.vector(values), AREF.vector(values));
        let (look_ahead, ahead) = (LOOK_AHEAD.get(values), AHEAD.vector(values));
        let ts = state.clock.period();
        while state.clock.take_before(time + step) {
            let feed_forward = if look_ahead {
                state.feed_forward.over_hold(velocity, ahead)
            } else {
                state
                    .feed_forward
                    .sample(time, velocity, acceleration, state.clock.latest(), ts)
            };
            let out = state
                .controller
                .sample_with(reference, actual, feed_forward);
            U.set(values, &out.u);
            CONTOUR_ERROR.set(values, out.contour.error);
            ERR.set(values, &out.following_error);
            let (kp, ki, kd) = out.gains;
            CCC_GAINS.set(values, &Vector3::new(kp, ki, kd));
        }
        if let Some(off) = state.controller.estimator_mut().take_off_path() {
            // Once per instance: the only text a step makes.
            self.warnings.push(format!(
                "the reference ref.x, ref.y came {off:.6} mm off the path of parameter \
                 'path' by t = {} s (more than {} mm: another program, file or tolerance than \
                 the interpolator's?); the contour error is measured to the nearest point \
                 ahead on 'path'",
                time + step,
                ON_PATH
            ));
        }
        Ok(())
    }

    fn take_warnings(&mut self) -> Vec<String> {
        std::mem::take(&mut self.warnings)
    }

    crate::framework::saved_state::sampled_state_methods!(State, LAYOUT);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn start_values_are_the_controller_library_defaults() {
        assert_eq!(DEFAULT, ControllerConfig::default());
        let values = Values::from_table(&VARIABLES);
        assert_eq!(config(&values), ControllerConfig::default());
        let (estimator, warnings) = estimator(&values, &Environment::default()).unwrap();
        assert_eq!(estimator.kind(), EstimatorKind::FreeCurve);
        assert!(warnings.is_empty());
    }

    #[test]
    fn configuration_errors_use_the_fmu_parameter_names() {
        let mut values = Values::from_table(&VARIABLES);
        values.set_real(AXIS_GAINS.at(4).vr(), -1.0);
        let e = CrossCoupledController::new(
            config(&values),
            Estimator::FreeCurve(FreeCurveEstimator::default()),
        )
        .unwrap_err();
        assert_eq!(
            config_message(e),
            "parameter axis.y.Ki = -1 is invalid: must be finite and >= 0"
        );
        let mut values = Values::from_table(&VARIABLES);
        values.set_real(FUZZY_FACTORS.at(3).vr(), f64::NAN);
        let e = config(&values).validate().unwrap_err();
        assert!(config_message(e).starts_with("parameter fuzzy.ki = NaN"));
    }

    /// A `program` estimator's exact-distance index is shared: instances on one path
    /// build it once, a state restored in the same process finds it, one restored in
    /// another builds it once; all go on bit for bit, with the same bytes saved.
    #[test]
    fn a_restored_program_estimator_finds_its_index() {
        use crate::framework::variables::Value;
        use contour_core::path::planar::builtin;
        use contour_core::path::Curve;
        let env = Environment::default();
        let mut values = Values::from_table(&VARIABLES);
        values.set(PATH.vr(), Value::String("infinity".into()));
        values.set(ESTIMATOR.vr(), Value::Integer(4));
        let infinity = builtin::by_name("infinity").unwrap();
        let feed = |values: &mut Values, k: usize| {
            let u = k as f64 * 2e-4;
            let (r, p) = (infinity.eval(u).p, infinity.eval((u - 4e-3).max(0.0)).p);
            values.set_real(REF.at(0).vr(), r[0]);
            values.set_real(REF.at(1).vr(), r[1]);
            values.set_real(POS.at(0).vr(), p[0] + 1e-3);
            values.set_real(POS.at(1).vr(), p[1]);
        };
        let mut a = (INFO.create)(&env);
        a.initialize(&mut values, 0.0).unwrap();
        let mut other = (INFO.create)(&env);
        other.initialize(&mut values.clone(), 0.0).unwrap();
        assert_eq!(env.indexes.indexes_made(), 1, "one index for two instances");
        for k in 0..100 {
            feed(&mut values, k);
            a.do_step(&mut values, k as f64 * 1e-3, 1e-3).unwrap();
        }
        let saved = a.save_state().unwrap();
        let mut b = (INFO.create)(&env);
        b.restore_state(&saved, 0.1).unwrap();
        assert_eq!(env.indexes.indexes_made(), 1, "found, not built again");
        assert_eq!(b.save_state().unwrap(), saved);
        let elsewhere = Environment::default();
        let mut c = (INFO.create)(&elsewhere);
        c.restore_state(&saved, 0.1).unwrap();
        assert_eq!(elsewhere.indexes.indexes_made(), 1);
        let (mut vb, mut vc) = (values.clone(), values.clone());
        for k in 100..300 {
            let t = k as f64 * 1e-3;
            for v in [&mut values, &mut vb, &mut vc] {
                feed(v, k);
            }
            a.do_step(&mut values, t, 1e-3).unwrap();
            b.do_step(&mut vb, t, 1e-3).unwrap();
            c.do_step(&mut vc, t, 1e-3).unwrap();
            assert!(values == vb && values == vc, "sample {k}");
        }
        assert!(
            CONTOUR_ERROR.get(&values).abs() > 1e-4,
            "a real error is measured"
        );
    }

    #[test]
    fn enumeration_items_are_the_estimator_kinds_in_order() {
        assert_eq!(ESTIMATOR_TYPE.items.len(), EstimatorKind::ALL.len());
        let mut values = Values::from_table(&VARIABLES);
        for (i, (item, kind)) in ESTIMATOR_TYPE
            .items
            .iter()
            .zip(EstimatorKind::ALL)
            .enumerate()
        {
            assert_eq!(item.name, kind.as_str());
            values.set(
                ESTIMATOR.vr(),
                crate::framework::variables::Value::Integer(i as i32 + 1),
            );
            assert_eq!(estimator_kind(&values), Ok(kind));
        }
        for bad in [0, 5, -1] {
            values.set(
                ESTIMATOR.vr(),
                crate::framework::variables::Value::Integer(bad),
            );
            let message = estimator_kind(&values).unwrap_err();
            assert!(
                message.contains("1 = free_curve, 2 = line, 3 = arc, 4 = program"),
                "{message}"
            );
        }
    }
}
