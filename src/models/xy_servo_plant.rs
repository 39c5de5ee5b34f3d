//! `XYServoPlant`: the two-axis test plant of docs/design.md §4.5 as an FMU model. Velocity
//! commands in, positions and velocities out; integrated exactly, so the trajectory does
//! not depend on the communication step.

use super::variables::{Start, Values, Variable, Vr};
use super::{
    decode_state, encode_state, state_check, DefaultExperiment, Environment, Model, ModelInfo,
    ModelResult, StateLayout,
};
use crate::plant::{AxisParams, ServoAxis, XyTable, XyTableParams};

pub const U_X: Vr = 0;
pub const U_Y: Vr = 1;
pub const POS_X: Vr = 2;
pub const POS_Y: Vr = 3;
pub const VEL_X: Vr = 4;
pub const VEL_Y: Vr = 5;
/// First parameter of each axis; the six drive parameters follow in [`AXIS_FIELDS`] order.
const X_PARAMS: Vr = 6;
const Y_PARAMS: Vr = 12;
pub const POS0_X: Vr = 18;
pub const POS0_Y: Vr = 19;

/// Per-axis parameter names (after the `x.`/`y.` prefix) in table order.
const AXIS_FIELDS: [&str; 6] = ["J", "B", "CT", "lead", "Kvp", "Kvi"];

const P: AxisParams = AxisParams::PAPER;

macro_rules! axis_parameters {
    ($first:expr, $axis:literal) => {
        [
            Variable::parameter(
                $first,
                concat!($axis, ".J"),
                Start::Real(P.inertia),
                concat!("Inertia of the ", $axis, " motor plus reflected load"),
            )
            .unit("kg.m2")
            .min(0.0),
            Variable::parameter(
                $first + 1,
                concat!($axis, ".B"),
                Start::Real(P.friction),
                concat!("Viscous friction of the ", $axis, " axis"),
            )
            .unit("N.m.s/rad")
            .min(0.0),
            Variable::parameter(
                $first + 2,
                concat!($axis, ".CT"),
                Start::Real(P.torque_constant),
                concat!("Torque constant of the ", $axis, " motor"),
            )
            .unit("N.m/A")
            .min(0.0),
            Variable::parameter(
                $first + 3,
                concat!($axis, ".lead"),
                Start::Real(P.lead),
                concat!(
                    "Ball-screw lead of the ",
                    $axis,
                    " axis (mm per revolution)"
                ),
            )
            .unit("mm")
            .min(0.0),
            Variable::parameter(
                $first + 4,
                concat!($axis, ".Kvp"),
                Start::Real(P.kvp),
                concat!("Proportional gain of the ", $axis, " drive's velocity loop"),
            )
            .unit("A.s/rad")
            .min(0.0),
            Variable::parameter(
                $first + 5,
                concat!($axis, ".Kvi"),
                Start::Real(P.kvi),
                concat!("Integral gain of the ", $axis, " drive's velocity loop"),
            )
            .unit("A/rad")
            .min(0.0),
        ]
    };
}

const X_AXIS: [Variable; 6] = axis_parameters!(X_PARAMS, "x");
const Y_AXIS: [Variable; 6] = axis_parameters!(Y_PARAMS, "y");

static VARIABLES: [Variable; 20] = [
    Variable::input(U_X, "u.x", 0.0, "Velocity command to the X drive").unit("mm/s"),
    Variable::input(U_Y, "u.y", 0.0, "Velocity command to the Y drive").unit("mm/s"),
    Variable::output(POS_X, "pos.x", "Position of the X axis").unit("mm"),
    Variable::output(POS_Y, "pos.y", "Position of the Y axis").unit("mm"),
    Variable::output(VEL_X, "vel.x", "Velocity of the X axis").unit("mm/s"),
    Variable::output(VEL_Y, "vel.y", "Velocity of the Y axis").unit("mm/s"),
    X_AXIS[0],
    X_AXIS[1],
    X_AXIS[2],
    X_AXIS[3],
    X_AXIS[4],
    X_AXIS[5],
    Y_AXIS[0],
    Y_AXIS[1],
    Y_AXIS[2],
    Y_AXIS[3],
    Y_AXIS[4],
    Y_AXIS[5],
    Variable::parameter(
        POS0_X,
        "pos0.x",
        Start::Real(0.0),
        "Initial position of the X axis",
    )
    .unit("mm"),
    Variable::parameter(
        POS0_Y,
        "pos0.y",
        Start::Real(0.0),
        "Initial position of the Y axis",
    )
    .unit("mm"),
];

pub static INFO: ModelInfo = ModelInfo {
    identifier: "XYServoPlant",
    description:
        "Two-axis servo test plant: per axis a PI velocity-loop drive, a motor (J, B, CT) \
                  and a ball screw; velocity commands in, positions out, integrated exactly",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment {
        start_time: 0.0,
        stop_time: 2.0,
        step_size: 1e-3,
    },
    // Both axes start at rest at pos0.
    initial_dependencies: &[(POS_X, &[POS0_X]), (POS_Y, &[POS0_Y])],
    create: |_: &Environment| Box::new(XyServoPlant::default()),
};

/// Version 1: the [`XyTable`] as it serialises.
const LAYOUT: StateLayout = StateLayout {
    model: "XYServoPlant",
    version: 1,
};

/// Checks a restored table like the parameters it was built from; the error names the
/// offending value.
fn validate(table: &XyTable) -> Result<(), String> {
    for (name, axis) in [("x", &table.x), ("y", &table.y)] {
        axis.params()
            .validate()
            .map_err(|e| format!("axis {name}: {e}"))?;
        state_check::all_finite(axis).map_err(|e| format!("axis {name}: {e}"))?;
        check_cached_transition(name, axis)?;
    }
    Ok(())
}

/// An axis keeps the transition matrices of its last step length; they must be the ones
/// its parameters give for that length (recomputed the same way, so bit for bit), or the
/// restored axis would follow other dynamics than its parameters say.
fn check_cached_transition(name: &str, axis: &ServoAxis) -> Result<(), String> {
    let cached = |a: &ServoAxis| -> Vec<(String, f64)> {
        state_check::floats(a)
            .into_iter()
            .filter(|(path, _)| path.starts_with("cached"))
            .collect()
    };
    let saved = cached(axis);
    let Some(&(_, step)) = saved.iter().find(|(path, _)| path == "cached.step") else {
        return Ok(()); // nothing cached yet
    };
    if !(step.is_finite() && step > 0.0) {
        return Err(format!(
            "axis {name}: cached step length {step} s must be finite and > 0"
        ));
    }
    let mut reference = ServoAxis::new(*axis.params(), 0.0);
    reference.step(0.0, step);
    let expected = cached(&reference);
    if saved.len() != expected.len()
        || saved
            .iter()
            .zip(&expected)
            .any(|(a, b)| a.0 != b.0 || a.1.to_bits() != b.1.to_bits())
    {
        return Err(format!(
            "axis {name}: the cached transition for steps of {step} s does not match the \
             axis parameters"
        ));
    }
    Ok(())
}

fn decode(bytes: &[u8]) -> Result<XyTable, String> {
    let table: XyTable = decode_state(LAYOUT, bytes)?;
    validate(&table)?;
    Ok(table)
}

/// The plant model; its state is the table's.
pub struct XyServoPlant {
    table: XyTable,
}

impl Default for XyServoPlant {
    fn default() -> Self {
        XyServoPlant {
            table: XyTable::new(XyTableParams::PAPER, [0.0, 0.0]),
        }
    }
}

fn axis_params(values: &Values, first: Vr, axis: &str) -> Result<AxisParams, String> {
    let p = |i: usize| values.real(first + i);
    let params = AxisParams {
        inertia: p(0),
        friction: p(1),
        torque_constant: p(2),
        lead: p(3),
        kvp: p(4),
        kvi: p(5),
    };
    // J, CT and lead divide or scale the dynamics: zero is as unphysical as negative.
    for i in [0, 2, 3] {
        if p(i) <= 0.0 {
            return Err(format!(
                "parameter '{axis}.{}' must be > 0 (got {})",
                AXIS_FIELDS[i],
                p(i)
            ));
        }
    }
    params.validate().map_err(|e| format!("axis {axis}: {e}"))?;
    Ok(params)
}

impl XyServoPlant {
    fn write_outputs(&self, values: &mut Values) {
        let [px, py] = self.table.position();
        let [vx, vy] = self.table.velocity();
        values.set_real(POS_X, px);
        values.set_real(POS_Y, py);
        values.set_real(VEL_X, vx);
        values.set_real(VEL_Y, vy);
    }
}

impl Model for XyServoPlant {
    fn initialize(&mut self, values: &mut Values, _start_time: f64) -> ModelResult {
        let params = XyTableParams {
            x: axis_params(values, X_PARAMS, "x")?,
            y: axis_params(values, Y_PARAMS, "y")?,
        };
        self.table = XyTable::new(params, [values.real(POS0_X), values.real(POS0_Y)]);
        self.write_outputs(values);
        Ok(())
    }

    fn do_step(&mut self, values: &mut Values, _time: f64, step: f64) -> ModelResult {
        self.table.step([values.real(U_X), values.real(U_Y)], step);
        self.write_outputs(values);
        Ok(())
    }

    fn save_state(&self) -> Result<Vec<u8>, String> {
        encode_state(LAYOUT, &self.table)
    }

    fn check_state(&self, bytes: &[u8], _time: f64) -> ModelResult {
        decode(bytes).map(drop)
    }

    fn restore_state(&mut self, bytes: &[u8], _time: f64) -> ModelResult {
        self.table = decode(bytes)?;
        Ok(())
    }
}
