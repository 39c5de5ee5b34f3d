//! `ContourCCC2D`: the two-axis controller. Per axis a position loop on the following
//! error, plus the cross-coupled correction along the contour normal with fixed or
//! fuzzy-adapted PID gains (docs/design.md §4.2, 4.3). The control law runs every `Ts` inside
//! `fmi2DoStep` on the inputs held over the step, whatever the communication step.

use super::sample_clock::{check_period, SampleClock};
use super::variables::{EnumItem, EnumType, Start, Values, Variable, Vr};
use super::{
    decode_checked, encode_state, geometry, state_check, DefaultExperiment, Environment, Model,
    ModelInfo, ModelResult, SavedState, StateLayout,
};
use crate::contour::{ArcEstimator, Estimator, EstimatorKind, FreeCurveEstimator, LineEstimator};
use crate::control::{
    CccConfig, CccMode, ControllerConfig, CrossCoupledController, FuzzyFactors, Pid, PidGains,
};

pub const REF_X: Vr = 0;
pub const REF_Y: Vr = 1;
pub const POS_X: Vr = 2;
pub const POS_Y: Vr = 3;
pub const U_X: Vr = 4;
pub const U_Y: Vr = 5;
pub const CONTOUR_ERROR: Vr = 6;
pub const ERR_X: Vr = 7;
pub const ERR_Y: Vr = 8;
pub const CCC_KP: Vr = 9;
pub const CCC_KI: Vr = 10;
pub const CCC_KD: Vr = 11;
pub const TS: Vr = 12;
/// Kp, Ki, Kd of the X position loop, then of Y.
pub const AXIS_GAINS: Vr = 13;
pub const CCC_ENABLE: Vr = 19;
pub const FUZZY_ENABLE: Vr = 20;
/// Kp0, Ki0, Kd0.
pub const CCC_GAINS0: Vr = 21;
pub const CCC_LIMIT: Vr = 24;
/// ke, kde, kp, ki, kd.
pub const FUZZY_FACTORS: Vr = 25;
pub const ESTIMATOR: Vr = 30;
pub const GEOMETRY: Vr = 31;

/// The `estimator` parameter's type: an FMI Enumeration (importers show a drop-down), in
/// the order of [`EstimatorKind::ALL`] (values 1, 2, 3).
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
    ],
};

/// Start values: the controller library's documented defaults.
const DEFAULT: ControllerConfig = ControllerConfig::DEFAULT;

const fn real(vr: Vr, name: &'static str, start: f64, description: &'static str) -> Variable {
    Variable::parameter(vr, name, Start::Real(start), description).min(0.0)
}

const G: [Variable; geometry::COUNT] = geometry::variables(GEOMETRY);
const A: [PidGains; 2] = DEFAULT.axis;
const C: CccConfig = DEFAULT.ccc;

static VARIABLES: [Variable; 31 + geometry::COUNT] = [
    Variable::input(REF_X, "ref.x", 0.0, "Reference (command) position, x").unit("mm"),
    Variable::input(REF_Y, "ref.y", 0.0, "Reference (command) position, y").unit("mm"),
    Variable::input(POS_X, "pos.x", 0.0, "Measured position, x").unit("mm"),
    Variable::input(POS_Y, "pos.y", 0.0, "Measured position, y").unit("mm"),
    Variable::output(U_X, "u.x", "Velocity command to the X drive").unit("mm/s"),
    Variable::output(U_Y, "u.y", "Velocity command to the Y drive").unit("mm/s"),
    Variable::output(
        CONTOUR_ERROR,
        "contourError",
        "Estimated contour error, > 0 when the tool is right of the direction of travel",
    )
    .unit("mm"),
    Variable::output(ERR_X, "err.x", "Following error ref.x - pos.x").unit("mm"),
    Variable::output(ERR_Y, "err.y", "Following error ref.y - pos.y").unit("mm"),
    Variable::output(CCC_KP, "ccc.Kp", "Contour PID gain Kp in use").unit("1/s"),
    Variable::output(CCC_KI, "ccc.Ki", "Contour PID gain Ki in use").unit("1/s2"),
    Variable::output(CCC_KD, "ccc.Kd", "Contour PID gain Kd in use"),
    Variable::parameter(
        TS,
        "Ts",
        Start::Real(DEFAULT.ts),
        "Control period (at least 1 us)",
    )
    .unit("s"),
    real(
        AXIS_GAINS,
        "axis.x.Kp",
        A[0].kp,
        "X position loop, proportional gain",
    )
    .unit("1/s"),
    real(
        AXIS_GAINS + 1,
        "axis.x.Ki",
        A[0].ki,
        "X position loop, integral gain",
    )
    .unit("1/s2"),
    real(
        AXIS_GAINS + 2,
        "axis.x.Kd",
        A[0].kd,
        "X position loop, derivative gain",
    ),
    real(
        AXIS_GAINS + 3,
        "axis.y.Kp",
        A[1].kp,
        "Y position loop, proportional gain",
    )
    .unit("1/s"),
    real(
        AXIS_GAINS + 4,
        "axis.y.Ki",
        A[1].ki,
        "Y position loop, integral gain",
    )
    .unit("1/s2"),
    real(
        AXIS_GAINS + 5,
        "axis.y.Kd",
        A[1].kd,
        "Y position loop, derivative gain",
    ),
    Variable::parameter(
        CCC_ENABLE,
        "ccc.enable",
        Start::Boolean(true),
        "Apply the cross-coupled correction",
    ),
    Variable::parameter(
        FUZZY_ENABLE,
        "fuzzy.enable",
        Start::Boolean(true),
        "Adapt the contour PID gains with the fuzzy system (else fixed Kp0, Ki0, Kd0)",
    ),
    real(
        CCC_GAINS0,
        "ccc.Kp0",
        C.gains0.kp,
        "Contour PID base gain Kp0",
    )
    .unit("1/s"),
    real(
        CCC_GAINS0 + 1,
        "ccc.Ki0",
        C.gains0.ki,
        "Contour PID base gain Ki0",
    )
    .unit("1/s2"),
    real(
        CCC_GAINS0 + 2,
        "ccc.Kd0",
        C.gains0.kd,
        "Contour PID base gain Kd0",
    ),
    Variable::parameter(
        CCC_LIMIT,
        "ccc.limit",
        Start::Real(100.0),
        "Bound on the contour correction (> 0), with anti-windup",
    )
    .unit("mm/s"),
    real(
        FUZZY_FACTORS,
        "fuzzy.ke",
        C.fuzzy.ke,
        "Contour error quantisation factor (per um)",
    ),
    real(
        FUZZY_FACTORS + 1,
        "fuzzy.kde",
        C.fuzzy.kde,
        "Error change quantisation factor (per um/sample)",
    ),
    real(
        FUZZY_FACTORS + 2,
        "fuzzy.kp",
        C.fuzzy.kpf,
        "Scale of the fuzzy Kp adjustment",
    )
    .unit("1/s"),
    real(
        FUZZY_FACTORS + 3,
        "fuzzy.ki",
        C.fuzzy.kif,
        "Scale of the fuzzy Ki adjustment",
    )
    .unit("1/s2"),
    real(
        FUZZY_FACTORS + 4,
        "fuzzy.kd",
        C.fuzzy.kdf,
        "Scale of the fuzzy Kd adjustment",
    ),
    Variable::parameter(
        ESTIMATOR,
        "estimator",
        Start::Integer(1),
        "Contour estimator: free_curve (two circles through recent references), or line / arc \
         (exact, from the line.*/arc.* parameters)",
    )
    .enumeration(&ESTIMATOR_TYPE),
    G[0],
    G[1],
    G[2],
    G[3],
    G[4],
    G[5],
    G[6],
    G[7],
    G[8],
];

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
    create: |_: &Environment| Box::new(ContourCcc2D { state: None }),
};

/// Version 1: `Option<State>` as below.
const LAYOUT: StateLayout = StateLayout {
    model: "ContourCCC2D",
    version: 1,
};

#[derive(Clone, serde::Serialize, serde::Deserialize)]
struct State {
    controller: CrossCoupledController<Estimator>,
    clock: SampleClock,
}

impl SavedState for State {
    /// Checks a restored state like the parameters it was built from; the error names
    /// the offending value.
    fn validate(&self, time: f64) -> Result<(), String> {
        self.clock.validate_at(time)?;
        let controller = &self.controller;
        let config = controller.config();
        config
            .validate()
            .map_err(|e| format!("controller configuration: {e}"))?;
        if self.clock.period() != config.ts {
            return Err(format!(
                "sample clock period {} s differs from the controller's Ts = {} s",
                self.clock.period(),
                config.ts
            ));
        }
        let [x, y] = controller.axes();
        for (name, pid) in [
            ("X position loop", x),
            ("Y position loop", y),
            ("contour PID", controller.law().pid()),
        ] {
            check_pid(name, pid, config.ts)?;
        }
        state_check::all_positive(self, "radius").map_err(|e| format!("estimator: {e}"))?;
        state_check::all_finite(self)
    }
}

/// A PID restored from bytes: its period, gains, limit and memory (integral and previous
/// error) as the configuration would have made them.
fn check_pid(name: &str, pid: &Pid, ts: f64) -> Result<(), String> {
    if pid.ts() != ts {
        return Err(format!(
            "{name}: PID sample period {} s differs from Ts = {ts} s",
            pid.ts()
        ));
    }
    if !pid.integral().is_finite() {
        return Err(format!(
            "{name}: PID memory (integral) = {} is not finite",
            pid.integral()
        ));
    }
    if let Some(e) = pid.previous_error().filter(|e| !e.is_finite()) {
        return Err(format!(
            "{name}: PID memory (previous error) = {e} is not finite"
        ));
    }
    let g = pid.gains();
    for (gain, value) in [("Kp", g.kp), ("Ki", g.ki), ("Kd", g.kd)] {
        if !(value.is_finite() && value >= 0.0) {
            return Err(format!(
                "{name}: PID gain {gain} = {value} must be finite and >= 0"
            ));
        }
    }
    if let Some(limit) = pid.limit().filter(|l| !(l.is_finite() && *l > 0.0)) {
        return Err(format!(
            "{name}: PID output limit {limit} must be finite and > 0"
        ));
    }
    Ok(())
}

pub struct ContourCcc2D {
    state: Option<State>,
}

fn gains(values: &Values, first: Vr) -> PidGains {
    PidGains::new(
        values.real(first),
        values.real(first + 1),
        values.real(first + 2),
    )
}

fn config(values: &Values) -> ControllerConfig {
    let f = |i| values.real(FUZZY_FACTORS + i);
    let mode = match (values.boolean(CCC_ENABLE), values.boolean(FUZZY_ENABLE)) {
        (false, _) => CccMode::Off,
        (true, false) => CccMode::Fixed,
        (true, true) => CccMode::Fuzzy,
    };
    ControllerConfig {
        ts: values.real(TS),
        axis: [gains(values, AXIS_GAINS), gains(values, AXIS_GAINS + 3)],
        axis_limit: None,
        ccc: CccConfig {
            mode,
            gains0: gains(values, CCC_GAINS0),
            fuzzy: FuzzyFactors {
                ke: f(0),
                kde: f(1),
                kpf: f(2),
                kif: f(3),
                kdf: f(4),
            },
            limit: Some(values.real(CCC_LIMIT)),
        },
    }
}

/// The estimator kind the `estimator` value selects.
fn estimator_kind(values: &Values) -> Result<EstimatorKind, String> {
    let value = values.integer(ESTIMATOR);
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

fn estimator(values: &Values) -> Result<Estimator, String> {
    let kind = estimator_kind(values)?;
    Ok(match kind {
        EstimatorKind::FreeCurve => Estimator::FreeCurve(FreeCurveEstimator::default()),
        EstimatorKind::Line => {
            Estimator::Line(LineEstimator::new(&geometry::line(values, GEOMETRY)?))
        }
        EstimatorKind::Arc => Estimator::Arc(ArcEstimator::new(&geometry::arc(values, GEOMETRY)?)),
    })
}

impl Model for ContourCcc2D {
    fn initialize(&mut self, values: &mut Values, start_time: f64) -> ModelResult {
        check_period("Ts", values.real(TS))?;
        let config = config(values);
        let controller =
            CrossCoupledController::new(config, estimator(values)?).map_err(|e| e.to_string())?;
        self.state = Some(State {
            controller,
            clock: SampleClock::new(start_time, config.ts),
        });
        for vr in U_X..=CCC_KD {
            values.set_real(vr, 0.0);
        }
        Ok(())
    }

    fn do_step(&mut self, values: &mut Values, time: f64, step: f64) -> ModelResult {
        let state = self.state.as_mut().ok_or("not initialized")?;
        let reference = [values.real(REF_X), values.real(REF_Y)];
        let actual = [values.real(POS_X), values.real(POS_Y)];
        while state.clock.take_before(time + step) {
            let out = state.controller.sample(reference, actual);
            values.set_real(U_X, out.u[0]);
            values.set_real(U_Y, out.u[1]);
            values.set_real(CONTOUR_ERROR, out.contour.error);
            values.set_real(ERR_X, out.following_error[0]);
            values.set_real(ERR_Y, out.following_error[1]);
            values.set_real(CCC_KP, out.gains.0);
            values.set_real(CCC_KI, out.gains.1);
            values.set_real(CCC_KD, out.gains.2);
        }
        Ok(())
    }

    fn save_state(&self) -> Result<Vec<u8>, String> {
        encode_state(LAYOUT, &self.state)
    }

    fn check_state(&self, bytes: &[u8], time: f64) -> ModelResult {
        decode_checked::<State>(LAYOUT, bytes, time).map(drop)
    }

    fn restore_state(&mut self, bytes: &[u8], time: f64) -> ModelResult {
        self.state = decode_checked(LAYOUT, bytes, time)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn start_values_are_the_controller_library_defaults() {
        assert_eq!(DEFAULT, ControllerConfig::default());
        let values = Values::from_table(&VARIABLES);
        assert_eq!(config(&values), ControllerConfig::default());
        assert_eq!(estimator(&values).unwrap().kind(), EstimatorKind::FreeCurve);
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
            values.set(ESTIMATOR, super::super::Value::Integer(i as i32 + 1));
            assert_eq!(estimator_kind(&values), Ok(kind));
        }
        for bad in [0, 4, -1] {
            values.set(ESTIMATOR, super::super::Value::Integer(bad));
            let message = estimator_kind(&values).unwrap_err();
            assert!(
                message.contains("1 = free_curve, 2 = line, 3 = arc"),
                "{message}"
            );
        }
    }
}
