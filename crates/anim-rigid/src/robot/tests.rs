//! Robot scenes against closed-form motion (a servoed hinge is a damped oscillator; a hinge under
//! a torque schedule accelerates piecewise uniformly), and every refusal naming its field.

use super::*;
use crate::kind::KIND;
use anim_core::scene::{BuildContext, BuildError, DynScene, Frame};
use anim_core::solver::Solver;

/// A hinge about the world z axis (gravity does no work on it) carrying a 1 kg point mass at
/// 1 m, so the moment of inertia about the hinge is exactly 1 kg m², and a massless tip link
/// at the mass, for drawing.
const HINGE: &str = r#"<robot name="hinge">
  <link name="base"/>
  <link name="rod"><inertial><origin xyz="1 0 0"/><mass value="1"/>
    <inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tip"/>
  <joint name="hinge" type="continuous"><parent link="base"/><child link="rod"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="tip_joint" type="fixed"><parent link="rod"/><child link="tip"/>
    <origin xyz="1 0 0"/></joint>
</robot>"#;

/// A folder of this test process holding `hinge.urdf`.
fn hinge_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("anim-rigid-robot-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    std::fs::write(dir.join("hinge.urdf"), HINGE).expect("write the URDF");
    dir
}

fn panda_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata")
}

fn spec(value: serde_json::Value) -> RobotSpec {
    serde_json::from_value(value).expect("a valid spec")
}

fn build_kind(value: serde_json::Value, base: &Path) -> Result<Box<dyn DynScene>, BuildError> {
    (KIND.build)(&value, &BuildContext { base: Some(base) })
}

/// The hinge angle from the drawn tip (the segment hinge -> tip ends at (cos q, sin q, 0) in
/// the robot's z-up frame, drawn y up at (cos q, 0, -sin q)).
fn tip_angle(scene: &dyn DynScene) -> f64 {
    let mut frame = Frame::default();
    scene.frame(&mut frame);
    assert_eq!(frame.points.len(), 6, "one segment: the hinge and the tip");
    (-frame.points[5]).atan2(frame.points[3])
}

#[test]
fn a_servoed_hinge_follows_the_damped_oscillator() {
    // I q'' = kp (q* - q) - kd q' with I = 1: e = q - q* obeys e'' + 2 zeta w e' + w^2 e = 0.
    let (kp, kd, target) = (4.0, 0.4, 1.0);
    let dir = hinge_dir("servo");
    let robot = spec(serde_json::json!({
        "urdf": "hinge.urdf",
        "servo": { "kp": kp, "kd": kd, "target": { "hinge": target } },
    }));
    let (scene, schedule) = robot.build(&dir.join(&robot.urdf)).expect("builds");
    assert!(schedule.is_empty());
    let (mut sim, mut state) = scene.into_simulation().expect("simulation");
    let dt = 1e-3;
    for _ in 0..2000 {
        sim.step(&mut state, dt).expect("step");
    }
    let (w, zeta) = (f64::sqrt(kp), kd / (2.0 * f64::sqrt(kp)));
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let t = state.t;
    let e = -(-zeta * w * t).exp() * ((wd * t).cos() + zeta * w / wd * (wd * t).sin());
    let exact = target + e;
    // RK4's global error at dt = 1e-3 on this oscillator is about 1e-13.
    assert!((t - 2.0).abs() < 1e-12);
    assert!((state.q[0] - exact).abs() < 1e-10, "q = {}, exact {exact}", state.q[0]);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_torque_schedule_is_held_over_each_step_and_switches_on_the_step_boundary() {
    // tau = 2 N m for 0.5 s, then none: q = t^2 up to 0.5 (q = 0.25, q' = 1), then q' = 1.
    let dir = hinge_dir("schedule");
    let params = serde_json::json!({ "robot": {
        "urdf": "hinge.urdf",
        "torque": [ { "from": 0.0, "joints": { "hinge": 2.0 } }, { "from": 0.5, "joints": {} } ],
    }});
    let mut scene = build_kind(params.clone(), &dir).expect("builds");
    for _ in 0..1000 {
        scene.step(1e-3).expect("step");
    }
    // RK4 integrates a piecewise-constant acceleration exactly when it switches on a step
    // boundary: only rounding remains.
    assert!((tip_angle(&*scene) - 0.75).abs() < 1e-12, "angle {}", tip_angle(&*scene));

    // The torque follows time, so a checkpoint taken before the switch resumes bit for bit.
    let mut straight = build_kind(params.clone(), &dir).expect("builds");
    let mut resumed = build_kind(params, &dir).expect("builds");
    for _ in 0..300 {
        straight.step(1e-3).expect("step");
    }
    let saved = straight.save();
    for _ in 0..400 {
        straight.step(1e-3).expect("step");
    }
    resumed.restore(&saved).expect("restores");
    for _ in 0..400 {
        resumed.step(1e-3).expect("step");
    }
    assert_eq!(tip_angle(&*straight).to_bits(), tip_angle(&*resumed).to_bits());
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn the_schedule_takes_the_entry_in_force_at_the_middle_of_the_step() {
    let s = TorqueSchedule::new(vec![(0.25, vec![1.0]), (0.5, vec![2.0])], 1).expect("valid");
    assert_eq!(s.at(0.0, 0.1), Some(&[0.0][..]));
    assert_eq!(s.at(0.2, 0.1), Some(&[1.0][..])); // middle 0.25: the entry starts there
    assert_eq!(s.at(0.5 - 1e-15, 0.01), Some(&[2.0][..])); // rounding below the boundary
    assert_eq!(s.at(9.0, 0.1), Some(&[2.0][..]));
    assert_eq!(TorqueSchedule::default().at(1.0, 0.1), None);
    for bad in
        [vec![(0.5, vec![1.0]), (0.5, vec![1.0])], vec![(-1.0, vec![1.0])], vec![(f64::NAN, vec![1.0])]]
    {
        assert!(TorqueSchedule::new(bad, 1).is_err());
    }
    assert!(TorqueSchedule::new(vec![(0.0, vec![1.0, 2.0])], 1).is_err());
    assert!(TorqueSchedule::new(vec![(0.0, vec![f64::INFINITY])], 1).is_err());
}

#[test]
fn the_panda_takes_its_base_locked_joints_and_initial_state_by_name() {
    let fixed = spec(serde_json::json!({
        "urdf": "panda.urdf",
        "locked": { "panda_finger_joint1": 0.01, "panda_finger_joint2": 0.01 },
        "q0": { "panda_joint2": 0.5, "panda_joint4": -2.0 },
        "v0": { "panda_joint1": 0.25 },
    }));
    let (scene, _) = fixed.build(&panda_dir().join("panda.urdf")).expect("builds");
    assert_eq!((scene.model.nq(), scene.model.nv()), (7, 7));
    assert_eq!(scene.state.q, [0.0, 0.5, 0.0, -2.0, 0.0, 0.0, 0.0]);
    assert_eq!(scene.state.v, [0.25, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    // Drawn from the base through the seven joints to the hand.
    assert!(scene.segments.len() >= 7, "{} segments", scene.segments.len());

    let floating = spec(serde_json::json!({
        "urdf": "panda.urdf",
        "base": "floating",
        "base_position": [1.0, 2.0, 3.0],
        "base_rpy": [0.0, 0.0, std::f64::consts::FRAC_PI_2],
        "locked": { "panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0 },
    }));
    let (scene, _) = floating.build(&panda_dir().join("panda.urdf")).expect("builds");
    assert_eq!((scene.model.nq(), scene.model.nv()), (14, 13));
    assert_eq!(&scene.state.q[..3], &[1.0, 2.0, 3.0]);
    let h = std::f64::consts::FRAC_PI_4;
    let quat = &scene.state.q[3..7]; // a quarter turn about z: (0, 0, sin 45°, cos 45°)
    assert!(quat.iter().zip([0.0, 0.0, h.sin(), h.cos()]).all(|(a, b)| (a - b).abs() < 1e-15), "{quat:?}");
}

#[test]
fn refusals_name_the_field_and_the_joints_it_could_have_been() {
    let panda = panda_dir().join("panda.urdf");
    let fingers = serde_json::json!({ "panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0 });
    let refuse = |extra: serde_json::Value| {
        let mut value = serde_json::json!({ "urdf": "panda.urdf", "locked": fingers });
        value.as_object_mut().expect("object").extend(extra.as_object().expect("object").clone());
        spec(value).build(&panda).expect_err("refused")
    };
    let e = refuse(serde_json::json!({ "q0": { "panda_joint9": 1.0 } }));
    assert_eq!(e.field(), "q0.panda_joint9");
    assert!(
        e.to_string().contains("no moving joint `panda_joint9`") && e.to_string().contains("panda_joint7"),
        "{e}"
    );
    let e = refuse(serde_json::json!({ "v0": { "panda_finger_joint1": 1.0 } }));
    assert_eq!(e.field(), "v0.panda_finger_joint1");
    assert!(e.to_string().contains("is locked"), "{e}");
    // JSON and TOML have no infinity; a spec built in Rust can hold one.
    let mut infinite = spec(serde_json::json!({ "urdf": "panda.urdf", "locked": fingers }));
    infinite.q0.insert("panda_joint1".into(), f64::INFINITY);
    let e = infinite.build(&panda).expect_err("refused");
    assert_eq!(e.field(), "q0.panda_joint1");
    assert!(e.to_string().contains("not finite"), "{e}");
    let e = refuse(serde_json::json!({ "base_position": [0.0, 0.0, 1.0] }));
    assert_eq!(e.field(), "base_position");
    assert!(e.to_string().contains("floating"), "{e}");
    let e =
        refuse(serde_json::json!({ "servo": { "kp": -1.0, "kd": 0.0, "target": { "panda_joint1": 0.0 } } }));
    assert_eq!(e.field(), "servo");
    assert!(e.to_string().contains("gains must be finite and >= 0"), "{e}");
    let e = refuse(serde_json::json!({ "damping": -0.5 }));
    assert_eq!(e.field(), "damping");
    let e = refuse(serde_json::json!({ "torque": [
        { "from": 1.0, "joints": { "panda_joint1": 1.0 } },
        { "from": 0.5, "joints": { "panda_joint1": 0.0 } },
    ] }));
    assert_eq!(e.field(), "torque");
    let e = refuse(serde_json::json!({ "torque": [ { "from": 0.0, "joints": { "hand": 1.0 } } ] }));
    assert_eq!(e.field(), "torque[0].joints.hand");

    // A missing URDF names the file; a locked joint the robot does not have is the URDF's error.
    let e = spec(serde_json::json!({ "urdf": "nowhere.urdf" }))
        .build(Path::new("nowhere.urdf"))
        .expect_err("missing");
    assert_eq!(e.field(), "urdf");
    assert!(e.to_string().contains("nowhere.urdf"), "{e}");
    let e = spec(serde_json::json!({ "urdf": "panda.urdf", "locked": { "elbow": 0.0 } }))
        .build(&panda)
        .expect_err("x");
    assert!(matches!(e, RobotError::Urdf(_)) && e.to_string().contains("elbow"), "{e}");
}

#[test]
fn the_rigid_kind_takes_a_preset_or_a_robot_and_names_the_field_it_refuses() {
    let base = panda_dir();
    let field = |e: BuildError| match e {
        BuildError::Invalid { field, message } | BuildError::Schema { field, message } => (field, message),
        other => panic!("unexpected {other}"),
    };
    let (f, m) = field(build_kind(serde_json::json!({}), &base).err().expect("refused"));
    assert_eq!(f, "preset");
    assert!(m.contains("robot"), "{m}");
    let both = serde_json::json!({ "preset": "t-handle", "robot": { "urdf": "panda.urdf" } });
    assert_eq!(field(build_kind(both, &base).err().expect("refused")).0, "robot");
    let (f, m) = field(
        build_kind(serde_json::json!({ "robot": { "urdf": "missing.urdf" } }), &base).err().expect("x"),
    );
    assert_eq!(f, "robot.urdf");
    assert!(m.contains("missing.urdf"), "{m}");
    let (f, _) = field(
        build_kind(serde_json::json!({ "robot": { "urdf": "panda.urdf", "q0": { "nope": 1.0 } } }), &base)
            .err()
            .expect("x"),
    );
    assert_eq!(f, "robot.q0.nope");
    let typo = serde_json::json!({ "robot": { "urdf": "panda.urdf", "dampin": 1.0 } });
    let (_, m) = field(build_kind(typo, &base).err().expect("unknown field"));
    assert!(m.contains("dampin"), "{m}");
}

#[test]
fn a_servo_must_sit_on_a_one_degree_of_freedom_joint_once() {
    let dir = hinge_dir("servo-checks");
    let robot = spec(serde_json::json!({ "urdf": "hinge.urdf" }));
    let (scene, _) = robot.build(&dir.join("hinge.urdf")).expect("builds");
    let servo = Servo { dof: 0, target: 0.0, kp: 1.0, kd: 0.0 };
    let check = |servos: Vec<Servo>| {
        crate::sim::ArticulatedSystem::new(scene.model.clone(), SimParams::default().with_servos(servos))
    };
    assert!(check(vec![servo]).is_ok());
    assert!(check(vec![Servo { dof: 1, ..servo }]).is_err(), "no such degree of freedom");
    assert!(check(vec![servo, servo]).is_err(), "servoed twice");
    assert!(check(vec![Servo { target: f64::NAN, ..servo }]).is_err());
    assert!(check(vec![Servo { kd: f64::INFINITY, ..servo }]).is_err());
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_single_floating_body_is_drawn_at_its_origin_and_falls() {
    let dir = std::env::temp_dir().join(format!("anim-rigid-robot-{}-ball", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary folder");
    let urdf = r#"<robot name="ball"><link name="ball"><inertial><mass value="1"/>
        <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>"#;
    std::fs::write(dir.join("ball.urdf"), urdf).expect("write the URDF");
    let params = serde_json::json!({ "robot": { "urdf": "ball.urdf", "base": "floating", "base_position": [0.0, 0.0, 2.0] } });
    let mut scene = build_kind(params, &dir).expect("builds");
    // At (0, 0, 2) in the robot's z-up frame, drawn y up at (0, 2, 0).
    let mut frame = Frame::default();
    scene.frame(&mut frame);
    assert_eq!(frame.points, [0.0, 2.0, 0.0, 0.0, 2.0, 0.0]);
    for _ in 0..100 {
        scene.step(1e-3).expect("step");
    }
    scene.frame(&mut frame);
    // Free fall for 0.1 s along -y: y = 2 - g t^2 / 2 (RK4 is exact on it up to rounding).
    assert!((frame.points[1] - (2.0 - 0.5 * 9.81 * 0.01)).abs() < 1e-12, "y = {}", frame.points[1]);
    let _ = std::fs::remove_dir_all(dir);
}
