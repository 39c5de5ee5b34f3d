//! Test plants: the servo axis of docs/design.md §4.5 and the XY table built from two of them.

pub mod servo_axis;
pub mod xy_table;

pub use servo_axis::{AxisParams, ServoAxis};
pub use xy_table::{XyTable, XyTableParams};
