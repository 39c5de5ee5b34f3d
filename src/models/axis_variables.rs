//! The per-axis inputs and outputs the models share, so that a signal has one name and
//! one description wherever it appears (the two-axis models name their axes x, y; the
//! five-axis ones X … C, with rad for the rotary joints).

use crate::framework::variable_table::{AxisTemplate, AxisUnit, AxisWord};

/// A reference output of an interpolator: `ref.<axis>`.
pub const REFERENCE_OUT: AxisTemplate =
    AxisTemplate::output(("ref.", ""), ("Reference position, ", AxisWord::Name, ""))
        .unit(AxisUnit::POSITION);

/// An interpolator's reference velocity output: `vref.<axis>`.
pub const REFERENCE_VELOCITY_OUT: AxisTemplate = AxisTemplate::output(
    ("vref.", ""),
    (
        "Reference velocity at the sample, ",
        AxisWord::Name,
        " (for feed-forward)",
    ),
)
.unit(AxisUnit::VELOCITY);

/// An interpolator's reference acceleration output: `aref.<axis>`.
pub const REFERENCE_ACCELERATION_OUT: AxisTemplate = AxisTemplate::output(
    ("aref.", ""),
    (
        "Reference acceleration at the sample, ",
        AxisWord::Name,
        " (for feed-forward)",
    ),
)
.unit(AxisUnit::ACCELERATION);

/// A controller's reference acceleration input: `aref.<axis>`.
pub const REFERENCE_ACCELERATION_IN: AxisTemplate = AxisTemplate::input(
    ("aref.", ""),
    (
        "Reference acceleration, ",
        AxisWord::Name,
        ", from the interpolator's aref (feed-forward; 0 when unconnected)",
    ),
)
.unit(AxisUnit::ACCELERATION);

/// A controller's reference velocity input: `vref.<axis>`.
pub const REFERENCE_VELOCITY_IN: AxisTemplate = AxisTemplate::input(
    ("vref.", ""),
    (
        "Reference velocity, ",
        AxisWord::Name,
        ", from the interpolator's vref (feed-forward; 0 when unconnected)",
    ),
)
.unit(AxisUnit::VELOCITY);

/// An interpolator's look-ahead: `ahead.<axis>`, the reference's mean acceleration over
/// the coming period.
pub const ACCELERATION_AHEAD_OUT: AxisTemplate = AxisTemplate::output(
    ("ahead.", ""),
    (
        "Mean reference acceleration over the coming period, ",
        AxisWord::Name,
        ": (v(t+Ts) - v(t))/Ts, the interpolator's look-ahead (for feed-forward)",
    ),
)
.unit(AxisUnit::ACCELERATION);

/// A controller's look-ahead input: `ahead.<axis>`.
pub const ACCELERATION_AHEAD_IN: AxisTemplate = AxisTemplate::input(
    ("ahead.", ""),
    (
        "Mean reference acceleration over the coming period, ",
        AxisWord::Name,
        ", from the interpolator's ahead (feed-forward with feedForwardLookAhead; 0 when \
         unconnected)",
    ),
)
.unit(AxisUnit::ACCELERATION);

/// A controller's reference input: `ref.<axis>`.
pub const REFERENCE_IN: AxisTemplate = AxisTemplate::input(
    ("ref.", ""),
    ("Reference (command) position, ", AxisWord::Name, ""),
)
.unit(AxisUnit::POSITION);

/// A controller's measured-position input: `pos.<axis>`.
pub const MEASURED_IN: AxisTemplate =
    AxisTemplate::input(("pos.", ""), ("Measured position, ", AxisWord::Name, ""))
        .unit(AxisUnit::POSITION);

/// A controller's velocity command: `u.<axis>`.
pub const COMMAND_OUT: AxisTemplate = AxisTemplate::output(
    ("u.", ""),
    ("Velocity command to the ", AxisWord::Label, " drive"),
)
.unit(AxisUnit::VELOCITY);

/// A controller's following error: `err.<axis>`.
pub const FOLLOWING_ERROR_OUT: AxisTemplate = AxisTemplate::output(
    ("err.", ""),
    ("Following error (ref - pos), ", AxisWord::Name, ""),
)
.unit(AxisUnit::POSITION);

/// A plant's velocity command input: `u.<axis>`.
pub const COMMAND_IN: AxisTemplate = AxisTemplate::input(
    ("u.", ""),
    ("Velocity command to the ", AxisWord::Label, " drive"),
)
.unit(AxisUnit::VELOCITY);

/// A plant's position output: `pos.<axis>`.
pub const POSITION_OUT: AxisTemplate =
    AxisTemplate::output(("pos.", ""), ("Position of the ", AxisWord::Label, " axis"))
        .unit(AxisUnit::POSITION);

/// A plant's velocity output: `vel.<axis>`.
pub const VELOCITY_OUT: AxisTemplate =
    AxisTemplate::output(("vel.", ""), ("Velocity of the ", AxisWord::Label, " axis"))
        .unit(AxisUnit::VELOCITY);

/// A plant's initial position parameter: `pos0.<axis>`.
pub const INITIAL_POSITION: AxisTemplate = AxisTemplate::parameter(
    ("pos0.", ""),
    (0.0, 0.0),
    ("Initial position of the ", AxisWord::Label, " axis"),
)
.unit(AxisUnit::POSITION);
