//! `XYServoPlant`: the two-axis test plant of docs/design/two-axis.md §4.5 as an FMU model. Velocity
//! commands in, positions and velocities out. Linear by default and then integrated exactly,
//! so the trajectory does not depend on the communication step; friction, backlash and a
//! current limit (§4.5b) are substepped.

use super::axis_variables::{COMMAND_IN, INITIAL_POSITION, POSITION_OUT, VELOCITY_OUT};
use super::servo_plant;
use crate::framework::model::{DefaultExperiment, Environment, Model, ModelInfo, ModelResult};
use crate::framework::saved_state::StateLayout;
use crate::framework::variable_table::{axis_block, variable_table, AxisTemplate, XY};
use crate::framework::variables::Values;
use contour_core::plant::{AxisParams, XyTable, XyTableParams};

const P: AxisParams = AxisParams::PAPER;
/// The drive parameters, in [`AxisParams`] field order.
const AXIS_FIELDS: [AxisTemplate; servo_plant::FIELDS] = servo_plant::drive_fields(P);

variable_table! {
    static VARIABLES;
    U: Reals<2> = axis_block(&XY, &[COMMAND_IN]);
    POS: Reals<2> = axis_block(&XY, &[POSITION_OUT]);
    VEL: Reals<2> = axis_block(&XY, &[VELOCITY_OUT]);
    /// J, B, CT, lead, Kvp, Kvi of X, then of Y.
    AXIS_PARAMS: Reals<12> = axis_block(&XY, &AXIS_FIELDS);
    POS0: Reals<2> = axis_block(&XY, &[INITIAL_POSITION]);
    /// Friction, backlash and current limit of X, then of Y (all off by default).
    EFFECTS: Reals<10> = axis_block(&XY, &servo_plant::EFFECT_TEMPLATES);
}

pub static INFO: ModelInfo = ModelInfo {
    identifier: "XYServoPlant",
    description:
        "Two-axis servo test plant: per axis a PI velocity-loop drive, a motor (J, B, CT) \
                  and a ball screw, optionally with friction, backlash and a current limit; \
                  velocity commands in, positions out, integrated exactly when linear",
    variables: &VARIABLES,
    default_experiment: DefaultExperiment {
        start_time: 0.0,
        stop_time: 2.0,
        step_size: 1e-3,
    },
    // Both axes start at rest at pos0.
    initial_dependencies: &[
        (POS.at(0).vr(), &[POS0.at(0).vr()]),
        (POS.at(1).vr(), &[POS0.at(1).vr()]),
    ],
    initial_dependencies_on_some_paths: &[],
    create: |_: &Environment| Box::new(XYServoPlant::default()),
};

/// The [`XyTable`] as it serialises. Version 2: each axis's lead became a
/// [`Transmission`] (linear or rotary); 3: each axis gained its effects and the table
/// behind the play.
const LAYOUT: StateLayout = StateLayout {
    model: "XYServoPlant",
    version: 3,
};

/// The plant model; its state is the table's.
pub struct XYServoPlant {
    table: XyTable,
}

impl Default for XYServoPlant {
    fn default() -> Self {
        XYServoPlant {
            table: XyTable::new(XyTableParams::PAPER, [0.0, 0.0].into()),
        }
    }
}

/// The parameters of axis `index` (0 = x, 1 = y).
fn axis_params(values: &Values, index: usize) -> Result<AxisParams, String> {
    let params = servo_plant::axis_params(
        values,
        &VARIABLES,
        AXIS_PARAMS,
        index * AXIS_FIELDS.len(),
        &XY[index],
    )?;
    let effects = servo_plant::axis_effects(
        values,
        EFFECTS,
        index * servo_plant::EFFECT_FIELDS,
        &XY[index],
    )?;
    Ok(AxisParams { effects, ..params })
}

impl XYServoPlant {
    fn write_outputs(&self, values: &mut Values) {
        POS.set(values, &self.table.position());
        VEL.set(values, &self.table.velocity());
    }
}

impl Model for XYServoPlant {
    fn initialize(&mut self, values: &mut Values, _start_time: f64) -> ModelResult {
        let params = XyTableParams {
            axes: [axis_params(values, 0)?, axis_params(values, 1)?],
        };
        self.table = XyTable::new(params, POS0.vector(values));
        self.write_outputs(values);
        Ok(())
    }

    fn do_step(&mut self, values: &mut Values, _time: f64, step: f64) -> ModelResult {
        self.table.step(U.vector(values), step);
        self.write_outputs(values);
        Ok(())
    }

    servo_plant::plant_state_methods!(LAYOUT, XY);
}
