//! The packager's pieces: each model's `modelDescription.xml` and documentation are
//! rendered from its variable table, for FMI 2.0 and for FMI 3.0, then zipped with each
//! platform's shared library (built and checked first; one library serves both standards)
//! into a `.fmu`.

pub mod binary_check;
pub mod documentation;
pub mod model_description;
pub mod package;
pub mod platform;
pub mod standard;

/// Escapes text for XML/HTML attribute values and element content.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            _ => out.push(c),
        }
    }
    out
}
