//! Declaring a model's variables once: [`variable_table!`] numbers the declarations in
//! order (value reference = position), gives each a typed handle ([`Real`], [`Reals`],
//! [`Bool`], [`Int`], [`Str`]) for reading and writing [`Values`], and assembles the
//! table, checking at compile time that the numbering and the table agree. Per-axis
//! blocks (`axis.x.Kp` … `axis.C.Kd`, with mm or rad units) come from an axis list and a
//! template ([`axis_block`]).

use super::text::Text;
use super::variables::{Causality, Start, Values, Variability, Variable, Vr};
use contour_core::geometry::Vector;

/// A Real variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Real(pub Vr);
/// `N` consecutive Real variables (one per axis, or a parameter group).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reals<const N: usize>(pub Vr);
/// A Boolean variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Bool(pub Vr);
/// An Integer (or Enumeration) variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Int(pub Vr);
/// A String variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Str(pub Vr);

/// The compile-time type check and the value reference of a one-variable handle.
macro_rules! scalar_handle {
    ($handle:ident, $start:pat, $type_name:literal) => {
        impl $handle {
            /// `variable`, checked to have the handle's type (used by `variable_table!`).
            pub const fn checked(variable: Variable) -> Variable {
                assert!(
                    matches!(variable.start, $start),
                    concat!(
                        "a ",
                        stringify!($handle),
                        " handle over a variable not of type ",
                        $type_name
                    )
                );
                variable
            }
            pub const fn vr(self) -> Vr {
                self.0
            }
        }
    };
}

scalar_handle!(Real, Start::Real(_), "Real");
scalar_handle!(Bool, Start::Boolean(_), "Boolean");
scalar_handle!(Int, Start::Integer(_), "Integer");
scalar_handle!(Str, Start::String(_), "String");

impl Real {
    pub fn get(self, values: &Values) -> f64 {
        values.real(self.0)
    }
    pub fn set(self, values: &mut Values, value: f64) {
        values.set_real(self.0, value)
    }
}

impl<const N: usize> Reals<N> {
    /// `block`, checked to hold Reals only (used by `variable_table!`).
    pub const fn checked(block: [Variable; N]) -> [Variable; N] {
        let mut i = 0;
        while i < N {
            Real::checked(block[i]);
            i += 1;
        }
        block
    }
    /// The first value reference.
    pub const fn vr(self) -> Vr {
        self.0
    }
    /// The `i`-th variable of the block.
    pub const fn at(self, i: usize) -> Real {
        assert!(i < N, "index past the block");
        Real(self.0 + i)
    }
    pub fn get(self, values: &Values) -> [f64; N] {
        std::array::from_fn(|i| values.real(self.0 + i))
    }
    pub fn vector(self, values: &Values) -> Vector<N> {
        Vector::from_fn(|i, _| values.real(self.0 + i))
    }
    pub fn set(self, values: &mut Values, value: &Vector<N>) {
        for (i, &v) in value.iter().enumerate() {
            values.set_real(self.0 + i, v);
        }
    }
}

impl Bool {
    pub fn get(self, values: &Values) -> bool {
        values.boolean(self.0)
    }
    pub fn set(self, values: &mut Values, value: bool) {
        values.set_boolean(self.0, value)
    }
}

impl Int {
    pub fn get(self, values: &Values) -> i32 {
        values.integer(self.0)
    }
}

impl Str {
    pub fn get(self, values: &Values) -> &str {
        values.string(self.0)
    }
}

/// How an axis moves, which decides its units.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxisKind {
    /// Position in mm.
    Linear,
    /// Position in rad.
    Rotary,
}

/// One machine axis as the variable names see it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Axis {
    /// Used in names (`ref.x`, `axis.C.Kp`).
    pub name: &'static str,
    /// Used in descriptions (`X position loop`).
    pub label: &'static str,
    pub kind: AxisKind,
}

impl Axis {
    pub const fn linear(name: &'static str, label: &'static str) -> Self {
        Axis {
            name,
            label,
            kind: AxisKind::Linear,
        }
    }
    pub const fn rotary(name: &'static str, label: &'static str) -> Self {
        Axis {
            name,
            label,
            kind: AxisKind::Rotary,
        }
    }
}

/// The two-axis models' axes.
pub const XY: [Axis; 2] = [Axis::linear("x", "X"), Axis::linear("y", "Y")];

/// The five-axis models' joints: X, Y, Z linear, A (tilt) and C (rotary table).
pub const XYZAC: [Axis; 5] = [
    Axis::linear("X", "X"),
    Axis::linear("Y", "Y"),
    Axis::linear("Z", "Z"),
    Axis::rotary("A", "A"),
    Axis::rotary("C", "C"),
];

/// A unit that may depend on the axis kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxisUnit {
    None,
    /// The same for every axis.
    Fixed(&'static str),
    /// The unit for a linear and for a rotary axis.
    ByKind(&'static str, &'static str),
}

impl AxisUnit {
    /// Position: mm or rad.
    pub const POSITION: AxisUnit = AxisUnit::ByKind("mm", "rad");
    /// Velocity: mm/s or rad/s.
    pub const VELOCITY: AxisUnit = AxisUnit::ByKind("mm/s", "rad/s");
    /// Acceleration: mm/s² or rad/s².
    pub const ACCELERATION: AxisUnit = AxisUnit::ByKind("mm/s2", "rad/s2");
}

/// Which word of the axis goes into a description.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxisWord {
    Name,
    Label,
}

/// A per-axis variable: its name is `prefix` + axis name + `suffix`, its description
/// `before` + the axis word + `after`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisTemplate {
    pub prefix: &'static str,
    pub suffix: &'static str,
    pub before: &'static str,
    pub word: AxisWord,
    pub after: &'static str,
    pub causality: Causality,
    pub variability: Variability,
    /// Start value for a linear and for a rotary axis.
    pub start: (f64, f64),
    pub unit: AxisUnit,
    pub min: Option<f64>,
}

impl AxisTemplate {
    const fn new(
        causality: Causality,
        variability: Variability,
        name: (&'static str, &'static str),
        description: (&'static str, AxisWord, &'static str),
    ) -> Self {
        AxisTemplate {
            prefix: name.0,
            suffix: name.1,
            before: description.0,
            word: description.1,
            after: description.2,
            causality,
            variability,
            start: (0.0, 0.0),
            unit: AxisUnit::None,
            min: None,
        }
    }
    /// A continuous Real input per axis, start 0.
    pub const fn input(
        name: (&'static str, &'static str),
        description: (&'static str, AxisWord, &'static str),
    ) -> Self {
        Self::new(Causality::Input, Variability::Continuous, name, description)
    }
    /// A continuous Real output per axis.
    pub const fn output(
        name: (&'static str, &'static str),
        description: (&'static str, AxisWord, &'static str),
    ) -> Self {
        Self::new(
            Causality::Output,
            Variability::Continuous,
            name,
            description,
        )
    }
    /// A fixed Real parameter per axis with its start for linear and rotary axes.
    pub const fn parameter(
        name: (&'static str, &'static str),
        start: (f64, f64),
        description: (&'static str, AxisWord, &'static str),
    ) -> Self {
        let mut t = Self::new(Causality::Parameter, Variability::Fixed, name, description);
        t.start = start;
        t
    }
    pub const fn unit(mut self, unit: AxisUnit) -> Self {
        self.unit = unit;
        self
    }
    pub const fn min(mut self, min: f64) -> Self {
        self.min = Some(min);
        self
    }

    const fn variable(&self, axis: &Axis) -> Variable {
        let word = match self.word {
            AxisWord::Name => axis.name,
            AxisWord::Label => axis.label,
        };
        let rotary = matches!(axis.kind, AxisKind::Rotary);
        let start = if rotary { self.start.1 } else { self.start.0 };
        let mut v = Variable::new(
            Text::join(self.prefix, axis.name, self.suffix),
            self.causality,
            self.variability,
            Start::Real(start),
            Text::join(self.before, word, self.after),
        );
        v.unit = match self.unit {
            AxisUnit::None => None,
            AxisUnit::Fixed(u) => Some(u),
            AxisUnit::ByKind(linear, rotary_unit) => {
                Some(if rotary { rotary_unit } else { linear })
            }
        };
        v.min = self.min;
        v
    }
}

/// The variables of `templates` for every axis, axis by axis (`axis.x.Kp`, `axis.x.Ki`, …,
/// `axis.y.Kp`, …). `N` must be `axes.len() × templates.len()` (checked at compile time).
pub const fn axis_block<const N: usize>(
    axes: &[Axis],
    templates: &[AxisTemplate],
) -> [Variable; N] {
    assert!(
        N == axes.len() * templates.len(),
        "block size differs from axes × templates"
    );
    let mut out = [PLACEHOLDER; N];
    let mut a = 0;
    while a < axes.len() {
        let mut t = 0;
        while t < templates.len() {
            out[a * templates.len() + t] = templates[t].variable(&axes[a]);
            t += 1;
        }
        a += 1;
    }
    out
}

const PLACEHOLDER: Variable = Variable::new(
    Text::plain(""),
    Causality::Output,
    Variability::Continuous,
    Start::Real(0.0),
    Text::plain(""),
);

/// The table from its blocks in order, each variable's value reference set to its
/// position. `N` must be the total length (checked at compile time).
pub const fn assemble<const N: usize>(blocks: &[&[Variable]]) -> [Variable; N] {
    let mut out = [PLACEHOLDER; N];
    let mut vr = 0;
    let mut b = 0;
    while b < blocks.len() {
        let mut i = 0;
        while i < blocks[b].len() {
            assert!(vr < N, "more variables than the numbering counted");
            out[vr] = blocks[b][i];
            out[vr].vr = vr;
            vr += 1;
            i += 1;
        }
        b += 1;
    }
    assert!(vr == N, "fewer variables than the numbering counted");
    out
}

/// Declares a model's variables in order:
///
/// ```ignore
/// variable_table! {
///     static VARIABLES;
///     REF: Reals<2> = axis_block(&XY, &[AxisTemplate::input(("ref.", ""), …)]);
///     TS: Real = Variable::parameter("Ts", Start::Real(1e-3), "…");
/// }
/// ```
///
/// Each line yields a `pub const` handle numbered after the previous ones (a `Reals<N>`
/// block is given as `[Variable; N]`, any other as one `Variable`), `VARIABLE_COUNT`, and
/// the static table, assembled with every value reference set from the numbering. A
/// handle whose kind differs from its variable's type (`X: Real` over a Boolean) does not
/// compile.
macro_rules! variable_table {
    (static $table:ident; $($body:tt)*) => {
        $crate::framework::variable_table::variable_table!(@handles 0usize; $($body)*);
        $crate::framework::variable_table::variable_table!(@table $table [] $($body)*);
    };
    (@handles $next:expr;) => {
        /// Number of variables in the table.
        pub const VARIABLE_COUNT: usize = $next;
    };
    (@handles $next:expr; $(#[$m:meta])* $name:ident : Reals<$n:tt> = $def:expr; $($rest:tt)*) => {
        $(#[$m])*
        pub const $name: $crate::framework::variable_table::Reals<$n> =
            $crate::framework::variable_table::Reals($next);
        $crate::framework::variable_table::variable_table!(@handles $next + $n; $($rest)*);
    };
    (@handles $next:expr; $(#[$m:meta])* $name:ident : $kind:ident = $def:expr; $($rest:tt)*) => {
        $(#[$m])*
        pub const $name: $crate::framework::variable_table::$kind =
            $crate::framework::variable_table::$kind($next);
        $crate::framework::variable_table::variable_table!(@handles $next + 1; $($rest)*);
    };
    (@table $table:ident [$($blocks:expr,)*]) => {
        static $table: [$crate::framework::variables::Variable; VARIABLE_COUNT] =
            $crate::framework::variable_table::assemble(&[$($blocks,)*]);
    };
    (@table $table:ident [$($blocks:expr,)*] $(#[$m:meta])* $name:ident : Reals<$n:tt> = $def:expr; $($rest:tt)*) => {
        $crate::framework::variable_table::variable_table!(@table $table [$($blocks,)* &{
            #[allow(unused_braces)]
            let block: [$crate::framework::variables::Variable; $n] = $def;
            $crate::framework::variable_table::Reals::<$n>::checked(block)
        },] $($rest)*);
    };
    (@table $table:ident [$($blocks:expr,)*] $(#[$m:meta])* $name:ident : $kind:ident = $def:expr; $($rest:tt)*) => {
        $crate::framework::variable_table::variable_table!(@table $table [$($blocks,)*
            &[$crate::framework::variable_table::$kind::checked($def)],] $($rest)*);
    };
}
pub(crate) use variable_table;

#[cfg(test)]
mod tests {
    use super::*;

    mod sample {
        use super::super::*;
        use crate::framework::variables::{Start, Variable};

        variable_table! {
            static TABLE;
            REF: Reals<2> = axis_block(&XY, &[AxisTemplate::input(("ref.", ""), ("Reference, ", AxisWord::Name, ""))
                .unit(AxisUnit::POSITION)]);
            TS: Real = Variable::parameter("Ts", Start::Real(1e-3), "Period");
            GAINS: Reals<4> = axis_block(
                &[Axis::linear("X", "X"), Axis::rotary("C", "C")],
                &[
                    AxisTemplate::parameter(("axis.", ".Kp"), (28.5, 20.0), ("", AxisWord::Label, " Kp")),
                    AxisTemplate::output(("vel.", ""), ("Velocity ", AxisWord::Label, ""))
                        .unit(AxisUnit::VELOCITY),
                ],
            );
            ON: Bool = Variable::parameter("on", Start::Boolean(true), "Switch");
        }

        pub fn table() -> &'static [Variable] {
            &TABLE
        }
    }

    #[test]
    fn numbers_in_order_and_builds_axis_blocks() {
        use sample::*;
        assert_eq!((REF.vr(), TS.vr(), GAINS.vr(), ON.vr()), (0, 2, 3, 7));
        assert_eq!(VARIABLE_COUNT, 8);
        let t = table();
        let names: Vec<String> = t.iter().map(|v| v.name.to_string()).collect();
        assert_eq!(
            names,
            [
                "ref.x",
                "ref.y",
                "Ts",
                "axis.X.Kp",
                "vel.X",
                "axis.C.Kp",
                "vel.C",
                "on"
            ]
        );
        assert!(t.iter().enumerate().all(|(i, v)| v.vr == i));
        assert_eq!(t[1].unit, Some("mm"));
        assert_eq!((t[4].unit, t[6].unit), (Some("mm/s"), Some("rad/s")));
        assert_eq!(
            (t[3].start, t[5].start),
            (Start::Real(28.5), Start::Real(20.0))
        );
        assert_eq!(t[5].description, "C Kp");
        let mut values = Values::from_table(t);
        GAINS.at(2).set(&mut values, 3.0);
        assert_eq!(GAINS.get(&values), [28.5, 0.0, 3.0, 0.0]);
        REF.set(&mut values, &Vector::<2>::new(1.0, 2.0));
        assert_eq!(REF.vector(&values), Vector::<2>::new(1.0, 2.0));
        assert!(ON.get(&values));
    }
}
