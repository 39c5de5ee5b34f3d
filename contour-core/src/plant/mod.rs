//! Test plants: the servo axis of docs/design/two-axis.md §4.5 (linear or rotary) and a machine's
//! axes built from several of them (the XY table is two).

mod axis_effects;
mod servo_axes;
mod servo_axis;

pub use axis_effects::AxisEffects;
pub use servo_axes::{ServoAxes, ServoAxesParams, XyTable, XyTableParams};
pub use servo_axis::{AxisParams, ServoAxis, Transmission};
