//! Table-tilting A–C five-axis machine (docs/design/five-axis.md §5.1): the linear axes X, Y, Z move
//! the tool; the workpiece sits on a C table (about the Z direction) carried by an A
//! cradle (about the X direction). Joints q = (X, Y, Z, A, C) in mm and rad; the tool tip
//! p and the unit tool axis o are expressed in the workpiece frame.
//!
//! With the C axis through `c_pivot` and the A axis through `a_pivot` (machine frame,
//! both zero by default), a workpiece point w sits in the machine at
//!   P = Rx(A)·(Rz(C)·(w − c) + c − a) + a,
//! so the tip P = (X, Y, Z) is at w = Rz(−C)·(Rx(−A)·(P − a) + a − c) + c, and the tool
//! axis (machine +Z) is o = Rz(−C)·Rx(−A)·e_z = (sC·sA, cC·sA, cA). With zero pivots this
//! is LinuxCNC's A–C trunnion convention.
//!
//! Inverse on the A ≥ 0 branch: A = atan2(|o_xy|, o_z) (acos(o_z) would lose digits near
//! A = 0, its error growing as eps/A), C = atan2(o_x, o_y) unwrapped to the turn
//! nearest the previous C. At A = 0 (tool along the C axis) C does not move the tool
//! axis: the previous C is kept, and the Jacobian loses rank (the controller damps it).

use crate::math;
use nalgebra::{Matrix3, SMatrix};
use serde::{Deserialize, Serialize};

use crate::geometry::Vector;

/// Machine joints (X, Y, Z mm; A, C rad).
pub type Joints = Vector<5>;

/// ∂(p, o)/∂(X, Y, Z, A, C): rows p_x, p_y, p_z, o_x, o_y, o_z.
pub type Jacobian = SMatrix<f64, 6, 5>;

/// A tool pose in the workpiece frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Tool tip, mm.
    pub tip: Vector<3>,
    /// Unit tool axis (from the tip toward the spindle).
    pub axis: Vector<3>,
}

/// Below this sin A (A < 1e-9 rad) the tool counts as parallel to the C axis: C no longer
/// turns it measurably, so C is held.
const VERTICAL: f64 = 1e-9;

/// The machine's geometry.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TableTiltingAc {
    /// A point of the A axis (machine frame, mm); only its y and z matter.
    pub a_pivot: Vector<3>,
    /// A point of the C axis at A = 0 (machine frame, mm); only its x and y matter.
    pub c_pivot: Vector<3>,
}

impl TableTiltingAc {
    /// Both axes through the origin (LinuxCNC's convention).
    pub const ORIGIN: TableTiltingAc = TableTiltingAc {
        a_pivot: Vector::<3>::new(0.0, 0.0, 0.0),
        c_pivot: Vector::<3>::new(0.0, 0.0, 0.0),
    };
}

impl Default for TableTiltingAc {
    fn default() -> Self {
        Self::ORIGIN
    }
}

fn rx(angle: f64) -> Matrix3<f64> {
    let (s, c) = math::sincos(angle);
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

fn rz(angle: f64) -> Matrix3<f64> {
    let (s, c) = math::sincos(angle);
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// d/dθ of rx(θ) and rz(θ).
fn drx(angle: f64) -> Matrix3<f64> {
    let (s, c) = math::sincos(angle);
    Matrix3::new(0.0, 0.0, 0.0, 0.0, -s, -c, 0.0, c, -s)
}

fn drz(angle: f64) -> Matrix3<f64> {
    let (s, c) = math::sincos(angle);
    Matrix3::new(-s, -c, 0.0, c, -s, 0.0, 0.0, 0.0, 0.0)
}

/// `angle` plus the whole turns that bring it nearest to `near`.
pub fn unwrap_near(angle: f64, near: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    angle + ((near - angle) / tau).round() * tau
}

/// The rotary angles of a unit tool axis on the A ≥ 0 branch: its tilt from the C axis,
/// A = atan2(|o_xy|, o_z), and its azimuth C = atan2(o_x, o_y) in (−π, π] (meaningless
/// when A = 0). The other branch is (−A, C + π).
pub fn axis_angles(axis: &Vector<3>) -> (f64, f64) {
    (
        math::atan2(math::hypot(axis[0], axis[1]), axis[2]),
        math::atan2(axis[0], axis[1]),
    )
}

impl TableTiltingAc {
    /// Tip and tool axis in the workpiece frame for joints `q`.
    pub fn forward(&self, q: &Joints) -> Pose {
        let machine = Vector::<3>::new(q[0], q[1], q[2]);
        let (ra, rc) = (rx(-q[3]), rz(-q[4]));
        let (a, c) = (self.a_pivot, self.c_pivot);
        Pose {
            tip: rc * (ra * (machine - a) + a - c) + c,
            // rc·ra·e_z, as the column of ra it picks (the same sums, without the products
            // by zero: bit for bit the full product).
            axis: rc * ra.column(2),
        }
    }

    /// Joints that put the tool at `pose` (A ≥ 0; C the turn nearest `previous_c`, held
    /// when the tool is along the C axis). The axis need not be normalised; a zero or
    /// non-finite pose gives `None`.
    pub fn inverse(&self, pose: &Pose, previous_c: f64) -> Option<Joints> {
        let length = crate::geometry::norm(&pose.axis);
        if !(length > 0.0 && length.is_finite() && crate::geometry::is_finite(&pose.tip)) {
            return None;
        }
        let o = pose.axis / length;
        let sideways = math::hypot(o[0], o[1]);
        let a_angle = math::atan2(sideways, o[2]);
        let c_angle = if sideways < VERTICAL || !previous_c.is_finite() {
            if previous_c.is_finite() {
                previous_c
            } else {
                0.0
            }
        } else {
            unwrap_near(math::atan2(o[0], o[1]), previous_c)
        };
        Some(self.joints_at(&pose.tip, a_angle, c_angle))
    }

    /// The joints that put the tool tip at workpiece point `tip` with the rotary axes at
    /// `a` and `c` (rad): the linear axes follow the table.
    pub fn joints_at(&self, tip: &Vector<3>, a: f64, c: f64) -> Joints {
        let (pa, pc) = (self.a_pivot, self.c_pivot);
        let machine = rx(a) * (rz(c) * (tip - pc) + pc - pa) + pa;
        Joints::new(machine[0], machine[1], machine[2], a, c)
    }

    /// ∂(tip, axis)/∂q at `q`, analytic.
    pub fn jacobian(&self, q: &Joints) -> Jacobian {
        let machine = Vector::<3>::new(q[0], q[1], q[2]);
        let (ra, rc) = (rx(-q[3]), rz(-q[4]));
        // d/dA of rx(−A) is −drx(−A); likewise for C.
        let (dra, drc) = (-drx(-q[3]), -drz(-q[4]));
        let (a, c) = (self.a_pivot, self.c_pivot);
        let inner = ra * (machine - a) + a - c;
        let ez = Vector::<3>::z();
        let mut j = Jacobian::zeros();
        j.fixed_view_mut::<3, 3>(0, 0).copy_from(&(rc * ra));
        j.fixed_view_mut::<3, 1>(0, 3)
            .copy_from(&(rc * dra * (machine - a)));
        j.fixed_view_mut::<3, 1>(0, 4).copy_from(&(drc * inner));
        j.fixed_view_mut::<3, 1>(3, 3).copy_from(&(rc * dra * ez));
        j.fixed_view_mut::<3, 1>(3, 4).copy_from(&(drc * ra * ez));
        j
    }
}

/// Joint increments for a workpiece-frame correction `e` (tip mm, orientation rad) by
/// damped least squares, Δq = Jᵀ·(J·Jᵀ + μ²·I)⁻¹·e (docs/design/five-axis.md §5.4): the
/// least-squares solution for μ = 0 where J has full rank, kept bounded near the A = 0
/// singularity by μ > 0. Computed in the equal form (JᵀJ + μ²·I)⁻¹·Jᵀ·e: J is 6 × 5, so
/// J·Jᵀ is always singular and the 6 × 6 system loses digits as μ → 0, while the 5 × 5
/// one is positive definite wherever J has full rank. `None` when Cholesky fails (μ = 0
/// at a singular pose).
pub fn damped_least_squares(jacobian: &Jacobian, e: &Vector<6>, mu: f64) -> Option<Joints> {
    damped_least_squares_per_joint(jacobian, e, &Joints::repeat(mu))
}

/// [`damped_least_squares`] with a damping of its own for each joint, (JᵀJ + D²)⁻¹·Jᵀ·e
/// with D = diag(`mu`): a joint whose motion alone grows without bound near a
/// singularity (C at A = 0) is damped there without slowing the others. |Δq| ≤
/// |e|/min μᵢ (Δq = 0 costs |e|², so μ²_min·|Δq|² cannot exceed it).
pub fn damped_least_squares_per_joint(
    jacobian: &Jacobian,
    e: &Vector<6>,
    mu: &Joints,
) -> Option<Joints> {
    let damping = SMatrix::<f64, 5, 5>::from_diagonal(&mu.component_mul(mu));
    let system = jacobian.transpose() * jacobian + damping;
    Some(system.cholesky()?.solve(&(jacobian.transpose() * e)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn machine() -> TableTiltingAc {
        TableTiltingAc {
            a_pivot: Vector::<3>::new(0.0, 12.0, -40.0),
            c_pivot: Vector::<3>::new(3.0, -5.0, 0.0),
        }
    }

    fn joints() -> Vec<Joints> {
        vec![
            Joints::new(10.0, -20.0, 35.0, 0.3, 1.1),
            Joints::new(-50.0, 7.5, 80.0, 1.2, -2.9),
            Joints::new(0.0, 0.0, 100.0, 0.0, 0.4),
            Joints::new(25.0, 30.0, -10.0, 0.01, 6.0),
        ]
    }

    #[test]
    fn forward_is_the_written_out_trunnion_formula_without_pivots() {
        // docs/design/five-axis.md §5.1, term by term.
        let m = TableTiltingAc::default();
        for q in joints() {
            let (x, y, z) = (q[0], q[1], q[2]);
            let (sa, ca) = math::sincos(q[3]);
            let (sc, cc) = math::sincos(q[4]);
            let pose = m.forward(&q);
            let tip = Vector::<3>::new(
                cc * x + sc * ca * y + sc * sa * z,
                -sc * x + cc * ca * y + cc * sa * z,
                -sa * y + ca * z,
            );
            let axis = Vector::<3>::new(sc * sa, cc * sa, ca);
            assert!((pose.tip - tip).amax() < 1e-12, "{q:?}");
            assert!((pose.axis - axis).amax() < 1e-15, "{q:?}");
        }
    }

    #[test]
    fn pivots_rotate_about_the_axes_where_they_are() {
        // The table as rigid motions: a workpiece point w is turned by C about the C axis
        // through c, then by A about the A axis through a (nalgebra isometries about a
        // point). The tip that touches w is where w ends up; forward must bring it back.
        use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion};
        let m = machine();
        let about = |centre: Vector<3>, axis: Vector<3>, angle: f64| {
            let to = Translation3::from(centre);
            let rot = UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle);
            Isometry3::from_parts(to, UnitQuaternion::identity())
                * Isometry3::from_parts(Translation3::identity(), rot)
                * Isometry3::from_parts(to.inverse(), UnitQuaternion::identity())
        };
        for q in joints() {
            let w = Point3::new(7.0, -3.0, 22.0);
            let table =
                about(m.a_pivot, Vector::<3>::x(), q[3]) * about(m.c_pivot, Vector::<3>::z(), q[4]);
            let machine_point = table * w;
            let mut at = q;
            at[0] = machine_point.x;
            at[1] = machine_point.y;
            at[2] = machine_point.z;
            let pose = m.forward(&at);
            assert!((pose.tip - w.coords).amax() < 1e-12, "{q:?}");
            // The tool axis (machine +Z) seen from the table.
            let axis = table.rotation.inverse() * Vector::<3>::z();
            assert!((pose.axis - axis).amax() < 1e-15);
        }
    }

    #[test]
    fn inverse_recovers_the_joints_on_the_a_positive_branch() {
        let m = machine();
        for q in joints() {
            let pose = m.forward(&q);
            let back = m.inverse(&pose, q[4] + 0.1).unwrap();
            if q[3] > 0.0 {
                assert!((back - q).amax() < 1e-9, "{q:?} -> {back:?}");
            } else {
                // Vertical tool: C is held at the given previous value, and the pose is
                // still reached.
                assert_eq!(back[4], q[4] + 0.1);
                let again = m.forward(&back);
                assert!((again.tip - pose.tip).amax() < 1e-9);
                assert!((again.axis - pose.axis).amax() < 1e-15);
            }
        }
        // The A < 0 branch maps to A > 0 with C turned by π: the same pose.
        let q = Joints::new(5.0, 6.0, 7.0, -0.5, 0.3);
        let pose = m.forward(&q);
        let back = m.inverse(&pose, 0.3).unwrap();
        assert!(back[3] > 0.0);
        let again = m.forward(&back);
        assert!((again.tip - pose.tip).amax() < 1e-9);
        assert!((again.axis - pose.axis).amax() < 1e-12);
        assert!(m
            .inverse(
                &Pose {
                    tip: pose.tip,
                    axis: Vector::zeros()
                },
                0.0
            )
            .is_none());
        let nan = Pose {
            tip: Vector::<3>::new(f64::NAN, 0.0, 0.0),
            axis: pose.axis,
        };
        assert!(m.inverse(&nan, 0.0).is_none());
    }

    #[test]
    fn c_is_unwrapped_to_the_nearest_turn() {
        let m = TableTiltingAc::default();
        let q = Joints::new(1.0, 2.0, 3.0, 0.7, 0.2 + 4.0 * std::f64::consts::TAU);
        let back = m.inverse(&m.forward(&q), q[4] - 0.5).unwrap();
        assert!((back[4] - q[4]).abs() < 1e-9, "{}", back[4]);
    }

    #[test]
    fn jacobian_matches_central_differences() {
        let m = machine();
        for q in joints() {
            let j = m.jacobian(&q);
            for k in 0..5 {
                let h = 1e-6;
                let mut qp = q;
                let mut qm = q;
                qp[k] += h;
                qm[k] -= h;
                let (fp, fm) = (m.forward(&qp), m.forward(&qm));
                for r in 0..3 {
                    let dp = (fp.tip[r] - fm.tip[r]) / (2.0 * h);
                    let dpo = (fp.axis[r] - fm.axis[r]) / (2.0 * h);
                    assert!(
                        (j[(r, k)] - dp).abs() < 1e-6 * (1.0 + dp.abs()),
                        "p{r}/q{k}"
                    );
                    assert!((j[(3 + r, k)] - dpo).abs() < 1e-8, "o{r}/q{k}");
                }
            }
        }
    }

    #[test]
    fn the_jacobian_loses_rank_only_with_a_vertical_tool() {
        let m = machine();
        let rank = |q: Joints| m.jacobian(&q).svd(false, false).rank(1e-9);
        assert_eq!(rank(Joints::new(1.0, 2.0, 3.0, 0.4, 1.0)), 5);
        assert_eq!(rank(Joints::new(1.0, 2.0, 3.0, 0.0, 1.0)), 4);
    }

    #[test]
    fn damped_least_squares_is_the_pseudo_inverse_without_damping_and_bounded_with_it() {
        let m = machine();
        let e = Vector::<6>::new(0.1, -0.2, 0.05, 0.01, -0.02, 0.003);
        // Full rank: μ → 0 gives the Moore–Penrose solution (nalgebra's SVD pseudo-inverse).
        let q = Joints::new(1.0, 2.0, 3.0, 0.6, 0.4);
        let j = m.jacobian(&q);
        let pinv = j.pseudo_inverse(1e-12).unwrap() * e;
        let dls = damped_least_squares(&j, &e, 0.0).unwrap();
        assert!((dls - pinv).amax() < 1e-9, "{dls:?} vs {pinv:?}");
        // Near A = 0 the undamped solution blows up in C; the damped one stays bounded by
        // |e|/(2μ) (the largest gain of σ/(σ² + μ²)).
        let near = Joints::new(1.0, 2.0, 3.0, 1e-7, 0.4);
        let j = m.jacobian(&near);
        let mu = 0.05;
        let dq = damped_least_squares(&j, &e, mu).unwrap();
        let bound = crate::geometry::norm(&e) / (2.0 * mu);
        assert!(crate::geometry::norm(&dq) <= bound * (1.0 + 1e-9), "{dq:?}");
        let free = j.pseudo_inverse(1e-30).unwrap() * e;
        assert!(crate::geometry::norm(&free) > 100.0 * bound);
    }
}
