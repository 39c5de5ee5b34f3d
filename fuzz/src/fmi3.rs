//! The library's 75 exported `fmi3*` functions, declared for static linking (as
//! tests/abi/common/linked.rs declares the `fmi2*` ones and the seven of a step round,
//! imported from there): one declaration per `fmi3...TYPE` typedef of the `fmi3-bindings`
//! crate (bindgen's output of the vendored `fmi3Functions.h`), written from them by a
//! script, and checked against them at compile time below: a declaration that disagrees
//! with its typedef does not build.

use fmi3_bindings::*;

// The functions of a step round are declared once, in tests/abi/common/linked.rs (shared
// with the ABI tests), and checked below with the rest.
use crate::linked::{
    fmi3DoStep, fmi3EnterInitializationMode, fmi3ExitInitializationMode, fmi3FreeInstance,
    fmi3GetFloat64, fmi3InstantiateCoSimulation, fmi3SetFloat64,
};

extern "C" {
    pub fn fmi3GetVersion() -> *const ::std::os::raw::c_char;
    pub fn fmi3SetDebugLogging(
        instance: fmi3Instance,
        loggingOn: fmi3Boolean,
        nCategories: usize,
        categories: *const fmi3String,
    ) -> fmi3Status;
    pub fn fmi3InstantiateModelExchange(
        instanceName: fmi3String,
        instantiationToken: fmi3String,
        resourcePath: fmi3String,
        visible: fmi3Boolean,
        loggingOn: fmi3Boolean,
        instanceEnvironment: fmi3InstanceEnvironment,
        logMessage: fmi3LogMessageCallback,
    ) -> fmi3Instance;
    pub fn fmi3InstantiateScheduledExecution(
        instanceName: fmi3String,
        instantiationToken: fmi3String,
        resourcePath: fmi3String,
        visible: fmi3Boolean,
        loggingOn: fmi3Boolean,
        instanceEnvironment: fmi3InstanceEnvironment,
        logMessage: fmi3LogMessageCallback,
        clockUpdate: fmi3ClockUpdateCallback,
        lockPreemption: fmi3LockPreemptionCallback,
        unlockPreemption: fmi3UnlockPreemptionCallback,
    ) -> fmi3Instance;
    pub fn fmi3EnterEventMode(instance: fmi3Instance) -> fmi3Status;
    pub fn fmi3Terminate(instance: fmi3Instance) -> fmi3Status;
    pub fn fmi3Reset(instance: fmi3Instance) -> fmi3Status;
    pub fn fmi3GetFloat32(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *mut fmi3Float32,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3GetInt8(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *mut fmi3Int8,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3GetUInt8(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *mut fmi3UInt8,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3GetInt16(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *mut fmi3Int16,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3GetUInt16(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *mut fmi3UInt16,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3GetInt32(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *mut fmi3Int32,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3GetUInt32(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *mut fmi3UInt32,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3GetInt64(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *mut fmi3Int64,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3GetUInt64(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *mut fmi3UInt64,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3GetBoolean(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *mut fmi3Boolean,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3GetString(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *mut fmi3String,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3GetBinary(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        valueSizes: *mut usize,
        values: *mut fmi3Binary,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3GetClock(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *mut fmi3Clock,
    ) -> fmi3Status;
    pub fn fmi3SetFloat32(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *const fmi3Float32,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3SetInt8(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *const fmi3Int8,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3SetUInt8(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *const fmi3UInt8,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3SetInt16(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *const fmi3Int16,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3SetUInt16(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *const fmi3UInt16,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3SetInt32(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *const fmi3Int32,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3SetUInt32(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *const fmi3UInt32,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3SetInt64(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *const fmi3Int64,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3SetUInt64(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *const fmi3UInt64,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3SetBoolean(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *const fmi3Boolean,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3SetString(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *const fmi3String,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3SetBinary(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        valueSizes: *const usize,
        values: *const fmi3Binary,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3SetClock(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        values: *const fmi3Clock,
    ) -> fmi3Status;
    pub fn fmi3GetNumberOfVariableDependencies(
        instance: fmi3Instance,
        valueReference: fmi3ValueReference,
        nDependencies: *mut usize,
    ) -> fmi3Status;
    pub fn fmi3GetVariableDependencies(
        instance: fmi3Instance,
        dependent: fmi3ValueReference,
        elementIndicesOfDependent: *mut usize,
        independents: *mut fmi3ValueReference,
        elementIndicesOfIndependents: *mut usize,
        dependencyKinds: *mut fmi3DependencyKind,
        nDependencies: usize,
    ) -> fmi3Status;
    pub fn fmi3GetFMUState(instance: fmi3Instance, FMUState: *mut fmi3FMUState) -> fmi3Status;
    pub fn fmi3SetFMUState(instance: fmi3Instance, FMUState: fmi3FMUState) -> fmi3Status;
    pub fn fmi3FreeFMUState(instance: fmi3Instance, FMUState: *mut fmi3FMUState) -> fmi3Status;
    pub fn fmi3SerializedFMUStateSize(
        instance: fmi3Instance,
        FMUState: fmi3FMUState,
        size: *mut usize,
    ) -> fmi3Status;
    pub fn fmi3SerializeFMUState(
        instance: fmi3Instance,
        FMUState: fmi3FMUState,
        serializedState: *mut fmi3Byte,
        size: usize,
    ) -> fmi3Status;
    pub fn fmi3DeserializeFMUState(
        instance: fmi3Instance,
        serializedState: *const fmi3Byte,
        size: usize,
        FMUState: *mut fmi3FMUState,
    ) -> fmi3Status;
    pub fn fmi3GetDirectionalDerivative(
        instance: fmi3Instance,
        unknowns: *const fmi3ValueReference,
        nUnknowns: usize,
        knowns: *const fmi3ValueReference,
        nKnowns: usize,
        seed: *const fmi3Float64,
        nSeed: usize,
        sensitivity: *mut fmi3Float64,
        nSensitivity: usize,
    ) -> fmi3Status;
    pub fn fmi3GetAdjointDerivative(
        instance: fmi3Instance,
        unknowns: *const fmi3ValueReference,
        nUnknowns: usize,
        knowns: *const fmi3ValueReference,
        nKnowns: usize,
        seed: *const fmi3Float64,
        nSeed: usize,
        sensitivity: *mut fmi3Float64,
        nSensitivity: usize,
    ) -> fmi3Status;
    pub fn fmi3EnterConfigurationMode(instance: fmi3Instance) -> fmi3Status;
    pub fn fmi3ExitConfigurationMode(instance: fmi3Instance) -> fmi3Status;
    pub fn fmi3GetIntervalDecimal(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        intervals: *mut fmi3Float64,
        qualifiers: *mut fmi3IntervalQualifier,
    ) -> fmi3Status;
    pub fn fmi3GetIntervalFraction(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        counters: *mut fmi3UInt64,
        resolutions: *mut fmi3UInt64,
        qualifiers: *mut fmi3IntervalQualifier,
    ) -> fmi3Status;
    pub fn fmi3GetShiftDecimal(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        shifts: *mut fmi3Float64,
    ) -> fmi3Status;
    pub fn fmi3GetShiftFraction(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        counters: *mut fmi3UInt64,
        resolutions: *mut fmi3UInt64,
    ) -> fmi3Status;
    pub fn fmi3SetIntervalDecimal(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        intervals: *const fmi3Float64,
    ) -> fmi3Status;
    pub fn fmi3SetIntervalFraction(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        counters: *const fmi3UInt64,
        resolutions: *const fmi3UInt64,
    ) -> fmi3Status;
    pub fn fmi3SetShiftDecimal(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        shifts: *const fmi3Float64,
    ) -> fmi3Status;
    pub fn fmi3SetShiftFraction(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        counters: *const fmi3UInt64,
        resolutions: *const fmi3UInt64,
    ) -> fmi3Status;
    pub fn fmi3EvaluateDiscreteStates(instance: fmi3Instance) -> fmi3Status;
    pub fn fmi3UpdateDiscreteStates(
        instance: fmi3Instance,
        discreteStatesNeedUpdate: *mut fmi3Boolean,
        terminateSimulation: *mut fmi3Boolean,
        nominalsOfContinuousStatesChanged: *mut fmi3Boolean,
        valuesOfContinuousStatesChanged: *mut fmi3Boolean,
        nextEventTimeDefined: *mut fmi3Boolean,
        nextEventTime: *mut fmi3Float64,
    ) -> fmi3Status;
    pub fn fmi3EnterContinuousTimeMode(instance: fmi3Instance) -> fmi3Status;
    pub fn fmi3CompletedIntegratorStep(
        instance: fmi3Instance,
        noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
        enterEventMode: *mut fmi3Boolean,
        terminateSimulation: *mut fmi3Boolean,
    ) -> fmi3Status;
    pub fn fmi3SetTime(instance: fmi3Instance, time: fmi3Float64) -> fmi3Status;
    pub fn fmi3SetContinuousStates(
        instance: fmi3Instance,
        continuousStates: *const fmi3Float64,
        nContinuousStates: usize,
    ) -> fmi3Status;
    pub fn fmi3GetContinuousStateDerivatives(
        instance: fmi3Instance,
        derivatives: *mut fmi3Float64,
        nContinuousStates: usize,
    ) -> fmi3Status;
    pub fn fmi3GetEventIndicators(
        instance: fmi3Instance,
        eventIndicators: *mut fmi3Float64,
        nEventIndicators: usize,
    ) -> fmi3Status;
    pub fn fmi3GetContinuousStates(
        instance: fmi3Instance,
        continuousStates: *mut fmi3Float64,
        nContinuousStates: usize,
    ) -> fmi3Status;
    pub fn fmi3GetNominalsOfContinuousStates(
        instance: fmi3Instance,
        nominals: *mut fmi3Float64,
        nContinuousStates: usize,
    ) -> fmi3Status;
    pub fn fmi3GetNumberOfEventIndicators(
        instance: fmi3Instance,
        nEventIndicators: *mut usize,
    ) -> fmi3Status;
    pub fn fmi3GetNumberOfContinuousStates(
        instance: fmi3Instance,
        nContinuousStates: *mut usize,
    ) -> fmi3Status;
    pub fn fmi3EnterStepMode(instance: fmi3Instance) -> fmi3Status;
    pub fn fmi3GetOutputDerivatives(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        orders: *const fmi3Int32,
        values: *mut fmi3Float64,
        nValues: usize,
    ) -> fmi3Status;
    pub fn fmi3ActivateModelPartition(
        instance: fmi3Instance,
        clockReference: fmi3ValueReference,
        activationTime: fmi3Float64,
    ) -> fmi3Status;
}

// Each declaration above as its standard typedef: a signature that differs from the
// header's is a compile error.
const _: fmi3GetVersionTYPE = Some(fmi3GetVersion);
const _: fmi3SetDebugLoggingTYPE = Some(fmi3SetDebugLogging);
const _: fmi3InstantiateModelExchangeTYPE = Some(fmi3InstantiateModelExchange);
const _: fmi3InstantiateCoSimulationTYPE = Some(fmi3InstantiateCoSimulation);
const _: fmi3InstantiateScheduledExecutionTYPE = Some(fmi3InstantiateScheduledExecution);
const _: fmi3FreeInstanceTYPE = Some(fmi3FreeInstance);
const _: fmi3EnterInitializationModeTYPE = Some(fmi3EnterInitializationMode);
const _: fmi3ExitInitializationModeTYPE = Some(fmi3ExitInitializationMode);
const _: fmi3EnterEventModeTYPE = Some(fmi3EnterEventMode);
const _: fmi3TerminateTYPE = Some(fmi3Terminate);
const _: fmi3ResetTYPE = Some(fmi3Reset);
const _: fmi3GetFloat32TYPE = Some(fmi3GetFloat32);
const _: fmi3GetFloat64TYPE = Some(fmi3GetFloat64);
const _: fmi3GetInt8TYPE = Some(fmi3GetInt8);
const _: fmi3GetUInt8TYPE = Some(fmi3GetUInt8);
const _: fmi3GetInt16TYPE = Some(fmi3GetInt16);
const _: fmi3GetUInt16TYPE = Some(fmi3GetUInt16);
const _: fmi3GetInt32TYPE = Some(fmi3GetInt32);
const _: fmi3GetUInt32TYPE = Some(fmi3GetUInt32);
const _: fmi3GetInt64TYPE = Some(fmi3GetInt64);
const _: fmi3GetUInt64TYPE = Some(fmi3GetUInt64);
const _: fmi3GetBooleanTYPE = Some(fmi3GetBoolean);
const _: fmi3GetStringTYPE = Some(fmi3GetString);
const _: fmi3GetBinaryTYPE = Some(fmi3GetBinary);
const _: fmi3GetClockTYPE = Some(fmi3GetClock);
const _: fmi3SetFloat32TYPE = Some(fmi3SetFloat32);
const _: fmi3SetFloat64TYPE = Some(fmi3SetFloat64);
const _: fmi3SetInt8TYPE = Some(fmi3SetInt8);
const _: fmi3SetUInt8TYPE = Some(fmi3SetUInt8);
const _: fmi3SetInt16TYPE = Some(fmi3SetInt16);
const _: fmi3SetUInt16TYPE = Some(fmi3SetUInt16);
const _: fmi3SetInt32TYPE = Some(fmi3SetInt32);
const _: fmi3SetUInt32TYPE = Some(fmi3SetUInt32);
const _: fmi3SetInt64TYPE = Some(fmi3SetInt64);
const _: fmi3SetUInt64TYPE = Some(fmi3SetUInt64);
const _: fmi3SetBooleanTYPE = Some(fmi3SetBoolean);
const _: fmi3SetStringTYPE = Some(fmi3SetString);
const _: fmi3SetBinaryTYPE = Some(fmi3SetBinary);
const _: fmi3SetClockTYPE = Some(fmi3SetClock);
const _: fmi3GetNumberOfVariableDependenciesTYPE = Some(fmi3GetNumberOfVariableDependencies);
const _: fmi3GetVariableDependenciesTYPE = Some(fmi3GetVariableDependencies);
const _: fmi3GetFMUStateTYPE = Some(fmi3GetFMUState);
const _: fmi3SetFMUStateTYPE = Some(fmi3SetFMUState);
const _: fmi3FreeFMUStateTYPE = Some(fmi3FreeFMUState);
const _: fmi3SerializedFMUStateSizeTYPE = Some(fmi3SerializedFMUStateSize);
const _: fmi3SerializeFMUStateTYPE = Some(fmi3SerializeFMUState);
const _: fmi3DeserializeFMUStateTYPE = Some(fmi3DeserializeFMUState);
const _: fmi3GetDirectionalDerivativeTYPE = Some(fmi3GetDirectionalDerivative);
const _: fmi3GetAdjointDerivativeTYPE = Some(fmi3GetAdjointDerivative);
const _: fmi3EnterConfigurationModeTYPE = Some(fmi3EnterConfigurationMode);
const _: fmi3ExitConfigurationModeTYPE = Some(fmi3ExitConfigurationMode);
const _: fmi3GetIntervalDecimalTYPE = Some(fmi3GetIntervalDecimal);
const _: fmi3GetIntervalFractionTYPE = Some(fmi3GetIntervalFraction);
const _: fmi3GetShiftDecimalTYPE = Some(fmi3GetShiftDecimal);
const _: fmi3GetShiftFractionTYPE = Some(fmi3GetShiftFraction);
const _: fmi3SetIntervalDecimalTYPE = Some(fmi3SetIntervalDecimal);
const _: fmi3SetIntervalFractionTYPE = Some(fmi3SetIntervalFraction);
const _: fmi3SetShiftDecimalTYPE = Some(fmi3SetShiftDecimal);
const _: fmi3SetShiftFractionTYPE = Some(fmi3SetShiftFraction);
const _: fmi3EvaluateDiscreteStatesTYPE = Some(fmi3EvaluateDiscreteStates);
const _: fmi3UpdateDiscreteStatesTYPE = Some(fmi3UpdateDiscreteStates);
const _: fmi3EnterContinuousTimeModeTYPE = Some(fmi3EnterContinuousTimeMode);
const _: fmi3CompletedIntegratorStepTYPE = Some(fmi3CompletedIntegratorStep);
const _: fmi3SetTimeTYPE = Some(fmi3SetTime);
const _: fmi3SetContinuousStatesTYPE = Some(fmi3SetContinuousStates);
const _: fmi3GetContinuousStateDerivativesTYPE = Some(fmi3GetContinuousStateDerivatives);
const _: fmi3GetEventIndicatorsTYPE = Some(fmi3GetEventIndicators);
const _: fmi3GetContinuousStatesTYPE = Some(fmi3GetContinuousStates);
const _: fmi3GetNominalsOfContinuousStatesTYPE = Some(fmi3GetNominalsOfContinuousStates);
const _: fmi3GetNumberOfEventIndicatorsTYPE = Some(fmi3GetNumberOfEventIndicators);
const _: fmi3GetNumberOfContinuousStatesTYPE = Some(fmi3GetNumberOfContinuousStates);
const _: fmi3EnterStepModeTYPE = Some(fmi3EnterStepMode);
const _: fmi3GetOutputDerivativesTYPE = Some(fmi3GetOutputDerivatives);
const _: fmi3DoStepTYPE = Some(fmi3DoStep);
const _: fmi3ActivateModelPartitionTYPE = Some(fmi3ActivateModelPartition);
