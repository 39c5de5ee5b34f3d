//! What the servo-plant models share (`XYServoPlant`, `FiveAxisPlant`): reading one
//! axis's drive parameters from a block of six (J, B, CT, lead or ratio, Kvp, Kvi) and its
//! nonlinear effects from a block of five (friction, backlash, current limit), and
//! checking a restored table of axes.

use crate::framework::saved_state::{self, decode_state, StateLayout};
use crate::framework::variable_table::{Axis, AxisKind, AxisTemplate, AxisUnit, AxisWord, Reals};
use crate::framework::variables::{Values, Variable};
use contour_core::plant::{AxisEffects, AxisParams, ServoAxes, Transmission};

/// Drive parameters per axis, in [`AxisParams`] field order.
pub const FIELDS: usize = 6;

/// A drive parameter of every axis of a block (`x.J`, `A.ratio`, …), ≥ 0 (J, CT and the
/// transmission are further checked > 0 by [`axis_params`]).
const fn drive(
    suffix: &'static str,
    start: f64,
    description: (&'static str, &'static str),
    unit: AxisUnit,
) -> AxisTemplate {
    AxisTemplate::parameter(
        ("", suffix),
        (start, start),
        (description.0, AxisWord::Name, description.1),
    )
    .unit(unit)
    .min(0.0)
}

/// The drive parameters of axes whose defaults are `p`, in [`AxisParams`] field order:
/// `.J`, `.B`, `.CT`, `.lead` (ball screw) or `.ratio` (gear), `.Kvp`, `.Kvi`.
pub const fn drive_fields(p: AxisParams) -> [AxisTemplate; FIELDS] {
    let transmission = match p.transmission {
        Transmission::Linear { lead } => drive(
            ".lead",
            lead,
            (
                "Ball-screw lead of the ",
                " axis (travel per screw revolution)",
            ),
            AxisUnit::Fixed("mm"),
        ),
        Transmission::Rotary { ratio } => drive(
            ".ratio",
            ratio,
            ("Gear ratio of the ", " axis (motor turns per axis turn)"),
            AxisUnit::None,
        ),
    };
    [
        drive(
            ".J",
            p.inertia,
            ("Inertia of the ", " motor plus reflected load"),
            AxisUnit::Fixed("kg.m2"),
        ),
        drive(
            ".B",
            p.friction,
            ("Viscous friction of the ", " axis"),
            AxisUnit::Fixed("N.m.s/rad"),
        ),
        drive(
            ".CT",
            p.torque_constant,
            ("Torque constant of the ", " motor"),
            AxisUnit::Fixed("N.m/A"),
        ),
        transmission,
        drive(
            ".Kvp",
            p.kvp,
            ("Proportional gain of the ", " drive's velocity loop"),
            AxisUnit::Fixed("A.s/rad"),
        ),
        drive(
            ".Kvi",
            p.kvi,
            ("Integral gain of the ", " drive's velocity loop"),
            AxisUnit::Fixed("A/rad"),
        ),
    ]
}

/// Nonlinear effects per axis, in [`AxisEffects`] field order.
pub const EFFECT_FIELDS: usize = 5;

/// An effect of every axis of a block, 0 (off) by default.
const fn effect(
    suffix: &'static str,
    description: (&'static str, &'static str),
    unit: AxisUnit,
) -> AxisTemplate {
    AxisTemplate::parameter(
        ("", suffix),
        (0.0, 0.0),
        (description.0, AxisWord::Name, description.1),
    )
    .unit(unit)
    .min(0.0)
}

/// The nonlinear effects of an axis (docs/design/two-axis.md §4.5b), all off (0) by
/// default: `.coulomb`, `.stiction`, `.stribeckVelocity`, `.backlash`, `.currentMax`.
pub const EFFECT_TEMPLATES: [AxisTemplate; EFFECT_FIELDS] = [
    effect(
        ".coulomb",
        (
            "Coulomb friction torque of the ",
            " axis at the motor (0: none)",
        ),
        AxisUnit::Fixed("N.m"),
    ),
    effect(
        ".stiction",
        (
            "Static (breakaway) friction torque of the ",
            " axis at the motor, 0 or >= coulomb",
        ),
        AxisUnit::Fixed("N.m"),
    ),
    effect(
        ".stribeckVelocity",
        (
            "Stribeck velocity of the ",
            " axis: friction falls from static to Coulomb as exp(-(v/vs)^2) (0: at once)",
        ),
        AxisUnit::VELOCITY,
    ),
    effect(
        ".backlash",
        (
            "Total play of the ",
            " axis's transmission; pos is the table's position behind it (0: none)",
        ),
        AxisUnit::POSITION,
    ),
    effect(
        ".currentMax",
        (
            "Current limit of the ",
            " drive, with anti-windup (0: none)",
        ),
        AxisUnit::Fixed("A"),
    ),
];

/// The effects of `axis` from its block `block` of [`EFFECT_FIELDS`] variables starting
/// at offset `first`.
pub fn axis_effects<const N: usize>(
    values: &Values,
    block: Reals<N>,
    first: usize,
    axis: &Axis,
) -> Result<AxisEffects, String> {
    let p = |i: usize| block.at(first + i).get(values);
    let effects = AxisEffects {
        coulomb: p(0),
        stiction: p(1),
        stribeck_velocity: p(2),
        backlash: p(3),
        current_max: p(4),
    };
    effects
        .validate()
        .map_err(|e| format!("axis {}: {e}", axis.name))?;
    Ok(effects)
}

/// The parameters of `axis` from its block `block` of [`FIELDS`] variables starting at
/// offset `first` in `table`; J, CT and the transmission must be > 0.
pub fn axis_params<const N: usize>(
    values: &Values,
    table: &[Variable],
    block: Reals<N>,
    first: usize,
    axis: &Axis,
) -> Result<AxisParams, String> {
    let p = |i: usize| block.at(first + i).get(values);
    let transmission = match axis.kind {
        AxisKind::Linear => Transmission::Linear { lead: p(3) },
        AxisKind::Rotary => Transmission::Rotary { ratio: p(3) },
    };
    let params = AxisParams {
        inertia: p(0),
        friction: p(1),
        torque_constant: p(2),
        transmission,
        kvp: p(4),
        kvi: p(5),
        effects: AxisEffects::NONE,
    };
    // J, CT and the transmission divide or scale the dynamics: zero is as unphysical as
    // negative.
    for i in [0, 2, 3] {
        if p(i) <= 0.0 {
            let name = table[block.at(first + i).vr()].name;
            return Err(format!("parameter '{name}' must be > 0 (got {})", p(i)));
        }
    }
    params
        .validate()
        .map_err(|e| format!("axis {}: {e}", axis.name))?;
    Ok(params)
}

/// The three state methods of a plant model whose internal state is `self.table`, a
/// [`ServoAxes`] of the axes `$axes`, saved with layout `$layout`: the same in both plants.
macro_rules! plant_state_methods {
    ($layout:expr, $axes:expr) => {
        fn save_state(&self) -> Result<Vec<u8>, String> {
            $crate::framework::saved_state::encode_state($layout, &self.table)
        }

        fn check_state(&self, bytes: &[u8], _time: f64) -> $crate::framework::model::ModelResult {
            $crate::models::servo_plant::decode(bytes, $layout, &$axes).map(drop)
        }

        fn restore_state(
            &mut self,
            bytes: &[u8],
            _time: f64,
        ) -> $crate::framework::model::ModelResult {
            self.table = $crate::models::servo_plant::decode(bytes, $layout, &$axes)?;
            Ok(())
        }
    };
}
pub(crate) use plant_state_methods;

/// A table restored from `bytes` saved with `layout`, checked by [`validate`].
pub fn decode<const D: usize>(
    bytes: &[u8],
    layout: StateLayout,
    axes: &[Axis; D],
) -> Result<ServoAxes<D>, String> {
    let table: ServoAxes<D> = decode_state(layout, bytes)?;
    validate(&table, axes)?;
    Ok(table)
}

/// Checks a restored table like the parameters it was built from: each axis's drive
/// valid, of its axis's kind (ball screw or gear), finite, with the cached transition
/// of its parameters. The error names the axis.
pub fn validate<const D: usize>(table: &ServoAxes<D>, axes: &[Axis; D]) -> Result<(), String> {
    for (axis, servo) in axes.iter().zip(&table.axes) {
        let name = axis.name;
        servo
            .params()
            .validate()
            .map_err(|e| format!("axis {name}: {e}"))?;
        let kind_fits = matches!(
            (axis.kind, servo.params().transmission),
            (AxisKind::Linear, Transmission::Linear { .. })
                | (AxisKind::Rotary, Transmission::Rotary { .. })
        );
        if !kind_fits {
            return Err(format!(
                "axis {name}: a transmission of the wrong kind for this axis"
            ));
        }
        saved_state::all_finite(servo).map_err(|e| format!("axis {name}: {e}"))?;
        servo
            .check_play()
            .map_err(|e| format!("axis {name}: {e}"))?;
        servo
            .check_caches()
            .map_err(|e| format!("axis {name}: {e}"))?;
    }
    Ok(())
}
