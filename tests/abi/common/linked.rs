//! The library's exported `fmi2*` functions (and the `fmi3*` ones of a step round) linked
//! statically from the rlib instead of
//! dlopened (as `super::lib()` does): the calls stay inside the test or bench binary, so
//! its global allocator sees every allocation they make and a timing sees no PLT stub of
//! a second copy of the library. Plus what an instance with logging off needs around
//! them: the smallest callbacks, the model by identifier, value references by name, and a
//! started instance.
//!
//! Shared by the tests (as `common::linked`) and by benches/fmu_abi.rs (through
//! `#[path]`), so it uses nothing else of `common`.
#![allow(dead_code)]

use std::ffi::{c_char, CStr};

use contour_fmu::framework::interface::{Interface, UnitSystem};
use contour_fmu::framework::model::ModelInfo;
use contour_fmu::models;
use fmi2_bindings::{
    fmi2Boolean, fmi2Byte, fmi2CallbackFunctions, fmi2CallbackLogger, fmi2Component,
    fmi2ComponentEnvironment, fmi2FMUstate, fmi2Integer, fmi2Real, fmi2Status, fmi2String,
    fmi2Type, fmi2Type_fmi2CoSimulation, fmi2ValueReference,
};
use fmi3_bindings::{
    fmi3Boolean, fmi3Float64, fmi3Instance, fmi3InstanceEnvironment,
    fmi3IntermediateUpdateCallback, fmi3LogMessageCallback, fmi3Status, fmi3String,
    fmi3ValueReference,
};

extern "C" {
    pub fn fmi2Instantiate(
        instance_name: fmi2String,
        fmu_type: fmi2Type,
        guid: fmi2String,
        resource_location: fmi2String,
        functions: *const fmi2CallbackFunctions,
        visible: fmi2Boolean,
        logging_on: fmi2Boolean,
    ) -> fmi2Component;
    pub fn fmi2SetupExperiment(
        c: fmi2Component,
        tolerance_defined: fmi2Boolean,
        tolerance: fmi2Real,
        start_time: fmi2Real,
        stop_time_defined: fmi2Boolean,
        stop_time: fmi2Real,
    ) -> fmi2Status;
    pub fn fmi2SetInteger(
        c: fmi2Component,
        vr: *const fmi2ValueReference,
        nvr: usize,
        value: *const fmi2Integer,
    ) -> fmi2Status;
    pub fn fmi2SetString(
        c: fmi2Component,
        vr: *const fmi2ValueReference,
        nvr: usize,
        value: *const fmi2String,
    ) -> fmi2Status;
    pub fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status;
    pub fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status;
    pub fn fmi2DoStep(
        c: fmi2Component,
        current_communication_point: fmi2Real,
        communication_step_size: fmi2Real,
        no_set_fmu_state_prior: fmi2Boolean,
    ) -> fmi2Status;
    pub fn fmi2GetReal(
        c: fmi2Component,
        vr: *const fmi2ValueReference,
        nvr: usize,
        value: *mut fmi2Real,
    ) -> fmi2Status;
    pub fn fmi2SetReal(
        c: fmi2Component,
        vr: *const fmi2ValueReference,
        nvr: usize,
        value: *const fmi2Real,
    ) -> fmi2Status;
    pub fn fmi2GetFMUstate(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status;
    pub fn fmi2SetFMUstate(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status;
    pub fn fmi2FreeFMUstate(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status;
    pub fn fmi2SerializedFMUstateSize(
        c: fmi2Component,
        state: fmi2FMUstate,
        size: *mut usize,
    ) -> fmi2Status;
    pub fn fmi2SerializeFMUstate(
        c: fmi2Component,
        state: fmi2FMUstate,
        bytes: *mut fmi2Byte,
        size: usize,
    ) -> fmi2Status;
    pub fn fmi2DeSerializeFMUstate(
        c: fmi2Component,
        bytes: *const fmi2Byte,
        size: usize,
        state: *mut fmi2FMUstate,
    ) -> fmi2Status;
    pub fn fmi2Terminate(c: fmi2Component) -> fmi2Status;
    pub fn fmi2FreeInstance(c: fmi2Component);
}

// The FMI 3.0 functions of a step round, the same way.
extern "C" {
    pub fn fmi3InstantiateCoSimulation(
        instanceName: fmi3String,
        instantiationToken: fmi3String,
        resourcePath: fmi3String,
        visible: fmi3Boolean,
        loggingOn: fmi3Boolean,
        eventModeUsed: fmi3Boolean,
        earlyReturnAllowed: fmi3Boolean,
        requiredIntermediateVariables: *const fmi3ValueReference,
        nRequiredIntermediateVariables: usize,
        instanceEnvironment: fmi3InstanceEnvironment,
        logMessage: fmi3LogMessageCallback,
        intermediateUpdate: fmi3IntermediateUpdateCallback,
    ) -> fmi3Instance;
    pub fn fmi3EnterInitializationMode(
        instance: fmi3Instance,
        toleranceDefined: fmi3Boolean,
        tolerance: fmi3Float64,
        startTime: fmi3Float64,
        stopTimeDefined: fmi3Boolean,
        stopTime: fmi3Float64,
    ) -> fmi3Status;
    pub fn fmi3ExitInitializationMode(instance: fmi3Instance) -> fmi3Status;
    pub fn fmi3SetFloat64(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *const fmi3Float64,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3GetFloat64(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *mut fmi3Float64,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3DoStep(
        instance: fmi3Instance,
        currentCommunicationPoint: fmi3Float64,
        communicationStepSize: fmi3Float64,
        noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
        eventHandlingNeeded: *mut fmi3Boolean,
        terminateSimulation: *mut fmi3Boolean,
        earlyReturn: *mut fmi3Boolean,
        lastSuccessfulTime: *mut fmi3Float64,
    ) -> fmi3Status;
    pub fn fmi3FreeInstance(instance: fmi3Instance);
}

/// A logger that drops every message. Declared with the five fixed parameters of the C
/// prototype only: on the C ABIs of the supported targets the caller passes (and cleans
/// up) the variadic arguments, which the callee may ignore.
unsafe extern "C" fn drop_message(
    _environment: fmi2ComponentEnvironment,
    _instance: fmi2String,
    _status: fmi2Status,
    _category: fmi2String,
    _format: fmi2String,
) {
}

/// Callbacks for an instance with logging off and no interest in its messages: the
/// library never calls `allocateMemory`/`freeMemory`, but a conforming importer passes
/// them, so they are C's `calloc` and `free`.
pub fn quiet_callbacks() -> fmi2CallbackFunctions {
    type Fixed = unsafe extern "C" fn(
        fmi2ComponentEnvironment,
        fmi2String,
        fmi2Status,
        fmi2String,
        fmi2String,
    );
    type Variadic = unsafe extern "C" fn(
        fmi2ComponentEnvironment,
        fmi2String,
        fmi2Status,
        fmi2String,
        fmi2String,
        ...
    );
    // SAFETY: the same function pointer under its C prototype's variadic type; calling a
    // function that ignores the variadic arguments through it is sound (see
    // `drop_message`).
    let logger: fmi2CallbackLogger =
        Some(unsafe { std::mem::transmute::<Fixed, Variadic>(drop_message) });
    fmi2CallbackFunctions {
        logger,
        allocateMemory: Some(libc::calloc),
        freeMemory: Some(libc::free),
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    }
}

/// The model served under `identifier`.
pub fn model(identifier: &str) -> &'static ModelInfo {
    models::all()
        .into_iter()
        .find(|m| m.identifier == identifier)
        .unwrap_or_else(|| panic!("no model {identifier}"))
}

/// The value references of `names` in `model`, in that order.
pub fn vrs(model: &ModelInfo, names: &[&str]) -> Vec<fmi2ValueReference> {
    names
        .iter()
        .map(|name| {
            let v = model
                .variables
                .iter()
                .find(|v| v.name == *name)
                .unwrap_or_else(|| panic!("{} has no variable {name}", model.identifier));
            v.vr as fmi2ValueReference
        })
        .collect()
}

/// A parameter value for [`instantiate_configured`].
pub enum Start<'a> {
    Real(f64),
    Integer(i32),
    String(&'a str),
}

/// A Co-Simulation instance of `model`, logging off, set up at t = 0 without a stop time
/// and initialized: ready for `fmi2DoStep(c, 0.0, …)`.
///
/// # Safety
/// `functions` stays valid until the instance is freed with `fmi2FreeInstance`.
pub unsafe fn instantiate_started(
    model: &ModelInfo,
    name: &CStr,
    functions: *const fmi2CallbackFunctions,
) -> fmi2Component {
    // SAFETY: as the caller promises.
    unsafe { instantiate_configured(model, name, functions, &[]) }
}

/// [`instantiate_started`] with `parameters` set in initialization mode.
///
/// # Safety
/// As [`instantiate_started`].
pub unsafe fn instantiate_configured(
    model: &ModelInfo,
    name: &CStr,
    functions: *const fmi2CallbackFunctions,
    parameters: &[(&str, Start)],
) -> fmi2Component {
    let interface = models::interface(model, UnitSystem::Millimetre);
    // SAFETY: as the caller promises.
    unsafe { instantiate_interface(interface, name, functions, parameters) }
}

/// An instance of one of a model's interfaces with the callbacks it logs through, freed
/// (the instance first) when dropped.
pub struct OwnedInstance {
    pub c: fmi2Component,
    _functions: Box<fmi2CallbackFunctions>,
}

impl OwnedInstance {
    /// [`instantiate_interface`] with quiet callbacks.
    pub fn new(interface: &Interface, parameters: &[(&str, Start)]) -> Self {
        let functions = Box::new(quiet_callbacks());
        let name = std::ffi::CString::new(format!(
            "{}-{}",
            interface.model.identifier,
            interface.units.name()
        ))
        .expect("a name without NUL");
        // SAFETY: the callbacks are boxed in the returned value, which frees the instance
        // before them.
        let c = unsafe { instantiate_interface(interface, &name, &*functions, parameters) };
        OwnedInstance {
            c,
            _functions: functions,
        }
    }
}

impl Drop for OwnedInstance {
    fn drop(&mut self) {
        // SAFETY: a live instance, freed once; nothing uses it after this.
        unsafe { fmi2FreeInstance(self.c) };
    }
}

/// [`instantiate_configured`] for one of the model's interfaces (its GUID; parameter
/// values in its units).
///
/// # Safety
/// As [`instantiate_started`].
pub unsafe fn instantiate_interface(
    interface: &Interface,
    name: &CStr,
    functions: *const fmi2CallbackFunctions,
    parameters: &[(&str, Start)],
) -> fmi2Component {
    let model = interface.model;
    let guid = std::ffi::CString::new(interface.guid.clone()).expect("GUID without NUL");
    // SAFETY: NUL-terminated strings that live across the call, callbacks as the caller
    // promises; no resource location (none of the models used this way needs one).
    let c = unsafe {
        fmi2Instantiate(
            name.as_ptr(),
            fmi2Type_fmi2CoSimulation,
            guid.as_ptr(),
            std::ptr::null::<c_char>(),
            functions,
            0,
            0,
        )
    };
    assert!(!c.is_null(), "{}: fmi2Instantiate failed", model.identifier);
    // SAFETY: a live instance.
    unsafe {
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), 0);
        assert_eq!(fmi2EnterInitializationMode(c), 0);
        for (name, value) in parameters {
            let vr = vrs(model, &[name])[0];
            let status = match value {
                Start::Real(x) => fmi2SetReal(c, &vr, 1, x),
                Start::Integer(i) => fmi2SetInteger(c, &vr, 1, i),
                Start::String(text) => {
                    let text = std::ffi::CString::new(*text).expect("a value without NUL");
                    fmi2SetString(c, &vr, 1, &text.as_ptr())
                }
            };
            assert_eq!(status, 0, "{}: setting {name}", model.identifier);
        }
        assert_eq!(
            fmi2ExitInitializationMode(c),
            0,
            "{}: initialization failed",
            model.identifier
        );
    }
    c
}
