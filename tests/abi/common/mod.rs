//! Test harness that drives the built library through its C ABI, as an importer would:
//! it dlopens `libcontour_fmu.so` and calls the exported `fmi2*` symbols.
#![allow(dead_code)]

use contour_core::math;
use std::ffi::{c_char, c_void, CStr, CString};
use std::path::PathBuf;
use std::sync::{Mutex, OnceLock};

use contour_fmu::framework::model::ModelInfo;
use contour_fmu::framework::variables::Values;
// Generated from third_party/fmi2/ by `cargo run -p xtask -- bindings` (kept as bindgen
// wrote it): `Fmi2Binding`, the dlopen'ed library's functions; the FMI 2.0 types are the
// library's own.
pub use fmi2_bindings::*;
#[rustfmt::skip]
mod fmi2_library;
pub use fmi2_library::*;
// FMI 3.0: `Fmi3Binding` (generated from third_party/fmi3/) and an instance wrapper.
#[rustfmt::skip]
mod fmi3_library;
pub mod fmi3;
// The same functions linked statically instead (tests/abi/no_alloc.rs, benches/fmu_abi.rs).
pub mod linked;

/// Steps a started XYServoPlant from sample `from` to `to` (1 ms) under sinusoidal
/// commands; the positions and the x velocity after each step.
pub fn run_plant(i: &Instance, from: usize, to: usize) -> Vec<[f64; 3]> {
    let h = 0.001;
    (from..to)
        .map(|k| {
            let t = k as f64 * h;
            let u = [20.0 * math::sin(5.0 * t), 15.0 * math::cos(3.0 * t)];
            assert_eq!(i.set_reals(&[plant_vr::U_X, plant_vr::U_Y], &u), OK);
            assert_eq!(i.step(t, h), OK);
            let (_, v) = i.get_reals(&[plant_vr::POS_X, plant_vr::POS_Y, plant_vr::VEL_X]);
            [v[0], v[1], v[2]]
        })
        .collect()
}

/// XYServoPlant's value references that the ABI tests set and read.
pub mod plant_vr {
    use contour_fmu::models::xy_servo_plant as plant;

    pub const U_X: u32 = plant::U.at(0).vr() as u32;
    pub const U_Y: u32 = plant::U.at(1).vr() as u32;
    pub const POS_X: u32 = plant::POS.at(0).vr() as u32;
    pub const POS_Y: u32 = plant::POS.at(1).vr() as u32;
    pub const VEL_X: u32 = plant::VEL.at(0).vr() as u32;
    /// The first axis's inertia parameter `x.J`.
    pub const X_J: u32 = 6;
    pub const POS0_X: u32 = plant::POS0.at(0).vr() as u32;
}
use serde::{Deserialize, Serialize};

pub const OK: fmi2Status = fmi2Status_fmi2OK;
pub const WARNING: fmi2Status = fmi2Status_fmi2Warning;
pub const DISCARD: fmi2Status = fmi2Status_fmi2Discard;
pub const ERROR: fmi2Status = fmi2Status_fmi2Error;
pub const FATAL: fmi2Status = fmi2Status_fmi2Fatal;

pub use contour_fmu::fmi::FMI2_CO_SIMULATION;

/// The cdylib cargo built with this test binary: `cargo test` leaves it beside the test
/// in target/<profile>/deps/, `cargo build` in target/<profile>/.
pub fn library_path() -> PathBuf {
    let exe = std::env::current_exe().expect("test binary path");
    let deps = exe.parent().expect("deps dir");
    [deps, deps.parent().expect("profile dir")]
        .iter()
        .map(|dir| dir.join("libcontour_fmu.so"))
        .find(|p| p.exists())
        .expect("libcontour_fmu.so next to the test binary")
}

pub fn lib() -> &'static Fmi2Binding {
    static LIB: OnceLock<Fmi2Binding> = OnceLock::new();
    LIB.get_or_init(|| {
        let path = library_path();
        // SAFETY: our own library, loaded once and never unloaded during the tests.
        unsafe { Fmi2Binding::new(&path) }
            .unwrap_or_else(|e| panic!("cannot load {}: {e}", path.display()))
    })
}

/// One message the library sent to the logger callback.
#[derive(Clone, Debug)]
pub struct Record {
    pub status: fmi2Status,
    pub category: String,
    pub format: String,
    pub message: String,
    pub instance: String,
}

#[derive(Default)]
pub struct Log {
    pub records: Mutex<Vec<Record>>,
    /// When set, the logger calls `fmi2GetReal` on this instance from inside the callback
    /// (as a debugging importer may) and records the status it got.
    pub reenter: std::sync::atomic::AtomicPtr<c_void>,
}

unsafe fn text(p: *const c_char) -> String {
    if p.is_null() {
        "<NULL>".into()
    } else {
        CStr::from_ptr(p).to_string_lossy().into_owned()
    }
}

/// The logger callback. C declares it variadic; a stable-Rust function cannot be, so it
/// is declared with the single `char*` argument the library must pass after its "%s"
/// format. On the System V x86-64 and AArch64 Linux ABIs a variadic pointer argument
/// travels exactly like a fixed one, so this reads what the library passed.
unsafe extern "C" fn capture(
    env: fmi2ComponentEnvironment,
    instance: fmi2String,
    status: fmi2Status,
    category: fmi2String,
    format: fmi2String,
    argument: *const c_char,
) {
    let log = &*(env as *const Log);
    let format = text(format);
    // Only read the argument when the format promises one.
    let message = if format == "%s" {
        text(argument)
    } else {
        String::new()
    };
    let reenter = log
        .reenter
        .swap(std::ptr::null_mut(), std::sync::atomic::Ordering::SeqCst);
    if !reenter.is_null() {
        let (vr, mut value) = (0u32, 0.0);
        let status = lib().fmi2GetReal(reenter, &vr, 1, &mut value);
        log.records.lock().unwrap().push(Record {
            status,
            category: "reentered".into(),
            format: String::new(),
            message: format!("fmi2GetReal from the logger returned {status}"),
            instance: text(instance),
        });
    }
    log.records.lock().unwrap().push(Record {
        status,
        category: text(category),
        format,
        message,
        instance: text(instance),
    });
}

pub fn logger_callback() -> fmi2CallbackLogger {
    type Fixed = unsafe extern "C" fn(
        fmi2ComponentEnvironment,
        fmi2String,
        fmi2Status,
        fmi2String,
        fmi2String,
        *const c_char,
    );
    type Variadic = unsafe extern "C" fn(
        fmi2ComponentEnvironment,
        fmi2String,
        fmi2Status,
        fmi2String,
        fmi2String,
        ...
    );
    // SAFETY: see `capture`.
    Some(unsafe { std::mem::transmute::<Fixed, Variadic>(capture) })
}

unsafe extern "C" fn allocate(n: usize, size: usize) -> *mut c_void {
    libc_calloc(n, size)
}
unsafe extern "C" fn free(p: *mut c_void) {
    libc_free(p)
}
extern "C" {
    #[link_name = "calloc"]
    fn libc_calloc(n: usize, size: usize) -> *mut c_void;
    #[link_name = "free"]
    fn libc_free(p: *mut c_void);
}

/// Callbacks with a logger writing into `log`.
pub fn callbacks(log: &Log) -> Box<fmi2CallbackFunctions> {
    Box::new(fmi2CallbackFunctions {
        logger: logger_callback(),
        allocateMemory: Some(allocate),
        freeMemory: Some(free),
        stepFinished: None,
        componentEnvironment: log as *const Log as *mut c_void,
    })
}

/// An instance with its own log; freed on drop.
pub struct Instance {
    pub c: fmi2Component,
    pub log: Box<Log>,
    _callbacks: Box<fmi2CallbackFunctions>,
    _strings: Vec<CString>,
    freed: bool,
}

pub fn cstr(s: &str) -> CString {
    CString::new(s).unwrap()
}

/// Raw fmi2Instantiate with a capturing logger; returns the component (maybe NULL) and log.
pub fn instantiate_raw(
    name: Option<&str>,
    fmu_type: fmi2Type,
    guid: Option<&str>,
    resources: Option<&str>,
    logging_on: bool,
) -> (fmi2Component, Box<Log>, Box<fmi2CallbackFunctions>) {
    let log = Box::<Log>::default();
    let callbacks = callbacks(&log);
    let name = name.map(cstr);
    let guid = guid.map(cstr);
    let resources = resources.map(cstr);
    let p = |s: &Option<CString>| s.as_ref().map_or(std::ptr::null(), |s| s.as_ptr());
    let c = unsafe {
        lib().fmi2Instantiate(
            p(&name),
            fmu_type,
            p(&guid),
            p(&resources),
            &*callbacks,
            0,
            logging_on as fmi2Boolean,
        )
    };
    (c, log, callbacks)
}

impl Instance {
    pub fn new(model: &ModelInfo) -> Self {
        Self::named(model, "test")
    }

    pub fn named(model: &ModelInfo, name: &str) -> Self {
        let (c, log, callbacks) = instantiate_raw(
            Some(name),
            fmi2Type_fmi2CoSimulation,
            Some(&model.guid()),
            None,
            false,
        );
        assert!(
            !c.is_null(),
            "instantiation failed: {:?}",
            log.records.lock().unwrap()
        );
        Instance {
            c,
            log,
            _callbacks: callbacks,
            _strings: Vec::new(),
            freed: false,
        }
    }

    pub fn records(&self) -> Vec<Record> {
        self.log.records.lock().unwrap().clone()
    }

    pub fn clear_log(&self) {
        self.log.records.lock().unwrap().clear();
    }

    /// The messages of the records with `status`.
    pub fn messages(&self, status: fmi2Status) -> Vec<String> {
        self.records()
            .into_iter()
            .filter(|r| r.status == status)
            .map(|r| r.message)
            .collect()
    }

    pub fn last_error(&self) -> String {
        self.messages(ERROR).pop().unwrap_or_default()
    }

    pub fn setup(&self, start: f64, stop: Option<f64>) -> fmi2Status {
        unsafe {
            lib().fmi2SetupExperiment(
                self.c,
                0,
                0.0,
                start,
                stop.is_some() as i32,
                stop.unwrap_or(0.0),
            )
        }
    }
    pub fn enter_init(&self) -> fmi2Status {
        unsafe { lib().fmi2EnterInitializationMode(self.c) }
    }
    pub fn exit_init(&self) -> fmi2Status {
        unsafe { lib().fmi2ExitInitializationMode(self.c) }
    }
    /// Setup at t = 0 without stop time, enter and exit initialization: ready to step.
    pub fn start(&self) {
        assert_eq!(self.setup(0.0, None), OK);
        assert_eq!(self.enter_init(), OK);
        assert_eq!(self.exit_init(), OK, "{}", self.last_error());
    }
    pub fn step(&self, t: f64, h: f64) -> fmi2Status {
        unsafe { lib().fmi2DoStep(self.c, t, h, 1) }
    }
    pub fn terminate(&self) -> fmi2Status {
        unsafe { lib().fmi2Terminate(self.c) }
    }
    pub fn reset(&self) -> fmi2Status {
        unsafe { lib().fmi2Reset(self.c) }
    }

    pub fn get_reals(&self, vrs: &[u32]) -> (fmi2Status, Vec<f64>) {
        let mut out = vec![f64::NAN; vrs.len()];
        let s = unsafe { lib().fmi2GetReal(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
        (s, out)
    }
    pub fn get_real(&self, vr: u32) -> f64 {
        let (s, v) = self.get_reals(&[vr]);
        assert_eq!(s, OK, "{}", self.last_error());
        v[0]
    }
    pub fn set_reals(&self, vrs: &[u32], values: &[f64]) -> fmi2Status {
        unsafe { lib().fmi2SetReal(self.c, vrs.as_ptr(), vrs.len(), values.as_ptr()) }
    }
    pub fn get_integer(&self, vr: u32) -> (fmi2Status, i32) {
        let mut out = -1;
        let s = unsafe { lib().fmi2GetInteger(self.c, &vr, 1, &mut out) };
        (s, out)
    }
    pub fn set_integer(&self, vr: u32, value: i32) -> fmi2Status {
        unsafe { lib().fmi2SetInteger(self.c, &vr, 1, &value) }
    }
    pub fn get_boolean(&self, vr: u32) -> (fmi2Status, bool) {
        let mut out = -1;
        let s = unsafe { lib().fmi2GetBoolean(self.c, &vr, 1, &mut out) };
        (s, out != 0)
    }
    pub fn set_boolean(&self, vr: u32, value: bool) -> fmi2Status {
        let v = value as fmi2Boolean;
        unsafe { lib().fmi2SetBoolean(self.c, &vr, 1, &v) }
    }
    /// Returns the raw pointer too, to check how long it stays valid.
    pub fn get_string(&self, vr: u32) -> (fmi2Status, *const c_char, String) {
        let mut out: fmi2String = std::ptr::null();
        let s = unsafe { lib().fmi2GetString(self.c, &vr, 1, &mut out) };
        let text = if out.is_null() {
            String::new()
        } else {
            unsafe { text(out) }
        };
        (s, out, text)
    }
    pub fn set_string(&self, vr: u32, value: &str) -> fmi2Status {
        let v = cstr(value);
        let p = v.as_ptr();
        unsafe { lib().fmi2SetString(self.c, &vr, 1, &p) }
    }
    pub fn set_debug_logging(&self, on: bool, categories: &[&str]) -> fmi2Status {
        let owned: Vec<CString> = categories.iter().map(|c| cstr(c)).collect();
        let ptrs: Vec<fmi2String> = owned.iter().map(|c| c.as_ptr()).collect();
        unsafe { lib().fmi2SetDebugLogging(self.c, on as i32, ptrs.len(), ptrs.as_ptr()) }
    }

    pub fn get_state(&self) -> (fmi2Status, fmi2FMUstate) {
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        let s = unsafe { lib().fmi2GetFMUstate(self.c, &mut state) };
        (s, state)
    }
    pub fn set_state(&self, state: fmi2FMUstate) -> fmi2Status {
        unsafe { lib().fmi2SetFMUstate(self.c, state) }
    }
    pub fn free_state(&self, state: &mut fmi2FMUstate) -> fmi2Status {
        unsafe { lib().fmi2FreeFMUstate(self.c, state) }
    }
    /// fmi2FreeFMUstate with an arbitrary pointer argument (fmusim 0.0.39 passes the state
    /// itself: `free_state_raw(state as *mut fmi2FMUstate)`).
    pub fn free_state_raw(&self, argument: *mut fmi2FMUstate) -> fmi2Status {
        unsafe { lib().fmi2FreeFMUstate(self.c, argument) }
    }
    /// fmi2SerializedFMUstateSize alone.
    pub fn state_size(&self, state: fmi2FMUstate) -> (fmi2Status, usize) {
        let mut size = usize::MAX;
        let s = unsafe { lib().fmi2SerializedFMUstateSize(self.c, state, &mut size) };
        (s, size)
    }
    pub fn serialize(&self, state: fmi2FMUstate) -> (fmi2Status, Vec<u8>) {
        let mut size = 0usize;
        let s = unsafe { lib().fmi2SerializedFMUstateSize(self.c, state, &mut size) };
        if s != OK {
            return (s, Vec::new());
        }
        let mut bytes = vec![0u8; size];
        let s = unsafe {
            lib().fmi2SerializeFMUstate(self.c, state, bytes.as_mut_ptr() as *mut fmi2Byte, size)
        };
        (s, bytes)
    }
    pub fn deserialize(&self, bytes: &[u8]) -> (fmi2Status, fmi2FMUstate) {
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        let s = unsafe {
            lib().fmi2DeSerializeFMUstate(
                self.c,
                bytes.as_ptr() as *const fmi2Byte,
                bytes.len(),
                &mut state,
            )
        };
        (s, state)
    }

    pub fn free(&mut self) {
        if !self.freed {
            unsafe { lib().fmi2FreeInstance(self.c) };
            self.freed = true;
        }
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        self.free();
    }
}

// ---------------------------------------------------------------------------------------
// Serialized FMU states, opened and resealed by hand (the layout of src/fmi/fmu_state.rs:
// magic, format version, postcard payload, CRC-32), to hand the library bytes that pass
// the checksum but carry a bad value inside.

pub const STATE_MAGIC: &[u8; 8] = b"CCCFMUst";
pub const STATE_FORMAT: u16 = 2;

/// The payload of a serialized FMU state. `mode` is the library's mode enum as postcard
/// writes it (the variant index); `model` is the model's own state: its layout version
/// (u16 LE) then its fields.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StateEnvelope {
    pub library: String,
    pub guid: String,
    pub mode: u32,
    pub time: f64,
    pub stop_time: Option<f64>,
    pub needs_initialize: bool,
    pub values: Values,
    pub model: Vec<u8>,
}

/// The format version and payload of serialized state bytes (checksum verified).
pub fn open_state(bytes: &[u8]) -> (u16, StateEnvelope) {
    assert_eq!(&bytes[..8], STATE_MAGIC);
    let (body, crc) = bytes.split_at(bytes.len() - 4);
    assert_eq!(
        crc32fast::hash(body).to_le_bytes(),
        crc,
        "checksum of the original bytes"
    );
    let format = u16::from_le_bytes([bytes[8], bytes[9]]);
    let envelope = postcard::from_bytes(&body[10..]).expect("payload");
    (format, envelope)
}

/// Serialized state bytes with a valid checksum.
pub fn seal_state(format: u16, envelope: &StateEnvelope) -> Vec<u8> {
    let mut bytes = STATE_MAGIC.to_vec();
    bytes.extend_from_slice(&format.to_le_bytes());
    bytes.extend_from_slice(&postcard::to_stdvec(envelope).expect("payload"));
    let crc = crc32fast::hash(&bytes);
    bytes.extend_from_slice(&crc.to_le_bytes());
    bytes
}

/// Positions of the little-endian bytes of `value` in `bytes`.
pub fn find_f64(bytes: &[u8], value: f64) -> Vec<usize> {
    let pattern = value.to_le_bytes();
    bytes
        .windows(8)
        .enumerate()
        .filter(|(_, w)| *w == pattern)
        .map(|(i, _)| i)
        .collect()
}

/// Writes `value` at byte offset `at`.
pub fn put_f64(bytes: &mut [u8], at: usize, value: f64) {
    bytes[at..at + 8].copy_from_slice(&value.to_le_bytes());
}
