//! `FiveAxisPlant`: the five-axis test plant of docs/design/five-axis.md §5.1 (the FMU: §5.6) as an FMU model —
//! X, Y, Z ball-screw axes as the two-axis plant's, A and C on a small trunnion table
//! (worm gears). Velocity commands in (mm/s, rad/s), positions and velocities out;
//! linear by default and then integrated exactly, so the trajectory does not depend on the
//! communication step; friction, backlash and a current limit (§4.5b) are substepped.

use super::axis_variables::{COMMAND_IN, INITIAL_POSITION, POSITION_OUT, VELOCITY_OUT};
use super::servo_plant::{self, FIELDS};
use crate::framework::model::{DefaultExperiment, Environment, Model, ModelInfo, ModelResult};
use crate::framework::saved_state::StateLayout;
use crate::framework::variable_table::{axis_block, variable_table, Axis, XYZAC};
use crate::framework::variables::Values;
use contour_core::plant::{AxisParams, ServoAxes, ServoAxesParams};

const PLANT: ServoAxesParams<5> = ServoAxesParams::<5>::TRUNNION;

const LINEAR: [Axis; 3] = [XYZAC[0], XYZAC[1], XYZAC[2]];

variable_table! {
    static VARIABLES;
    U: Reals<5> = axis_block(&XYZAC, &[COMMAND_IN]);
    POS: Reals<5> = axis_block(&XYZAC, &[POSITION_OUT]);
    VEL: Reals<5> = axis_block(&XYZAC, &[VELOCITY_OUT]);
    /// J, B, CT, lead, Kvp, Kvi of X, Y, Z (the same ball-screw drive on each).
    LINEAR_PARAMS: Reals<18> = axis_block(&LINEAR, &servo_plant::drive_fields(PLANT.axes[0]));
    /// J, B, CT, ratio, Kvp, Kvi of A (tilting cradle).
    A_PARAMS: Reals<6> = axis_block(&[XYZAC[3]], &servo_plant::drive_fields(PLANT.axes[3]));
    /// J, B, CT, ratio, Kvp, Kvi of C (rotary table).
    C_PARAMS: Reals<6> = axis_block(&[XYZAC[4]], &servo_plant::drive_fields(PLANT.axes[4]));
    POS0: Reals<5> = axis_block(&XYZAC, &[INITIAL_POSITION]);
    /// Friction, backlash and current limit of X, Y, Z, A, C (all off by default).
    EFFECTS: Reals<25> = axis_block(&XYZAC, &servo_plant::EFFECT_TEMPLATES);
}

pub static INFO: ModelInfo = ModelInfo {
    identifier: "FiveAxisPlant",
    description: "Five-axis servo test plant (X Y Z ball screws, A C trunnion table on worm \
                  gears): per axis a PI velocity-loop drive and a motor, optionally with \
                  friction, backlash and a current limit; velocity commands in, positions \
                  out, integrated exactly when linear",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment {
        start_time: 0.0,
        stop_time: 2.0,
        step_size: 1e-3,
    },
    // Every axis starts at rest at pos0.
    initial_dependencies: &[
        (POS.at(0).vr(), &[POS0.at(0).vr()]),
        (POS.at(1).vr(), &[POS0.at(1).vr()]),
        (POS.at(2).vr(), &[POS0.at(2).vr()]),
        (POS.at(3).vr(), &[POS0.at(3).vr()]),
        (POS.at(4).vr(), &[POS0.at(4).vr()]),
    ],
    initial_dependencies_on_some_paths: &[],
    create: |_: &Environment| Box::new(FiveAxisPlant::default()),
};

/// The [`ServoAxes`] as they serialise. Version 2: each axis gained its effects and the
/// table behind the play.
const LAYOUT: StateLayout = StateLayout {
    model: "FiveAxisPlant",
    version: 2,
};

/// The plant model; its state is the axes'.
pub struct FiveAxisPlant {
    table: ServoAxes<5>,
}

impl Default for FiveAxisPlant {
    fn default() -> Self {
        FiveAxisPlant {
            table: ServoAxes::new(PLANT, Vector5::zeros()),
        }
    }
}

type Vector5 = contour_core::geometry::Vector<5>;

/// The parameters of joint `index` (X, Y, Z, A, C).
fn axis_params(values: &Values, index: usize) -> Result<AxisParams, String> {
    let axis = &XYZAC[index];
    let params = match index {
        0..=2 => servo_plant::axis_params(values, &VARIABLES, LINEAR_PARAMS, index * FIELDS, axis),
        3 => servo_plant::axis_params(values, &VARIABLES, A_PARAMS, 0, axis),
        _ => servo_plant::axis_params(values, &VARIABLES, C_PARAMS, 0, axis),
    }?;
    let effects =
        servo_plant::axis_effects(values, EFFECTS, index * servo_plant::EFFECT_FIELDS, axis)?;
    Ok(AxisParams { effects, ..params })
}

impl FiveAxisPlant {
    fn write_outputs(&self, values: &mut Values) {
        POS.set(values, &self.table.position());
        VEL.set(values, &self.table.velocity());
    }
}

impl Model for FiveAxisPlant {
    fn initialize(&mut self, values: &mut Values, _start_time: f64) -> ModelResult {
        let mut axes = [PLANT.axes[0]; 5];
        for (index, axis) in axes.iter_mut().enumerate() {
            *axis = axis_params(values, index)?;
        }
        self.table = ServoAxes::new(ServoAxesParams { axes }, POS0.vector(values));
        self.write_outputs(values);
        Ok(())
    }

    fn do_step(&mut self, values: &mut Values, _time: f64, step: f64) -> ModelResult {
        // Inputs are finite: fmi2SetReal refuses NaN and infinities.
        let command = U.vector(values);
        self.table.step(command, step);
        self.write_outputs(values);
        Ok(())
    }

    servo_plant::plant_state_methods!(LAYOUT, XYZAC);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn start_values_are_the_trunnion_plant() {
        let values = Values::from_table(&VARIABLES);
        for (index, expected) in PLANT.axes.iter().enumerate() {
            assert_eq!(axis_params(&values, index).as_ref(), Ok(expected));
        }
        let names: Vec<String> = VARIABLES.iter().map(|v| v.name.to_string()).collect();
        for name in [
            "u.X", "pos.C", "vel.A", "X.lead", "A.ratio", "C.Kvi", "pos0.Z",
        ] {
            assert!(names.iter().any(|n| n == name), "{name}");
        }
    }
}
