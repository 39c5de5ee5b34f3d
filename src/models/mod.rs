//! The FMUs' models: each is a plain Rust type with a variable table and a step
//! function. Nothing here knows FMI types; `crate::fmi2` adapts these to the C ABI.

pub mod axis_variables;
pub mod contour_ccc_2d;
pub mod contour_ccc_5x;
pub mod controller_parameters;
pub mod five_axis_plant;
pub mod kinematics_parameters;
pub mod line_arc_parameters;
pub mod path_interpolator_2d;
pub mod path_interpolator_5x;
pub mod sample_clock;
pub mod servo_plant;
pub mod state_check;
pub mod text;
pub mod units;
pub mod variable_table;
pub mod variables;
pub mod xy_servo_plant;

#[cfg(feature = "test-hooks")]
pub mod fault_probe;
#[cfg(feature = "test-hooks")]
pub mod pass_through;

use std::path::PathBuf;

use sha2::{Digest, Sha256};

pub use text::Text;
pub use variables::{
    Causality, EnumItem, EnumType, Start, Value, Values, VarType, Variability, Variable, Vr,
};

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

    /// Warnings about the last initialization that did not stop it (a path file's
    /// tolerated irregularities): the FMI layer logs them, and they are gone.
    fn take_warnings(&mut self) -> Vec<String> {
        Vec::new()
    }

    /// Tunable parameters changed between steps: check and adopt them. On error the FMI
    /// layer restores the previous values.
    fn parameters_changed(&mut self, _values: &mut Values) -> ModelResult {
        Ok(())
    }

    /// Advances from `time` by `step` > 0 with the inputs in `values` held, then writes
    /// the outputs. Must not allocate on the heap.
    fn do_step(&mut self, values: &mut Values, time: f64, step: f64) -> ModelResult;

    /// Refuses a communication step the model cannot take in reasonable time (a sampled
    /// model: too many samples), before anything changes. Must not allocate on success.
    fn check_step(&self, _time: f64, _step: f64) -> ModelResult {
        Ok(())
    }

    /// The internal state as bytes, for FMU state save/restore: [`encode_state`] with the
    /// model's own [`StateLayout`].
    fn save_state(&self) -> Result<Vec<u8>, String>;

    /// Checks bytes as [`Model::restore_state`] would, without applying them: the layout
    /// version, then every value like a parameter (periods, radii, finite memories) and,
    /// for a sampled model, that its sample clock is at `time`, the instance time saved
    /// with the state. The error names the cause.
    fn check_state(&self, bytes: &[u8], time: f64) -> ModelResult;

    /// Restores what [`Model::save_state`] produced at instance time `time`; nothing
    /// changes when it is refused.
    fn restore_state(&mut self, bytes: &[u8], time: f64) -> ModelResult;
}

/// The three state methods of a sampled model whose internal state is
/// `self.state: Option<State>` (`None` before initialization), saved with layout `$layout`,
/// and its step check (the sample clock's): the same in every such model, written once.
macro_rules! sampled_state_methods {
    ($state:ty, $layout:expr) => {
        fn save_state(&self) -> Result<Vec<u8>, String> {
            $crate::models::encode_state($layout, &self.state)
        }

        fn check_state(&self, bytes: &[u8], time: f64) -> $crate::models::ModelResult {
            $crate::models::decode_checked::<$state>($layout, bytes, time).map(drop)
        }

        fn restore_state(&mut self, bytes: &[u8], time: f64) -> $crate::models::ModelResult {
            self.state = $crate::models::decode_checked($layout, bytes, time)?;
            Ok(())
        }

        // Not a state method, but every sampled model has its clock in `self.state`.
        fn check_step(&self, time: f64, step: f64) -> $crate::models::ModelResult {
            match &self.state {
                Some(state) => state.clock.check_step(time + step),
                None => Ok(()),
            }
        }
    };
}
pub(crate) use sampled_state_methods;

/// The version of one model's internal state layout. Bump `version` whenever the saved
/// state of that model changes shape or meaning (a field added, a type changed, a unit
/// changed): states saved with another layout are then refused with a message instead of
/// being misread. The interface GUID does not cover the internal state, so this is the
/// only guard.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StateLayout {
    /// The model's identifier, for messages.
    pub model: &'static str,
    pub version: u16,
}

/// A model's internal state that checks itself once restored, like the parameters it was
/// built from, at the instance time `time` saved with it; the error names the cause.
pub trait SavedState: serde::de::DeserializeOwned {
    fn validate(&self, time: f64) -> Result<(), String>;
}

/// [`decode_state`] of a sampled model's optional state (`None` before initialization),
/// then its [`SavedState::validate`].
pub fn decode_checked<S: SavedState>(
    layout: StateLayout,
    bytes: &[u8],
    time: f64,
) -> Result<Option<S>, String> {
    let state: Option<S> = decode_state(layout, bytes)?;
    if let Some(state) = &state {
        state.validate(time)?;
    }
    Ok(state)
}

/// Serialises a model's internal state with the same codec for every model: the layout
/// version (u16, little endian), then the state in postcard.
pub fn encode_state<T: serde::Serialize>(
    layout: StateLayout,
    state: &T,
) -> Result<Vec<u8>, String> {
    let mut bytes = Vec::with_capacity(256);
    bytes.extend_from_slice(&layout.version.to_le_bytes());
    postcard::to_extend(state, bytes).map_err(|e| format!("cannot encode the model state: {e}"))
}

/// The inverse of [`encode_state`]: refuses another layout version, truncated bytes and
/// trailing bytes. The caller still validates the values.
pub fn decode_state<T: serde::de::DeserializeOwned>(
    layout: StateLayout,
    bytes: &[u8],
) -> Result<T, String> {
    let Some((version, body)) = bytes.split_first_chunk::<2>() else {
        return Err(format!(
            "the {} state is truncated (no layout version)",
            layout.model
        ));
    };
    let version = u16::from_le_bytes(*version);
    if version != layout.version {
        let age = if version < layout.version {
            "an older"
        } else {
            "a newer"
        };
        return Err(format!(
            "the {} state has internal layout version {version}, this build reads layout \
             version {} only: it was saved by {age} build of contour-fmu and cannot be restored",
            layout.model, layout.version
        ));
    }
    let (state, rest) = postcard::take_from_bytes(body)
        .map_err(|e| format!("cannot decode the {} state: {e}", layout.model))?;
    if !rest.is_empty() {
        return Err(format!(
            "cannot decode the {} state: {} trailing bytes",
            layout.model,
            rest.len()
        ));
    }
    Ok(state)
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
    /// For each output whose initial value (at the end of initialization) depends on other
    /// variables: the value references of those variables (parameters or inputs, the
    /// "Knowns" of FMI 2.0's `InitialUnknowns`). An output not listed starts at a constant.
    /// Checked against the model by perturbing every variable (see the tests below).
    pub initial_dependencies: &'static [(Vr, &'static [Vr])],
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

    /// The variables the initial value of `output` depends on, in value reference order.
    pub fn initial_dependencies_of(&self, output: Vr) -> Vec<Vr> {
        let mut knowns: Vec<Vr> = self
            .initial_dependencies
            .iter()
            .filter(|(o, _)| *o == output)
            .flat_map(|(_, knowns)| knowns.iter().copied())
            .collect();
        knowns.sort_unstable();
        knowns.dedup();
        knowns
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
    // Only enumerations add a field, so the GUIDs of other interfaces stay as they were.
    let enumeration = v.enumeration.map_or(String::new(), |e| {
        let items: Vec<String> = e
            .items
            .iter()
            .map(|i| format!("{}:{}", i.name, i.description))
            .collect();
        format!(
            "Enumeration={}:{}:{}\0",
            e.name,
            e.description,
            items.join("\u{1}")
        )
    });
    format!(
        "\0{}\0{}\0{}\0{}\0{start}\0{unit}\0{enumeration}{}\0{}\0{}",
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
        &path_interpolator_5x::INFO,
        &contour_ccc_5x::INFO,
        &five_axis_plant::INFO,
    ]
}

/// Models reachable through `fmi2Instantiate`: [`all`] plus test-only models.
pub fn instantiable() -> Vec<&'static ModelInfo> {
    #[allow(unused_mut)]
    let mut models = all();
    #[cfg(feature = "test-hooks")]
    models.extend([&fault_probe::INFO, &pass_through::INFO]);
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
                    names.insert(v.name.to_string()),
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

    /// Other valid values of a variable, to perturb it with.
    fn alternatives(v: &Variable, value: &Value) -> Vec<Value> {
        let candidates = match value {
            Value::Real(x) => vec![
                Value::Real(if *x == 0.0 { 1.5 } else { x * 1.25 }),
                Value::Real(x + 0.75),
            ],
            Value::Integer(x) => match v.enumeration {
                Some(e) => (1..=e.items.len() as i32)
                    .filter(|i| i != x)
                    .map(Value::Integer)
                    .collect(),
                None => vec![Value::Integer(x + 1)],
            },
            Value::Boolean(b) => vec![Value::Boolean(!b)],
            Value::String(text) => [
                "circle",
                "line",
                "arc",
                "infinity",
                "trident",
                "tilted_helix",
                "figure_eight",
                "other",
            ]
            .iter()
            .filter(|t| **t != text)
            .map(|t| Value::String(t.to_string()))
            .collect(),
        };
        candidates
            .into_iter()
            .filter(|c| v.check(c).is_ok())
            .collect()
    }

    /// The outputs after initialization from `values`, or `None` if the model refuses them.
    fn initial_outputs(model: &ModelInfo, values: &Values) -> Option<Vec<Value>> {
        let mut values = values.clone();
        let mut instance = (model.create)(&Environment::default());
        instance.initialize(&mut values, 0.0).ok()?;
        Some(
            model
                .variables
                .iter()
                .filter(|v| v.causality == Causality::Output)
                .map(|v| values.get(v.vr).clone())
                .collect(),
        )
    }

    /// The `InitialUnknowns` dependencies written to the model descriptions are the true
    /// ones: perturbing a variable that is not listed never changes an output's initial
    /// value (in every context: each built-in path, each estimator, …), and every listed
    /// variable does change it in some context.
    #[test]
    fn initial_dependencies_are_exactly_the_variables_that_change_initial_outputs() {
        for model in instantiable() {
            let outputs: Vec<&Variable> = model
                .variables
                .iter()
                .filter(|v| v.causality == Causality::Output)
                .collect();
            let knowns: Vec<&Variable> = model
                .variables
                .iter()
                .filter(|v| v.causality != Causality::Output)
                .collect();
            for (output, deps) in model.initial_dependencies {
                assert!(outputs.iter().any(|o| o.vr == *output), "{output}");
                assert!(deps.iter().all(|d| knowns.iter().any(|k| k.vr == *d)));
            }
            // Contexts: the start values and every alternative of a String or
            // enumeration variable (they switch between whole behaviours), each also with
            // every Real shifted off its start value (a start angle of 0 hides the radius
            // in sin(start)).
            let start = Values::from_table(model.variables);
            let mut shifted = start.clone();
            for v in &knowns {
                if let Value::Real(x) = start.get(v.vr) {
                    let candidate = Value::Real(x + 0.75);
                    if v.check(&candidate).is_ok() {
                        shifted.set(v.vr, candidate);
                    }
                }
            }
            let mut contexts = vec![start.clone(), shifted.clone()];
            for v in &knowns {
                if v.var_type() == VarType::String || v.enumeration.is_some() {
                    for alt in alternatives(v, start.get(v.vr)) {
                        for base in [&start, &shifted] {
                            let mut c = base.clone();
                            c.set(v.vr, alt.clone());
                            contexts.push(c);
                        }
                    }
                }
            }
            let mut seen = std::collections::HashSet::new();
            let mut initialized = 0;
            for context in &contexts {
                let Some(base) = initial_outputs(model, context) else {
                    continue;
                };
                initialized += 1;
                for k in &knowns {
                    for alt in alternatives(k, context.get(k.vr)) {
                        let mut changed = context.clone();
                        changed.set(k.vr, alt.clone());
                        let Some(after) = initial_outputs(model, &changed) else {
                            continue;
                        };
                        for (i, o) in outputs.iter().enumerate() {
                            if after[i] == base[i] {
                                continue;
                            }
                            assert!(
                                model.initial_dependencies_of(o.vr).contains(&k.vr),
                                "{}: initial '{}' changes with '{}' ({:?} -> {:?}) but does \
                                 not list it",
                                model.identifier,
                                o.name,
                                k.name,
                                context.get(k.vr),
                                alt
                            );
                            seen.insert((o.vr, k.vr));
                        }
                    }
                }
            }
            assert!(initialized >= 1, "{}", model.identifier);
            for o in &outputs {
                for k in model.initial_dependencies_of(o.vr) {
                    assert!(
                        seen.contains(&(o.vr, k)),
                        "{}: '{}' lists '{}' but never changes with it",
                        model.identifier,
                        o.name,
                        model.variables[k].name
                    );
                }
            }
        }
    }

    #[test]
    fn model_states_carry_their_layout_version() {
        let layout = StateLayout {
            model: "Demo",
            version: 3,
        };
        let bytes = encode_state(layout, &(1.5f64, 7u32)).unwrap();
        assert_eq!(&bytes[..2], &[3, 0]);
        assert_eq!(decode_state::<(f64, u32)>(layout, &bytes), Ok((1.5, 7)));
        let older = StateLayout {
            version: 4,
            ..layout
        };
        let message = decode_state::<(f64, u32)>(older, &bytes).unwrap_err();
        assert_eq!(
            message,
            "the Demo state has internal layout version 3, this build reads layout version 4 \
             only: it was saved by an older build of contour-fmu and cannot be restored"
        );
        let newer = StateLayout {
            version: 2,
            ..layout
        };
        assert!(decode_state::<(f64, u32)>(newer, &bytes)
            .unwrap_err()
            .contains("a newer build"));
        assert!(decode_state::<(f64, u32)>(layout, &bytes[..1])
            .unwrap_err()
            .contains("truncated"));
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(decode_state::<(f64, u32)>(layout, &longer)
            .unwrap_err()
            .contains("1 trailing bytes"));
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
