//! The FMUs: each is a plain Rust type with a variable table and a step function, built
//! on [`crate::framework`]; `crate::fmi` adapts them to the C ABI. Adding an FMU is one
//! file here and one line in [`all`].

pub mod axis_variables;
pub mod contour_ccc_2d;
pub mod contour_ccc_5x;
pub mod controller_parameters;
pub mod five_axis_plant;
pub mod joint_limits_parameters;
pub mod kinematics_parameters;
pub mod line_arc_parameters;
pub mod path_interpolator_2d;
pub mod path_interpolator_5x;
pub mod path_parameter;
pub mod servo_drive;
pub mod servo_plant;
pub mod xy_servo_plant;

#[cfg(feature = "test-hooks")]
pub mod fault_probe;
#[cfg(feature = "test-hooks")]
pub mod pass_through;

use std::sync::OnceLock;

use crate::framework::interface::{Interface, UnitSystem};
use crate::framework::model::ModelInfo;

/// Every model this library serves (the packager builds one FMU per entry).
pub fn all() -> Vec<&'static ModelInfo> {
    vec![
        &path_interpolator_2d::INFO,
        &contour_ccc_2d::INFO,
        &xy_servo_plant::INFO,
        &path_interpolator_5x::INFO,
        &contour_ccc_5x::INFO,
        &five_axis_plant::INFO,
        &servo_drive::INFO,
        &servo_drive::INFO_ROTARY,
    ]
}

/// Models reachable through `fmi2Instantiate`: [`all`] plus test-only models.
pub fn instantiable() -> Vec<&'static ModelInfo> {
    #[allow(unused_mut)]
    let mut models = all();
    #[cfg(feature = "test-hooks")]
    models.extend([&fault_probe::INFO, &pass_through::INFO]);
    models
}

/// Every interface of every instantiable model: the mm one, then the SI one, model by
/// model (built once).
pub fn interfaces() -> &'static [Interface] {
    static INTERFACES: OnceLock<Vec<Interface>> = OnceLock::new();
    INTERFACES.get_or_init(|| {
        instantiable()
            .into_iter()
            .flat_map(|m| UnitSystem::ALL.map(|units| Interface::new(m, units)))
            .collect()
    })
}

/// `model`'s interface in `units`.
pub fn interface(model: &ModelInfo, units: UnitSystem) -> &'static Interface {
    interfaces()
        .iter()
        .find(|i| i.units == units && std::ptr::eq(i.model, model))
        .unwrap_or_else(|| panic!("{} is not an instantiable model", model.identifier))
}

/// The interface whose GUID this is.
pub fn by_guid(guid: &str) -> Option<&'static Interface> {
    interfaces().iter().find(|i| i.guid == guid)
}

/// The interface whose FMI 3.0 instantiation token this is.
pub fn by_instantiation_token(token: &str) -> Option<&'static Interface> {
    interfaces().iter().find(|i| i.instantiation_token == token)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::framework::model::Environment;
    use crate::framework::units;
    use crate::framework::variables::{Causality, Value, Values, VarType, Variability, Variable};

    #[test]
    fn tables_are_well_formed() {
        for model in instantiable() {
            let mut names = std::collections::HashSet::new();
            for (index, v) in model.variables.iter().enumerate() {
                assert_eq!(
                    v.vr, index,
                    "{}: '{}' out of place",
                    model.identifier, v.name
                );
                assert!(
                    names.insert(v.name.to_string()),
                    "{}: '{}' twice",
                    model.identifier,
                    v.name
                );
                if let Some(unit) = v.unit {
                    assert!(units::find(unit).is_some(), "unit '{unit}' undefined");
                }
                // Start values must satisfy their own bounds.
                v.check(&Value::from(v.start)).unwrap();
                if matches!(
                    v.var_type(),
                    VarType::Integer | VarType::Boolean | VarType::String
                ) {
                    assert_ne!(v.variability, Variability::Continuous, "{}", v.name);
                }
            }
        }
    }

    /// Other valid values of a variable, to perturb it with.
    fn alternatives(v: &Variable, value: &Value) -> Vec<Value> {
        let candidates = match value {
            Value::Real(x) => vec![
                Value::Real(if *x == 0.0 { 1.5 } else { x * 1.25 }),
                Value::Real(x + 0.75),
            ],
            Value::Integer(x) => match v.enumeration {
                Some(e) => (1..=e.items.len() as i32)
                    .filter(|i| i != x)
                    .map(Value::Integer)
                    .collect(),
                None => vec![Value::Integer(x + 1)],
            },
            Value::Boolean(b) => vec![Value::Boolean(!b)],
            Value::String(text) => [
                "circle",
                "line",
                "arc",
                "infinity",
                "trident",
                "tilted_helix",
                "figure_eight",
                "other",
            ]
            .iter()
            .filter(|t| **t != text)
            .map(|t| Value::String(t.to_string()))
            .collect(),
        };
        candidates
            .into_iter()
            .filter(|c| v.check(c).is_ok())
            .collect()
    }

    /// The outputs after initialization from `values`, or `None` if the model refuses them.
    fn initial_outputs(model: &ModelInfo, values: &Values) -> Option<Vec<Value>> {
        let mut values = values.clone();
        let mut instance = (model.create)(&Environment::default());
        instance.initialize(&mut values, 0.0).ok()?;
        Some(
            model
                .variables
                .iter()
                .filter(|v| v.causality == Causality::Output)
                .map(|v| values.get(v.vr).clone())
                .collect(),
        )
    }

    /// The `InitialUnknowns` dependencies written to the model descriptions are the true
    /// ones: perturbing a variable that is not listed never changes an output's initial
    /// value (in every context: each built-in path, each estimator, …), and every listed
    /// variable does change it in some context.
    #[test]
    fn initial_dependencies_are_exactly_the_variables_that_change_initial_outputs() {
        for model in instantiable() {
            let outputs: Vec<&Variable> = model
                .variables
                .iter()
                .filter(|v| v.causality == Causality::Output)
                .collect();
            let knowns: Vec<&Variable> = model
                .variables
                .iter()
                .filter(|v| v.causality != Causality::Output)
                .collect();
            for (output, deps) in model.initial_dependencies {
                assert!(outputs.iter().any(|o| o.vr == *output), "{output}");
                assert!(deps.iter().all(|d| knowns.iter().any(|k| k.vr == *d)));
            }
            // Contexts: the start values and every alternative of a String or
            // enumeration variable (they switch between whole behaviours), each also with
            // every Real shifted off its start value (a start angle of 0 hides the radius
            // in sin(start)).
            let start = Values::from_table(model.variables);
            let mut shifted = start.clone();
            for v in &knowns {
                if let Value::Real(x) = start.get(v.vr) {
                    let candidate = Value::Real(x + 0.75);
                    if v.check(&candidate).is_ok() {
                        shifted.set(v.vr, candidate);
                    }
                }
            }
            let mut contexts = vec![start.clone(), shifted.clone()];
            for v in &knowns {
                if v.var_type() == VarType::String || v.enumeration.is_some() {
                    for alt in alternatives(v, start.get(v.vr)) {
                        for base in [&start, &shifted] {
                            let mut c = base.clone();
                            c.set(v.vr, alt.clone());
                            contexts.push(c);
                        }
                    }
                }
            }
            let mut seen = std::collections::HashSet::new();
            let mut initialized = 0;
            for context in &contexts {
                let Some(base) = initial_outputs(model, context) else {
                    continue;
                };
                initialized += 1;
                for k in &knowns {
                    for alt in alternatives(k, context.get(k.vr)) {
                        let mut changed = context.clone();
                        changed.set(k.vr, alt.clone());
                        let Some(after) = initial_outputs(model, &changed) else {
                            continue;
                        };
                        for (i, o) in outputs.iter().enumerate() {
                            if after[i] == base[i] {
                                continue;
                            }
                            assert!(
                                model.initial_dependencies_of(o.vr).contains(&k.vr),
                                "{}: initial '{}' changes with '{}' ({:?} -> {:?}) but does \
                                 not list it",
                                model.identifier,
                                o.name,
                                k.name,
                                context.get(k.vr),
                                alt
                            );
                            seen.insert((o.vr, k.vr));
                        }
                    }
                }
            }
            assert!(initialized >= 1, "{}", model.identifier);
            for o in &outputs {
                let witnessed = model
                    .initial_dependencies
                    .iter()
                    .filter(|(out, _)| *out == o.vr)
                    .flat_map(|(_, knowns)| knowns.iter().copied());
                for k in witnessed {
                    assert!(
                        seen.contains(&(o.vr, k)),
                        "{}: '{}' lists '{}' but never changes with it",
                        model.identifier,
                        o.name,
                        model.variables[k].name
                    );
                }
            }
        }
    }

    #[test]
    fn guids_are_distinct_and_formatted() {
        let guids: Vec<String> = interfaces().iter().map(|i| i.guid.clone()).collect();
        assert_eq!(guids.len(), 2 * instantiable().len());
        // The mm interface keeps the model's GUID.
        for m in instantiable() {
            assert_eq!(interface(m, UnitSystem::Millimetre).guid, m.guid());
        }
        for g in &guids {
            assert_eq!(g.len(), 38);
            assert!(g.starts_with('{') && g.ends_with('}'));
        }
        let unique: std::collections::HashSet<_> = guids.iter().collect();
        assert_eq!(unique.len(), guids.len());
    }
}
