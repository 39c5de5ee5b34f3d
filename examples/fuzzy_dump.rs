//! Prints the fuzzy engine's three outputs on an n × n grid of (E, EC) over [−3, 3]² as
//! JSON, for the scikit-fuzzy cross-check in `tests/reference/test_fuzzy_skfuzzy.py`.
//!
//! Usage: `cargo run --release --example fuzzy_dump -- [n]` (default n = 61).
//! Output: `{"grid": [..n values..], "dkp": [[..]], "dki": [[..]], "dkd": [[..]]}` with
//! `dkp[i][j]` the output for E = grid[i], EC = grid[j].

use contour_core::control::FuzzyEngine;

fn main() {
    let n: usize = match std::env::args().nth(1) {
        Some(arg) => arg.parse().expect("grid size must be an integer"),
        None => 61,
    };
    assert!(n >= 2, "grid size must be at least 2");
    // Same points as numpy.linspace(-3, 3, n): −3 + 6·k/(n − 1).
    let grid: Vec<f64> = (0..n)
        .map(|k| -3.0 + 6.0 * k as f64 / (n - 1) as f64)
        .collect();
    let engine = FuzzyEngine::default();
    let mut out = [
        vec![vec![0.0; n]; n],
        vec![vec![0.0; n]; n],
        vec![vec![0.0; n]; n],
    ];
    for (i, &e) in grid.iter().enumerate() {
        for (j, &ec) in grid.iter().enumerate() {
            let r = engine.evaluate(e, ec);
            out[0][i][j] = r.dkp;
            out[1][i][j] = r.dki;
            out[2][i][j] = r.dkd;
        }
    }
    let [dkp, dki, dkd] = out;
    let json = serde_json::json!({ "grid": grid, "dkp": dkp, "dki": dki, "dkd": dkd });
    println!("{json}");
}
