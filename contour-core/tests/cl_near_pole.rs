//! A pass whose tool axis stays 0.3°–2.05° from vertical while its azimuth swings ±143°
//! (docs/design/five-axis.md §5.3b), written as NX writes CL data (inch, MSYS, FEDRAT/IPM):
//! the pass crosses the default pole cone (2°) again and again, and C must follow the
//! swing outside the cone and turn through it inside. Before the cone's band chose its
//! branch at both ends, such passes were refused ("no choice of branch and turn keeps A
//! and C within their travel", 1.99° from the C axis).

use contour_core::geometry;
use contour_core::kinematics::TableTiltingAc;
use contour_core::limits::{JointLimits, PathLimits};
use contour_core::part_program::cl_data::parse_cl;
use contour_core::path::five_axis::{cam_examples::nx_near_pole_pass as nx_pass, plan_joints};

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
