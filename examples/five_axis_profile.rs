use contour_fmu::control::{CccMode, FiveAxisConfig, FiveAxisController};
use contour_fmu::kinematics::Joints;
fn main() {
    let q = |k: usize| {
        let t = k as f64 * 2.5e-3;
        Joints::new(
            30.0 + 20.0 * t.cos(),
            10.0 + 20.0 * t.sin(),
            0.8 * t,
            0.35 + 0.1 * (0.3 * t).sin(),
            t,
        )
    };
    let mut c = FiveAxisController::new(FiveAxisConfig::DEFAULT.with_mode(CccMode::Fuzzy)).unwrap();
    let mut s = 0.0;
    for k in 0..5000usize {
        s += c
            .sample(&q(k), &(q(k.saturating_sub(35)) + Joints::repeat(2e-3)))
            .unwrap()
            .u[0];
    }
    println!("{s}");
}
