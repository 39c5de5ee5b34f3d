//! `fmi2DeSerializeFMUstate` on arbitrary bytes, for every model.
//!
//! The first byte picks the model (low three bits, modulo the seven models) and how the
//! rest is used (next two bits):
//! - 0: as the serialized state itself, so the envelope checks (magic, version, CRC) are
//!   fuzzed;
//! - 1: as the postcard payload, wrapped in a valid header and CRC, so the snapshot
//!   decoder and every value check are reached;
//! - 2: as the model's own state inside an otherwise valid snapshot at t = 0, so each
//!   model's `check_state` / `restore_state` is reached through the FMI layer;
//! - 3: the same bytes straight into the model's `check_state` / `restore_state`.
//!
//! An accepted state is set, stepped, read and serialized again. The oracle, besides the
//! sanitizers and the panic hook: `fmi2SetFMUstate` accepts what `fmi2DeSerializeFMUstate`
//! accepted (both run the same checks), no model answers fmi2Fatal except FaultProbe, and
//! `restore_state` accepts what `check_state` accepted.
//!
//! Seeds: run the target binary with `CONTOUR_FUZZ_SEEDS=<folder>` and it writes valid
//! states of every model there, in all four forms, and exits (fuzz/smoke.sh does this
//! before fuzzing): no binary blobs in git, and they follow the format as it changes.
#![no_main]

use std::cell::RefCell;
use std::ffi::c_char;
use std::ptr;

use contour_core::contour::planar::TrueErrorIndexes;
use contour_core::path::five_axis::Planner;
use contour_core::path::planar::XyPlans;
use contour_fmu::framework::model::{Environment, ModelInfo};
use contour_fmu::framework::variables::{Values, VarType};
use contour_fmu::models;
use contour_fmu_fuzz::envelope::{self, Mode, Snapshot};
use contour_fmu_fuzz::*;
use fmi2_bindings::{fmi2CallbackFunctions, fmi2Component, fmi2FMUstate, fmi2Status, fmi2String};
use libfuzzer_sys::fuzz_target;

const OK: fmi2Status = 0;
const FATAL: fmi2Status = 4;
/// One control period of the default models: a restored clock is within one period of
/// the state's time, so this step takes at most a few samples at the default period (at
/// the shortest period the models accept, 1 µs, a thousand).
const STEP: f64 = 1e-3;

fn vrs_of(model: &ModelInfo, var_type: VarType) -> Vec<u32> {
    model
        .variables
        .iter()
        .filter(|v| v.var_type() == var_type)
        .map(|v| v.vr as u32)
        .collect()
}

fn no_fatal(model: &ModelInfo, what: &str, status: fmi2Status) {
    if status == FATAL {
        assert_eq!(model.identifier, "FaultProbe", "{what}: fmi2Fatal");
    }
}

/// A started instance of every model and its state right after initialization, made
/// once: starting one costs more than all the rest of an input.
struct Started {
    c: fmi2Component,
    fresh: fmi2FMUstate,
}

thread_local! {
    static STARTED: RefCell<Vec<Option<Started>>> = const { RefCell::new(Vec::new()) };
}

thread_local! {
    /// The callbacks of the cached instances, alive as long as the thread.
    static CALLBACKS: fmi2CallbackFunctions = checking_callbacks(0);
}

/// The cached instance of `model` (index `index`), started on first use.
///
/// # Safety
/// FMI rules only.
unsafe fn instance(index: usize, model: &'static ModelInfo) -> fmi2Component {
    STARTED.with_borrow_mut(|started| {
        if started.len() <= index {
            started.resize_with(index + 1, || None);
        }
        let slot = &mut started[index];
        if slot.is_none() {
            let c = started_instance(model);
            let mut fresh: fmi2FMUstate = ptr::null_mut();
            assert_eq!(fmi2GetFMUstate(c, &mut fresh), OK);
            *slot = Some(Started { c, fresh });
        }
        slot.as_ref().map(|s| s.c).expect("just started")
    })
}

unsafe fn started_instance(model: &'static ModelInfo) -> fmi2Component {
    let c = CALLBACKS.with(|callbacks| started(model, callbacks));
    assert!(!c.is_null(), "{}: cannot start", model.identifier);
    c
}

/// Puts the cached instance back to its fresh state; a fatal one (FaultProbe) is freed
/// and started again next time.
///
/// # Safety
/// FMI rules only.
unsafe fn rewind(index: usize) {
    STARTED.with_borrow_mut(|started| {
        let Some(s) = started[index].take() else {
            return;
        };
        if fmi2SetFMUstate(s.c, s.fresh) == OK {
            started[index] = Some(s);
        } else {
            fmi2FreeInstance(s.c);
        }
    })
}

/// Through the C functions: deserialize, and if accepted set, step, read, save again.
///
/// # Safety
/// None beyond the FMI rules, which this follows.
unsafe fn through_fmi(index: usize, model: &'static ModelInfo, bytes: &[u8]) {
    let c = instance(index, model);
    let mut state: fmi2FMUstate = ptr::null_mut();
    let status =
        fmi2DeSerializeFMUstate(c, bytes.as_ptr() as *const c_char, bytes.len(), &mut state);
    no_fatal(model, "fmi2DeSerializeFMUstate", status);
    if status == OK {
        assert!(!state.is_null());
        assert_eq!(
            fmi2SetFMUstate(c, state),
            OK,
            "{}: a deserialized state was refused by fmi2SetFMUstate",
            model.identifier
        );
        let mut now = 0.0;
        fmi2GetRealStatus(c, 2, &mut now);
        no_fatal(model, "fmi2DoStep", fmi2DoStep(c, now, STEP, 1));
        let reals = vrs_of(model, VarType::Real);
        let mut values = vec![0.0; reals.len()];
        fmi2GetReal(c, reals.as_ptr(), reals.len(), values.as_mut_ptr());
        let strings = vrs_of(model, VarType::String);
        let mut texts: Vec<fmi2String> = vec![ptr::null(); strings.len()];
        if fmi2GetString(c, strings.as_ptr(), strings.len(), texts.as_mut_ptr()) == OK {
            for &t in &texts {
                let _ = std::ffi::CStr::from_ptr(t).to_bytes().len();
            }
        }
        // Whatever it saves now it must read back.
        if let Some(again) = serialized_state(c) {
            let mut copy: fmi2FMUstate = ptr::null_mut();
            let status =
                fmi2DeSerializeFMUstate(c, again.as_ptr() as *const c_char, again.len(), &mut copy);
            no_fatal(model, "fmi2DeSerializeFMUstate", status);
            fmi2FreeFMUstate(c, &mut copy);
        }
        // A fatal FaultProbe refuses this too; `rewind` then starts it again.
        fmi2FreeFMUstate(c, &mut state);
    }
    rewind(index);
}

/// The environment a model is created in here: the FMU library's own planner is not
/// reachable from outside, so one of the same kind, planning within the fuzz budget and
/// kept across inputs as the library keeps its own.
fn fuzz_environment() -> Environment {
    static PLANNER: std::sync::OnceLock<std::sync::Arc<Planner>> = std::sync::OnceLock::new();
    static XY_PLANS: std::sync::OnceLock<std::sync::Arc<XyPlans>> = std::sync::OnceLock::new();
    static INDEXES: std::sync::OnceLock<std::sync::Arc<TrueErrorIndexes>> =
        std::sync::OnceLock::new();
    let planner = PLANNER.get_or_init(|| {
        let planner = Planner::new();
        planner.set_sample_budget(FUZZ_SAMPLE_BUDGET);
        std::sync::Arc::new(planner)
    });
    Environment {
        resource_dir: None,
        planner: std::sync::Arc::clone(planner),
        xy_plans: std::sync::Arc::clone(XY_PLANS.get_or_init(Default::default)),
        indexes: std::sync::Arc::clone(INDEXES.get_or_init(Default::default)),
    }
}

/// `model.guid()`, computed once per model (it hashes the variable table).
fn guid_of(index: usize, model: &'static ModelInfo) -> String {
    thread_local! {
        static GUIDS: RefCell<Vec<Option<String>>> = const { RefCell::new(Vec::new()) };
    }
    GUIDS.with_borrow_mut(|guids| {
        if guids.len() <= index {
            guids.resize(index + 1, None);
        }
        guids[index].get_or_insert_with(|| model.guid()).clone()
    })
}

/// Straight into the model: `check_state`, then `restore_state`, a few steps and a save.
fn through_model(model: &'static ModelInfo, bytes: &[u8]) {
    let mut m = (model.create)(&fuzz_environment());
    let checked = m.check_state(bytes, 0.0);
    let restored = m.restore_state(bytes, 0.0);
    assert_eq!(
        checked.is_ok(),
        restored.is_ok(),
        "{}: check_state and restore_state disagree: {checked:?} / {restored:?}",
        model.identifier
    );
    if restored.is_ok() {
        let mut values = Values::from_table(model.variables);
        // FaultProbe panics on demand only; its start values do not ask for it.
        for k in 0..3 {
            let _ = m.do_step(&mut values, k as f64 * STEP, STEP);
        }
        let _ = m.save_state();
    }
}

/// The states of a started instance of every model (after initialization, after a few
/// steps, terminated), each in the four forms of the selector byte.
fn write_seeds(dir: &std::path::Path) {
    std::fs::create_dir_all(dir).expect("seed folder");
    let callbacks = quiet_callbacks();
    for (index, model) in models::instantiable().into_iter().enumerate() {
        let mut states = Vec::new();
        // SAFETY: the callbacks outlive the instance, freed at the end.
        unsafe {
            let c = started(model, &callbacks);
            assert!(!c.is_null(), "{}: cannot start", model.identifier);
            states.extend(serialized_state(c));
            for k in 0..3 {
                fmi2DoStep(c, k as f64 * STEP, STEP, 0);
            }
            states.extend(serialized_state(c));
            fmi2Terminate(c);
            states.extend(serialized_state(c));
            fmi2FreeInstance(c);
        }
        for (n, bytes) in states.iter().enumerate() {
            let snapshot = envelope::decode(bytes).expect("the library's own state");
            let payload = envelope::unwrap(bytes).expect("the library's own state");
            let forms: [&[u8]; 4] = [bytes, payload, &snapshot.model, &snapshot.model];
            for (mode, body) in forms.into_iter().enumerate() {
                let mut seed = vec![index as u8 | (mode as u8) << 3];
                seed.extend_from_slice(body);
                let name = format!("{}-{n}-mode{mode}", model.identifier);
                std::fs::write(dir.join(name), seed).expect("seed file");
            }
        }
    }
}

fuzz_target!(
    init: {
        install_panic_hook();
        // A restored five-axis state plans again: within the 10 s a fuzz input may take
        // (FUZZ_SAMPLE_BUDGET), a longer plan refused.
        contour_fmu::fmi::set_plan_sample_budget(FUZZ_SAMPLE_BUDGET);
        check_envelope();
        if let Some(dir) = std::env::var_os("CONTOUR_FUZZ_SEEDS") {
            write_seeds(std::path::Path::new(&dir));
            std::process::exit(0);
        }
    },
    |data: &[u8]| {
        let Some((&selector, body)) = data.split_first() else {
            return;
        };
        let all = models::instantiable();
        let index = (selector & 7) as usize % all.len();
        let model = all[index];
        match (selector >> 3) & 3 {
            // SAFETY (all three): see `through_fmi`.
            0 => unsafe { through_fmi(index, model, body) },
            1 => unsafe { through_fmi(index, model, &envelope::wrap(body)) },
            2 => {
                let snapshot = Snapshot {
                    library: "fuzz".into(),
                    guid: guid_of(index, model),
                    mode: Mode::StepComplete,
                    time: 0.0,
                    stop_time: None,
                    needs_initialize: false,
                    values: Values::from_table(model.variables),
                    model: body.to_vec(),
                };
                unsafe { through_fmi(index, model, &envelope::encode(&snapshot)) }
            }
            _ => through_model(model, body),
        }
    }
);
