//! The built FMU library exports exactly the functions of FMI 2.0 Co-Simulation (the
//! common functions plus the Co-Simulation ones, FMI 2.0.4 section 2.1 and 4.2) and every
//! function of FMI 3.0's fmi3Functions.h (importers such as fmpy look each one up), and
//! nothing else: no FMI 2.0 Model Exchange functions (the model descriptions declare
//! Co-Simulation only), no helper of a dependency, no Rust symbol. Read from the ELF
//! dynamic symbol table, the table an importer's dlsym looks in.

use std::collections::BTreeSet;

use object::{Object, ObjectSymbol, SymbolKind};

#[test]
fn the_library_exports_exactly_the_fmi2_co_simulation_and_the_fmi3_functions() {
    let path = crate::common::library_path();
    let data =
        std::fs::read(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let file = object::File::parse(&*data)
        .unwrap_or_else(|e| panic!("cannot parse {}: {e}", path.display()));

    // Every symbol the library defines and exports (undefined ones are its imports).
    let mut functions = BTreeSet::new();
    let mut others = BTreeSet::new();
    for symbol in file.dynamic_symbols() {
        if !symbol.is_definition() || !symbol.is_global() {
            continue;
        }
        let name = symbol.name().expect("symbol name is UTF-8").to_string();
        if symbol.kind() == SymbolKind::Text {
            functions.insert(name);
        } else {
            others.insert(format!("{name} ({:?})", symbol.kind()));
        }
    }

    let expected: BTreeSet<String> = crate::common::FMI2_CO_SIMULATION
        .iter()
        .chain(&contour_fmu::fmi::FMI3_FUNCTIONS)
        .map(|s| s.to_string())
        .collect();
    assert_eq!(expected.len(), 34 + 75);
    // The list is the header's: every function fmi3Functions.h exports.
    let header = include_str!("../../third_party/fmi3/fmi3Functions.h");
    let declared: BTreeSet<String> = header
        .lines()
        .filter_map(|line| line.strip_prefix("FMI3_Export "))
        .filter_map(|rest| rest.split_whitespace().nth(1))
        .map(|name| name.trim_end_matches(';').to_string())
        .collect();
    let listed: BTreeSet<String> = contour_fmu::fmi::FMI3_FUNCTIONS
        .iter()
        .map(|s| s.to_string())
        .collect();
    assert_eq!(
        declared, listed,
        "FMI3_FUNCTIONS is not fmi3Functions.h's list"
    );
    let missing: Vec<_> = expected.difference(&functions).collect();
    let extra: Vec<_> = functions.difference(&expected).collect();
    assert!(
        missing.is_empty() && extra.is_empty() && others.is_empty(),
        "{}: missing functions {missing:?}; unexpected exported functions {extra:?}; \
         unexpected exported non-functions {others:?}",
        path.display()
    );
}

/// Through the dlopened library: every function is found and answers.
#[cfg(feature = "test-hooks")]
mod through_dlopen {
    use crate::common::*;

    #[test]
    fn all_34_functions_are_exported_and_report_the_platform() {
        let lib = lib();
        let present = [
            lib.fmi2GetTypesPlatform.is_ok(),
            lib.fmi2GetVersion.is_ok(),
            lib.fmi2SetDebugLogging.is_ok(),
            lib.fmi2Instantiate.is_ok(),
            lib.fmi2FreeInstance.is_ok(),
            lib.fmi2SetupExperiment.is_ok(),
            lib.fmi2EnterInitializationMode.is_ok(),
            lib.fmi2ExitInitializationMode.is_ok(),
            lib.fmi2Terminate.is_ok(),
            lib.fmi2Reset.is_ok(),
            lib.fmi2GetReal.is_ok(),
            lib.fmi2GetInteger.is_ok(),
            lib.fmi2GetBoolean.is_ok(),
            lib.fmi2GetString.is_ok(),
            lib.fmi2SetReal.is_ok(),
            lib.fmi2SetInteger.is_ok(),
            lib.fmi2SetBoolean.is_ok(),
            lib.fmi2SetString.is_ok(),
            lib.fmi2GetFMUstate.is_ok(),
            lib.fmi2SetFMUstate.is_ok(),
            lib.fmi2FreeFMUstate.is_ok(),
            lib.fmi2SerializedFMUstateSize.is_ok(),
            lib.fmi2SerializeFMUstate.is_ok(),
            lib.fmi2DeSerializeFMUstate.is_ok(),
            lib.fmi2GetDirectionalDerivative.is_ok(),
            lib.fmi2SetRealInputDerivatives.is_ok(),
            lib.fmi2GetRealOutputDerivatives.is_ok(),
            lib.fmi2DoStep.is_ok(),
            lib.fmi2CancelStep.is_ok(),
            lib.fmi2GetStatus.is_ok(),
            lib.fmi2GetRealStatus.is_ok(),
            lib.fmi2GetIntegerStatus.is_ok(),
            lib.fmi2GetBooleanStatus.is_ok(),
            lib.fmi2GetStringStatus.is_ok(),
        ];
        assert_eq!(present.len(), 34);
        assert!(present.iter().all(|&p| p));
        let platform = unsafe { std::ffi::CStr::from_ptr(lib.fmi2GetTypesPlatform()) };
        let version = unsafe { std::ffi::CStr::from_ptr(lib.fmi2GetVersion()) };
        assert_eq!(platform.to_str().unwrap(), "default");
        assert_eq!(version.to_str().unwrap(), "2.0");
    }
}
