//! An FMU's interface: a model's variable table in the units the FMU declares.
//!
//! A model computes in its own units (mm, mm/s, rad, s). Plant models exported by
//! Modelica tools speak SI, so every model is also built with an SI interface (lengths
//! in m, m/s, m/s², m/s³; everything else as it was, SI already): the same table with
//! those units, starts and bounds scaled, and a GUID of its own. The FMI layer converts
//! Real values as they cross the interface (interface value = model value × scale), so
//! the control law, its gains, fuzzy factors and tuned files are the same in both.

use super::model::ModelInfo;
use super::units;
use super::variables::{Start, Variable};

/// The units an interface declares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnitSystem {
    /// The models' own: mm, mm/s, mm/s², mm/s³ (and rad, s).
    Millimetre,
    /// m, m/s, m/s², m/s³ (and rad, s).
    Si,
}

impl UnitSystem {
    /// Both, the models' own first.
    pub const ALL: [UnitSystem; 2] = [UnitSystem::Millimetre, UnitSystem::Si];

    /// How documentation and messages name it.
    pub fn name(self) -> &'static str {
        match self {
            UnitSystem::Millimetre => "mm",
            UnitSystem::Si => "SI",
        }
    }
}

/// A model's interface in a unit system.
pub struct Interface {
    pub model: &'static ModelInfo,
    pub units: UnitSystem,
    /// The variables as the FMU declares them, value references as the model's.
    pub variables: Vec<Variable>,
    /// Interface value = model value × scale, by value reference (1 but for lengths in SI).
    pub scale: Vec<f64>,
    pub guid: String,
    /// The FMI 3.0 `instantiationToken`: distinct from the FMI 2.0 GUID.
    pub instantiation_token: String,
}

impl Interface {
    /// `model`'s interface in `units` (the mm one is the model's table as it is, with the
    /// model's GUID).
    pub fn new(model: &'static ModelInfo, units: UnitSystem) -> Self {
        let mut variables = model.variables.to_vec();
        let mut scale = vec![1.0; variables.len()];
        if units == UnitSystem::Si {
            for (v, s) in variables.iter_mut().zip(&mut scale) {
                if let (Start::Real(start), Some(model_unit)) = (v.start, v.unit) {
                    if let Some(si) = units::si_counterpart(model_unit) {
                        let factor = units::find(model_unit).map_or(1.0, |u| u.factor);
                        *s = factor;
                        v.unit = Some(si.name);
                        v.start = Start::Real(start * factor);
                        v.min = v.min.map(|x| x * factor);
                        v.max = v.max.map(|x| x * factor);
                    }
                }
            }
        }
        let name = match units {
            UnitSystem::Millimetre => "",
            UnitSystem::Si => units.name(),
        };
        let guid = model.guid_of(&variables, name);
        let instantiation_token = model.instantiation_token_of(&variables, name);
        Interface {
            model,
            units,
            variables,
            scale,
            guid,
            instantiation_token,
        }
    }

    /// The model's description, with the interface's units when they are not its own.
    pub fn description(&self) -> String {
        match (self.units, self.converts()) {
            (UnitSystem::Millimetre, _) => self.model.description.to_string(),
            (UnitSystem::Si, true) => format!(
                "{} (SI interface: lengths in m, m/s, m/s2, m/s3)",
                self.model.description
            ),
            // A rotary drive has no length: its SI build is the mm build's units.
            (UnitSystem::Si, false) => format!(
                "{} (SI interface: every unit as in the mm build, already SI)",
                self.model.description
            ),
        }
    }

    /// The value reference of FMI 3.0's independent variable `time` (s): the first after
    /// the table's (FMI 2.0 has no such variable).
    pub fn time_vr(&self) -> u32 {
        self.variables.len() as u32
    }

    /// Whether any value is scaled at the interface.
    pub fn converts(&self) -> bool {
        self.scale.iter().any(|s| *s != 1.0)
    }
}
