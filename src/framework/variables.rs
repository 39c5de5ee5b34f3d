//! The variable table: the single source of truth for a model's interface.
//!
//! The FMI layer does get/set from it, `fmu-build` renders `modelDescription.xml` and the
//! documentation from it, and the GUID is a hash of it. A variable's value reference is
//! its index in the table, so storage is a plain vector indexed by value reference; the
//! tables are declared with [`variable_table!`](super::variable_table), which numbers
//! them.

use serde::{Deserialize, Serialize};

pub use super::text::Text;

/// Value reference: the index of the variable in its model's table.
pub type Vr = usize;

/// FMI causality, restricted to what our models use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Causality {
    Parameter,
    Input,
    Output,
}

impl Causality {
    /// The name FMI uses in `modelDescription.xml`.
    pub fn name(self) -> &'static str {
        match self {
            Causality::Parameter => "parameter",
            Causality::Input => "input",
            Causality::Output => "output",
        }
    }
}

/// FMI variability, restricted to what our models use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Variability {
    /// Parameter that may only change before initialization ends.
    Fixed,
    /// Parameter that may also change between steps.
    Tunable,
    /// Changes only at communication points (Integer, Boolean, String inputs/outputs).
    Discrete,
    /// Real input or output.
    Continuous,
}

impl Variability {
    /// The name FMI uses in `modelDescription.xml`.
    pub fn name(self) -> &'static str {
        match self {
            Variability::Fixed => "fixed",
            Variability::Tunable => "tunable",
            Variability::Discrete => "discrete",
            Variability::Continuous => "continuous",
        }
    }
}

/// The FMI base type of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum VarType {
    Real,
    Integer,
    Boolean,
    String,
}

impl VarType {
    pub fn name(self) -> &'static str {
        match self {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::Boolean => "Boolean",
            VarType::String => "String",
        }
    }
}

/// A start value as written in the table (usable in `static` tables).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Start {
    Real(f64),
    Integer(i32),
    Boolean(bool),
    String(&'static str),
}

impl Start {
    pub fn var_type(self) -> VarType {
        match self {
            Start::Real(_) => VarType::Real,
            Start::Integer(_) => VarType::Integer,
            Start::Boolean(_) => VarType::Boolean,
            Start::String(_) => VarType::String,
        }
    }
}

/// One item of an FMI enumeration type; its value is its position in the list, from 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnumItem {
    /// The item's name, as importers show it in a drop-down.
    pub name: &'static str,
    pub description: &'static str,
}

/// An FMI `Enumeration` type (`TypeDefinitions/SimpleType`): a variable declared with it
/// stores an Integer (set and read with `fmi2SetInteger`/`fmi2GetInteger`) that must be the
/// value of one of the items, 1..=items.len().
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnumType {
    /// The `SimpleType` name the variable's `declaredType` refers to.
    pub name: &'static str,
    pub description: &'static str,
    pub items: &'static [EnumItem],
}

impl EnumType {
    /// The item with FMI value `value`, if there is one.
    pub fn item(&self, value: i32) -> Option<&'static EnumItem> {
        usize::try_from(value)
            .ok()
            .and_then(|v| v.checked_sub(1))
            .and_then(|i| self.items.get(i))
    }

    /// "1 = a, 2 = b, …", for messages.
    pub fn listing(&self) -> String {
        self.items
            .iter()
            .enumerate()
            .map(|(i, item)| format!("{} = {}", i + 1, item.name))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// One row of a model's variable table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Variable {
    /// Its index in the table (set when the table is assembled).
    pub vr: Vr,
    /// Structured FMI name, e.g. `x.Kvp`.
    pub name: Text,
    pub description: Text,
    pub causality: Causality,
    pub variability: Variability,
    /// Start value; for outputs it is the value before the first computation and is not
    /// written to the XML (outputs are `initial="calculated"`).
    pub start: Start,
    /// Unit name, defined in [`crate::models::units`].
    pub unit: Option<&'static str>,
    /// Inclusive bounds for Real and Integer variables, checked on every set.
    pub min: Option<f64>,
    pub max: Option<f64>,
    /// For an Integer variable: the FMI enumeration type it is declared with.
    pub enumeration: Option<&'static EnumType>,
}

impl Variable {
    pub(crate) const fn new(
        name: Text,
        causality: Causality,
        variability: Variability,
        start: Start,
        description: Text,
    ) -> Self {
        Variable {
            vr: 0,
            name,
            description,
            causality,
            variability,
            start,
            unit: None,
            min: None,
            max: None,
            enumeration: None,
        }
    }

    /// A continuous Real input.
    pub const fn input(name: &'static str, start: f64, description: &'static str) -> Self {
        Self::new(
            Text::plain(name),
            Causality::Input,
            Variability::Continuous,
            Start::Real(start),
            Text::plain(description),
        )
    }

    /// A discrete input of a non-Real type.
    pub const fn discrete_input(
        name: &'static str,
        start: Start,
        description: &'static str,
    ) -> Self {
        Self::new(
            Text::plain(name),
            Causality::Input,
            Variability::Discrete,
            start,
            Text::plain(description),
        )
    }

    /// A continuous Real output.
    pub const fn output(name: &'static str, description: &'static str) -> Self {
        Self::new(
            Text::plain(name),
            Causality::Output,
            Variability::Continuous,
            Start::Real(0.0),
            Text::plain(description),
        )
    }

    /// A discrete output of a non-Real type (`start` only gives the type and the value
    /// before the first computation).
    pub const fn discrete_output(
        name: &'static str,
        start: Start,
        description: &'static str,
    ) -> Self {
        Self::new(
            Text::plain(name),
            Causality::Output,
            Variability::Discrete,
            start,
            Text::plain(description),
        )
    }

    /// A parameter fixed after initialization.
    pub const fn parameter(name: &'static str, start: Start, description: &'static str) -> Self {
        Self::new(
            Text::plain(name),
            Causality::Parameter,
            Variability::Fixed,
            start,
            Text::plain(description),
        )
    }

    /// Makes a parameter tunable between steps.
    pub const fn tunable(mut self) -> Self {
        self.variability = Variability::Tunable;
        self
    }

    pub const fn unit(mut self, unit: &'static str) -> Self {
        self.unit = Some(unit);
        self
    }

    pub const fn min(mut self, min: f64) -> Self {
        self.min = Some(min);
        self
    }

    pub const fn max(mut self, max: f64) -> Self {
        self.max = Some(max);
        self
    }

    /// Declares an Integer variable with an enumeration type (FMI `Enumeration`).
    pub const fn enumeration(mut self, declared: &'static EnumType) -> Self {
        assert!(
            matches!(self.start, Start::Integer(_)),
            "an enumeration variable stores an Integer"
        );
        self.enumeration = Some(declared);
        self
    }

    pub fn var_type(&self) -> VarType {
        self.start.var_type()
    }

    /// Checks a candidate value against the type and bounds; the error says why.
    pub fn check(&self, value: &Value) -> Result<(), String> {
        if value.var_type() != self.var_type() {
            return Err(format!(
                "variable '{}' is of type {}, not {}",
                self.name,
                self.var_type().name(),
                value.var_type().name()
            ));
        }
        if let (Some(declared), Value::Integer(v)) = (self.enumeration, value) {
            if declared.item(*v).is_none() {
                return Err(format!(
                    "variable '{}' = {v} is not a value of its enumeration {} ({})",
                    self.name,
                    declared.name,
                    declared.listing()
                ));
            }
        }
        let number = match *value {
            Value::Real(v) => v,
            Value::Integer(v) => f64::from(v),
            _ => return Ok(()),
        };
        if !number.is_finite() {
            return Err(format!(
                "variable '{}' refuses the non-finite value {number}",
                self.name
            ));
        }
        if let Some(min) = self.min {
            if number < min {
                return Err(format!(
                    "variable '{}' = {number} is below its minimum {min}",
                    self.name
                ));
            }
        }
        if let Some(max) = self.max {
            if number > max {
                return Err(format!(
                    "variable '{}' = {number} is above its maximum {max}",
                    self.name
                ));
            }
        }
        Ok(())
    }
}

/// A variable's current value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Value {
    Real(f64),
    Integer(i32),
    Boolean(bool),
    String(String),
}

impl Value {
    pub fn var_type(&self) -> VarType {
        match self {
            Value::Real(_) => VarType::Real,
            Value::Integer(_) => VarType::Integer,
            Value::Boolean(_) => VarType::Boolean,
            Value::String(_) => VarType::String,
        }
    }
}

impl From<Start> for Value {
    fn from(start: Start) -> Self {
        match start {
            Start::Real(v) => Value::Real(v),
            Start::Integer(v) => Value::Integer(v),
            Start::Boolean(v) => Value::Boolean(v),
            Start::String(v) => Value::String(v.to_owned()),
        }
    }
}

/// The values of all variables of one instance, indexed by value reference.
///
/// Typed accessors panic on a type mismatch: that is a bug in a model's own table
/// (caught by the table tests), never a user error, which the FMI layer rejects first.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Values {
    slots: Vec<Value>,
}

impl Values {
    /// The start values of a table.
    pub fn from_table(table: &[Variable]) -> Self {
        Values {
            slots: table.iter().map(|v| Value::from(v.start)).collect(),
        }
    }

    pub fn len(&self) -> usize {
        self.slots.len()
    }

    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    pub fn get(&self, vr: Vr) -> &Value {
        &self.slots[vr]
    }

    /// Stores a value without checks (the caller has checked it against the table).
    pub fn set(&mut self, vr: Vr, value: Value) {
        self.slots[vr] = value;
    }

    pub fn real(&self, vr: Vr) -> f64 {
        match self.slots[vr] {
            Value::Real(v) => v,
            ref other => panic!("value reference {vr} holds {other:?}, not a Real"),
        }
    }

    pub fn integer(&self, vr: Vr) -> i32 {
        match self.slots[vr] {
            Value::Integer(v) => v,
            ref other => panic!("value reference {vr} holds {other:?}, not an Integer"),
        }
    }

    pub fn boolean(&self, vr: Vr) -> bool {
        match self.slots[vr] {
            Value::Boolean(v) => v,
            ref other => panic!("value reference {vr} holds {other:?}, not a Boolean"),
        }
    }

    pub fn string(&self, vr: Vr) -> &str {
        match &self.slots[vr] {
            Value::String(v) => v,
            other => panic!("value reference {vr} holds {other:?}, not a String"),
        }
    }

    pub fn set_real(&mut self, vr: Vr, value: f64) {
        match &mut self.slots[vr] {
            Value::Real(slot) => *slot = value,
            other => panic!("value reference {vr} holds {other:?}, not a Real"),
        }
    }

    pub fn set_boolean(&mut self, vr: Vr, value: bool) {
        match &mut self.slots[vr] {
            Value::Boolean(slot) => *slot = value,
            other => panic!("value reference {vr} holds {other:?}, not a Boolean"),
        }
    }
}
