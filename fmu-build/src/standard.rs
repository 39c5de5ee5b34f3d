//! The FMI standard an FMU is packaged for. One library serves FMI 2.0 and FMI 3.0, so a
//! model's two FMUs differ only in what the packager writes around the same binary: the
//! model description, the names of the platform folders and the documentation's words.

use std::path::{Path, PathBuf};

use contour_fmu::framework::interface::{Interface, UnitSystem};
use contour_fmu::framework::variables::VarType;

use crate::model_description;
use crate::platform::Platform;

/// FMI 2.0 or FMI 3.0 Co-Simulation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Standard {
    Fmi2,
    Fmi3,
}

impl Standard {
    /// Both, FMI 2.0 first.
    pub const ALL: [Standard; 2] = [Standard::Fmi2, Standard::Fmi3];

    /// How documentation and messages name it.
    pub fn name(self) -> &'static str {
        match self {
            Standard::Fmi2 => "FMI 2.0",
            Standard::Fmi3 => "FMI 3.0",
        }
    }

    /// The prefix of its function names.
    pub fn prefix(self) -> &'static str {
        match self {
            Standard::Fmi2 => "fmi2",
            Standard::Fmi3 => "fmi3",
        }
    }

    /// The interface's `modelDescription.xml`.
    pub fn model_description(self, interface: &Interface) -> String {
        match self {
            Standard::Fmi2 => model_description::fmi2::render(interface),
            Standard::Fmi3 => model_description::fmi3::render(interface),
        }
    }

    /// The folder under `binaries/` of `platform`'s library.
    pub fn binaries_folder(self, platform: Platform) -> &'static str {
        match self {
            Standard::Fmi2 => platform.folder(),
            Standard::Fmi3 => platform.fmi3_folder(),
        }
    }

    /// The name the model description gives a variable type (Enumerations aside).
    pub fn type_name(self, var_type: VarType) -> &'static str {
        match self {
            Standard::Fmi2 => var_type.name(),
            Standard::Fmi3 => model_description::fmi3::type_name(var_type),
        }
    }

    /// The function an importer sets an Enumeration with.
    pub fn enumeration_setter(self) -> &'static str {
        match self {
            Standard::Fmi2 => "fmi2SetInteger",
            Standard::Fmi3 => "fmi3SetInt64",
        }
    }

    /// Where the FMUs of `units` go, given the folder of the FMI 2.0 mm build: `out`,
    /// `out-si`, `out3`, `out3-si` (by default target/fmu, target/fmu-si, target/fmu3,
    /// target/fmu3-si).
    pub fn output_folder(self, out: &Path, units: UnitSystem) -> PathBuf {
        let mut name = out.as_os_str().to_owned();
        if self == Standard::Fmi3 {
            name.push("3");
        }
        if units == UnitSystem::Si {
            name.push("-si");
        }
        PathBuf::from(name)
    }
}
