//! A run's per-sample errors summed up: their largest and their mean.
//!
//! The mean adds pairwise, in the blocks numpy's `add.reduce` uses, so the runner's means
//! of the controller's own outputs are the fmpy engine's bit for bit, and a long run's
//! rounding grows with log n rather than n.

/// The largest value; NaN when one is NaN or there are none.
pub fn max(values: &[f64]) -> f64 {
    if values.is_empty() || values.iter().any(|v| v.is_nan()) {
        return f64::NAN;
    }
    values.iter().copied().fold(f64::NEG_INFINITY, f64::max)
}

/// The mean; NaN when there are no values.
pub fn mean(values: &[f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    pairwise_sum(values) / values.len() as f64
}

/// Blocks up to this long are added along eight running sums.
const BLOCK: usize = 128;
const LANES: usize = 8;

fn pairwise_sum(values: &[f64]) -> f64 {
    let n = values.len();
    if n < LANES {
        return values.iter().fold(0.0, |sum, v| sum + v);
    }
    if n <= BLOCK {
        let mut lanes = [0.0; LANES];
        lanes.copy_from_slice(&values[..LANES]);
        let whole = n - n % LANES;
        for chunk in values[LANES..whole].chunks_exact(LANES) {
            for (lane, v) in lanes.iter_mut().zip(chunk) {
                *lane += v;
            }
        }
        let [a, b, c, d, e, f, g, h] = lanes;
        let mut sum = ((a + b) + (c + d)) + ((e + f) + (g + h));
        for v in &values[whole..] {
            sum += v;
        }
        return sum;
    }
    let half = n / 2;
    let half = half - half % LANES;
    pairwise_sum(&values[..half]) + pairwise_sum(&values[half..])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exact where every partial sum is exact (integers), and the pairwise order differs
    /// from the running one where it should: 1 + 2⁻⁵³ + … loses every small term when
    /// added in a row, keeps them paired.
    #[test]
    fn sums_pair_up_as_numpys_do() {
        for n in [1, 7, 8, 9, 127, 128, 129, 1000, 8193] {
            let values: Vec<f64> = (1..=n).map(|k| k as f64).collect();
            assert_eq!(mean(&values), (n as f64 + 1.0) / 2.0, "{n}");
        }
        let mut values = vec![1.0];
        values.extend(std::iter::repeat_n(f64::EPSILON / 2.0, 255));
        let running = values.iter().fold(0.0, |s, v| s + v);
        assert_eq!(running, 1.0);
        assert!(pairwise_sum(&values) > 1.0);
        assert!(mean(&[]).is_nan() && max(&[]).is_nan());
        assert!(max(&[1.0, f64::NAN, 3.0]).is_nan());
        assert_eq!(max(&[1.0, 3.0, 2.0]), 3.0);
    }
}
