//! A pass whose tool axis stays 0.3°–2.05° from vertical while its azimuth swings ±143°
//! (docs/design/five-axis.md §5.3b), written as NX writes CL data (inch, MSYS, FEDRAT/IPM):
//! the pass crosses the default pole cone (2°) again and again, and C must follow the
//! swing outside the cone and turn through it inside. Before the cone's band chose its
//! branch at both ends, such passes were refused ("no choice of branch and turn keeps A
//! and C within their travel", 1.99° from the C axis).

use contour_core::geometry;
use contour_core::kinematics::TableTiltingAc;
use contour_core::limits::{JointLimits, PathLimits};
use contour_core::math;
use contour_core::part_program::cl_data::parse_cl;
use contour_core::path::five_axis::plan_joints;

/// The pass as CL text: `n` GOTOs `step` inches apart along x, the axis tilted between
/// 0.3° and `max_tilt` degrees, its azimuth `swing`·sin(x / period).
fn nx_pass(n: usize, step: f64, max_tilt: f64, swing: f64, period: f64) -> String {
    let mut text = String::from(
        "TOOL PATH/NEAR_POLE,TOOL,BALL_125\nTLDATA/MILL,0.1250,0.0625,2.0000,0.0000,0.0000\n\
         MSYS/0.0000,0.0000,0.0000,1.0000000,0.0000000,0.0000000,0.0000000,1.0000000,0.0000000\n\
         PAINT/PATH\nFEDRAT/IPM,40.0000\n",
    );
    for i in 0..n {
        let x = i as f64 * step;
        let tilt = (0.3 + (max_tilt - 0.3) * 0.5 * (1.0 + math::sin(x / 0.12))).to_radians();
        let azimuth = swing * math::sin(x / period);
        let (st, ct) = math::sincos(tilt);
        text += &format!(
            "GOTO/{x:.4},{:.4},0.0000,{:.7},{:.7},{:.7}\n",
            0.01 * math::sin(x / 0.3),
            st * math::cos(azimuth),
            st * math::sin(azimuth),
            ct
        );
    }
    text + "END-OF-PATH\n"
}

#[test]
fn a_near_vertical_pass_with_the_azimuth_swinging_is_planned_within_the_travel() {
    let machine = TableTiltingAc::default();
    let joints = JointLimits::default();
    let limits = PathLimits::at_feed(20.0);
    let budget = 0.5 * limits.orientation_tolerance;
    for (step, swing, period) in [(0.004, 2.5, 0.2), (0.02, 2.5, 0.08), (0.004, 3.0, 0.8)] {
        let text = nx_pass(600, step, 2.05, swing, period);
        let program = parse_cl(&text, "near_pole.cls").unwrap();
        let poses = program.poses();
        // Inches read as inches.
        assert!((poses[1].tip[0] - 25.4 * step).abs() < 1e-9);
        let path = plan_joints(&poses, &[], &machine, &joints, &limits, 0.1, &|i| {
            format!("near_pole.cls: GOTO {}", i + 1)
        })
        .unwrap_or_else(|e| panic!("step {step} swing {swing} period {period}: {e}"));
        for (k, q) in path.joints.iter().enumerate() {
            let pose = machine.forward(q);
            let programmed = path.poses[k];
            assert!(
                geometry::dist(&pose.tip, &programmed.tip) < 1e-6,
                "node {k}: the tip"
            );
            let off = geometry::angle_between(&pose.axis, &programmed.axis);
            assert!(off <= budget * (1.0 + 1e-6) + 1e-12, "node {k}: {off}");
            assert!(
                q[3] >= joints.min[3] && q[3] <= joints.max[3],
                "node {k}: A {}",
                q[3]
            );
        }
        // C turns smoothly: no node-to-node jump of more than 0.2 rad.
        let jump = path
            .joints
            .windows(2)
            .map(|w| (w[1][4] - w[0][4]).abs())
            .fold(0.0, f64::max);
        assert!(jump <= 0.2, "step {step}: C jumps {jump} rad");
    }
}
