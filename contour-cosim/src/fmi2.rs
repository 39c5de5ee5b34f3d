//! The FMI 2.0 C ABI, seen from the importer's side: opens an FMU's shared library, looks up
//! its fmi2* functions and calls them. The only `unsafe` of the crate; everything above it
//! works with [`Library`] and [`Instance`], whose methods are safe.
//!
//! Types and function typedefs are the ones our FMUs are built against
//! (the `fmi2-bindings` crate, generated from the standard's headers).

// The status constants keep the standard's C names.
#![allow(non_upper_case_globals)]

use std::ffi::{c_char, c_void, CStr, CString};
use std::path::{Path, PathBuf};
use std::ptr::NonNull;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use fmi2_bindings::*;

use crate::Error;

/// The platform folder of `binaries/` this build loads from: FMI 2.0's names (section
/// 2.1) for x86-64, FMI 3.0's platform tuple for 64-bit ARM Linux (which FMI 2.0.4
/// allows and 2.0 names none for).
pub const PLATFORM: &str = if cfg!(all(target_os = "linux", target_arch = "x86_64")) {
    "linux64"
} else if cfg!(all(target_os = "linux", target_arch = "aarch64")) {
    "aarch64-linux"
} else if cfg!(all(target_os = "macos", target_arch = "x86_64")) {
    "darwin64"
} else if cfg!(all(target_os = "macos", target_arch = "aarch64")) {
    "aarch64-darwin"
} else if cfg!(all(windows, target_arch = "x86_64")) {
    "win64"
} else {
    "unsupported"
};

const LIBRARY_SUFFIX: &str = std::env::consts::DLL_SUFFIX;

/// The fmi2* functions a Co-Simulation master calls; an FMU must export them all.
struct Api {
    instantiate: unsafe extern "C" fn(
        fmi2String,
        fmi2Type,
        fmi2String,
        fmi2String,
        *const fmi2CallbackFunctions,
        fmi2Boolean,
        fmi2Boolean,
    ) -> fmi2Component,
    free_instance: unsafe extern "C" fn(fmi2Component),
    setup_experiment: unsafe extern "C" fn(
        fmi2Component,
        fmi2Boolean,
        fmi2Real,
        fmi2Real,
        fmi2Boolean,
        fmi2Real,
    ) -> fmi2Status,
    enter_initialization_mode: unsafe extern "C" fn(fmi2Component) -> fmi2Status,
    exit_initialization_mode: unsafe extern "C" fn(fmi2Component) -> fmi2Status,
    terminate: unsafe extern "C" fn(fmi2Component) -> fmi2Status,
    reset: unsafe extern "C" fn(fmi2Component) -> fmi2Status,
    get_real: unsafe extern "C" fn(
        fmi2Component,
        *const fmi2ValueReference,
        usize,
        *mut fmi2Real,
    ) -> fmi2Status,
    get_integer: unsafe extern "C" fn(
        fmi2Component,
        *const fmi2ValueReference,
        usize,
        *mut fmi2Integer,
    ) -> fmi2Status,
    get_boolean: unsafe extern "C" fn(
        fmi2Component,
        *const fmi2ValueReference,
        usize,
        *mut fmi2Boolean,
    ) -> fmi2Status,
    get_string: unsafe extern "C" fn(
        fmi2Component,
        *const fmi2ValueReference,
        usize,
        *mut fmi2String,
    ) -> fmi2Status,
    set_real: unsafe extern "C" fn(
        fmi2Component,
        *const fmi2ValueReference,
        usize,
        *const fmi2Real,
    ) -> fmi2Status,
    set_integer: unsafe extern "C" fn(
        fmi2Component,
        *const fmi2ValueReference,
        usize,
        *const fmi2Integer,
    ) -> fmi2Status,
    set_boolean: unsafe extern "C" fn(
        fmi2Component,
        *const fmi2ValueReference,
        usize,
        *const fmi2Boolean,
    ) -> fmi2Status,
    set_string: unsafe extern "C" fn(
        fmi2Component,
        *const fmi2ValueReference,
        usize,
        *const fmi2String,
    ) -> fmi2Status,
    do_step: unsafe extern "C" fn(fmi2Component, fmi2Real, fmi2Real, fmi2Boolean) -> fmi2Status,
}

/// An FMU's shared library, open. It stays loaded while an [`Instance`] of it lives.
pub struct Library {
    api: Api,
    /// Set when any instance's call returned fmi2Fatal: FMI 2.0 then allows no further
    /// call into the FMU, for any of its instances.
    fatal: AtomicBool,
    // Last: the functions above point into it.
    _library: libloading::Library,
}

impl Library {
    /// Opens `binaries/<platform>/<model_identifier>.so` (or .dylib, .dll) of the FMU
    /// unpacked in `folder`; `fmu` names the FMU in messages.
    /// The library's initialisers run while `activity` counts a call under way.
    pub fn open(
        folder: &Path,
        model_identifier: &str,
        fmu: &Path,
        activity: &Activity,
    ) -> Result<Library, Error> {
        let binaries = folder.join("binaries");
        let file = binaries
            .join(PLATFORM)
            .join(format!("{model_identifier}{LIBRARY_SUFFIX}"));
        if !file.is_file() {
            let mut platforms: Vec<String> = std::fs::read_dir(&binaries)
                .map(|entries| {
                    entries
                        .flatten()
                        .map(|e| e.file_name().to_string_lossy().into_owned())
                        .collect()
                })
                .unwrap_or_default();
            platforms.sort();
            let has = if platforms.is_empty() {
                "none".to_string()
            } else {
                platforms.join(", ")
            };
            return Err(Error::Refused(format!(
                "{}: no binary for this platform (binaries/{PLATFORM}/{model_identifier}{LIBRARY_SUFFIX}); \
                 its binaries are for: {has}",
                fmu.display()
            )));
        }
        // SAFETY: loading a library runs its initialisers; an FMU's library is code the
        // user asked to run, which is what a co-simulation master is for.
        activity.bump();
        let opened = unsafe { libloading::Library::new(&file) };
        activity.bump();
        let library = opened.map_err(|e| {
            // pythonfmu's binary takes Python's symbols from the process it is loaded into.
            let text = e.to_string();
            let hint = if text.contains("undefined symbol: _Py")
                || text.contains("undefined symbol: Py")
            {
                " (a pythonfmu FMU: load libpython first, LD_PRELOAD=<its libpython3.x.so>, with \
                 PYTHONPATH naming the site-packages that hold pythonfmu; \
                 contour_fmu.engines.native.pythonfmu_environment() gives both)"
            } else {
                ""
            };
            Error::Refused(format!(
                "{}: cannot load {}: {text}{hint}",
                fmu.display(),
                file.display()
            ))
        })?;
        let missing = |name: &str, e: libloading::Error| {
            Error::Refused(format!(
                "{}: its library does not export {name} ({e})",
                fmu.display()
            ))
        };
        macro_rules! function {
            ($name:literal, $typedef:ty) => {{
                // SAFETY: the symbol's type is the standard's typedef for that function.
                let symbol = unsafe { library.get::<$typedef>(concat!($name, "\0").as_bytes()) }
                    .map_err(|e| missing($name, e))?;
                (*symbol).ok_or_else(|| {
                    Error::Refused(format!("{}: {} is a null symbol", fmu.display(), $name))
                })?
            }};
        }
        let api = Api {
            instantiate: function!("fmi2Instantiate", fmi2InstantiateTYPE),
            free_instance: function!("fmi2FreeInstance", fmi2FreeInstanceTYPE),
            setup_experiment: function!("fmi2SetupExperiment", fmi2SetupExperimentTYPE),
            enter_initialization_mode: function!(
                "fmi2EnterInitializationMode",
                fmi2EnterInitializationModeTYPE
            ),
            exit_initialization_mode: function!(
                "fmi2ExitInitializationMode",
                fmi2ExitInitializationModeTYPE
            ),
            terminate: function!("fmi2Terminate", fmi2TerminateTYPE),
            reset: function!("fmi2Reset", fmi2ResetTYPE),
            get_real: function!("fmi2GetReal", fmi2GetRealTYPE),
            get_integer: function!("fmi2GetInteger", fmi2GetIntegerTYPE),
            get_boolean: function!("fmi2GetBoolean", fmi2GetBooleanTYPE),
            get_string: function!("fmi2GetString", fmi2GetStringTYPE),
            set_real: function!("fmi2SetReal", fmi2SetRealTYPE),
            set_integer: function!("fmi2SetInteger", fmi2SetIntegerTYPE),
            set_boolean: function!("fmi2SetBoolean", fmi2SetBooleanTYPE),
            set_string: function!("fmi2SetString", fmi2SetStringTYPE),
            do_step: function!("fmi2DoStep", fmi2DoStepTYPE),
        };
        Ok(Library {
            api,
            fatal: AtomicBool::new(false),
            _library: library,
        })
    }
}

/// Counts the FMU calls made through the instances that share it: odd while a call is
/// under way. A watchdog that sees the same odd count for too long knows a call hangs.
#[derive(Default)]
pub struct Activity(AtomicU64);

impl Activity {
    pub fn count(&self) -> u64 {
        self.0.load(Ordering::Relaxed)
    }
    pub(crate) fn bump(&self) {
        self.0.fetch_add(1, Ordering::Relaxed);
    }
}

/// A message an FMU logged.
#[derive(Clone, Debug)]
pub struct Message {
    pub status: &'static str,
    pub category: String,
    pub text: String,
}

/// Where an instance's logger callback puts its messages (the callbacks' component
/// environment points here). `receive` comes first: c/logger.c calls it with the
/// formatted message.
#[repr(C)]
struct LogSink {
    receive: unsafe extern "C" fn(*const LogSink, fmi2String, fmi2Status, fmi2String, fmi2String),
    messages: Mutex<Vec<Message>>,
    echo: bool,
}

/// How many of an instance's latest messages are kept for error reports.
const KEPT_MESSAGES: usize = 64;

extern "C" {
    /// c/logger.c: formats the FMU's printf-style message, then calls the sink's `receive`.
    fn contour_cosim_logger(
        environment: fmi2ComponentEnvironment,
        instance_name: fmi2String,
        status: fmi2Status,
        category: fmi2String,
        message: fmi2String,
        ...
    );
}

unsafe extern "C" fn receive(
    sink: *const LogSink,
    instance_name: fmi2String,
    status: fmi2Status,
    category: fmi2String,
    text: fmi2String,
) {
    let text_of = |s: fmi2String| {
        if s.is_null() {
            String::new()
        } else {
            CStr::from_ptr(s).to_string_lossy().into_owned()
        }
    };
    // A panic must not unwind into the FMU's C frames.
    let _ = std::panic::catch_unwind(|| {
        let Some(sink) = sink.as_ref() else { return };
        let message = Message {
            status: status_name(status),
            category: text_of(category),
            text: text_of(text),
        };
        if sink.echo {
            eprintln!(
                "[{}] {} {}: {}",
                message.status,
                text_of(instance_name),
                message.category,
                message.text
            );
        }
        if let Ok(mut messages) = sink.messages.lock() {
            if messages.len() == KEPT_MESSAGES {
                messages.remove(0);
            }
            messages.push(message);
        }
    });
}

fn status_name(status: fmi2Status) -> &'static str {
    match status {
        fmi2Status_fmi2OK => "OK",
        fmi2Status_fmi2Warning => "Warning",
        fmi2Status_fmi2Discard => "Discard",
        fmi2Status_fmi2Error => "Error",
        fmi2Status_fmi2Fatal => "Fatal",
        fmi2Status_fmi2Pending => "Pending",
        _ => "unknown status",
    }
}

/// An FMU call that did not return fmi2OK or fmi2Warning.
#[derive(Clone, Debug)]
pub struct CallFailed {
    pub call: &'static str,
    pub status: &'static str,
}

/// One instance of an FMU, Co-Simulation.
pub struct Instance {
    component: NonNull<c_void>,
    library: Arc<Library>,
    activity: Arc<Activity>,
    // The FMU keeps pointers to both for its lifetime: owned as raw pointers (from
    // Box::into_raw), freed after fmi2FreeInstance, never moved meanwhile.
    callbacks: NonNull<fmi2CallbackFunctions>,
    sink: NonNull<LogSink>,
}

// SAFETY: FMI 2.0 lets an instance be called from any thread, one call at a time; an
// `Instance` is only called through `&mut self`, and `&self` reaches only the sink's
// mutex, never from two threads at once.
unsafe impl Send for Instance {}

impl Instance {
    /// fmi2Instantiate (Co-Simulation, not visible). `resources` is the FMU's unpacked
    /// resources folder; `echo` prints every message the FMU logs on stderr.
    pub fn new(
        library: Arc<Library>,
        name: &str,
        guid: &str,
        resources: &Path,
        activity: Arc<Activity>,
        echo: bool,
    ) -> Result<Instance, String> {
        let c_name = CString::new(name).map_err(|_| "the instance name holds a NUL".to_string())?;
        let c_guid = CString::new(guid).map_err(|_| "the GUID holds a NUL".to_string())?;
        let c_uri = CString::new(file_uri(resources))
            .map_err(|_| "the resource path holds a NUL".to_string())?;
        if library.fatal.load(Ordering::Relaxed) {
            return Err("not instantiated: a call of this FMU returned Fatal earlier".into());
        }
        let sink = NonNull::from(Box::leak(Box::new(LogSink {
            receive,
            messages: Mutex::new(Vec::new()),
            echo,
        })));
        let callbacks = NonNull::from(Box::leak(Box::new(fmi2CallbackFunctions {
            logger: Some(contour_cosim_logger),
            allocateMemory: Some(libc::calloc),
            freeMemory: Some(libc::free),
            stepFinished: None,
            componentEnvironment: sink.as_ptr() as *mut c_void,
        })));
        activity.bump();
        // SAFETY: every pointer is valid for the call; callbacks and sink outlive the
        // instance (freed after fmi2FreeInstance).
        let component = unsafe {
            (library.api.instantiate)(
                c_name.as_ptr(),
                fmi2Type_fmi2CoSimulation,
                c_guid.as_ptr(),
                c_uri.as_ptr(),
                callbacks.as_ptr(),
                fmi2False as fmi2Boolean,
                fmi2False as fmi2Boolean,
            )
        };
        activity.bump();
        // SAFETY: both came from Box::leak above and nothing else owns them.
        let free_both = || unsafe {
            drop(Box::from_raw(callbacks.as_ptr()));
            drop(Box::from_raw(sink.as_ptr()));
        };
        match NonNull::new(component) {
            Some(component) => Ok(Instance {
                component,
                library,
                activity,
                callbacks,
                sink,
            }),
            None => {
                // SAFETY: the FMU made no instance, so it keeps no pointer to the sink.
                let said = unsafe { sink.as_ref() }
                    .messages
                    .lock()
                    .map(|m| {
                        m.iter()
                            .map(|m| m.text.clone())
                            .collect::<Vec<_>>()
                            .join("; ")
                    })
                    .unwrap_or_default();
                free_both();
                Err(format!(
                    "fmi2Instantiate returned NULL{}",
                    if said.is_empty() {
                        String::new()
                    } else {
                        format!(": {said}")
                    }
                ))
            }
        }
    }

    fn sink(&self) -> &LogSink {
        // SAFETY: owned by this instance until its drop; the FMU only reads it through
        // the logger callback, which takes the mutex.
        unsafe { self.sink.as_ref() }
    }

    fn fatal(&self) -> bool {
        self.library.fatal.load(Ordering::Relaxed)
    }

    /// The latest messages the FMU logged (at most 64), oldest first.
    pub fn messages(&self) -> Vec<Message> {
        self.sink()
            .messages
            .lock()
            .map(|m| m.clone())
            .unwrap_or_default()
    }

    pub fn clear_messages(&self) {
        if let Ok(mut m) = self.sink().messages.lock() {
            m.clear();
        }
    }

    fn checked(
        &mut self,
        call: &'static str,
        run: impl FnOnce(&Api, fmi2Component) -> fmi2Status,
    ) -> Result<(), CallFailed> {
        if self.fatal() {
            return Err(CallFailed {
                call,
                status: "not called: a call of this FMU returned Fatal earlier",
            });
        }
        self.activity.bump();
        let status = run(&self.library.api, self.component.as_ptr());
        self.activity.bump();
        match status {
            fmi2Status_fmi2OK | fmi2Status_fmi2Warning => Ok(()),
            other => {
                if other == fmi2Status_fmi2Fatal {
                    self.library.fatal.store(true, Ordering::Relaxed);
                }
                Err(CallFailed {
                    call,
                    status: status_name(other),
                })
            }
        }
    }

    pub fn setup_experiment(&mut self, start: f64, stop: Option<f64>) -> Result<(), CallFailed> {
        let (defined, stop) = match stop {
            Some(stop) => (fmi2True, stop),
            None => (fmi2False, 0.0),
        };
        // SAFETY: a live component; plain values.
        self.checked("fmi2SetupExperiment", |api, c| unsafe {
            (api.setup_experiment)(
                c,
                fmi2False as fmi2Boolean,
                0.0,
                start,
                defined as fmi2Boolean,
                stop,
            )
        })
    }

    pub fn enter_initialization_mode(&mut self) -> Result<(), CallFailed> {
        // SAFETY: a live component.
        self.checked("fmi2EnterInitializationMode", |api, c| unsafe {
            (api.enter_initialization_mode)(c)
        })
    }

    pub fn exit_initialization_mode(&mut self) -> Result<(), CallFailed> {
        // SAFETY: a live component.
        self.checked("fmi2ExitInitializationMode", |api, c| unsafe {
            (api.exit_initialization_mode)(c)
        })
    }

    pub fn terminate(&mut self) -> Result<(), CallFailed> {
        // SAFETY: a live component.
        self.checked("fmi2Terminate", |api, c| unsafe { (api.terminate)(c) })
    }

    pub fn reset(&mut self) -> Result<(), CallFailed> {
        // SAFETY: a live component.
        self.checked("fmi2Reset", |api, c| unsafe { (api.reset)(c) })
    }

    pub fn do_step(&mut self, time: f64, step: f64) -> Result<(), CallFailed> {
        // SAFETY: a live component; plain values. noSetFMUStatePriorToCurrentPoint: this
        // master never goes back.
        self.checked("fmi2DoStep", |api, c| unsafe {
            (api.do_step)(c, time, step, fmi2True as fmi2Boolean)
        })
    }

    pub fn get_real(&mut self, vrs: &[u32], values: &mut [f64]) -> Result<(), CallFailed> {
        assert_eq!(vrs.len(), values.len());
        // SAFETY: both slices hold vrs.len() elements.
        self.checked("fmi2GetReal", |api, c| unsafe {
            (api.get_real)(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr())
        })
    }

    pub fn set_real(&mut self, vrs: &[u32], values: &[f64]) -> Result<(), CallFailed> {
        assert_eq!(vrs.len(), values.len());
        // SAFETY: both slices hold vrs.len() elements.
        self.checked("fmi2SetReal", |api, c| unsafe {
            (api.set_real)(c, vrs.as_ptr(), vrs.len(), values.as_ptr())
        })
    }

    pub fn get_integer(&mut self, vrs: &[u32], values: &mut [i32]) -> Result<(), CallFailed> {
        assert_eq!(vrs.len(), values.len());
        // SAFETY: both slices hold vrs.len() elements.
        self.checked("fmi2GetInteger", |api, c| unsafe {
            (api.get_integer)(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr())
        })
    }

    pub fn set_integer(&mut self, vrs: &[u32], values: &[i32]) -> Result<(), CallFailed> {
        assert_eq!(vrs.len(), values.len());
        // SAFETY: both slices hold vrs.len() elements.
        self.checked("fmi2SetInteger", |api, c| unsafe {
            (api.set_integer)(c, vrs.as_ptr(), vrs.len(), values.as_ptr())
        })
    }

    /// FMI booleans are C ints: 0 is false, anything else true.
    pub fn get_boolean(&mut self, vrs: &[u32], values: &mut [i32]) -> Result<(), CallFailed> {
        assert_eq!(vrs.len(), values.len());
        // SAFETY: both slices hold vrs.len() elements.
        self.checked("fmi2GetBoolean", |api, c| unsafe {
            (api.get_boolean)(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr())
        })
    }

    pub fn set_boolean(&mut self, vrs: &[u32], values: &[i32]) -> Result<(), CallFailed> {
        assert_eq!(vrs.len(), values.len());
        // SAFETY: both slices hold vrs.len() elements.
        self.checked("fmi2SetBoolean", |api, c| unsafe {
            (api.set_boolean)(c, vrs.as_ptr(), vrs.len(), values.as_ptr())
        })
    }

    pub fn get_string(&mut self, vr: u32) -> Result<String, CallFailed> {
        let mut value: fmi2String = std::ptr::null();
        // SAFETY: one value reference, one pointer to fill.
        self.checked("fmi2GetString", |api, c| unsafe {
            (api.get_string)(c, &vr, 1, &mut value)
        })?;
        // SAFETY: the FMU's string stays valid until its next call; copied at once.
        Ok(if value.is_null() {
            String::new()
        } else {
            unsafe { CStr::from_ptr(value) }
                .to_string_lossy()
                .into_owned()
        })
    }

    pub fn set_string(&mut self, vr: u32, value: &str) -> Result<(), CallFailed> {
        let Ok(text) = CString::new(value) else {
            return Err(CallFailed {
                call: "fmi2SetString",
                status: "not called: the string holds a NUL",
            });
        };
        let pointer: *const c_char = text.as_ptr();
        // SAFETY: one value reference, one valid C string.
        self.checked("fmi2SetString", |api, c| unsafe {
            (api.set_string)(c, &vr, 1, &pointer)
        })
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        if self.fatal() {
            // After fmi2Fatal the standard allows no further call: the instance is
            // leaked with everything it may still point to, its library included.
            std::mem::forget(self.library.clone());
            return;
        }
        self.activity.bump();
        // SAFETY: a live component, freed once; then the FMU holds no pointer to the
        // callbacks or the sink, which came from Box::leak in `new`.
        unsafe {
            (self.library.api.free_instance)(self.component.as_ptr());
            drop(Box::from_raw(self.callbacks.as_ptr()));
            drop(Box::from_raw(self.sink.as_ptr()));
        }
        self.activity.bump();
    }
}

/// Whether a call of this FMU returned fmi2Fatal: the process must not call it again.
pub fn is_fatal(library: &Library) -> bool {
    library.fatal.load(Ordering::Relaxed)
}

/// Gives this process's standard output to its caller alone: returns a file writing to
/// what was file descriptor 1, which then points at standard error. What an FMU prints
/// (a C printf, a pythonfmu print) goes to standard error and cannot corrupt results
/// written to the returned file. On Windows descriptor 1 is the C runtime's, which an
/// FMU's printf writes to; the results go to its duplicate's Windows handle.
pub fn private_stdout() -> std::io::Result<std::fs::File> {
    // SAFETY: dup and dup2 (the C runtime's _dup and _dup2 on Windows) on the process's
    // own standard descriptors; the duplicate is owned by the returned File alone (on
    // Windows its descriptor is never closed, so the handle is not closed twice).
    unsafe {
        // Close-on-exec on Unix: a process an FMU starts must not hold the results'
        // pipe open (its reader would wait for an end that never comes).
        #[cfg(unix)]
        let duplicate = libc::fcntl(1, libc::F_DUPFD_CLOEXEC, 0);
        #[cfg(windows)]
        let duplicate = libc::dup(1);
        if duplicate < 0 || libc::dup2(2, 1) < 0 {
            return Err(std::io::Error::last_os_error());
        }
        #[cfg(unix)]
        {
            use std::os::fd::FromRawFd;
            Ok(std::fs::File::from_raw_fd(duplicate))
        }
        #[cfg(windows)]
        {
            use std::os::windows::io::{FromRawHandle, RawHandle};
            let handle = libc::get_osfhandle(duplicate);
            if handle == -1 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(std::fs::File::from_raw_handle(handle as RawHandle))
        }
    }
}

/// Ends the process at once with `status`, running no exit handler or library destructor:
/// a hung FMU call still holds whatever locks they might need.
pub fn abandon_process(status: i32) -> ! {
    // SAFETY: _exit is async-signal-safe and never returns.
    unsafe { libc::_exit(status) }
}

/// The `file:` URI of a folder (RFC 8089), as fmuResourceLocation wants it: without a
/// trailing slash, as FMPy passes it.
fn file_uri(folder: &Path) -> String {
    let absolute: PathBuf = std::path::absolute(folder).unwrap_or_else(|_| folder.to_path_buf());
    let mut uri = String::from("file://");
    // A Windows path starts with its drive: file:///C:/...
    if !absolute.to_string_lossy().starts_with(['/', '\\']) {
        uri.push('/');
    }
    for byte in absolute.to_string_lossy().bytes() {
        match byte {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'/' | b'-' | b'_' | b'.' | b'~' | b':' => {
                uri.push(byte as char)
            }
            b'\\' => uri.push('/'),
            other => uri.push_str(&format!("%{other:02X}")),
        }
    }
    uri
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resource_uris_escape_what_a_uri_cannot_hold() {
        assert_eq!(
            file_uri(Path::new("/tmp/a b/r%s")),
            "file:///tmp/a%20b/r%25s"
        );
    }
}
