//! What the FMI layer needs of a model: the [`Model`] trait it drives, and the
//! [`ModelInfo`] that describes an FMU's interface (its variables, default experiment,
//! initial dependencies and the GUID hashed from them).

use std::path::PathBuf;
use std::sync::Arc;

use contour_core::contour::planar::TrueErrorIndexes;
use contour_core::path::five_axis::Planner;
use contour_core::path::planar::XyPlans;
use sha2::{Digest, Sha256};

use super::units;
use super::variables::{Start, Values, Variable, Vr};

/// What a model learns about its surroundings when it is created.
#[derive(Clone, Debug, Default)]
pub struct Environment {
    /// The unpacked FMU's `resources/` folder, when the importer gave one.
    pub resource_dir: Option<PathBuf>,
    /// Makes and keeps the five-axis plans: the library's instances share one (see
    /// `fmi2::plans`), so instances on one path plan once and a restored state finds its
    /// plan.
    pub planner: Arc<Planner>,
    /// The same for the XY table's planned references.
    pub xy_plans: Arc<XyPlans>,
    /// The same for the `program` estimator's exact-distance indexes.
    pub indexes: Arc<TrueErrorIndexes>,
}

/// A model's answer when it cannot do what was asked; the text goes to the log.
pub type ModelResult = Result<(), String>;

/// The behaviour of one FMU. The FMI layer owns the [`Values`] (inputs, parameters and
/// outputs) and hands them in; the model owns everything else (its internal state).
pub trait Model: Send {
    /// Checks the parameters, rebuilds the internal state from them at `start_time` and
    /// computes the outputs. Called in initialization mode, possibly several times.
    fn initialize(&mut self, values: &mut Values, start_time: f64) -> ModelResult;

    /// Warnings about the last initialization or step that did not stop it (a path
    /// file's tolerated irregularities, an input that does not fit a parameter): the FMI
    /// layer logs them, and they are gone. Called after every step: it must not allocate
    /// when there is nothing to say.
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

    /// The internal state as bytes, for FMU state save/restore: [`encode_state`](super::saved_state::encode_state) with the
    /// model's own [`StateLayout`](super::saved_state::StateLayout).
    fn save_state(&self) -> Result<Vec<u8>, String>;

    /// Checks bytes as [`Model::restore_state`] would, without applying them: the layout
    /// version, then every value like a parameter (periods, radii, finite memories) and,
    /// for a sampled model, that its sample clock is at `time`, the instance time saved
    /// with the state (the model's one check: its [`SavedState`](super::saved_state::SavedState),
    /// which sees the model's [`Environment`]). The error names the cause.
    fn check_state(&self, bytes: &[u8], time: f64) -> ModelResult;

    /// Restores what [`Model::save_state`] produced at instance time `time`; nothing
    /// changes when it is refused.
    fn restore_state(&mut self, bytes: &[u8], time: f64) -> ModelResult;
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
    /// More knowns an output's initial value depends on, but only on inputs the tests'
    /// contexts do not hold (a CL path that starts near the pole, a limit that binds
    /// only on some part): written to the model description with the others, not
    /// required to show in the perturbation test.
    pub initial_dependencies_on_some_paths: &'static [(Vr, &'static [Vr])],
    pub create: fn(&Environment) -> Box<dyn Model>,
}

impl ModelInfo {
    /// A hash of the whole interface (name, every variable's attributes), formatted as a
    /// GUID: it changes whenever the interface does, so importers that cache unpacked
    /// FMUs by GUID never mix versions.
    pub fn guid(&self) -> String {
        self.guid_of(self.variables, "")
    }

    /// [`ModelInfo::guid`] of the model with the table `variables` as its interface
    /// named `interface` (crate::framework::interface; "" for the model's own, whose GUID
    /// it keeps). A named interface gets a GUID of its own even where its table is the
    /// model's (a model without lengths).
    pub fn guid_of(&self, variables: &[Variable], interface: &str) -> String {
        self.token_of(b"fmi2-cs\0", variables, interface)
    }

    /// The FMI 3.0 `instantiationToken` of the model with the table `variables` as its
    /// interface named `interface`: [`ModelInfo::guid_of`]'s hash under another prefix,
    /// so an FMI 3.0 description never matches an FMI 2.0 binary's check, nor the reverse.
    pub fn instantiation_token_of(&self, variables: &[Variable], interface: &str) -> String {
        self.token_of(b"fmi3-cs\0", variables, interface)
    }

    /// A GUID-shaped hash of `standard`, the identifier, the interface and the table.
    fn token_of(&self, standard: &[u8], variables: &[Variable], interface: &str) -> String {
        let mut hash = Sha256::new();
        hash.update(standard);
        hash.update(self.identifier.as_bytes());
        if !interface.is_empty() {
            hash.update(b"\0interface\0");
            hash.update(interface.as_bytes());
        }
        for v in variables {
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
            .chain(self.initial_dependencies_on_some_paths)
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
