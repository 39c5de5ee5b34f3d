//! Units used by the variable tables, with their SI base-unit definitions (written to
//! `UnitDefinitions` so importers can convert).

/// Exponents of the SI base units plus rad, and the factor to SI: value_SI = factor·value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitDefinition {
    pub name: &'static str,
    pub kg: i32,
    pub m: i32,
    pub s: i32,
    pub a: i32,
    pub rad: i32,
    pub factor: f64,
}

const fn unit(
    name: &'static str,
    kg: i32,
    m: i32,
    s: i32,
    a: i32,
    rad: i32,
    factor: f64,
) -> UnitDefinition {
    UnitDefinition {
        name,
        kg,
        m,
        s,
        a,
        rad,
        factor,
    }
}

/// Every unit a model may name.
pub const UNITS: &[UnitDefinition] = &[
    unit("s", 0, 0, 1, 0, 0, 1.0),
    unit("1/s", 0, 0, -1, 0, 0, 1.0),
    unit("1/s2", 0, 0, -2, 0, 0, 1.0),
    unit("mm", 0, 1, 0, 0, 0, 1e-3),
    unit("mm/s", 0, 1, -1, 0, 0, 1e-3),
    unit("mm/s2", 0, 1, -2, 0, 0, 1e-3),
    unit("mm/s3", 0, 1, -3, 0, 0, 1e-3),
    unit("A", 0, 0, 0, 1, 0, 1.0),
    unit("kg.m2", 1, 2, 0, 0, 0, 1.0),
    unit("N.m.s/rad", 1, 2, -1, 0, -1, 1.0),
    unit("N.m/A", 1, 2, -2, -1, 0, 1.0),
    unit("A.s/rad", 0, 0, 1, 1, -1, 1.0),
    unit("A/rad", 0, 0, 0, 1, -1, 1.0),
    unit("rad", 0, 0, 0, 0, 1, 1.0),
    unit("rad/s", 0, 0, -1, 0, 1, 1.0),
    unit("rad/s2", 0, 0, -2, 0, 1, 1.0),
    unit("mm/rad", 0, 1, 0, 0, -1, 1e-3),
    // Servo drives: force and torque, and their velocity-loop gains.
    unit("N", 1, 1, -2, 0, 0, 1.0),
    unit("N.m", 1, 2, -2, 0, 0, 1.0),
    unit("N.s/mm", 1, 0, -1, 0, 0, 1e3),
    unit("N/mm", 1, 0, -2, 0, 0, 1e3),
    unit("N.m/rad", 1, 2, -2, 0, -1, 1.0),
    // The SI build's lengths (crate::framework::interface).
    unit("m", 0, 1, 0, 0, 0, 1.0),
    unit("m/s", 0, 1, -1, 0, 0, 1.0),
    unit("m/s2", 0, 1, -2, 0, 0, 1.0),
    unit("m/s3", 0, 1, -3, 0, 0, 1.0),
    unit("m/rad", 0, 1, 0, 0, -1, 1.0),
    unit("N.s/m", 1, 0, -1, 0, 0, 1.0),
    unit("N/m", 1, 0, -2, 0, 0, 1.0),
];

pub fn find(name: &str) -> Option<&'static UnitDefinition> {
    UNITS.iter().find(|u| u.name == name)
}

/// The SI unit of the same quantity as `unit` (factor 1: m for mm, m/s for mm/s, …),
/// `None` for a unit that is SI already or not defined.
pub fn si_counterpart(unit: &str) -> Option<&'static UnitDefinition> {
    let u = find(unit)?;
    if u.factor == 1.0 {
        return None;
    }
    UNITS.iter().find(|si| {
        si.factor == 1.0 && (si.kg, si.m, si.s, si.a, si.rad) == (u.kg, u.m, u.s, u.a, u.rad)
    })
}
