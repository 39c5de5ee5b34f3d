//! Poses shaped like a five-axis CAM system's CL data, for tests and benchmarks: the tool
//! normal to a surface, through or beside vertical (docs/design/five-axis.md §5.3b). The
//! Python package writes the same shapes as CL files (`contour_fmu.demo.cam_paths`).

use crate::geometry::Vector;
use crate::kinematics::Pose;
use crate::math;

/// A straight pass along x of `length` mm in `step` mm CL steps, the tool axis tilting
/// from +`tilt` to −`tilt` about y (rad), `beside` rad to the side of vertical (0: through
/// it).
pub fn tilting_pass(beside: f64, length: f64, step: f64, tilt: f64) -> Vec<Pose> {
    let n = (length / step).round().max(1.0) as usize;
    (0..=n)
        .map(|i| {
            let f = i as f64 / n as f64;
            let theta = tilt * (1.0 - 2.0 * f);
            Pose {
                tip: Vector::<3>::new(-length / 2.0 + length * f, 0.0, 0.0),
                axis: Vector::<3>::new(
                    math::sin(theta) * math::cos(beside),
                    math::sin(beside),
                    math::cos(theta) * math::cos(beside),
                ),
            }
        })
        .collect()
}

/// A finishing raster over a hemisphere of `radius` mm centred at the origin, the tool
/// normal to the surface: 2·`passes` + 1 passes along x, zigzag, `stepover` mm apart, the
/// middle one `offset` mm beside the apex, `step` mm between CL points, within `within`
/// rad of the apex.
pub fn dome_raster(
    radius: f64,
    stepover: f64,
    passes: i32,
    step: f64,
    within: f64,
    offset: f64,
) -> Vec<Pose> {
    let mut poses = Vec::new();
    for (k, j) in (-passes..=passes).enumerate() {
        let y = stepover * j as f64 + offset;
        let half = ((radius * math::sin(within)).powi(2) - y * y)
            .max(0.0)
            .sqrt();
        let steps = (2.0 * half / step).ceil().max(1.0) as usize;
        for i in 0..=steps {
            let f = i as f64 / steps as f64;
            let f = if k % 2 == 0 { f } else { 1.0 - f };
            let x = -half + 2.0 * half * f;
            let tip = Vector::<3>::new(x, y, (radius * radius - x * x - y * y).sqrt());
            poses.push(Pose {
                tip,
                axis: tip / radius,
            });
        }
    }
    poses
}
