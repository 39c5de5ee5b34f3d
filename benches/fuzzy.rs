//! Fuzzy-engine benchmark (in progress).

fn main() {}
