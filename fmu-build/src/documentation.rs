//! `documentation/index.html` of an FMU: what it does, its variables (from the table),
//! and a minimal fmpy example, in the words of the FMU's standard.

use std::fmt::Write;

use contour_fmu::framework::interface::{Interface, UnitSystem};
use contour_fmu::framework::variables::{Causality, Start, Variability};

use crate::escape;
use crate::standard::Standard;

fn start_text(start: Start) -> String {
    match start {
        Start::Real(x) => format!("{x}"),
        Start::Integer(x) => format!("{x}"),
        Start::Boolean(x) => format!("{x}"),
        Start::String(x) => format!("\"{x}\""),
    }
}

pub fn render(interface: &Interface, standard: Standard) -> String {
    let model = interface.model;
    let mut rows = String::new();
    for v in &interface.variables {
        let kind = match (v.causality, v.variability) {
            (Causality::Parameter, Variability::Tunable) => "tunable parameter",
            (Causality::Parameter, _) => "parameter",
            (Causality::Input, _) => "input",
            (Causality::Output, _) => "output",
        };
        let start = match (v.causality, v.enumeration, v.start) {
            (Causality::Output, _, _) => String::new(),
            (_, Some(e), Start::Integer(x)) => match e.item(x) {
                Some(item) => format!("{x} ({})", item.name),
                None => x.to_string(),
            },
            _ => start_text(v.start),
        };
        let type_name = match v.enumeration {
            Some(e) => format!("Enumeration {} ({})", e.name, e.listing()),
            None => standard.type_name(v.var_type()).to_string(),
        };
        let range = match (v.min, v.max) {
            (None, None) => String::new(),
            (min, max) => format!(
                "[{}, {}]",
                min.map_or("−∞".into(), |m| m.to_string()),
                max.map_or("∞".into(), |m| m.to_string())
            ),
        };
        writeln!(
            rows,
            "<tr><td><code>{}</code></td><td>{}</td><td>{kind}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            escape(&v.name.to_string()),
            v.vr,
            escape(&type_name),
            escape(&start),
            escape(v.unit.unwrap_or("")),
            escape(&range),
            escape(&v.description.to_string()),
        )
        .unwrap();
    }
    let inputs: Vec<String> = interface
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Input)
        .map(|v| v.name.to_string())
        .collect();
    let outputs: Vec<String> = interface
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Output)
        .map(|v| v.name.to_string())
        .collect();
    let e = model.default_experiment;
    format!(
        r#"<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{id}</title>
<style>
body {{ font-family: sans-serif; max-width: 60em; margin: 2em auto; }}
table {{ border-collapse: collapse; }}
td, th {{ border: 1px solid #ccc; padding: 0.2em 0.5em; text-align: left; }}
pre {{ background: #f4f4f4; padding: 0.8em; }}
</style>
</head>
<body>
<h1>{id}</h1>
<p>{description}</p>
<p>{units}</p>
<p>{standard} Co-Simulation; the platforms are the folders under <code>binaries/</code>.
Inputs: {inputs}. Outputs: {outputs}.{time}
Default experiment: {start} s to {stop} s with {step} s steps; any communication step
size is accepted.</p>
<h2>Variables</h2>
<table>
<tr><th>name</th><th>value reference</th><th>kind</th><th>type</th><th>start</th><th>unit</th><th>range</th><th>description</th></tr>
{rows}</table>
<h2>Using it from Python (fmpy)</h2>
<pre>from fmpy import simulate_fmu
result = simulate_fmu("{id}.fmu", stop_time={stop}, output_interval={step})
print(result.dtype.names)</pre>
<h2>Behaviour at the FMI boundary</h2>
<ul>
<li>Calls in the wrong state return <code>{p}Error</code> and log <code>&lt;function&gt;: illegal call sequence</code>.</li>
<li>Non-finite or out-of-range values are refused with <code>{p}Error</code>; the previous value stays. Enumerations are set with <code>{enumeration_setter}</code>; a value that is not one of the items is refused.</li>
<li>Parameters are checked again in <code>{p}ExitInitializationMode</code>; on error the instance stays in initialization mode so they can be corrected.</li>
<li>FMU states can be saved, restored and serialized (a versioned, checksummed byte format); a restored state brings its mode with it, so it can be set right after instantiation. Restored bytes are validated like parameters; handles that are not live FMU states of the instance are refused.</li>
<li>Log categories: logEvents, logStatusWarning, logStatusError, logStatusFatal, logAll. Errors are always logged.</li>
</ul>
</body>
</html>
"#,
        id = model.identifier,
        standard = standard.name(),
        p = standard.prefix(),
        enumeration_setter = standard.enumeration_setter(),
        time = match standard {
            Standard::Fmi2 => String::new(),
            Standard::Fmi3 => format!(
                "\nThe independent variable <code>time</code> (s) has value reference {}.",
                interface.time_vr()
            ),
        },
        description = escape(&interface.description()),
        units = match interface.units {
            UnitSystem::Si if !interface.converts() => "SI build: this model has no lengths, so its units are those of the mm build, SI already; it exists so that an SI loop takes every FMU from one folder.",
            UnitSystem::Millimetre => "Lengths in mm (mm/s, mm/s², mm/s³); the SI build of this model takes and gives metres.",
            UnitSystem::Si => "SI build: lengths in m (m/s, m/s², m/s³), angles in rad, time in s. It computes as the mm build does (lengths in mm inside) and converts at the interface, so gains, fuzzy factors and tuned files carry over unchanged; path files (NURBS JSON, G-code) keep their own units (mm, or G20 inches). Error and warning messages quote the model's values in mm and say so.",
        },
        inputs = if inputs.is_empty() {
            "none".into()
        } else {
            inputs.join(", ")
        },
        outputs = outputs.join(", "),
        start = e.start_time,
        stop = e.stop_time,
        step = e.step_size,
    )
}
