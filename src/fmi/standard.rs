//! Which FMI standard an instance was made by: its handle answers only that standard's
//! functions (an FMI 3.0 instance passed to `fmi2DoStep` is refused, not misread).

/// FMI 2.0 or FMI 3.0 (Co-Simulation both).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Standard {
    Fmi2,
    Fmi3,
}

impl Standard {
    /// The prefix of the standard's function names.
    pub fn prefix(self) -> &'static str {
        match self {
            Standard::Fmi2 => "fmi2",
            Standard::Fmi3 => "fmi3",
        }
    }

    /// How messages name it.
    pub fn name(self) -> &'static str {
        match self {
            Standard::Fmi2 => "FMI 2.0",
            Standard::Fmi3 => "FMI 3.0",
        }
    }

    /// How the standard's header names an FMU state argument, for messages.
    pub fn fmu_state_argument(self) -> &'static str {
        match self {
            Standard::Fmi2 => "FMUstate",
            Standard::Fmi3 => "FMUState",
        }
    }
}
