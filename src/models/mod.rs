//! The FMUs' models: each is a plain Rust type with a variable table and a step
//! function. Nothing here knows FMI types; `crate::fmi2` adapts these to the C ABI.

pub mod contour_ccc_2d;
pub mod geometry;
pub mod path_interpolator_2d;
pub mod sample_clock;
pub mod units;
pub mod variables;
pub mod xy_servo_plant;

#[cfg(feature = "test-hooks")]
pub mod fault_probe;

use std::path::PathBuf;

use sha2::{Digest, Sha256};

pub use variables::{Causality, Start, Value, Values, VarType, Variability, Variable, Vr};

/// What a model learns about its surroundings when it is created.
#[derive(Clone, Debug, Default)]
pub struct Environment {
    /// The unpacked FMU's `resources/` folder, when the importer gave one.
    pub resource_dir: Option<PathBuf>,
}

/// A model's answer when it cannot do what was asked; the text goes to the log.
pub type ModelResult = Result<(), String>;

/// The behaviour of one FMU. The FMI layer owns the [`Values`] (inputs, parameters and
/// outputs) and hands them in; the model owns everything else (its internal state).
pub trait Model: Send {
    /// Checks the parameters, rebuilds the internal state from them at `start_time` and
    /// computes the outputs. Called in initialization mode, possibly several times.
    fn initialize(&mut self, values: &mut Values, start_time: f64) -> ModelResult;

    /// Tunable parameters changed between steps: check and adopt them. On error the FMI
    /// layer restores the previous values.
    fn parameters_changed(&mut self, _values: &mut Values) -> ModelResult {
        Ok(())
    }

    /// Advances from `time` by `step` > 0 with the inputs in `values` held, then writes
    /// the outputs. Must not allocate on the heap.
    fn do_step(&mut self, values: &mut Values, time: f64, step: f64) -> ModelResult;

    /// The internal state as bytes (serde), for FMU state save/restore.
    fn save_state(&self) -> Result<Vec<u8>, String>;

    /// Restores what [`Model::save_state`] produced.
    fn restore_state(&mut self, bytes: &[u8]) -> ModelResult;
}

/// Serialises a model's internal state with the same codec for every model.
pub fn encode_state<T: serde::Serialize>(state: &T) -> Result<Vec<u8>, String> {
    postcard::to_stdvec(state).map_err(|e| format!("cannot encode the model state: {e}"))
}

/// The inverse of [`encode_state`].
pub fn decode_state<T: serde::de::DeserializeOwned>(bytes: &[u8]) -> Result<T, String> {
    postcard::from_bytes(bytes).map_err(|e| format!("cannot decode the model state: {e}"))
}

/// `DefaultExperiment` of the model description.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DefaultExperiment {
    pub start_time: f64,
    pub stop_time: f64,
    pub step_size: f64,
}

/// Everything about a model that does not change between instances.
pub struct ModelInfo {
    /// The FMU's `modelIdentifier` (also its `modelName`).
    pub identifier: &'static str,
    pub description: &'static str,
    pub variables: &'static [Variable],
    pub default_experiment: DefaultExperiment,
    pub create: fn(&Environment) -> Box<dyn Model>,
}

impl ModelInfo {
    /// A hash of the whole interface (name, every variable's attributes), formatted as a
    /// GUID: it changes whenever the interface does, so importers that cache unpacked
    /// FMUs by GUID never mix versions.
    pub fn guid(&self) -> String {
        let mut hash = Sha256::new();
        hash.update(b"fmi2-cs\0");
        hash.update(self.identifier.as_bytes());
        for v in self.variables {
            hash.update(canonical_interface(v).as_bytes());
        }
        let d = hash.finalize();
        let hex: String = d.iter().take(16).map(|b| format!("{b:02x}")).collect();
        format!(
            "{{{}-{}-{}-{}-{}}}",
            &hex[0..8],
            &hex[8..12],
            &hex[12..16],
            &hex[16..20],
            &hex[20..32]
        )
    }

    pub fn variable(&self, vr: Vr) -> Option<&'static Variable> {
        self.variables.get(vr)
    }
}

/// One variable's attributes as a fixed text, for the GUID: explicit fields (numbers by
/// their bits, units with their definitions) rather than `Debug`, whose format Rust does
/// not promise to keep.
fn canonical_interface(v: &Variable) -> String {
    let bits = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{:016x}", x.to_bits()));
    let start = match v.start {
        Start::Real(x) => format!("Real={}", bits(Some(x))),
        Start::Integer(x) => format!("Integer={x}"),
        Start::Boolean(x) => format!("Boolean={x}"),
        Start::String(x) => format!("String={x}"),
    };
    let unit = v
        .unit
        .map_or("-".to_string(), |name| match units::find(name) {
            Some(u) => format!(
                "{name}:kg{},m{},s{},A{},rad{},{}",
                u.kg,
                u.m,
                u.s,
                u.a,
                u.rad,
                bits(Some(u.factor))
            ),
            None => format!("{name}:undefined"),
        });
    format!(
        "\0{}\0{}\0{}\0{}\0{start}\0{unit}\0{}\0{}\0{}",
        v.vr,
        v.name,
        v.causality.name(),
        v.variability.name(),
        bits(v.min),
        bits(v.max),
        v.description
    )
}

/// Every model this library serves (the packager builds one FMU per entry).
pub fn all() -> Vec<&'static ModelInfo> {
    vec![
        &path_interpolator_2d::INFO,
        &contour_ccc_2d::INFO,
        &xy_servo_plant::INFO,
    ]
}

/// Models reachable through `fmi2Instantiate`: [`all`] plus test-only models.
pub fn instantiable() -> Vec<&'static ModelInfo> {
    #[allow(unused_mut)]
    let mut models = all();
    #[cfg(feature = "test-hooks")]
    models.push(&fault_probe::INFO);
    models
}

/// The model whose GUID this is.
pub fn by_guid(guid: &str) -> Option<&'static ModelInfo> {
    instantiable().into_iter().find(|m| m.guid() == guid)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_are_well_formed() {
        for model in instantiable() {
            let mut names = std::collections::HashSet::new();
            for (index, v) in model.variables.iter().enumerate() {
                assert_eq!(
                    v.vr, index,
                    "{}: '{}' out of place",
                    model.identifier, v.name
                );
                assert!(
                    names.insert(v.name),
                    "{}: '{}' twice",
                    model.identifier,
                    v.name
                );
                if let Some(unit) = v.unit {
                    assert!(units::find(unit).is_some(), "unit '{unit}' undefined");
                }
                // Start values must satisfy their own bounds.
                v.check(&Value::from(v.start)).unwrap();
                if matches!(
                    v.var_type(),
                    VarType::Integer | VarType::Boolean | VarType::String
                ) {
                    assert_ne!(v.variability, Variability::Continuous, "{}", v.name);
                }
            }
        }
    }

    #[test]
    fn guids_are_distinct_and_formatted() {
        let guids: Vec<String> = instantiable().iter().map(|m| m.guid()).collect();
        for g in &guids {
            assert_eq!(g.len(), 38);
            assert!(g.starts_with('{') && g.ends_with('}'));
        }
        let unique: std::collections::HashSet<_> = guids.iter().collect();
        assert_eq!(unique.len(), guids.len());
    }
}
