//! Missing resources.

use super::*;

pub(super) static CASES: &[Case] = &[
    case(
        "a resource location that is not a file URI",
        P2,
        NoInstance,
        |s| {
            let uri = Some("http://example.org/resources");
            s.instantiate(Some("a"), fmi2Type_fmi2CoSimulation, Guid::Own, uri)
        },
        OK,
        Some("fmi2Instantiate: resource location 'http://example.org/resources' is not a file: URI; continuing without resources"),
        Usable,
    ),
    case(
        "a resource location on a remote host",
        P5,
        NoInstance,
        |s| {
            let uri = Some("file://server/share/resources");
            s.instantiate(Some("a"), fmi2Type_fmi2CoSimulation, Guid::Own, uri)
        },
        OK,
        Some("names the remote host 'server'"),
        Usable,
    ),
    case(
        "a resource location with a bad %-escape",
        XY,
        NoInstance,
        |s| {
            let uri = Some("file:///tmp/res%zzources");
            s.instantiate(Some("a"), fmi2Type_fmi2CoSimulation, Guid::Own, uri)
        },
        OK,
        Some("has a bad %-escape"),
        Usable,
    ),
    case(
        "a relative path file without a resource location",
        P2,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", "part.json")),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'path': part.json: cannot read…the importer gave no usable resource location"),
        Corrected,
    ),
    case(
        "a relative CL file with a resource location that is not a file URI",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", "blade.cl")),
        ERROR,
        Some("fmi2ExitInitializationMode: parameter 'path': blade.cl: cannot read…the importer gave no usable resource location"),
        Corrected,
    )
    .with(Resources::Uri("http://example.org/resources")),
    case(
        "a relative CL file missing from the resources folder",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", "absent.cl")),
        ERROR,
        Some("absent.cl: cannot read"),
        Corrected,
    )
    .with(Resources::Folder),
    case(
        "an absolute NURBS file that does not exist",
        P2,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", &s.file("absent.json"))),
        ERROR,
        Some("absent.json: cannot read"),
        Corrected,
    ),
    case(
        "an absolute two-curve file that does not exist",
        P5,
        Initialization,
        |s| s.exit_with(|s| s.set_string("path", &s.file("absent.json"))),
        ERROR,
        Some("absent.json: cannot read"),
        Corrected,
    ),
];
