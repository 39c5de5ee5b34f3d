//! The machine's kinematics parameters shared by `PathInterpolator5X` (joints from the
//! path's poses) and `ContourCCC5X` (poses from the joints): the same names and
//! defaults in both, so one set of values describes one machine. Default: both pivots
//! at the machine origin, LinuxCNC's A–C trunnion convention (docs/design/five-axis.md §5.1).

use crate::framework::variable_table::Reals;
use crate::framework::variables::{Start, Values, Variable};
use contour_core::geometry::Vector;
use contour_core::kinematics::TableTiltingAc;

/// Number of variables in the block.
pub const COUNT: usize = 4;

/// The block's handle in a model's table.
pub type Block = Reals<COUNT>;

const fn pivot(name: &'static str, description: &'static str) -> Variable {
    Variable::parameter(name, Start::Real(0.0), description).unit("mm")
}

/// The block's variables: where the A axis (along machine x) crosses the y-z plane, and
/// where the C axis (along machine z at A = 0) crosses the x-y plane. A point's position
/// along its own axis changes nothing, so those two coordinates are not parameters.
pub const VARIABLES: [Variable; COUNT] = [
    pivot(
        "pivot.A.y",
        "A (tilt) axis, along machine x: its y coordinate",
    ),
    pivot(
        "pivot.A.z",
        "A (tilt) axis, along machine x: its z coordinate",
    ),
    pivot(
        "pivot.C.x",
        "C (table) axis, along machine z at A = 0: its x coordinate",
    ),
    pivot(
        "pivot.C.y",
        "C (table) axis, along machine z at A = 0: its y coordinate",
    ),
];

/// The machine of the block (every value is finite: the variables refuse others).
pub fn machine(values: &Values, block: Block) -> TableTiltingAc {
    let [ay, az, cx, cy] = block.get(values);
    TableTiltingAc {
        a_pivot: Vector::<3>::new(0.0, ay, az),
        c_pivot: Vector::<3>::new(cx, cy, 0.0),
    }
}
