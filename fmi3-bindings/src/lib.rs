//! The FMI 3.0 C types, constants, callback types and `fmi3...TYPE` function typedefs, as
//! bindgen makes them of the vendored headers (`third_party/fmi3/`): one copy of the ABI
//! for the exporter (the contour-fmu library) and the ABI tests. `cargo run -p xtask --
//! bindings` regenerates `bindings.rs`; it is kept as bindgen wrote it, since rustfmt would
//! make it differ from the generator's output.

#[rustfmt::skip]
mod bindings;

pub use bindings::*;
