//! Unit tests of the model types and builder.
use super::*;

#[test]
fn axis_rotations_match_rodrigues() {
    for axis in [Axis::X, Axis::Y, Axis::Z, Axis::Unaligned(DVec3::new(1.0, -2.0, 0.5).normalize())] {
        for angle in [-2.5, -0.3, 0.0, 0.7, 3.1] {
            let r = axis.rotation(angle);
            let reference = so3::exp(axis.vector() * angle);
            let err = (r - reference).to_cols_array().iter().fold(0.0_f64, |a, e| a.max(e.abs()));
            assert!(err < 1e-15, "{axis:?} {angle}: {err}");
        }
    }
}

#[test]
fn axis_from_vector_snaps_and_rejects() {
    assert_eq!(Axis::from_vector(DVec3::new(0.0, 0.0, 2.0)), Some(Axis::Z));
    assert_eq!(Axis::from_vector(DVec3::ZERO), None);
    assert_eq!(Axis::from_vector(DVec3::new(f64::NAN, 0.0, 1.0)), None);
    assert!(matches!(Axis::from_vector(DVec3::new(0.0, -1.0, 0.0)), Some(Axis::Unaligned(_))));
}

#[test]
fn merged_inertia_matches_point_masses() {
    // Two unit point masses at ±x: mass 2, com 0, inertia diag(0, 2, 2).
    let a = Inertia::new(1.0, DVec3::X, DMat3::ZERO);
    let b = Inertia::new(1.0, -DVec3::X, DMat3::ZERO);
    let m = a.merged(&b);
    assert_eq!(m.mass, 2.0);
    assert_eq!(m.com, DVec3::ZERO);
    assert!((m.rotational - DMat3::from_diagonal(DVec3::new(0.0, 2.0, 2.0))).abs_diff_eq(DMat3::ZERO, 1e-15));
    assert_eq!(Inertia::ZERO.merged(&Inertia::ZERO), Inertia::ZERO);
}

#[test]
fn builder_rejects_bad_input() {
    let mut b = ModelBuilder::new("m");
    assert!(matches!(
        b.add_joint(3, "j", JointType::Fixed, Se3::IDENTITY, JointLimits::UNBOUNDED),
        Err(ModelError::UnknownParent { .. })
    ));
    let j = b.add_joint(0, "j", JointType::Revolute(Axis::Z), Se3::IDENTITY, JointLimits::UNBOUNDED).unwrap();
    assert!(matches!(
        b.add_joint(j, "j", JointType::Fixed, Se3::IDENTITY, JointLimits::UNBOUNDED),
        Err(ModelError::DuplicateJoint(_))
    ));
    assert!(matches!(
        b.add_joint(j, "k", JointType::Revolute(Axis::X), Se3::IDENTITY, JointLimits::position(1.0, -1.0)),
        Err(ModelError::BadLimits { .. })
    ));
    let skew = Se3::new(DMat3::from_diagonal(DVec3::new(1.0, 2.0, 1.0)), DVec3::ZERO);
    assert!(matches!(
        b.add_joint(j, "k", JointType::Fixed, skew, JointLimits::UNBOUNDED),
        Err(ModelError::BadPlacement { .. })
    ));
    assert!(matches!(
        b.append_body(j, &Inertia::new(-1.0, DVec3::ZERO, DMat3::ZERO), &Se3::IDENTITY),
        Err(ModelError::BadInertia { .. })
    ));
    let s =
        b.add_joint(j, "ball", JointType::Spherical, Se3::IDENTITY, JointLimits::position(0.0, 1.0)).unwrap();
    let m = b.build();
    assert_eq!(m.joint(s).limits, JointLimits::UNBOUNDED);
    assert_eq!((m.nq(), m.nv()), (5, 4));
    assert_eq!(m.support(s), vec![1, 2]);
    assert!(m.is_ancestor(1, 2) && !m.is_ancestor(2, 1) && m.is_ancestor(0, 2));
    assert_eq!(m.children(0), &[1]);
}

#[test]
fn builder_couples_and_refuses_mimic_joints() {
    let mut b = ModelBuilder::new("m");
    let rz = JointType::Revolute(Axis::Z);
    let a = b.add_joint(0, "a", rz, Se3::IDENTITY, JointLimits::position(-1.0, 1.0)).unwrap();
    let ball = b.add_joint(a, "ball", JointType::Spherical, Se3::IDENTITY, JointLimits::UNBOUNDED).unwrap();
    let c =
        b.add_mimic_joint(a, "c", rz, Se3::IDENTITY, JointLimits::position(-2.0, 2.0), a, -2.0, 0.1).unwrap();
    let bad = |b: &mut ModelBuilder, name: &str, kind, master, m: f64| {
        matches!(
            b.add_mimic_joint(a, name, kind, Se3::IDENTITY, JointLimits::UNBOUNDED, master, m, 0.0),
            Err(ModelError::BadMimic { .. })
        )
    };
    assert!(bad(&mut b, "d", rz, 0, 1.0), "the universe is no master");
    assert!(bad(&mut b, "d", rz, 99, 1.0), "missing master");
    assert!(bad(&mut b, "d", rz, ball, 1.0), "spherical master");
    assert!(bad(&mut b, "d", rz, c, 1.0), "chain");
    assert!(bad(&mut b, "d", JointType::Spherical, a, 1.0), "spherical follower");
    assert!(bad(&mut b, "d", rz, a, f64::NAN), "NaN multiplier");
    assert!(bad(&mut b, "d", rz, a, f64::INFINITY), "infinite multiplier");
    let p = b
        .add_joint(a, "p", JointType::Prismatic(Axis::X), Se3::IDENTITY, JointLimits::position(0.0, 1.0))
        .unwrap();
    let m = b.build();
    // The coupled joint owns nothing; the prismatic joint after it gets the next entries.
    assert_eq!((m.nq(), m.nv(), m.nv_extended()), (6, 5, 6));
    assert_eq!((m.joint(c).idx_q, m.joint(c).idx_v, m.joint(c).nq(), m.joint(c).nv()), (0, 0, 0, 0));
    assert_eq!((m.joint(p).idx_q, m.joint(p).idx_v), (5, 4));
    assert_eq!(m.mimic_joints(), &[c]);
    let mimic = m.joint(c).mimic.unwrap();
    assert_eq!((mimic.master, mimic.multiplier, mimic.offset, mimic.column), (a, -2.0, 0.1, 5));
    assert_eq!(m.lower_limits().len(), m.nq());
}
