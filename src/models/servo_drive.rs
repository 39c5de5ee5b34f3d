//! `ServoDrive` and `ServoDriveRotary`: one axis of a digital servo drive (a velocity PI
//! loop with anti-windup, an effort limit, an optional current-loop lag and velocity
//! filter; contour_core::control::VelocityDrive, docs/design/two-axis.md §4.10) between
//! the NC's velocity command and a mechanics model that takes a force (linear axis) or a
//! torque (rotary axis). With it, our interpolator and controller drive a user's
//! mechanics FMU with wires only: u from the controller, vel from the mechanics, effort to
//! the mechanics.
//!
//! The two models are one law with two truthful interfaces: mm/s, N, N·s/mm, N/mm for a
//! linear axis (m/s, N·s/m, N/m in the SI build), rad/s, N·m, N·m·s/rad, N·m/rad for a
//! rotary one. Like a digital drive it samples u and vel once per communication step and
//! outputs the effort for that step (no direct feedthrough).

use crate::framework::model::{DefaultExperiment, Environment, Model, ModelInfo, ModelResult};
use crate::framework::saved_state::{self, decode_state, encode_state, StateLayout};
use crate::framework::variable_table::variable_table;
use crate::framework::variables::{Start, Values, Variable};
use contour_core::control::{DriveParams, VelocityDrive};

/// The defaults: a 100 kg slide (or 0.1 kg·m² table) with a 50 Hz velocity loop
/// (Kvp = 2π·50·m) whose PI zero sits a decade below (Kvi = Kvp·2π·5), 5 kN (5 kN·m)
/// peak, no current lag or filter.
const DEFAULTS: DriveParams = DriveParams {
    kvp: 31.4,
    kvi: 987.0,
    effort_max: 5000.0,
    current_lag: 0.0,
    velocity_filter: 0.0,
};

/// The variable table of a drive whose velocities, efforts and gains are in the given
/// units: (velocity, effort, Kvp, Kvi).
macro_rules! drive_table {
    ($table:ident, $velocity:literal, $effort:literal, $kvp:literal, $kvi:literal) => {
        variable_table! {
            static $table;
            U: Real = Variable::input("u", 0.0, "Velocity command (from the controller)")
                .unit($velocity);
            VEL: Real = Variable::input("vel", 0.0, "Measured velocity (from the mechanics)")
                .unit($velocity);
            EFFORT: Real = Variable::output(
                "effort",
                "Effort to apply over the step: Kvp·e + Kvi·∫e dt, e = u − vel, limited to \
±effortMax (through the current lag when set)",
            )
            .unit($effort);
            KVP: Real = Variable::parameter(
                "Kvp",
                Start::Real(DEFAULTS.kvp),
                "Proportional gain of the velocity loop",
            )
            .unit($kvp)
            .min(0.0);
            KVI: Real = Variable::parameter(
                "Kvi",
                Start::Real(DEFAULTS.kvi),
                "Integral gain of the velocity loop",
            )
            .unit($kvi)
            .min(0.0);
            EFFORT_MAX: Real = Variable::parameter(
                "effortMax",
                Start::Real(DEFAULTS.effort_max),
                "Largest effort either way (> 0); the integral stops while the demand is \
beyond it (anti-windup)",
            )
            .unit($effort)
            .min(0.0);
            CURRENT_LAG: Real = Variable::parameter(
                "currentLag",
                Start::Real(DEFAULTS.current_lag),
                "Time constant of the current loop (0: the effort follows at once)",
            )
            .unit("s")
            .min(0.0);
            VELOCITY_FILTER: Real = Variable::parameter(
                "velocityFilter",
                Start::Real(DEFAULTS.velocity_filter),
                "Time constant of the measured velocity's low-pass filter (0: none)",
            )
            .unit("s")
            .min(0.0);
        }
    };
}

mod linear {
    use super::*;
    drive_table!(VARIABLES, "mm/s", "N", "N.s/mm", "N/mm");
    pub(super) static TABLE: &[Variable] = &VARIABLES;
}

mod rotary {
    use super::*;
    drive_table!(VARIABLES, "rad/s", "N.m", "N.m.s/rad", "N.m/rad");
    pub(super) static TABLE: &[Variable] = &VARIABLES;
}

// The two tables have the same rows in the same order: one set of handles serves both.
use linear::{CURRENT_LAG, EFFORT, EFFORT_MAX, KVI, KVP, U, VEL, VELOCITY_FILTER};
const _: () = {
    let pairs = [
        (U.vr(), rotary::U.vr()),
        (VEL.vr(), rotary::VEL.vr()),
        (EFFORT.vr(), rotary::EFFORT.vr()),
        (KVP.vr(), rotary::KVP.vr()),
        (KVI.vr(), rotary::KVI.vr()),
        (EFFORT_MAX.vr(), rotary::EFFORT_MAX.vr()),
        (CURRENT_LAG.vr(), rotary::CURRENT_LAG.vr()),
        (VELOCITY_FILTER.vr(), rotary::VELOCITY_FILTER.vr()),
    ];
    let mut i = 0;
    while i < pairs.len() {
        assert!(pairs[i].0 == pairs[i].1, "the drive tables differ");
        i += 1;
    }
    assert!(linear::VARIABLE_COUNT == rotary::VARIABLE_COUNT);
};

pub static INFO: ModelInfo = drive_info(
    "ServoDrive",
    "One linear axis of a digital servo drive: velocity PI loop with anti-windup and an \
     effort limit, optional current-loop lag and velocity filter; velocity command and \
     measured velocity in, force out",
    linear::TABLE,
);

pub static INFO_ROTARY: ModelInfo = drive_info(
    "ServoDriveRotary",
    "One rotary axis of a digital servo drive: velocity PI loop with anti-windup and an \
     effort limit, optional current-loop lag and velocity filter; velocity command and \
     measured velocity in, torque out",
    rotary::TABLE,
);

/// A drive's model description: the law is the same, the table gives the units.
const fn drive_info(
    identifier: &'static str,
    description: &'static str,
    variables: &'static [Variable],
) -> ModelInfo {
    ModelInfo {
        identifier,
        description,
        variables,
        default_experiment: DefaultExperiment {
            start_time: 0.0,
            stop_time: 1.0,
            step_size: 1e-3,
        },
        // The effort starts at 0 whatever the parameters and inputs.
        initial_dependencies: &[],
        initial_dependencies_on_some_paths: &[],
        create: new_drive,
    }
}

fn new_drive(_: &Environment) -> Box<dyn Model> {
    Box::new(ServoDrive::default())
}

/// The [`VelocityDrive`] as it serialises (once initialized).
const LAYOUT: StateLayout = StateLayout {
    model: "ServoDrive",
    version: 1,
};

/// The model; its state is the drive's (none before initialization).
#[derive(Default)]
struct ServoDrive {
    drive: Option<VelocityDrive>,
}

fn params(values: &Values) -> DriveParams {
    DriveParams {
        kvp: KVP.get(values),
        kvi: KVI.get(values),
        effort_max: EFFORT_MAX.get(values),
        current_lag: CURRENT_LAG.get(values),
        velocity_filter: VELOCITY_FILTER.get(values),
    }
}

/// A restored drive, checked like the parameters it was built from.
fn decode(bytes: &[u8]) -> Result<Option<VelocityDrive>, String> {
    let drive: Option<VelocityDrive> = decode_state(LAYOUT, bytes)?;
    if let Some(d) = &drive {
        d.params().validate()?;
        saved_state::all_finite(d)?;
        if d.effort().abs() > d.params().effort_max || d.integral().abs() > d.params().effort_max {
            return Err(format!(
                "an effort or integral beyond effortMax {}",
                d.params().effort_max
            ));
        }
    }
    Ok(drive)
}

impl Model for ServoDrive {
    fn initialize(&mut self, values: &mut Values, _start_time: f64) -> ModelResult {
        let drive = VelocityDrive::new(params(values), VEL.get(values))?;
        EFFORT.set(values, drive.effort());
        self.drive = Some(drive);
        Ok(())
    }

    fn do_step(&mut self, values: &mut Values, _time: f64, step: f64) -> ModelResult {
        let drive = self
            .drive
            .as_mut()
            .ok_or("the drive steps before it is initialized")?;
        let effort = drive.step(U.get(values), VEL.get(values), step);
        EFFORT.set(values, effort);
        Ok(())
    }

    fn save_state(&self) -> Result<Vec<u8>, String> {
        encode_state(LAYOUT, &self.drive)
    }

    fn check_state(&self, bytes: &[u8], _time: f64) -> ModelResult {
        decode(bytes).map(drop)
    }

    fn restore_state(&mut self, bytes: &[u8], _time: f64) -> ModelResult {
        self.drive = decode(bytes)?;
        Ok(())
    }
}
