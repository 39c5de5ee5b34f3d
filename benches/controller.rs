//! Controller-sample benchmark (in progress).

fn main() {}
