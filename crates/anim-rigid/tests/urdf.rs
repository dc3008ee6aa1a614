//! URDF loading: the robots load, options behave, and bad files give errors that name the file,
//! the line, the element and the cause.

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

mod common;

use anim_rigid::config::random_configuration;
use anim_rigid::{
    Data, FrameKind, JointType, UrdfCause, UrdfError, UrdfOptions, frames_forward_kinematics, load_urdf,
    parse_urdf,
};
use common::{se3_err, testdata};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn err(xml: &str) -> UrdfError {
    parse_urdf(xml, &UrdfOptions::default()).expect_err("should fail")
}

/// A two-link robot with `joint` inserted as its only joint.
fn robot(joint: &str) -> String {
    format!(
        "<?xml version=\"1.0\"?>\n<robot name=\"r\">\n  <link name=\"a\"/>\n  <link name=\"b\"/>\n{joint}\n</robot>\n"
    )
}

#[test]
fn the_robots_load_with_visuals_and_collisions_ignored() {
    let options = UrdfOptions::default();
    let panda = load_urdf(testdata("panda.urdf"), &options).unwrap();
    // Unlocked: 7 arm joints and 2 finger joints (the second, with an axis -y, unaligned).
    assert_eq!((panda.nq(), panda.nv(), panda.njoints()), (9, 9, 10));
    assert!(matches!(panda.joint(9).kind, JointType::Prismatic(anim_rigid::Axis::Unaligned(_))));
    let ur5 = load_urdf(testdata("ur5_robot.urdf"), &options).unwrap();
    assert_eq!((ur5.nq(), ur5.njoints(), ur5.frames().len()), (6, 7, 22));
    assert_eq!(ur5.joint(1).limits.lower, "-6.28318530718".parse::<f64>().unwrap());
    assert!((ur5.total_mass() - (4.0 + 3.7 + 8.393 + 2.275 + 1.219 + 1.219 + 0.1879)).abs() < 1e-12);
}

#[test]
fn unmerged_fixed_joints_give_the_same_frames() {
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    for file in ["panda.urdf", "ur5_robot.urdf", "puma_like.urdf"] {
        let merged = load_urdf(testdata(file), &UrdfOptions::default()).unwrap();
        let split = load_urdf(testdata(file), &UrdfOptions::default().merge_fixed_joints(false)).unwrap();
        assert_eq!(merged.nq(), split.nq());
        assert!(split.njoints() > merged.njoints(), "{file}: fixed joints kept as joints");
        let (mut dm, mut ds) = (Data::new(&merged), Data::new(&split));
        for _ in 0..10 {
            let q = random_configuration(&merged, &mut || rng.random::<f64>());
            frames_forward_kinematics(&merged, &mut dm, &q);
            frames_forward_kinematics(&split, &mut ds, &q);
            for (f, frame) in merged.frames().iter().enumerate() {
                if frame.kind != FrameKind::Body {
                    continue;
                }
                let g = split.frame_id_of_kind(&frame.name, FrameKind::Body).unwrap();
                assert!(
                    se3_err(&dm.frame_placements[f], &ds.frame_placements[g]) < 1e-14,
                    "{file}: {}",
                    frame.name
                );
            }
        }
        assert!((merged.total_mass() - split.total_mass()).abs() < 1e-12);
    }
}

#[test]
fn floating_base_and_locked_joints() {
    let options = UrdfOptions::default().floating_base(true).lock_joint("panda_finger_joint1", 0.02);
    let m = load_urdf(testdata("panda.urdf"), &options).unwrap();
    assert_eq!((m.nq(), m.nv()), (7 + 7 + 1, 6 + 7 + 1));
    assert_eq!(m.joint(1).name, "root_joint");
    assert_eq!(m.joint(1).kind, JointType::Free);
    // The locked finger sits 2 cm along +y of the hand.
    let mut d = Data::new(&m);
    frames_forward_kinematics(&m, &mut d, &anim_rigid::config::neutral(&m));
    let hand = d.frame_placements[m.frame_id("panda_hand").unwrap()];
    let finger = d.frame_placements[m.frame_id("panda_leftfinger").unwrap()];
    let local = hand.inverse() * finger;
    assert!((local.translation - anim_core::glam::DVec3::new(0.0, 0.02, 0.0584)).length() < 1e-15);
    let bad = UrdfOptions::default().lock_joint("no_such_joint", 0.0);
    let e = load_urdf(testdata("panda.urdf"), &bad).unwrap_err();
    assert!(matches!(*e.cause, UrdfCause::BadLockedJoint(_)), "{e}");
}

#[test]
fn missing_parent_or_child_link() {
    let e = err(&robot(
        r#"  <joint name="j" type="revolute">
    <parent link="nope"/>
    <child link="b"/>
    <limit lower="-1" upper="1"/>
  </joint>"#,
    ));
    assert_eq!(*e.cause, UrdfCause::MissingLink { role: "parent", link: "nope".into() });
    assert_eq!(e.line, 6);
    assert_eq!(e.element, "parent");
    let text = e.to_string();
    assert!(text.starts_with("<string>:6: <parent>:") && text.contains("'nope'"), "{text}");
    let e = err(&robot(r#"  <joint name="j" type="fixed"><parent link="a"/><child link="c"/></joint>"#));
    assert_eq!(*e.cause, UrdfCause::MissingLink { role: "child", link: "c".into() });
}

#[test]
fn cycles_and_roots() {
    // a -> b -> a: every link has a parent, no root.
    let xml = robot(
        r#"  <joint name="ab" type="fixed"><parent link="a"/><child link="b"/></joint>
  <joint name="ba" type="fixed"><parent link="b"/><child link="a"/></joint>"#,
    );
    let e = err(&xml);
    assert!(matches!(&*e.cause, UrdfCause::Cycle(links) if links.len() == 2), "{e}");
    // A cycle beside a proper root: r is the root, c -> d -> c is unreachable.
    let xml = r#"<robot name="r">
  <link name="r"/><link name="c"/><link name="d"/>
  <joint name="cd" type="fixed"><parent link="c"/><child link="d"/></joint>
  <joint name="dc" type="fixed"><parent link="d"/><child link="c"/></joint>
</robot>"#;
    let e = err(xml);
    assert!(matches!(&*e.cause, UrdfCause::Cycle(links) if links.contains(&"c".to_string())), "{e}");
    assert!(e.line >= 3, "{e}");
    // Two roots.
    let e = err(&robot(""));
    assert_eq!(*e.cause, UrdfCause::MultipleRoots(vec!["a".into(), "b".into()]));
    assert_eq!(e.line, 4);
    // A link with two parents.
    let xml = r#"<robot name="r">
  <link name="a"/><link name="b"/><link name="c"/>
  <joint name="ac" type="fixed"><parent link="a"/><child link="c"/></joint>
  <joint name="bc" type="fixed"><parent link="b"/><child link="c"/></joint>
</robot>"#;
    let e = err(xml);
    assert!(matches!(&*e.cause, UrdfCause::TwoParents { link, .. } if link == "c"), "{e}");
    assert_eq!(e.line, 4);
    assert_eq!(e.element, "joint bc");
}

#[test]
fn the_axis_of_a_fixed_joint_is_ignored() {
    // As urdfdom (and so Pinocchio) does: Talos, TIAGo, iCub and others write `0 0 0` there.
    let fixed = robot(
        "  <joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/>\n    <axis xyz=\"0 0 0\"/></joint>",
    );
    let m = parse_urdf(&fixed, &UrdfOptions::default()).unwrap();
    assert_eq!((m.nq(), m.nv(), m.njoints()), (0, 0, 1));
    assert!(m.frame_id_of_kind("j", FrameKind::FixedJoint).is_some());
    let unmerged = parse_urdf(&fixed, &UrdfOptions::default().merge_fixed_joints(false)).unwrap();
    assert_eq!(unmerged.joint(1).kind, JointType::Fixed);
    // A revolute joint with the same axis is still refused, naming the file and line.
    let revolute = robot(
        "  <joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/>\n    <axis xyz=\"0 0 0\"/><limit lower=\"-1\" upper=\"1\"/></joint>",
    );
    let e = err(&revolute);
    assert_eq!(*e.cause, UrdfCause::BadAxis("0 0 0".into()));
    assert_eq!((e.file.as_str(), e.line, e.element.as_str()), ("<string>", 6, "axis"));
    assert!(e.to_string().starts_with("<string>:6: <axis>:"), "{e}");
}

#[test]
fn bad_axes_and_numbers() {
    let joint = |axis: &str| {
        robot(&format!(
            "  <joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/>\n    <axis xyz=\"{axis}\"/><limit lower=\"-1\" upper=\"1\"/></joint>"
        ))
    };
    let e = err(&joint("0 0 0"));
    assert_eq!(*e.cause, UrdfCause::BadAxis("0 0 0".into()));
    assert_eq!((e.line, e.element.as_str()), (6, "axis"));
    let e = err(&joint("NaN 0 1"));
    assert_eq!(*e.cause, UrdfCause::BadAxis("NaN 0 1".into()));
    let e = err(&joint("0 0 x"));
    assert!(matches!(*e.cause, UrdfCause::BadNumber { attribute: "xyz", .. }), "{e}");
    let e = err(&joint("0 1"));
    assert!(matches!(&*e.cause, UrdfCause::BadNumber { reason, .. } if reason.contains("expected 3")), "{e}");
    let e = err(&robot(
        r#"  <joint name="j" type="fixed"><parent link="a"/><child link="b"/><origin xyz="0 0 1e400"/></joint>"#,
    ));
    assert!(matches!(&*e.cause, UrdfCause::BadNumber { reason, .. } if reason.contains("not finite")), "{e}");
    let e = err(&robot(
        r#"  <joint name="j" type="revolute"><parent link="a"/><child link="b"/><limit lower="-1.5.2" upper="1"/></joint>"#,
    ));
    assert!(matches!(&*e.cause, UrdfCause::BadNumber { attribute: "lower", .. }), "{e}");
    let e = err(&robot(
        r#"  <joint name="j" type="revolute"><parent link="a"/><child link="b"/><limit lower="1" upper="-1"/></joint>"#,
    ));
    assert!(matches!(*e.cause, UrdfCause::Model(anim_rigid::ModelError::BadLimits { .. })), "{e}");
    let e = err(
        r#"<robot name="r"><link name="a"><inertial><mass value="heavy"/><inertia ixx="1"/></inertial></link></robot>"#,
    );
    assert!(matches!(*e.cause, UrdfCause::BadNumber { attribute: "value", .. }), "{e}");
}

#[test]
fn unsupported_and_malformed() {
    let e = err(&robot(r#"  <joint name="j" type="screw"><parent link="a"/><child link="b"/></joint>"#));
    assert_eq!(*e.cause, UrdfCause::UnsupportedJointType("screw".into()));
    let e = err(&robot(r#"  <joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint>"#));
    assert_eq!(*e.cause, UrdfCause::MissingElement("limit"));
    let e = err("<robot name=\"r\"><link name=\"a\"></robot>");
    assert!(matches!(*e.cause, UrdfCause::Xml(_)), "{e}");
    assert_eq!(e.line, 1);
    let e = err("<model/>");
    assert_eq!(*e.cause, UrdfCause::NotARobot("model".into()));
    let e = err("<robot name=\"r\"/>");
    assert_eq!(*e.cause, UrdfCause::NoLinks);
    let e = err(r#"<robot name="r"><link name="a"/><link name="a"/></robot>"#);
    assert_eq!(*e.cause, UrdfCause::DuplicateLink("a".into()));
    let e = load_urdf("/no/such/file.urdf", &UrdfOptions::default()).unwrap_err();
    assert!(matches!(*e.cause, UrdfCause::Io(_)));
    assert!(e.to_string().starts_with("/no/such/file.urdf:0:"), "{e}");
}

#[test]
fn continuous_and_floating_joints() {
    let xml = r#"<robot name="r">
  <link name="a"/><link name="b"/><link name="c"/>
  <joint name="spin" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 0 2"/></joint>
  <joint name="float" type="floating"><parent link="b"/><child link="c"/></joint>
</robot>"#;
    let m = parse_urdf(xml, &UrdfOptions::default()).unwrap();
    assert_eq!((m.nq(), m.nv()), (8, 7));
    assert_eq!(m.joint(1).kind, JointType::Revolute(anim_rigid::Axis::Z));
    assert!(m.joint(1).limits.lower == f64::NEG_INFINITY && m.joint(1).limits.upper == f64::INFINITY);
    assert_eq!(m.joint(2).kind, JointType::Free);
}

#[test]
fn children_are_ordered_by_joint_name_depth_first() {
    // As urdfdom + Pinocchio: below a link, joints in name order; depth first.
    let xml = r#"<robot name="r">
  <link name="base"/><link name="x"/><link name="y"/><link name="x2"/>
  <joint name="zeta" type="revolute"><parent link="base"/><child link="x"/><limit lower="-1" upper="1"/></joint>
  <joint name="alpha" type="revolute"><parent link="base"/><child link="y"/><limit lower="-1" upper="1"/></joint>
  <joint name="zeta2" type="revolute"><parent link="x"/><child link="x2"/><limit lower="-1" upper="1"/></joint>
</robot>"#;
    let m = parse_urdf(xml, &UrdfOptions::default()).unwrap();
    let names: Vec<&str> = m.joints().iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, ["universe", "alpha", "zeta", "zeta2"]);
    assert_eq!(m.parent(3), 2);
}
