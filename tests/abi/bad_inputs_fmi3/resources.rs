//! FMI 3.0's resourcePath, a native path (no URI): one that does not exist, none, an
//! empty one, one that is not UTF-8, a URI where a path belongs; path files looked up in
//! it; and a log message with `%` in it, passed as it is (FMI 3.0's callback has no format).

use super::*;

pub(super) static CASES: &[Case<Fmi3>] = &[
    case(
        "a resourcePath that does not exist",
        P2,
        Initialization,
        |s| s.exit_after(&[("path", Text("part.json"))]),
        ERROR3,
        Some("fmi3ExitInitializationMode: parameter 'path': /nonexistent/contour_fmu/resources/part.json: cannot read"),
        Corrected,
    )
    .with(Resources::Uri("/nonexistent/contour_fmu/resources/")),
    case(
        "a relative path file without a resourcePath",
        P5,
        Initialization,
        |s| s.exit_after(&[("path", Text("blade.cl"))]),
        ERROR3,
        Some("fmi3ExitInitializationMode: parameter 'path': blade.cl: cannot read…the importer gave no usable resource location"),
        Corrected,
    ),
    case(
        "a relative path file with an empty resourcePath",
        P2,
        Initialization,
        |s| s.exit_after(&[("path", Text("part.json"))]),
        ERROR3,
        Some("part.json: cannot read…the importer gave no usable resource location"),
        Corrected,
    )
    .with(Resources::Uri("")),
    case(
        "a resourcePath that is not UTF-8 (a warning; no resources)",
        XY,
        NoInstance,
        |s| {
            let token = s.token();
            s.instantiate(Instantiation {
                resources: Some(b"/tmp/r\xe9sources/"),
                logging_on: true,
                ..Instantiation::new("latin1", token)
            })
        },
        OK3,
        Some("fmi3InstantiateCoSimulation: resourcePath is not UTF-8; continuing without resources"),
        Usable,
    ),
    case(
        "the resources folder as a file URI (FMI 2.0's way) instead of a path",
        P2,
        Initialization,
        |s| s.exit_after(&[("path", Text("syntax.json"))]),
        ERROR3,
        Some("fmi3ExitInitializationMode: parameter 'path': file://…syntax.json: cannot read"),
        Corrected,
    )
    .with(Resources::FolderUri),
    case(
        "a malformed NURBS file named relative to the resourcePath",
        P2,
        Initialization,
        |s| s.exit_after(&[("path", Text("syntax.json"))]),
        ERROR3,
        Some("syntax.json:3:"),
        Corrected,
    )
    .with(Resources::Folder),
    case(
        "a relative CL file missing from the resourcePath",
        P5,
        Initialization,
        |s| s.exit_after(&[("path", Text("absent.cl"))]),
        ERROR3,
        Some("absent.cl: cannot read"),
        Corrected,
    )
    .with(Resources::Folder),
    case(
        "a malformed CL file named relative to the resourcePath",
        P5,
        Initialization,
        |s| s.exit_after(&[("path", Text("dangling.cl"))]),
        ERROR3,
        Some("dangling.cl:3: the last record ends in a continuation '$'"),
        Corrected,
    )
    .with(Resources::Folder),
    case(
        "a G-code program the program estimator reads from the resourcePath",
        C2,
        Initialization,
        |s| s.exit_after(&[("estimator", Int(4)), ("path", Text("off_circle.ngc"))]),
        ERROR3,
        Some("off_circle.ngc:2:1: the arc's end is not on its circle"),
        Corrected,
    )
    .with(Resources::Folder),
    case(
        "a path file whose name holds %s and %n (passed to the callback as it is)",
        P2,
        Initialization,
        |s| s.exit_after(&[("path", Text(&s.file("100%s%n%%.json")))]),
        ERROR3,
        Some("100%s%n%%.json: cannot read"),
        Corrected,
    ),
];
