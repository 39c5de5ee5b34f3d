//! The FMI 3.0 side of the harness: the dlopened library's `fmi3*` functions and an
//! instance wrapper with a capturing logger (FMI 3.0's callback: no format arguments).

use std::ffi::{c_void, CString};
use std::sync::OnceLock;

pub use fmi3_bindings::*;

pub use super::fmi3_library::Fmi3Binding;
use super::{text, Log, Record};
use contour_fmu::framework::interface::Interface;

pub const OK3: fmi3Status = fmi3Status_fmi3OK;
pub const ERROR3: fmi3Status = fmi3Status_fmi3Error;
pub const FATAL3: fmi3Status = fmi3Status_fmi3Fatal;

pub fn lib3() -> &'static Fmi3Binding {
    static LIB: OnceLock<Fmi3Binding> = OnceLock::new();
    LIB.get_or_init(|| {
        let path = super::library_path();
        // SAFETY: our own library, loaded once and never unloaded during the tests.
        unsafe { Fmi3Binding::new(&path) }
            .unwrap_or_else(|e| panic!("cannot load {}: {e}", path.display()))
    })
}

/// FMI 3.0's log callback, into a [`Log`]. It gets the message itself: no format, no
/// arguments, no instance name (the record's `format` and `instance` stay empty).
unsafe extern "C" fn capture(
    env: fmi3InstanceEnvironment,
    status: fmi3Status,
    category: fmi3String,
    message: fmi3String,
) {
    let log = &*(env as *const Log);
    log.records.lock().unwrap().push(Record {
        status,
        category: text(category),
        format: String::new(),
        message: text(message),
        instance: String::new(),
    });
}

/// The callback that logs into the [`Log`] given as the instance environment.
pub fn log_message_callback() -> fmi3LogMessageCallback {
    Some(capture)
}

/// An FMI 3.0 Co-Simulation instance (maybe NULL: refused) with its own log; freed on
/// drop.
pub struct Instance3 {
    pub c: fmi3Instance,
    pub log: Box<Log>,
    freed: bool,
}

/// The arguments of an fmi3InstantiateCoSimulation, as an importer may get them wrong.
pub struct Instantiation<'a> {
    pub name: Option<&'a str>,
    pub token: Option<&'a str>,
    /// The resourcePath's bytes (without the NUL; any bytes, UTF-8 or not).
    pub resources: Option<&'a [u8]>,
    /// Whether the log callback is passed (FMI 3.0 allows NULL).
    pub logger: bool,
    pub logging_on: bool,
    pub event_mode_used: bool,
    pub intermediate: &'a [fmi3ValueReference],
}

impl<'a> Instantiation<'a> {
    /// The arguments of a good instantiation of the interface with `token`, logging off.
    pub fn new(name: &'a str, token: &'a str) -> Self {
        Instantiation {
            name: Some(name),
            token: Some(token),
            resources: None,
            logger: true,
            logging_on: false,
            event_mode_used: false,
            intermediate: &[],
        }
    }

    /// fmi3InstantiateCoSimulation with these arguments and a capturing logger.
    pub fn instantiate(&self) -> Instance3 {
        let log = Box::<Log>::default();
        let owned = |s: Option<&[u8]>| s.map(|s| CString::new(s).unwrap());
        let (name, token) = (
            owned(self.name.map(str::as_bytes)),
            owned(self.token.map(str::as_bytes)),
        );
        let resources = owned(self.resources);
        let p = |s: &Option<CString>| s.as_ref().map_or(std::ptr::null(), |s| s.as_ptr());
        let c = unsafe {
            lib3().fmi3InstantiateCoSimulation(
                p(&name),
                p(&token),
                p(&resources),
                false,
                self.logging_on,
                self.event_mode_used,
                false,
                self.intermediate.as_ptr(),
                self.intermediate.len(),
                &*log as *const Log as *mut c_void,
                if self.logger {
                    log_message_callback()
                } else {
                    None
                },
                None,
            )
        };
        Instance3 {
            c,
            log,
            freed: false,
        }
    }
}

/// Raw fmi3InstantiateCoSimulation with a capturing logger.
pub fn instantiate3_raw(name: &str, token: &str, resources: Option<&str>) -> Instance3 {
    Instantiation {
        resources: resources.map(str::as_bytes),
        ..Instantiation::new(name, token)
    }
    .instantiate()
}

impl Instance3 {
    pub fn new(interface: &Interface) -> Self {
        let i = instantiate3_raw("test3", &interface.instantiation_token, None);
        assert!(!i.c.is_null(), "instantiation failed: {:?}", i.messages());
        i
    }

    pub fn records(&self) -> Vec<Record> {
        self.log.records.lock().unwrap().clone()
    }

    pub fn messages(&self) -> Vec<String> {
        self.records().into_iter().map(|r| r.message).collect()
    }

    pub fn last_error(&self) -> String {
        let records = self.records();
        let last = records.into_iter().rev().find(|r| r.status == ERROR3);
        last.map(|r| r.message).unwrap_or_default()
    }

    pub fn enter_init(&self, start: f64, stop: Option<f64>) -> fmi3Status {
        unsafe {
            lib3().fmi3EnterInitializationMode(
                self.c,
                false,
                0.0,
                start,
                stop.is_some(),
                stop.unwrap_or(0.0),
            )
        }
    }

    pub fn exit_init(&self) -> fmi3Status {
        unsafe { lib3().fmi3ExitInitializationMode(self.c) }
    }

    pub fn start(&self) {
        assert_eq!(self.enter_init(0.0, None), OK3, "{:?}", self.messages());
        assert_eq!(self.exit_init(), OK3, "{:?}", self.messages());
    }

    /// fmi3DoStep; the status and the lastSuccessfulTime it reported (NaN if it wrote
    /// none). A step that succeeds reports no event, no early return, no termination.
    pub fn step(&self, t: f64, h: f64) -> (fmi3Status, f64) {
        let (mut event, mut terminate, mut early, mut last) = (true, true, true, f64::NAN);
        let status = unsafe {
            lib3().fmi3DoStep(
                self.c,
                t,
                h,
                false,
                &mut event,
                &mut terminate,
                &mut early,
                &mut last,
            )
        };
        if status == OK3 {
            assert!(!event && !terminate && !early, "no events, no early return");
        }
        (status, last)
    }

    pub fn get_float64(&self, vrs: &[u32]) -> (fmi3Status, Vec<f64>) {
        let mut out = vec![f64::NAN; vrs.len()];
        let status = unsafe {
            lib3().fmi3GetFloat64(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr(), out.len())
        };
        (status, out)
    }

    pub fn set_float64(&self, vrs: &[u32], values: &[f64]) -> fmi3Status {
        unsafe {
            lib3().fmi3SetFloat64(
                self.c,
                vrs.as_ptr(),
                vrs.len(),
                values.as_ptr(),
                values.len(),
            )
        }
    }

    /// Serializes the instance's current state.
    pub fn serialize(&self) -> Vec<u8> {
        let mut state: fmi3FMUState = std::ptr::null_mut();
        let lib = lib3();
        unsafe {
            assert_eq!(lib.fmi3GetFMUState(self.c, &mut state), OK3);
            let mut size = 0;
            assert_eq!(
                lib.fmi3SerializedFMUStateSize(self.c, state, &mut size),
                OK3
            );
            let mut bytes = vec![0u8; size];
            assert_eq!(
                lib.fmi3SerializeFMUState(self.c, state, bytes.as_mut_ptr(), size),
                OK3
            );
            assert_eq!(lib.fmi3FreeFMUState(self.c, &mut state), OK3);
            assert!(state.is_null());
            bytes
        }
    }

    /// Deserializes `bytes` and sets the instance to that state.
    pub fn restore(&self, bytes: &[u8]) -> fmi3Status {
        let mut state: fmi3FMUState = std::ptr::null_mut();
        let lib = lib3();
        unsafe {
            let status =
                lib.fmi3DeserializeFMUState(self.c, bytes.as_ptr(), bytes.len(), &mut state);
            if status != OK3 {
                return status;
            }
            let status = lib.fmi3SetFMUState(self.c, state);
            assert_eq!(lib.fmi3FreeFMUState(self.c, &mut state), OK3);
            status
        }
    }

    /// fmi3FreeInstance, once (the handle stays as it was, now stale).
    pub fn free(&mut self) {
        if !self.freed && !self.c.is_null() {
            unsafe { lib3().fmi3FreeInstance(self.c) };
        }
        self.freed = true;
    }
}

impl Drop for Instance3 {
    fn drop(&mut self) {
        self.free();
    }
}
