//! The machine's joint limits, shared by `PathInterpolator5X` (a reference within them)
//! and `ContourCCC5X`: the same names and defaults in both, so one set of values
//! describes one machine (docs/design/five-axis.md §5.3b). The travel of the rotary axes,
//! and every joint's velocity and acceleration; the linear axes' travel is the part
//! program's business. Defaults: a mid-size trunnion table (contour_core::limits).

use crate::framework::variable_table::Reals;
use crate::framework::variables::{Start, Values, Variable};
use contour_core::kinematics::Joints;
use contour_core::limits::{JointLimits, ENDLESS};

/// Number of variables in the block.
pub const COUNT: usize = 14;

/// The block's handle in a model's table.
pub type Block = Reals<COUNT>;

const fn limit(
    name: &'static str,
    start: f64,
    unit: &'static str,
    description: &'static str,
) -> Variable {
    Variable::parameter(name, Start::Real(start), description).unit(unit)
}

const fn rate(
    name: &'static str,
    start: f64,
    unit: &'static str,
    description: &'static str,
) -> Variable {
    limit(name, start, unit, description).min(0.0)
}

/// −35° and 110°.
const A_MIN: f64 = -35.0 * std::f64::consts::PI / 180.0;
const A_MAX: f64 = 110.0 * std::f64::consts::PI / 180.0;

/// The block's variables, in this order: the rotary travel, then each joint's velocity,
/// then each joint's acceleration.
pub const VARIABLES: [Variable; COUNT] = [
    limit("A.min", A_MIN, "rad", "Least tilt of the A axis"),
    limit("A.max", A_MAX, "rad", "Greatest tilt of the A axis"),
    limit(
        "C.min",
        -ENDLESS,
        "rad",
        "Least angle of the C table (-1e9: endless)",
    ),
    limit(
        "C.max",
        ENDLESS,
        "rad",
        "Greatest angle of the C table (1e9: endless)",
    ),
    rate(
        "X.vmax",
        500.0,
        "mm/s",
        "Greatest speed of the X axis (> 0)",
    ),
    rate(
        "Y.vmax",
        500.0,
        "mm/s",
        "Greatest speed of the Y axis (> 0)",
    ),
    rate(
        "Z.vmax",
        500.0,
        "mm/s",
        "Greatest speed of the Z axis (> 0)",
    ),
    rate("A.vmax", 3.0, "rad/s", "Greatest speed of the A axis (> 0)"),
    rate("C.vmax", 5.0, "rad/s", "Greatest speed of the C axis (> 0)"),
    rate(
        "X.amax",
        5000.0,
        "mm/s2",
        "Greatest acceleration of the X axis (> 0)",
    ),
    rate(
        "Y.amax",
        5000.0,
        "mm/s2",
        "Greatest acceleration of the Y axis (> 0)",
    ),
    rate(
        "Z.amax",
        5000.0,
        "mm/s2",
        "Greatest acceleration of the Z axis (> 0)",
    ),
    rate(
        "A.amax",
        20.0,
        "rad/s2",
        "Greatest acceleration of the A axis (> 0)",
    ),
    rate(
        "C.amax",
        30.0,
        "rad/s2",
        "Greatest acceleration of the C axis (> 0)",
    ),
];

/// The limits of the block, checked (the error names the first bad value).
pub fn joint_limits(values: &Values, block: Block) -> Result<JointLimits, String> {
    let [a_min, a_max, c_min, c_max, vx, vy, vz, va, vc, ax, ay, az, aa, ac] = block.get(values);
    let limits = JointLimits {
        min: Joints::new(-ENDLESS, -ENDLESS, -ENDLESS, a_min, c_min),
        max: Joints::new(ENDLESS, ENDLESS, ENDLESS, a_max, c_max),
        velocity: Joints::new(vx, vy, vz, va, vc),
        acceleration: Joints::new(ax, ay, az, aa, ac),
    };
    limits.check().map_err(|e| format!("machine limits: {e}"))?;
    Ok(limits)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_are_the_libraries() {
        let values = Values::from_table(&VARIABLES);
        let limits = joint_limits(&values, Reals(0)).unwrap();
        assert_eq!(limits, JointLimits::default());
    }
}
