//! Planar joints (URDF `type="planar"`): placements worked out by hand, Jacobians against finite
//! differences of the placements, the configuration moves on SE(2), RNEA against Newton-Euler
//! worked out by hand, and Pinocchio's `(x, y, cos θ, sin θ)` layout.

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

mod common;

use anim_core::glam::{DMat3, DVec3};
use anim_core::lie::{Se3, Twist};
use anim_rigid::config::{difference, integrate};
use anim_rigid::pinocchio::{from_pinocchio, nq, to_pinocchio};
use anim_rigid::{
    Axis, Data, FrameKind, Jacobian, JointType, Model, ReferenceFrame, UrdfOptions, aba,
    compute_joint_jacobians, crba, frame_jacobian, frames_forward_kinematics, parse_urdf, rnea,
};
use common::se3_err;

/// A planar base with normal `normal`, then a revolute joint about z 0.5 m along x, carrying a
/// body with its centre of mass off the joint.
fn robot(normal: &str) -> Model {
    let xml = format!(
        r#"<robot name="p">
  <link name="a"/>
  <link name="b"><inertial><mass value="2"/><inertia ixx="0.1" iyy="0.2" izz="0.3"/></inertial></link>
  <link name="c"><inertial><origin xyz="0.2 0.1 0"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.02" izz="0.03"/></inertial></link>
  <joint name="base" type="planar"><parent link="a"/><child link="b"/>
    <origin xyz="0 0 0.3" rpy="0.1 0 0"/><axis xyz="{normal}"/><limit effort="1" velocity="1"/></joint>
  <joint name="arm" type="revolute"><parent link="b"/><child link="c"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>"#
    );
    parse_urdf(&xml, &UrdfOptions::default()).unwrap()
}

fn rz(t: f64) -> DMat3 {
    let (s, c) = t.sin_cos();
    DMat3::from_cols(DVec3::new(c, s, 0.0), DVec3::new(-s, c, 0.0), DVec3::Z)
}

#[test]
fn a_planar_joint_loads_and_moves_in_its_plane() {
    let m = robot("0 0 1");
    assert_eq!(m.joint(1).kind, JointType::Planar(Axis::Z));
    assert_eq!((m.nq(), m.nv(), m.njoints()), (4, 4, 3));
    assert!(!m.is_euclidean());
    let mut d = Data::new(&m);
    let q = [0.3, -0.7, 1.1, 0.4];
    frames_forward_kinematics(&m, &mut d, &q);
    // b: origin · (Rz(θ), (x, y, 0)); c: b · (I, (0.5, 0, 0)) · Rz(φ).
    let origin = Se3::new(anim_rigid::urdf::rpy_to_matrix(0.1, 0.0, 0.0), DVec3::new(0.0, 0.0, 0.3));
    let b = origin * Se3::new(rz(1.1), DVec3::new(0.3, -0.7, 0.0));
    let c = b * Se3::new(rz(0.4), DVec3::new(0.5, 0.0, 0.0));
    let fb = m.frame_id_of_kind("b", FrameKind::Body).unwrap();
    let fc = m.frame_id_of_kind("c", FrameKind::Body).unwrap();
    assert!(se3_err(&d.frame_placements[fb], &b) < 1e-15);
    assert!(se3_err(&d.frame_placements[fc], &c) < 1e-15);
    // The plane basis of the other axes: (y, z) about x, (z, x) about y.
    assert_eq!(Axis::X.plane_basis(), (DVec3::Y, DVec3::Z));
    assert_eq!(Axis::Y.plane_basis(), (DVec3::Z, DVec3::X));
    let n = DVec3::new(1.0, 2.0, 2.0) / 3.0;
    let (e1, e2) = Axis::Unaligned(n).plane_basis();
    assert!(e1.dot(n).abs() < 1e-16 && e2.dot(n).abs() < 1e-16 && (e1.cross(e2) - n).length() < 1e-15);
}

#[test]
fn jacobians_match_finite_differences_of_the_placements() {
    for normal in ["0 0 1", "0 1 0", "1 2 2"] {
        let m = robot(normal);
        let mut d = Data::new(&m);
        let q = [0.3, -0.7, 1.1, 0.4];
        compute_joint_jacobians(&m, &mut d, &q);
        let fc = m.frame_id_of_kind("c", FrameKind::Body).unwrap();
        let mut j = Jacobian::zeros(m.nv());
        frame_jacobian(&m, &d, fc, ReferenceFrame::Local, &mut j);
        let place = |q: &[f64]| {
            let mut d = Data::new(&m);
            frames_forward_kinematics(&m, &mut d, q);
            d.frame_placements[fc]
        };
        let m0 = place(&q);
        let h = 1e-6;
        for k in 0..m.nv() {
            let mut e = vec![0.0; m.nv()];
            e[k] = 1.0;
            let plus = (m0.inverse() * place(&integrate(&m, &q, &e, h))).log();
            let minus = (m0.inverse() * place(&integrate(&m, &q, &e, -h))).log();
            let fd = (plus - minus) * (0.5 / h);
            let col = j.column(k);
            let err = (fd.v - col.v).length().max((fd.w - col.w).length());
            assert!(err < 1e-9, "axis {normal}, column {k}: {fd:?} vs {col:?}");
        }
    }
}

#[test]
fn integrate_is_the_se2_exponential_and_difference_its_inverse() {
    let m = robot("0 0 1");
    let q = [0.3, -0.7, 1.1, 0.4];
    let v = [0.5, -0.2, 0.8, 0.1];
    let q1 = integrate(&m, &q, &v, 1.0);
    // The planar joint moves by exp of its local twist (vx, vy, 0; 0, 0, ω).
    let x0 = Se3::new(rz(1.1), DVec3::new(0.3, -0.7, 0.0));
    let x1 = x0 * Se3::exp(Twist::new(DVec3::new(0.5, -0.2, 0.0), DVec3::new(0.0, 0.0, 0.8)));
    let got = Se3::new(rz(q1[2]), DVec3::new(q1[0], q1[1], 0.0));
    assert!(se3_err(&got, &x1) < 1e-15, "{got:?} vs {x1:?}");
    assert!((q1[2] - 1.9).abs() < 1e-15 && (q1[3] - 0.5).abs() < 1e-15);
    let back = difference(&m, &q, &q1);
    for (a, b) in back.iter().zip(v) {
        assert!((a - b).abs() < 1e-15, "{back:?} vs {v:?}");
    }
    // The series branch (small rotation) agrees with the exponential too.
    let small = [0.5, -0.2, 1e-6, 0.0];
    let q2 = integrate(&m, &q, &small, 1.0);
    let x2 = x0 * Se3::exp(Twist::new(DVec3::new(0.5, -0.2, 0.0), DVec3::new(0.0, 0.0, 1e-6)));
    assert!(se3_err(&Se3::new(rz(q2[2]), DVec3::new(q2[0], q2[1], 0.0)), &x2) < 1e-15);
}

#[test]
fn rnea_matches_newton_euler_worked_by_hand() {
    // One planar joint (normal z) carrying mass m with its centre on the joint, inertia
    // diag(·, ·, I); gravity g along -y. In the moving frame, with v = (vx, vy, ω):
    // τx = m (ax - ω vy + g sin θ), τy = m (ay + ω vx + g cos θ), τθ = I α.
    let xml = r#"<robot name="p"><link name="a"/>
  <link name="b"><inertial><mass value="2"/><inertia ixx="0.1" iyy="0.2" izz="0.3"/></inertial></link>
  <joint name="base" type="planar"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>
</robot>"#;
    let mut m = parse_urdf(xml, &UrdfOptions::default()).unwrap();
    let g = 9.81;
    m.set_gravity(DVec3::new(0.0, -g, 0.0));
    let mut d = Data::new(&m);
    let (mass, izz) = (2.0, 0.3);
    let q = [0.4, -1.2, 0.7];
    let v = [0.3, -0.6, 1.5];
    let a = [0.2, 0.9, -0.4];
    let tau = rnea(&m, &mut d, &q, &v, &a).to_vec();
    let (s, c) = q[2].sin_cos();
    let expected = [mass * (a[0] - v[2] * v[1] + g * s), mass * (a[1] + v[2] * v[0] + g * c), izz * a[2]];
    for (t, e) in tau.iter().zip(expected) {
        assert!((t - e).abs() < 1e-13, "{tau:?} vs {expected:?}");
    }
    // H = diag(m, m, I) for a centre of mass on the joint; ABA inverts RNEA.
    let h = crba(&m, &mut d, &q).clone();
    for (i, hd) in [mass, mass, izz].iter().enumerate() {
        for k in 0..3 {
            let want = if i == k { *hd } else { 0.0 };
            assert!((h[(i, k)] - want).abs() < 1e-15, "H[{i},{k}] = {}", h[(i, k)]);
        }
    }
    let acc = aba(&m, &mut d, &q, &v, &tau).to_vec();
    for (x, y) in acc.iter().zip(a) {
        assert!((x - y).abs() < 1e-13);
    }
}

#[test]
fn pinocchio_stores_a_planar_joint_as_x_y_cos_sin() {
    let m = robot("0 0 1");
    assert_eq!(nq(&m), 5);
    let q = [0.3, -0.7, 2.0, 0.4];
    // cos 2 = -0.4161468365471424, sin 2 = 0.9092974268256817.
    let expected = [0.3, -0.7, -0.416_146_836_547_142_4, 0.909_297_426_825_681_7, 0.4];
    let pin = to_pinocchio(&m, &q).unwrap();
    for (a, b) in pin.iter().zip(expected) {
        assert!((a - b).abs() < 3e-16, "{pin:?}");
    }
    let back = from_pinocchio(&m, &expected).unwrap();
    for (a, b) in back.iter().zip(q) {
        assert!((a - b).abs() < 1e-15, "{back:?}");
    }
    let e = from_pinocchio(&m, &[0.3, -0.7, 0.0, 0.0, 0.4]).unwrap_err();
    assert_eq!(e, anim_rigid::InputError::ZeroCosSin { index: 2, joint: "base".into() });
}
