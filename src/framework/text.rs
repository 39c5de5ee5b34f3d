//! Names and descriptions that a constant table can build from pieces (`"axis."`, `"x"`,
//! `".Kp"`): `const fn`s cannot concatenate strings, so a [`Text`] keeps up to three
//! static parts and joins them when it is printed or compared.

use std::fmt;

/// Up to three static strings read as one (compared and hashed as the joined text).
#[derive(Clone, Copy, Debug)]
pub struct Text {
    parts: [&'static str; 3],
}

impl Text {
    /// One string.
    pub const fn plain(text: &'static str) -> Self {
        Text {
            parts: [text, "", ""],
        }
    }

    /// `a` followed by `b` and `c`.
    pub const fn join(a: &'static str, b: &'static str, c: &'static str) -> Self {
        Text { parts: [a, b, c] }
    }

    /// The joined text's bytes.
    fn bytes(&self) -> impl Iterator<Item = u8> + '_ {
        self.parts.iter().flat_map(|p| p.bytes())
    }
}

impl PartialEq for Text {
    fn eq(&self, other: &Text) -> bool {
        self.bytes().eq(other.bytes())
    }
}

impl Eq for Text {}

impl std::hash::Hash for Text {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.parts.iter().for_each(|p| state.write(p.as_bytes()));
        state.write_u8(0xff);
    }
}

impl fmt::Display for Text {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.parts.iter().try_for_each(|p| f.write_str(p))
    }
}

impl PartialEq<str> for Text {
    fn eq(&self, other: &str) -> bool {
        let mut rest = other;
        for part in self.parts {
            match rest.strip_prefix(part) {
                Some(r) => rest = r,
                None => return false,
            }
        }
        rest.is_empty()
    }
}

impl PartialEq<&str> for Text {
    fn eq(&self, other: &&str) -> bool {
        *self == **other
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joins_and_compares_as_one_string() {
        let t = Text::join("axis.", "x", ".Kp");
        assert_eq!(t.to_string(), "axis.x.Kp");
        assert_eq!(t, "axis.x.Kp");
        assert_ne!(t, "axis.x.K");
        assert_ne!(t, "axis.x.Kpp");
        assert_eq!(Text::plain("Ts"), "Ts");
        // Equal texts are equal however they are split, and hash alike.
        let whole = Text::plain("axis.x.Kp");
        assert_eq!(t, whole);
        assert_ne!(t, Text::plain("axis.y.Kp"));
        let set: std::collections::HashSet<Text> = [t, whole].into_iter().collect();
        assert_eq!(set.len(), 1);
    }
}
