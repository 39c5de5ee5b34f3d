//! The checks on a restored model state that reach every number in it, also the private
//! fields of the algorithm types (estimator geometry, PID memories, cached matrices):
//! the state is walked through its own `Serialize` implementation, which is exactly what
//! was saved, and every floating-point value is reported with its field path, e.g.
//! `controller.axes[0].integral` or `estimator.Arc.mode.Fixed.radius`.

use std::fmt;

use serde::ser::{self, Serialize};

/// `fn name(self, _: T) -> Done { Ok(()) }` for each `name: T`.
macro_rules! ignore_scalars {
    ($($name:ident: $ty:ty),* $(,)?) => {
        $(fn $name(self, _: $ty) -> Done {
            Ok(())
        })*
    };
}

/// One of serde's compound traits for [`Compound`], walking each value with `walk`
/// (`element` for positional values, `field` for named ones).
macro_rules! compound_impl {
    ($trait:ident, $method:ident, element) => {
        impl ser::$trait for Compound<'_, '_> {
            type Ok = ();
            type Error = WalkError;
            fn $method<T: Serialize + ?Sized>(&mut self, value: &T) -> Done {
                self.element(value)
            }
            fn end(self) -> Done {
                self.finish()
            }
        }
    };
    ($trait:ident, $method:ident, field) => {
        impl ser::$trait for Compound<'_, '_> {
            type Ok = ();
            type Error = WalkError;
            fn $method<T: Serialize + ?Sized>(&mut self, key: &'static str, value: &T) -> Done {
                self.field(key, value)
            }
            fn end(self) -> Done {
                self.finish()
            }
        }
    };
}

/// The floating-point values of `value` that `keep(path, x)`, with their field paths, in
/// serialisation order: only those are copied out (a restore checks every number of a
/// state, and nearly all pass).
fn walk<T: Serialize + ?Sized>(value: &T, keep: &dyn Fn(&str, f64) -> bool) -> Vec<(String, f64)> {
    let mut walker = Walker {
        path: String::new(),
        found: Vec::new(),
        keep,
    };
    // The walker itself never fails; a `Serialize` implementation that does (a custom
    // one refusing its own value) only shortens the list, and the decoder accepted it.
    let _ = value.serialize(&mut walker);
    walker.found
}

/// Refuses a non-finite number anywhere in `value`, naming the first one.
pub fn all_finite<T: Serialize + ?Sized>(value: &T) -> Result<(), String> {
    match walk(value, &|_, x| !x.is_finite()).into_iter().next() {
        Some((path, x)) => Err(format!("{path} = {x} is not finite")),
        None => Ok(()),
    }
}

/// Refuses a value ≤ 0 (or NaN) in any field named `field` (e.g. every `radius`).
pub fn all_positive<T: Serialize + ?Sized>(value: &T, field: &str) -> Result<(), String> {
    let wanted = |path: &str| {
        path.strip_suffix(field)
            .is_some_and(|head| head.is_empty() || head.ends_with('.'))
    };
    let bad = |path: &str, x: f64| (x.is_nan() || x <= 0.0) && wanted(path);
    match walk(value, &bad).into_iter().next() {
        Some((path, x)) => Err(format!("{path} = {x} must be > 0")),
        None => Ok(()),
    }
}

struct Walker<'k> {
    path: String,
    found: Vec<(String, f64)>,
    keep: &'k dyn Fn(&str, f64) -> bool,
}

impl Walker<'_> {
    /// Runs `f` with the field `name` appended to the path (`.name`).
    fn nested<R>(&mut self, name: &str, f: impl FnOnce(&mut Self) -> R) -> R {
        let len = self.path.len();
        if !self.path.is_empty() {
            self.path.push('.');
        }
        self.path.push_str(name);
        let result = f(self);
        self.path.truncate(len);
        result
    }

    /// Runs `f` with the element `[index]` appended to the path.
    fn indexed<R>(&mut self, index: usize, f: impl FnOnce(&mut Self) -> R) -> R {
        let len = self.path.len();
        fmt::Write::write_fmt(&mut self.path, format_args!("[{index}]"))
            .expect("a String takes every write");
        let result = f(self);
        self.path.truncate(len);
        result
    }
}

#[derive(Debug)]
pub struct WalkError(String);

impl fmt::Display for WalkError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for WalkError {}

impl ser::Error for WalkError {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        WalkError(msg.to_string())
    }
}

type Done = Result<(), WalkError>;

/// Sequences, tuples and variants' fields: elements are `[i]`, named fields `.name`; a
/// variant's name was pushed when it started and is popped at its end.
pub struct Compound<'a, 'k> {
    walker: &'a mut Walker<'k>,
    index: usize,
    /// Path length to restore at the end (the variant name's segment), if any.
    restore: Option<usize>,
}

impl Compound<'_, '_> {
    fn element<T: Serialize + ?Sized>(&mut self, value: &T) -> Done {
        let index = self.index;
        self.index += 1;
        self.walker.indexed(index, |w| value.serialize(w))
    }

    fn field<T: Serialize + ?Sized>(&mut self, key: &'static str, value: &T) -> Done {
        self.walker.nested(key, |w| value.serialize(w))
    }

    fn finish(self) -> Done {
        if let Some(len) = self.restore {
            self.walker.path.truncate(len);
        }
        Ok(())
    }
}

impl<'k> Walker<'k> {
    fn compound<'a>(&'a mut self, variant: Option<&'static str>) -> Compound<'a, 'k> {
        let restore = variant.map(|name| {
            let len = self.path.len();
            if !self.path.is_empty() {
                self.path.push('.');
            }
            self.path.push_str(name);
            len
        });
        Compound {
            walker: self,
            index: 0,
            restore,
        }
    }
}

impl<'a, 'k> ser::Serializer for &'a mut Walker<'k> {
    type Ok = ();
    type Error = WalkError;
    type SerializeSeq = Compound<'a, 'k>;
    type SerializeTuple = Compound<'a, 'k>;
    type SerializeTupleStruct = Compound<'a, 'k>;
    type SerializeTupleVariant = Compound<'a, 'k>;
    type SerializeMap = Compound<'a, 'k>;
    type SerializeStruct = Compound<'a, 'k>;
    type SerializeStructVariant = Compound<'a, 'k>;

    fn serialize_f64(self, v: f64) -> Done {
        if (self.keep)(&self.path, v) {
            self.found.push((self.path.clone(), v));
        }
        Ok(())
    }
    fn serialize_f32(self, v: f32) -> Done {
        self.serialize_f64(f64::from(v))
    }
    // Nothing but floats is collected.
    ignore_scalars! {
        serialize_bool: bool, serialize_i8: i8, serialize_i16: i16, serialize_i32: i32,
        serialize_i64: i64, serialize_u8: u8, serialize_u16: u16, serialize_u32: u32,
        serialize_u64: u64, serialize_char: char, serialize_str: &str, serialize_bytes: &[u8],
    }
    fn serialize_none(self) -> Done {
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Done {
        value.serialize(self)
    }
    fn serialize_unit(self) -> Done {
        Ok(())
    }
    fn serialize_unit_struct(self, _: &'static str) -> Done {
        Ok(())
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, _: &'static str) -> Done {
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(self, _: &'static str, value: &T) -> Done {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        value: &T,
    ) -> Done {
        self.nested(variant, |w| value.serialize(w))
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Compound<'a, 'k>, WalkError> {
        Ok(self.compound(None))
    }
    fn serialize_tuple(self, _: usize) -> Result<Compound<'a, 'k>, WalkError> {
        Ok(self.compound(None))
    }
    fn serialize_tuple_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> Result<Compound<'a, 'k>, WalkError> {
        Ok(self.compound(None))
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<Compound<'a, 'k>, WalkError> {
        Ok(self.compound(Some(variant)))
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Compound<'a, 'k>, WalkError> {
        Ok(self.compound(None))
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Compound<'a, 'k>, WalkError> {
        Ok(self.compound(None))
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<Compound<'a, 'k>, WalkError> {
        Ok(self.compound(Some(variant)))
    }
}

// Sequences, tuples and map values are walked as elements (`[i]`), struct fields by
// name; map keys are not walked (no state here uses numbers as keys).
compound_impl!(SerializeSeq, serialize_element, element);
compound_impl!(SerializeTuple, serialize_element, element);
compound_impl!(SerializeTupleStruct, serialize_field, element);
compound_impl!(SerializeTupleVariant, serialize_field, element);
compound_impl!(SerializeStruct, serialize_field, field);
compound_impl!(SerializeStructVariant, serialize_field, field);

impl ser::SerializeMap for Compound<'_, '_> {
    type Ok = ();
    type Error = WalkError;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, _: &T) -> Done {
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Done {
        self.element(value)
    }
    fn end(self) -> Done {
        self.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Serialize;

    #[derive(Serialize)]
    enum Shape {
        Circle { radius: f64 },
        Points(Vec<[f64; 2]>),
        Nothing,
    }

    #[derive(Serialize)]
    struct State {
        shapes: Vec<Shape>,
        memory: Option<f64>,
        count: u64,
        pair: (f32, f64),
    }

    fn sample() -> State {
        State {
            shapes: vec![
                Shape::Nothing,
                Shape::Circle { radius: 2.5 },
                Shape::Points(vec![[1.0, 2.0], [3.0, 4.0]]),
            ],
            memory: Some(-7.0),
            count: 3,
            pair: (0.5, 6.0),
        }
    }

    #[test]
    fn every_float_is_found_with_its_path() {
        let found = walk(&sample(), &|_, _| true);
        let expected: Vec<(String, f64)> = [
            ("shapes[1].Circle.radius", 2.5),
            ("shapes[2].Points[0][0]", 1.0),
            ("shapes[2].Points[0][1]", 2.0),
            ("shapes[2].Points[1][0]", 3.0),
            ("shapes[2].Points[1][1]", 4.0),
            ("memory", -7.0),
            ("pair[0]", 0.5),
            ("pair[1]", 6.0),
        ]
        .iter()
        .map(|(p, x)| (p.to_string(), *x))
        .collect();
        assert_eq!(found, expected);
    }

    #[test]
    fn non_finite_and_non_positive_values_are_named() {
        let mut s = sample();
        assert_eq!(all_finite(&s), Ok(()));
        assert_eq!(all_positive(&s, "radius"), Ok(()));
        s.memory = Some(f64::NAN);
        assert_eq!(all_finite(&s), Err("memory = NaN is not finite".into()));
        s.shapes[1] = Shape::Circle { radius: -1.0 };
        assert_eq!(
            all_positive(&s, "radius"),
            Err("shapes[1].Circle.radius = -1 must be > 0".into())
        );
        // Only fields with that exact name count.
        assert_eq!(all_positive(&s, "adius"), Ok(()));
    }
}
