//! A loop ready to run: its SSP structure read, every FMU unpacked, described and its
//! library opened, and the wiring checked against the model descriptions (every connector
//! a variable of its FMU, both ends of a connection of one type and one unit) before any
//! instance exists.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::archive::{unpack, Unpacked};
use crate::fmi2::{Activity, Library};
use crate::model_description::{ModelDescription, Variable, VariableType};
use crate::ssp::{Connection, SystemStructure, Value};
use crate::Error;

/// An FMU, unpacked and its library open.
pub struct Fmu {
    pub file: PathBuf,
    pub description: ModelDescription,
    pub library: Arc<Library>,
    unpacked: Unpacked,
}

impl Fmu {
    /// Unpacks and describes the FMU `file` and opens its library (counted in `activity`).
    pub fn load(file: &Path, activity: &Activity) -> Result<Fmu, Error> {
        if !file.is_file() {
            return Err(Error::Refused(format!("{}: no such FMU", file.display())));
        }
        let unpacked = unpack(file, "an FMU")?;
        let text =
            std::fs::read_to_string(unpacked.path().join("modelDescription.xml")).map_err(|e| {
                Error::Refused(format!(
                    "{}: no readable modelDescription.xml: {e}",
                    file.display()
                ))
            })?;
        let description = ModelDescription::parse(&text, file)?;
        let library = Arc::new(Library::open(
            unpacked.path(),
            &description.model_identifier,
            file,
            activity,
        )?);
        Ok(Fmu {
            file: file.to_path_buf(),
            description,
            library,
            unpacked,
        })
    }

    pub fn resources(&self) -> PathBuf {
        self.unpacked.path().join("resources")
    }

    /// The variable `name`, or a message saying it does not exist.
    pub fn variable(&self, unit: &str, name: &str) -> Result<&Variable, Error> {
        self.description.variable(name).ok_or_else(|| {
            Error::Refused(format!(
                "{unit} ({}) has no variable {name:?}",
                self.file.file_name().unwrap_or_default().to_string_lossy()
            ))
        })
    }
}

/// A variable of a unit, resolved: the unit's index in the step order, its value
/// reference and type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Resolved {
    pub unit: usize,
    pub value_reference: u32,
    pub kind: VariableType,
}

/// One unit of the loop.
pub struct Unit {
    pub name: String,
    pub fmu: Arc<Fmu>,
}

pub struct System {
    pub structure: SystemStructure,
    /// In the step order.
    pub units: Vec<Unit>,
    /// (from, to) of every connection, in the file's order.
    pub connections: Vec<(Resolved, Resolved)>,
    pub initial_copies: Vec<(Resolved, Resolved)>,
}

impl System {
    /// Reads the SSP file `file` and loads its FMUs (an FMU named by several components is
    /// unpacked once); every error names the file it is about.
    pub fn load(file: &Path) -> Result<System, Error> {
        System::from_structure(SystemStructure::read(file)?, &Activity::default())
    }

    /// Loads the FMUs of `structure` (read, and perhaps with a component's FMU replaced);
    /// opening their libraries counts as calls in `activity`, which a watchdog may watch.
    pub fn from_structure(
        structure: SystemStructure,
        activity: &Activity,
    ) -> Result<System, Error> {
        let mut loaded: HashMap<PathBuf, Arc<Fmu>> = HashMap::new();
        let mut units = Vec::new();
        for name in &structure.order {
            let component = structure
                .component(name)
                .expect("the order lists the components");
            let fmu = match loaded.get(&component.source) {
                Some(fmu) => fmu.clone(),
                None => {
                    let fmu = Arc::new(Fmu::load(&component.source, activity).map_err(|e| {
                        Error::Refused(format!(
                            "{}: component {name}: {e}",
                            structure.file.display()
                        ))
                    })?);
                    loaded.insert(component.source.clone(), fmu.clone());
                    fmu
                }
            };
            units.push(Unit {
                name: name.clone(),
                fmu,
            });
        }
        for unit in &units {
            let sharing: Vec<&str> = units
                .iter()
                .filter(|u| Arc::ptr_eq(&u.fmu, &unit.fmu))
                .map(|u| u.name.as_str())
                .collect();
            if unit.fmu.description.once_per_process && sharing.len() > 1 {
                return Err(Error::Refused(format!(
                    "{}: {} can be instantiated only once per process (canBeInstantiatedOnlyOncePerProcess), so it cannot serve {}",
                    structure.file.display(),
                    unit.fmu.file.display(),
                    sharing.join(" and ")
                )));
            }
        }
        let mut system = System {
            structure,
            units,
            connections: Vec::new(),
            initial_copies: Vec::new(),
        };
        let in_file =
            |e: Error| Error::Refused(format!("{}: {e}", system.structure.file.display()));
        for component in &system.structure.components {
            let unit = &system.units[system
                .unit_index(&component.name)
                .expect("every component is a unit")];
            for (connector, _, kind) in &component.connectors {
                let variable = unit.fmu.variable(&unit.name, connector).map_err(in_file)?;
                if let Some(kind) = kind.as_deref().filter(|k| {
                    *k != variable.kind.name()
                        && !(*k == "Enumeration" && variable.kind == VariableType::Integer)
                }) {
                    return Err(in_file(Error::Refused(format!(
                        "connector {}.{connector} is declared {kind}, but the FMU's variable is a {}",
                        unit.name,
                        variable.kind.name()
                    ))));
                }
            }
        }
        let connections = system
            .checked(&system.structure.connections)
            .map_err(in_file)?;
        let initial_copies = system
            .checked(&system.structure.initial_copies)
            .map_err(in_file)?;
        system.connections = connections;
        system.initial_copies = initial_copies;
        Ok(system)
    }

    pub fn unit_index(&self, name: &str) -> Option<usize> {
        self.units.iter().position(|u| u.name == name)
    }

    /// The variable `unit.name`; a message names what does not exist.
    pub fn resolve(&self, unit: &str, name: &str) -> Result<Resolved, Error> {
        let index = self.unit_index(unit).ok_or_else(|| {
            let names: Vec<&str> = self.units.iter().map(|u| u.name.as_str()).collect();
            Error::Refused(format!(
                "no unit {unit:?} (the loop has {})",
                names.join(", ")
            ))
        })?;
        let variable = self.units[index].fmu.variable(unit, name)?;
        Ok(Resolved {
            unit: index,
            value_reference: variable.value_reference,
            kind: variable.kind,
        })
    }

    fn checked(&self, connections: &[Connection]) -> Result<Vec<(Resolved, Resolved)>, Error> {
        connections
            .iter()
            .map(|c| {
                let (from, to) = (self.resolve(&c.from.0, &c.from.1)?, self.resolve(&c.to.0, &c.to.1)?);
                let what = format!("connection {}.{} -> {}.{}", c.from.0, c.from.1, c.to.0, c.to.1);
                if from.kind != to.kind {
                    return Err(Error::Refused(format!("{what}: a {} onto a {}", from.kind.name(), to.kind.name())));
                }
                let unit_of = |(unit, name): &(String, String)| {
                    self.units[self.unit_index(unit).expect("resolved")].fmu.description.variable(name).and_then(|v| v.unit.clone())
                };
                if let (Some(a), Some(b)) = (unit_of(&c.from), unit_of(&c.to)) {
                    if a != b {
                        return Err(Error::Refused(format!(
                            "{what}: units differ ({a} onto {b}); take every FMU from one build or convert in the model"
                        )));
                    }
                }
                Ok((from, to))
            })
            .collect()
    }

    /// Start values (unit, variable, value) resolved and typed for their variables: an
    /// Integer onto a Real is exact and allowed, any other mix refused.
    pub fn start_values(
        &self,
        values: &[(String, String, Value)],
    ) -> Result<Vec<(Resolved, Value)>, Error> {
        values
            .iter()
            .map(|(unit, name, value)| {
                let target = self.resolve(unit, name)?;
                let typed = match (target.kind, value) {
                    (VariableType::Real, Value::Integer(i)) => Value::Real(f64::from(*i)),
                    (VariableType::Real, Value::Real(_))
                    | (VariableType::Integer, Value::Integer(_))
                    | (VariableType::Boolean, Value::Boolean(_))
                    | (VariableType::String, Value::String(_)) => value.clone(),
                    (kind, value) => {
                        return Err(Error::Refused(format!(
                            "{unit}.{name} is a {}; {value:?} is not one",
                            kind.name()
                        )))
                    }
                };
                Ok((target, typed))
            })
            .collect()
    }

    /// A command line's `UNIT.VARIABLE=TEXT` (the unit's name up to the first dot), read
    /// as [`System::parse_start_value`] reads it.
    pub fn parse_assignment(&self, assignment: &str) -> Result<(String, String, Value), Error> {
        let malformed = || Error::Refused(format!("{assignment:?} is not UNIT.VARIABLE=VALUE"));
        let (target, text) = assignment.split_once('=').ok_or_else(malformed)?;
        let (unit, name) = target.split_once('.').ok_or_else(malformed)?;
        self.parse_start_value(unit, name, text)
    }

    /// A start value given as text (a command line's unit.variable=text), read as the
    /// variable's type.
    pub fn parse_start_value(
        &self,
        unit: &str,
        name: &str,
        text: &str,
    ) -> Result<(String, String, Value), Error> {
        let target = self.resolve(unit, name)?;
        let wrong = || {
            Error::Refused(format!(
                "{unit}.{name} is a {}; {text:?} is not one",
                target.kind.name()
            ))
        };
        let value = match target.kind {
            VariableType::Real => Value::Real(text.trim().parse().map_err(|_| wrong())?),
            VariableType::Integer => Value::Integer(text.trim().parse().map_err(|_| wrong())?),
            VariableType::Boolean => match text.trim() {
                "true" | "1" => Value::Boolean(true),
                "false" | "0" => Value::Boolean(false),
                _ => return Err(wrong()),
            },
            VariableType::String => Value::String(text.to_string()),
        };
        Ok((unit.to_string(), name.to_string(), value))
    }

    /// Whether one of the loop's FMUs allows only one instance per process: the loop then
    /// runs once at a time in a process.
    pub fn once_per_process(&self) -> bool {
        self.units
            .iter()
            .any(|u| u.fmu.description.once_per_process)
    }

    /// Every output of every unit, in the step order: what a run records by default.
    pub fn outputs(&self) -> Vec<(String, String)> {
        self.units
            .iter()
            .flat_map(|u| {
                u.fmu
                    .description
                    .variables
                    .iter()
                    .filter(|v| v.causality == "output" && v.kind != VariableType::String)
                    .map(|v| (u.name.clone(), v.name.clone()))
            })
            .collect()
    }
}
