//! `modelDescription.xml` rendered from a model's interface, for FMI 2.0 (`fmi2.rs`) and
//! FMI 3.0 (`fmi3.rs`) Co-Simulation; what both write alike is here. The output is
//! deterministic (no timestamps), so the committed copies under `modelDescription/` can be
//! compared byte for byte.

pub mod fmi2;
pub mod fmi3;

use std::fmt::Write;
use std::path::{Path, PathBuf};

use contour_fmu::fmi::LogCategory;
use contour_fmu::framework::interface::{Interface, UnitSystem};
use contour_fmu::framework::model::ModelInfo;
use contour_fmu::framework::units::{self, UnitDefinition};
use contour_fmu::framework::variables::{Causality, EnumType, Start, Variable};

use crate::escape;
use crate::standard::Standard;

/// Where the committed copy of an interface's model description lives under the
/// workspace `root`: `modelDescription/[fmi3/][si/]<Model>.xml`.
pub fn committed(root: &Path, interface: &Interface, standard: Standard) -> PathBuf {
    let mut dir = root.join("modelDescription");
    if standard == Standard::Fmi3 {
        dir.push("fmi3");
    }
    if interface.units == UnitSystem::Si {
        dir.push("si");
    }
    dir.join(format!("{}.xml", interface.model.identifier))
}

fn number(x: f64) -> String {
    // Debug formatting round-trips every f64 exactly and never loses the exponent.
    format!("{x:?}")
}

/// A variable's start value as attribute text (unescaped); outputs have none, as they are
/// computed by the model (initial="calculated").
fn start_text(v: &Variable) -> Option<String> {
    match (v.causality, v.start) {
        (Causality::Output, _) => None,
        (_, Start::Real(x)) => Some(number(x)),
        (_, Start::Integer(x)) => Some(x.to_string()),
        (_, Start::Boolean(x)) => Some(x.to_string()),
        (_, Start::String(x)) => Some(x.to_string()),
    }
}

/// ` initial="calculated"` for an output (computed by the model), nothing for the others:
/// parameters and inputs take the default, `exact`, in both standards.
fn initial(v: &Variable) -> &'static str {
    if v.causality == Causality::Output {
        " initial=\"calculated\""
    } else {
        ""
    }
}

/// ` unit=".." min=".." max=".."`, those a variable has.
fn unit_and_bounds(v: &Variable) -> String {
    let mut attributes = String::new();
    if let Some(unit) = v.unit {
        write!(attributes, " unit=\"{}\"", escape(unit)).unwrap();
    }
    for (name, bound) in [("min", v.min), ("max", v.max)] {
        if let Some(bound) = bound {
            let text = match v.start {
                Start::Integer(_) => format!("{}", bound as i64),
                _ => number(bound),
            };
            write!(attributes, " {name}=\"{text}\"").unwrap();
        }
    }
    attributes
}

fn unit_element(u: &UnitDefinition) -> String {
    let mut base = String::new();
    for (name, exponent) in [
        ("kg", u.kg),
        ("m", u.m),
        ("s", u.s),
        ("A", u.a),
        ("rad", u.rad),
    ] {
        if exponent != 0 {
            write!(base, " {name}=\"{exponent}\"").unwrap();
        }
    }
    if u.factor != 1.0 {
        write!(base, " factor=\"{}\"", number(u.factor)).unwrap();
    }
    format!(
        "    <Unit name=\"{}\">\n      <BaseUnit{base}/>\n    </Unit>\n",
        escape(u.name)
    )
}

/// What stands between `<CoSimulation>` and `<ModelVariables>` in both standards: the
/// units, the enumeration types, the log categories and the default experiment.
fn definitions(w: &mut String, interface: &Interface, standard: Standard) {
    // FMI 3.0's `time` is in s, which a model without durations does not declare otherwise.
    let also: &[&'static str] = match standard {
        Standard::Fmi2 => &[],
        Standard::Fmi3 => &["s"],
    };
    unit_definitions(w, &interface.variables, also);
    let types = enumeration_types(&interface.variables);
    if !types.is_empty() {
        writeln!(w, "  <TypeDefinitions>").unwrap();
        for e in types {
            w.push_str(&enumeration_type(e, standard));
        }
        writeln!(w, "  </TypeDefinitions>").unwrap();
    }
    log_categories(w, standard);
    default_experiment(w, interface.model);
}

/// `<UnitDefinitions>` of every unit the variables and `also` use, sorted by name.
fn unit_definitions(w: &mut String, variables: &[Variable], also: &[&'static str]) {
    let mut used: Vec<&'static str> = variables.iter().filter_map(|v| v.unit).collect();
    used.extend(also);
    used.sort_unstable();
    used.dedup();
    if !used.is_empty() {
        writeln!(w, "  <UnitDefinitions>").unwrap();
        for name in used {
            let unit = units::find(name).unwrap_or_else(|| panic!("unit '{name}' is not defined"));
            w.push_str(&unit_element(unit));
        }
        writeln!(w, "  </UnitDefinitions>").unwrap();
    }
}

/// The enumeration types the variables are declared with, each once, in table order.
fn enumeration_types(variables: &[Variable]) -> Vec<&'static EnumType> {
    let mut types: Vec<&'static EnumType> = Vec::new();
    for e in variables.iter().filter_map(|v| v.enumeration) {
        if !types.iter().any(|t| t.name == e.name) {
            types.push(e);
        }
    }
    types
}

/// An enumeration type: FMI 2.0's `SimpleType` around an `Enumeration`, FMI 3.0's
/// `EnumerationType`; the items alike in both, values from 1.
fn enumeration_type(e: &EnumType, standard: Standard) -> String {
    let (name, description) = (escape(e.name), escape(e.description));
    let (mut xml, indent, close) = match standard {
        Standard::Fmi2 => (
            format!("    <SimpleType name=\"{name}\" description=\"{description}\">\n      <Enumeration>\n"),
            "        ",
            "      </Enumeration>\n    </SimpleType>\n",
        ),
        Standard::Fmi3 => (
            format!("    <EnumerationType name=\"{name}\" description=\"{description}\">\n"),
            "      ",
            "    </EnumerationType>\n",
        ),
    };
    for (i, item) in e.items.iter().enumerate() {
        writeln!(
            xml,
            "{indent}<Item name=\"{}\" value=\"{}\" description=\"{}\"/>",
            escape(item.name),
            i + 1,
            escape(item.description)
        )
        .unwrap();
    }
    xml.push_str(close);
    xml
}

/// `<LogCategories>`, each description in `standard`'s words (the library's are FMI 2.0's:
/// "Calls that return fmi2Warning", which FMI 3.0 spells fmi3Warning).
fn log_categories(w: &mut String, standard: Standard) {
    writeln!(w, "  <LogCategories>").unwrap();
    for c in LogCategory::ALL {
        let description = c.description().replace("fmi2", standard.prefix());
        writeln!(
            w,
            "    <Category name=\"{}\" description=\"{}\"/>",
            c.name(),
            escape(&description)
        )
        .unwrap();
    }
    writeln!(w, "  </LogCategories>").unwrap();
}

fn default_experiment(w: &mut String, model: &ModelInfo) {
    let e = model.default_experiment;
    writeln!(
        w,
        "  <DefaultExperiment startTime=\"{}\" stopTime=\"{}\" stepSize=\"{}\"/>",
        number(e.start_time),
        number(e.stop_time),
        number(e.step_size)
    )
    .unwrap();
}

/// A `dependencies` attribute: the Knowns (FMI 2.0: indices, FMI 3.0: value references),
/// or the empty list for "depends on none of the Knowns". Always written, also when empty:
/// an importer (syssimx) fails on a missing attribute, which both standards read as
/// "depends on every Known".
fn dependencies(knowns: &[usize]) -> String {
    let list: Vec<String> = knowns.iter().map(|i| i.to_string()).collect();
    format!(" dependencies=\"{}\"", list.join(" "))
}

/// The outputs of the interface, in table order.
fn outputs(interface: &Interface) -> impl Iterator<Item = &Variable> {
    interface
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Output)
}
