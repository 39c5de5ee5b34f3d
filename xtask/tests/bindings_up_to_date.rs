//! The committed FMI 2.0 and FMI 3.0 bindings are exactly what bindgen makes of the vendored headers
//! (`cargo run -p xtask -- bindings` regenerates them). Needs libclang (Debian:
//! libclang-dev); the FMU library itself builds without it.

#[test]
fn committed_bindings_equal_bindgen_output() {
    let generate = || {
        xtask::generate().unwrap_or_else(|e| {
            panic!(
                "cannot generate the bindings (is libclang installed? Debian: libclang-dev): {e}"
            )
        })
    };
    let outputs = generate();

    // Nothing local leaks into the files, and a second run gives the same bytes.
    let root = xtask::workspace_root();
    for output in &outputs {
        let root = root.to_string_lossy();
        assert!(
            !output.contents.contains(&*root),
            "{} names a local path",
            output.path
        );
        assert!(
            !output.contents.contains("clang version"),
            "{} names a clang version",
            output.path
        );
    }
    assert_eq!(generate(), outputs, "two runs of bindgen disagree");

    let stale: Vec<String> = outputs
        .iter()
        .filter_map(|output| {
            xtask::drift(&root, output).map(|drift| format!("{} {drift}", output.path))
        })
        .collect();
    assert!(
        stale.is_empty(),
        "out of date: {}; run `cargo run -p xtask -- bindings` and commit the result",
        stale.join("; ")
    );
}
