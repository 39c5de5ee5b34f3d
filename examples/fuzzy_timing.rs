//! Times the fuzzy engine (all three outputs per evaluation) and prints JSON
//! `{"evaluations": N, "ns_per_eval": x}`; used by `benches/fuzzy_vs_skfuzzy.py`.
//!
//! Usage: `cargo run --release --example fuzzy_timing -- [N]` (default 2 000 000).
//! Inputs sweep pseudo-randomly over [−3.5, 3.5]² (clamping included) so branch
//! prediction cannot memorise a single point.

use std::hint::black_box;
use std::time::Instant;

use contour_core::control::FuzzyEngine;

fn main() {
    let n: usize = match std::env::args().nth(1) {
        Some(arg) => arg.parse().expect("evaluation count must be an integer"),
        None => 2_000_000,
    };
    let inputs: Vec<(f64, f64)> = {
        let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 7.0 - 3.5
        };
        (0..4096).map(|_| (next(), next())).collect()
    };
    let engine = FuzzyEngine::default();
    let mut sink = 0.0;
    // Warm-up, then the timed run.
    for &(e, ec) in inputs.iter().cycle().take(n / 10 + 1) {
        sink += black_box(&engine).evaluate(black_box(e), black_box(ec)).dkp;
    }
    let start = Instant::now();
    for &(e, ec) in inputs.iter().cycle().take(n) {
        let r = black_box(&engine).evaluate(black_box(e), black_box(ec));
        sink += r.dkp + r.dki + r.dkd;
    }
    let elapsed = start.elapsed();
    black_box(sink);
    let ns = elapsed.as_secs_f64() * 1e9 / n as f64;
    println!(
        "{}",
        serde_json::json!({ "evaluations": n, "ns_per_eval": ns })
    );
}
