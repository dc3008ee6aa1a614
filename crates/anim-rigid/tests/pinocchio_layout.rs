//! Configurations in Pinocchio's layout: a continuous joint is `(cos θ, sin θ)` there, the angle
//! here; everything else is copied. Expected values worked out by hand.

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

use anim_rigid::checked::InputError;
use anim_rigid::pinocchio::{from_pinocchio, idx_q, is_unbounded_revolute, nq, to_pinocchio};
use anim_rigid::{UrdfOptions, parse_urdf};

/// A revolute joint (limited), a continuous joint, a prismatic joint, in a chain, on a floating
/// base: Pinocchio's q is (x y z qx qy qz qw, θ1, cos θ2, sin θ2, d3), 11 entries; ours 10.
const URDF: &str = r#"<robot name="r">
  <link name="a"/><link name="b"/><link name="c"/><link name="d"/>
  <joint name="j1" type="revolute"><parent link="a"/><child link="b"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="continuous"><parent link="b"/><child link="c"/>
    <origin xyz="1 0 0"/><axis xyz="0 1 0"/><limit effort="10" velocity="3"/></joint>
  <joint name="j3" type="prismatic"><parent link="c"/><child link="d"/>
    <axis xyz="1 0 0"/><limit lower="0" upper="0.2" effort="1" velocity="1"/></joint>
</robot>"#;

#[test]
fn a_continuous_joint_is_cos_sin_in_pinocchio() {
    let m = parse_urdf(URDF, &UrdfOptions::default().floating_base(true)).unwrap();
    assert_eq!((m.nq(), m.nv(), nq(&m)), (10, 9, 11));
    let continuous: Vec<bool> = m.joints().iter().map(is_unbounded_revolute).collect();
    assert_eq!(continuous, [false, false, false, true, false]);
    // Pinocchio's idx_q: root_joint 0, j1 7, j2 8, j3 10.
    assert_eq!((1..5).map(|j| idx_q(&m, j)).collect::<Vec<_>>(), [0, 7, 8, 10]);

    let base = [0.1, -0.2, 0.3, 0.0, 0.0, 0.6, 0.8];
    let mut q = base.to_vec();
    q.extend([0.3, 2.0, 0.05]);
    // cos 2 = -0.416146836547142387, sin 2 = 0.909297426825681695.
    let mut expected = base.to_vec();
    expected.extend([0.3, -0.416_146_836_547_142_4, 0.909_297_426_825_681_7, 0.05]);
    let pin = to_pinocchio(&m, &q).unwrap();
    assert_eq!(pin.len(), 11);
    for (a, b) in pin.iter().zip(&expected) {
        assert!((a - b).abs() < 3e-16, "{pin:?} vs {expected:?}");
    }
    let back = from_pinocchio(&m, &expected).unwrap();
    for (a, b) in back.iter().zip(&q) {
        assert!((a - b).abs() < 1e-15, "{back:?} vs {q:?}");
    }

    // 4 rad comes back as 4 - 2π; a (cos, sin) not of unit length still gives its angle:
    // (0, 2) is π/2, (-3, 0) is π.
    q[8] = 4.0;
    let back = from_pinocchio(&m, &to_pinocchio(&m, &q).unwrap()).unwrap();
    assert!((back[8] - (4.0 - 2.0 * std::f64::consts::PI)).abs() < 1e-15, "{}", back[8]);
    expected[8..10].copy_from_slice(&[0.0, 2.0]);
    assert!((from_pinocchio(&m, &expected).unwrap()[8] - std::f64::consts::FRAC_PI_2).abs() < 1e-16);
    expected[8..10].copy_from_slice(&[-3.0, 0.0]);
    assert_eq!(from_pinocchio(&m, &expected).unwrap()[8], std::f64::consts::PI);
}

#[test]
fn without_continuous_joints_the_layouts_are_the_same() {
    let m = parse_urdf(URDF, &UrdfOptions::default().lock_joint("j2", 0.0)).unwrap();
    assert_eq!((m.nq(), nq(&m)), (2, 2));
    let q = [0.25, 0.125];
    assert_eq!(to_pinocchio(&m, &q).unwrap(), q);
    assert_eq!(from_pinocchio(&m, &q).unwrap(), q);
}

#[test]
fn bad_pinocchio_vectors_are_named() {
    let m = parse_urdf(URDF, &UrdfOptions::default()).unwrap();
    assert_eq!(nq(&m), 4);
    assert!(matches!(
        from_pinocchio(&m, &[0.0; 3]),
        Err(InputError::Length { name: "q_pin", expected: 4, got: 3, .. })
    ));
    let e = from_pinocchio(&m, &[0.1, 0.0, 0.0, 0.0]).unwrap_err();
    assert_eq!(e, InputError::ZeroCosSin { index: 1, joint: "j2".into() });
    assert_eq!(e.to_string(), "q_pin[1..3]: the (cos, sin) of joint 'j2' is zero");
    let e = from_pinocchio(&m, &[0.1, 1.0, f64::NAN, 0.0]).unwrap_err();
    assert!(
        matches!(&e, InputError::NonFinite { name: "q_pin", index: 2, joint, .. } if joint == "j2"),
        "{e}"
    );
    assert!(matches!(to_pinocchio(&m, &[0.0; 4]), Err(InputError::Length { name: "q", .. })));
}
