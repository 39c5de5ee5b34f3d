//! What the fuzz targets share: the exported `fmi2*` functions linked statically (those
//! of tests/abi/common/linked.rs plus the rest) and the `fmi3*` ones ([`fmi3`]), loggers
//! of both standards that read every message they are sent, the panic policy, and the
//! small path files under `fuzz/resources/`.
//!
//! Built only by `cargo fuzz` (with `RUSTC_BOOTSTRAP=1`): the logger is a real C variadic
//! function, so that the `"%s"` argument of every message is read too, not just the
//! fixed parameters.
#![feature(c_variadic)]
#![allow(non_snake_case)]

use std::ffi::{c_char, CStr};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

use fmi2_bindings::{
    fmi2Boolean, fmi2CallbackFunctions, fmi2Component, fmi2ComponentEnvironment, fmi2Integer,
    fmi2Real, fmi2Status, fmi2StatusKind, fmi2String, fmi2ValueReference,
};

#[path = "../../tests/abi/common/linked.rs"]
pub mod linked;

pub mod fmi3;

pub use fmi3::*;
pub use linked::*;

// The exported functions tests/abi/common/linked.rs does not declare.
extern "C" {
    pub fn fmi2GetTypesPlatform() -> *const c_char;
    pub fn fmi2GetVersion() -> *const c_char;
    pub fn fmi2SetDebugLogging(
        c: fmi2Component,
        logging_on: fmi2Boolean,
        n_categories: usize,
        categories: *const fmi2String,
    ) -> fmi2Status;
    pub fn fmi2Reset(c: fmi2Component) -> fmi2Status;
    pub fn fmi2GetInteger(
        c: fmi2Component,
        vr: *const fmi2ValueReference,
        nvr: usize,
        value: *mut fmi2Integer,
    ) -> fmi2Status;
    pub fn fmi2GetBoolean(
        c: fmi2Component,
        vr: *const fmi2ValueReference,
        nvr: usize,
        value: *mut fmi2Boolean,
    ) -> fmi2Status;
    pub fn fmi2GetString(
        c: fmi2Component,
        vr: *const fmi2ValueReference,
        nvr: usize,
        value: *mut fmi2String,
    ) -> fmi2Status;
    pub fn fmi2SetInteger(
        c: fmi2Component,
        vr: *const fmi2ValueReference,
        nvr: usize,
        value: *const fmi2Integer,
    ) -> fmi2Status;
    pub fn fmi2SetBoolean(
        c: fmi2Component,
        vr: *const fmi2ValueReference,
        nvr: usize,
        value: *const fmi2Boolean,
    ) -> fmi2Status;
    pub fn fmi2SetString(
        c: fmi2Component,
        vr: *const fmi2ValueReference,
        nvr: usize,
        value: *const fmi2String,
    ) -> fmi2Status;
    pub fn fmi2GetDirectionalDerivative(
        c: fmi2Component,
        v_unknown_ref: *const fmi2ValueReference,
        n_unknown: usize,
        v_known_ref: *const fmi2ValueReference,
        n_known: usize,
        dv_known: *const fmi2Real,
        dv_unknown: *mut fmi2Real,
    ) -> fmi2Status;
    pub fn fmi2SetRealInputDerivatives(
        c: fmi2Component,
        vr: *const fmi2ValueReference,
        nvr: usize,
        order: *const fmi2Integer,
        value: *const fmi2Real,
    ) -> fmi2Status;
    pub fn fmi2GetRealOutputDerivatives(
        c: fmi2Component,
        vr: *const fmi2ValueReference,
        nvr: usize,
        order: *const fmi2Integer,
        value: *mut fmi2Real,
    ) -> fmi2Status;
    pub fn fmi2CancelStep(c: fmi2Component) -> fmi2Status;
    pub fn fmi2GetStatus(c: fmi2Component, s: fmi2StatusKind, value: *mut fmi2Status)
        -> fmi2Status;
    pub fn fmi2GetRealStatus(
        c: fmi2Component,
        s: fmi2StatusKind,
        value: *mut fmi2Real,
    ) -> fmi2Status;
    pub fn fmi2GetIntegerStatus(
        c: fmi2Component,
        s: fmi2StatusKind,
        value: *mut fmi2Integer,
    ) -> fmi2Status;
    pub fn fmi2GetBooleanStatus(
        c: fmi2Component,
        s: fmi2StatusKind,
        value: *mut fmi2Boolean,
    ) -> fmi2Status;
    pub fn fmi2GetStringStatus(
        c: fmi2Component,
        s: fmi2StatusKind,
        value: *mut fmi2String,
    ) -> fmi2Status;
}

/// The most samples a five-axis plan may have under the fuzzer (20 s of motion at 1 ms):
/// planning costs microseconds a sample and round, ten times that under
/// AddressSanitizer, up to 30 rounds, and no input may take 10 s.
pub const FUZZ_SAMPLE_BUDGET: u64 = 20_000;

/// The message of FaultProbe's `panic` input (src/models/fault_probe.rs).
pub const INJECTED_PANIC: &str = "FaultProbe: injected panic";

/// Call from a target's `init`. libfuzzer-sys aborts on every panic, even one that would
/// be caught; the library catches panics at the FMI boundary on purpose, so FaultProbe's
/// injected panic must unwind to that `catch_unwind` (and come back as fmi2Fatal). Any
/// other panic is a finding: it still aborts, with the stack of where it happened.
pub fn install_panic_hook() {
    let abort_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<&str>()
            .copied()
            .or_else(|| payload.downcast_ref::<String>().map(String::as_str));
        if message != Some(INJECTED_PANIC) {
            abort_hook(info);
        }
    }));
}

/// The folder of the small path files the targets name (a two-curve JSON, a CL file, a
/// planar NURBS and a few broken ones).
pub fn resources_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("resources")
}

/// `resources_dir()` as the `file:` URI an importer passes to `fmi2Instantiate`.
pub fn resources_uri() -> String {
    format!("file://{}", resources_dir().display())
}

/// An instance the logger calls back into while it is being sent a message (0: none),
/// and whether that call frees it.
pub static REENTER: AtomicUsize = AtomicUsize::new(0);
pub static REENTER_FREES: AtomicBool = AtomicBool::new(false);
/// The handles the logger freed (cleared by the target), so that a target knows which of
/// its instances are gone without its doing.
pub static FREED_BY_LOGGER: Mutex<Vec<usize>> = Mutex::new(Vec::new());
static IN_LOGGER: AtomicBool = AtomicBool::new(false);
/// Messages received, so the reading of each one is not optimised away.
pub static MESSAGE_BYTES: AtomicUsize = AtomicUsize::new(0);

/// The category names the library logs under.
const CATEGORIES: [&str; 5] = [
    "logEvents",
    "logStatusWarning",
    "logStatusError",
    "logStatusFatal",
    "logAll",
];

/// A logger that checks what the library promises about every message (strings
/// NUL-terminated and readable, a known category, a valid status, the message passed as
/// the argument of a "%s" format) and optionally calls back into an instance, as FMI 2.0
/// allows an importer to do.
///
/// # Safety
/// Called by the library with the logger arguments of FMI 2.0.
pub unsafe extern "C" fn checking_logger(
    _environment: fmi2ComponentEnvironment,
    instance_name: fmi2String,
    status: fmi2Status,
    category: fmi2String,
    format: fmi2String,
    mut args: ...
) {
    assert!((0..=4).contains(&status), "logger: status {status}");
    assert!(!instance_name.is_null() && !category.is_null() && !format.is_null());
    let name = CStr::from_ptr(instance_name);
    let category = CStr::from_ptr(category)
        .to_str()
        .expect("category is UTF-8");
    assert!(
        CATEGORIES.contains(&category),
        "logger: category {category}"
    );
    assert_eq!(CStr::from_ptr(format), c"%s", "logger: format");
    let message = CStr::from_ptr(args.arg::<*const c_char>());
    MESSAGE_BYTES.fetch_add(
        name.to_bytes().len() + message.to_bytes().len(),
        Ordering::Relaxed,
    );
    reenter();
}

/// What both loggers do after reading a message: call back into the [`REENTER`] instance,
/// whatever its standard (the other standard's calls are refused and logged through the
/// instance's own callback, which does not recurse), and perhaps free it.
unsafe fn reenter() {
    let target = REENTER.load(Ordering::Relaxed);
    if target != 0 && !IN_LOGGER.swap(true, Ordering::Relaxed) {
        let c = target as fmi2Component;
        let mut value = 0.0;
        fmi2GetRealStatus(c, 2, &mut value);
        fmi2GetReal(c, std::ptr::null(), 0, std::ptr::null_mut());
        fmi3GetFloat64(c, std::ptr::null(), 0, std::ptr::null_mut(), 0);
        if REENTER_FREES.load(Ordering::Relaxed) {
            // One frees it; the other standard's leaves it (or a freed handle) alone.
            fmi2FreeInstance(c);
            fmi3FreeInstance(c);
            let mut freed = FREED_BY_LOGGER.lock().unwrap_or_else(|e| e.into_inner());
            if !freed.contains(&target) {
                freed.push(target);
            }
        }
        IN_LOGGER.store(false, Ordering::Relaxed);
    }
}

/// FMI 3.0's log callback: the message itself, no format and no arguments. Checks what the
/// library promises (a valid status, a known category, NUL-terminated readable strings)
/// and calls back into an instance as [`checking_logger`] does.
///
/// # Safety
/// Called by the library with the `fmi3LogMessageCallback` arguments.
pub unsafe extern "C" fn checking_logger3(
    _environment: fmi3_bindings::fmi3InstanceEnvironment,
    status: fmi3_bindings::fmi3Status,
    category: fmi3_bindings::fmi3String,
    message: fmi3_bindings::fmi3String,
) {
    assert!(status <= 4, "logger: status {status}");
    assert!(!category.is_null() && !message.is_null());
    let category = CStr::from_ptr(category)
        .to_str()
        .expect("category is UTF-8");
    assert!(
        CATEGORIES.contains(&category),
        "logger: category {category}"
    );
    MESSAGE_BYTES.fetch_add(CStr::from_ptr(message).to_bytes().len(), Ordering::Relaxed);
    reenter();
}

/// Callbacks with [`checking_logger`], handing `environment` back to it unread.
pub fn checking_callbacks(environment: usize) -> fmi2CallbackFunctions {
    fmi2CallbackFunctions {
        logger: Some(checking_logger),
        allocateMemory: Some(libc::calloc),
        freeMemory: Some(libc::free),
        stepFinished: None,
        componentEnvironment: environment as fmi2ComponentEnvironment,
    }
}

/// The FMU state envelope of src/fmi/fmu_state.rs, rebuilt here (the module is private)
/// so that a target can wrap fuzzed bytes with a valid header and checksum and reach the
/// decoder and the models' `check_state` instead of dying at the CRC. `check_envelope`
/// (called from each target's init) fails loudly if the library's format moves on.
pub mod envelope {
    use contour_fmu::framework::variables::Values;
    use serde::{Deserialize, Serialize};

    pub const MAGIC: &[u8; 8] = b"CCCFMUst";
    pub const FORMAT_VERSION: u16 = 2;

    /// `state_machine::Mode`, variant for variant (postcard writes the index).
    #[derive(Clone, Copy, Debug, Serialize, Deserialize)]
    pub enum Mode {
        Instantiated,
        Initialization,
        StepComplete,
        StepFailed,
        Terminated,
        Error,
        Fatal,
    }

    /// `fmu_state::Snapshot`, field for field.
    #[derive(Clone, Debug, Serialize, Deserialize)]
    pub struct Snapshot {
        pub library: String,
        pub guid: String,
        pub mode: Mode,
        pub time: f64,
        pub stop_time: Option<f64>,
        pub needs_initialize: bool,
        pub values: Values,
        #[serde(with = "contour_fmu::framework::saved_state::bytes")]
        pub model: Vec<u8>,
    }

    /// MAGIC · version · `payload` · CRC-32 of what precedes it.
    pub fn wrap(payload: &[u8]) -> Vec<u8> {
        let mut bytes = Vec::with_capacity(payload.len() + 14);
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
        bytes.extend_from_slice(payload);
        let crc = crc32fast::hash(&bytes);
        bytes.extend_from_slice(&crc.to_le_bytes());
        bytes
    }

    /// The payload of serialized state bytes, if the envelope is intact.
    pub fn unwrap(bytes: &[u8]) -> Option<&[u8]> {
        let body = bytes.get(..bytes.len().checked_sub(4)?)?;
        let crc = u32::from_le_bytes(bytes[body.len()..].try_into().ok()?);
        (body.starts_with(MAGIC)
            && body.get(8..10) == Some(&FORMAT_VERSION.to_le_bytes()[..])
            && crc32fast::hash(body) == crc)
            .then(|| &body[10..])
    }

    pub fn encode(snapshot: &Snapshot) -> Vec<u8> {
        wrap(&postcard::to_allocvec(snapshot).expect("a snapshot encodes"))
    }

    pub fn decode(bytes: &[u8]) -> Option<Snapshot> {
        postcard::from_bytes(unwrap(bytes)?).ok()
    }
}

/// A started instance of `model` (logging off; PathInterpolator5X on fuzz/resources'
/// small CL file instead of its 80 001-pose built-in), or NULL.
///
/// # Safety
/// `functions` outlives the instance.
pub unsafe fn started(
    model: &contour_fmu::framework::model::ModelInfo,
    functions: *const fmi2CallbackFunctions,
) -> fmi2Component {
    let guid = std::ffi::CString::new(model.guid()).expect("GUID without NUL");
    let uri = std::ffi::CString::new(resources_uri()).expect("path without NUL");
    let c = fmi2Instantiate(
        c"fuzz".as_ptr(),
        1,
        guid.as_ptr(),
        uri.as_ptr(),
        functions,
        0,
        0,
    );
    if c.is_null() {
        return c;
    }
    if model.identifier == "PathInterpolator5X" {
        let vr = model
            .variables
            .iter()
            .find(|v| v.name == "path")
            .expect("PathInterpolator5X has a path")
            .vr as fmi2ValueReference;
        let value = c"part.cl".as_ptr();
        assert_eq!(fmi2SetString(c, &vr, 1, &value), 0);
    }
    assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), 0);
    assert_eq!(fmi2EnterInitializationMode(c), 0);
    assert_eq!(fmi2ExitInitializationMode(c), 0);
    c
}

/// The serialized FMU state of `c` now, or None.
///
/// # Safety
/// `c` is a live instance.
pub unsafe fn serialized_state(c: fmi2Component) -> Option<Vec<u8>> {
    let mut state: fmi2_bindings::fmi2FMUstate = std::ptr::null_mut();
    if fmi2GetFMUstate(c, &mut state) != 0 {
        return None;
    }
    let mut size = 0;
    let mut bytes = None;
    if fmi2SerializedFMUstateSize(c, state, &mut size) == 0 {
        let mut buffer = vec![0u8; size];
        if fmi2SerializeFMUstate(c, state, buffer.as_mut_ptr() as *mut c_char, size) == 0 {
            bytes = Some(buffer);
        }
    }
    assert_eq!(fmi2FreeFMUstate(c, &mut state), 0);
    bytes
}

/// Checks that [`envelope`] still describes the library's FMU states: a real state of
/// every model decodes with it and encodes back to the same bytes.
pub fn check_envelope() {
    let callbacks = quiet_callbacks();
    for model in contour_fmu::models::instantiable() {
        // SAFETY: the callbacks outlive the instance, freed before returning.
        unsafe {
            let c = started(model, &callbacks);
            assert!(!c.is_null(), "{}: cannot start", model.identifier);
            let bytes = serialized_state(c).expect("a state serializes");
            fmi2FreeInstance(c);
            let snapshot = envelope::decode(&bytes).unwrap_or_else(|| {
                panic!(
                    "{}: the library's FMU state format changed: update fuzz/src/lib.rs",
                    model.identifier
                )
            });
            assert_eq!(envelope::encode(&snapshot), bytes, "{}", model.identifier);
        }
    }
}
