//! One evaluation of the fuzzy gain scheduler (all three outputs), the per-sample cost
//! the CCC adds in fuzzy mode. Target: well under 1 µs.

use std::hint::black_box;

use contour_core::control::evaluate_table;
use contour_core::control::FuzzyEngine;
use contour_core::control::KP_RULES;
use criterion::{criterion_group, criterion_main, Criterion};

/// Inputs spread over [−3.5, 3.5]² (clamping included), cycled so that the branch
/// predictor cannot settle on one rule block.
fn inputs() -> Vec<(f64, f64)> {
    let mut s: u64 = 0x853c_49e6_748f_ea9b;
    let mut next = || {
        s = s
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (s >> 11) as f64 / (1u64 << 53) as f64 * 7.0 - 3.5
    };
    (0..1024).map(|_| (next(), next())).collect()
}

fn bench_fuzzy(c: &mut Criterion) {
    let engine = FuzzyEngine::default();
    let points = inputs();
    let mut k = 0;
    c.bench_function("fuzzy/evaluate_three_outputs", |b| {
        b.iter(|| {
            let (e, ec) = points[k & 1023];
            k += 1;
            engine.evaluate(black_box(e), black_box(ec))
        })
    });
    let mut k = 0;
    c.bench_function("fuzzy/evaluate_one_table", |b| {
        b.iter(|| {
            let (e, ec) = points[k & 1023];
            k += 1;
            evaluate_table(black_box(&KP_RULES), black_box(e), black_box(ec))
        })
    });
    c.bench_function("fuzzy/evaluate_fixed_point", |b| {
        b.iter(|| engine.evaluate(black_box(0.4), black_box(-1.7)))
    });
}

criterion_group!(benches, bench_fuzzy);
criterion_main!(benches);
