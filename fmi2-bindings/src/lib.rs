//! The FMI 2.0 C types, constants, callback-functions struct and `fmi2...TYPE` function
//! typedefs, as bindgen makes them of the vendored headers (`third_party/fmi2/`): one copy
//! of the ABI for the exporter (the contour-fmu library) and the importers (contour-cosim,
//! the ABI tests). `cargo run -p xtask -- bindings` regenerates `bindings.rs`; it is kept
//! as bindgen wrote it, since rustfmt would make it differ from the generator's output.

#[rustfmt::skip]
mod bindings;

pub use bindings::*;
