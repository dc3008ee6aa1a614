//! Coupled (mimic) joints against Pinocchio 4.1 built with `mimic=True`, on every robot of the
//! example-robot-data collection that has coupled joints (Panda, Baxter, PR2, TIAGo Pro), from
//! `testdata/pinocchio_mimic.json.gz` written by `testdata/make_pinocchio_mimic_reference.py`:
//! model layout, joint placements, the extended and per-joint Jacobians, RNEA, CRBA, the bias
//! term, forward dynamics through the Cholesky factorisation and the energies. Then the loader's
//! options and refusals, and the layers above the algorithms (checked API, simulation).

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

use std::io::Read;

use anim_rigid::sim::{RigidIntegrator, RigidSimulation, SimParams};
use anim_rigid::{
    Data, InputError, Jacobian, Model, ReferenceFrame, UrdfCause, UrdfOptions, compute_joint_jacobians, crba,
    forward_dynamics_cholesky, forward_kinematics, joint_jacobian, kinetic_energy, nonlinear_effects,
    parse_urdf, pinocchio, potential_energy, rnea,
};
use serde_json::Value;

/// Relative tolerance (to the largest reference entry of each quantity and sample, at least 1).
const TOL: f64 = 1e-12;

fn testdata(file: &str) -> String {
    format!("{}/testdata/{file}", env!("CARGO_MANIFEST_DIR"))
}

fn gunzip(path: &str) -> String {
    let mut text = String::new();
    flate2::read::GzDecoder::new(std::fs::File::open(path).unwrap()).read_to_string(&mut text).unwrap();
    text
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

fn rel_err(ours: &[f64], reference: &[f64]) -> f64 {
    assert_eq!(ours.len(), reference.len());
    let scale = reference.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
    ours.iter().zip(reference).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs())) / scale
}

fn reference() -> Value {
    serde_json::from_str(&gunzip(&testdata("pinocchio_mimic.json.gz"))).unwrap()
}

fn coupled(urdf: &str) -> Result<Model, anim_rigid::UrdfError> {
    parse_urdf(&gunzip(&testdata(urdf)), &UrdfOptions::default().couple_mimic_joints(true))
}

/// Column `c` of a 6-row column-major matrix, as (linear, angular).
fn column(m: &[f64], c: usize) -> [f64; 6] {
    m[6 * c..6 * c + 6].try_into().unwrap()
}

fn twist(t: anim_core::lie::Twist) -> [f64; 6] {
    [t.v.x, t.v.y, t.v.z, t.w.x, t.w.y, t.w.z]
}

#[test]
fn coupled_models_match_pinocchio() {
    let reference = reference();
    let robots = reference["robots"].as_array().unwrap();
    assert_eq!(robots.len(), 5, "Panda (two files), Baxter, PR2, TIAGo Pro");
    for robot in robots {
        let urdf = robot["urdf"].as_str().unwrap();
        let model = coupled(urdf).unwrap();
        assert_eq!(pinocchio::nq(&model) as u64, robot["nq"].as_u64().unwrap(), "{urdf}");
        assert_eq!(model.nv() as u64, robot["nv"].as_u64().unwrap(), "{urdf}");
        assert_eq!(model.nv_extended() as u64, robot["nv_extended"].as_u64().unwrap(), "{urdf}");
        let joints = robot["joints"].as_array().unwrap();
        assert_eq!(model.njoints(), joints.len(), "{urdf}");
        // Our own column of every joint in Data::jacobian, and Pinocchio's.
        let mut columns = Vec::new();
        for (i, j) in joints.iter().enumerate().skip(1) {
            let ours = model.joint(i);
            assert_eq!(ours.name, j["name"].as_str().unwrap());
            assert_eq!(ours.parent as u64, j["parent"].as_u64().unwrap());
            assert_eq!(pinocchio::idx_q(&model, i) as u64, j["idx_q"].as_u64().unwrap(), "{}", ours.name);
            assert_eq!(ours.idx_v as u64, j["idx_v"].as_u64().unwrap(), "{}", ours.name);
            match (&ours.mimic, j.get("master")) {
                (None, None) => {}
                (Some(m), Some(master)) => {
                    assert_eq!(model.joint(m.master).name, master.as_str().unwrap());
                    assert_eq!(m.multiplier, j["multiplier"].as_f64().unwrap());
                    assert_eq!(m.offset, j["offset"].as_f64().unwrap());
                }
                _ => panic!("{urdf}: joint {} coupled on one side only", ours.name),
            }
            let first = ours.mimic.map_or(ours.idx_v, |m| m.column);
            let pin_first = j["idx_v_extended"].as_u64().unwrap() as usize;
            for k in 0..j["nv_extended"].as_u64().unwrap() as usize {
                columns.push((first + k, pin_first + k));
            }
        }
        let mut data = Data::new(&model);
        let mut out = Jacobian::zeros(model.nv());
        let mut worst = [0.0_f64; 9];
        for s in robot["samples"].as_array().unwrap() {
            let q = pinocchio::from_pinocchio(&model, &floats(&s["q"])).unwrap();
            let (v, a, tau) = (floats(&s["v"]), floats(&s["a"]), floats(&s["tau"]));
            forward_kinematics(&model, &mut data, &q);
            let placements: Vec<f64> = s["placements"].as_array().unwrap().iter().flat_map(floats).collect();
            let mut ours = Vec::new();
            for m in &data.world_placements {
                for r in 0..3 {
                    ours.extend(m.rotation.row(r).to_array());
                }
                ours.extend(m.translation.to_array());
            }
            worst[0] = worst[0].max(rel_err(&ours, &placements));

            compute_joint_jacobians(&model, &mut data, &q);
            let jref = floats(&s["jacobian"]);
            let (mut ours, mut theirs) = (Vec::new(), Vec::new());
            for &(c, p) in &columns {
                ours.extend(twist(data.jacobian.column(c)));
                theirs.extend(column(&jref, p));
            }
            worst[1] = worst[1].max(rel_err(&ours, &theirs));
            for (name, jj) in s["joint_jacobians"].as_object().unwrap() {
                let i = model.joint_id(name).unwrap();
                joint_jacobian(&model, &data, i, ReferenceFrame::World, &mut out);
                let ours: Vec<f64> = out.columns().iter().flat_map(|t| twist(*t)).collect();
                worst[2] = worst[2].max(rel_err(&ours, &floats(jj)));
            }

            worst[3] = worst[3].max(rel_err(rnea(&model, &mut data, &q, &v, &a), &floats(&s["rnea"])));
            worst[4] = worst[4].max(rel_err(crba(&model, &mut data, &q).as_slice(), &floats(&s["crba"])));
            worst[5] =
                worst[5].max(rel_err(nonlinear_effects(&model, &mut data, &q, &v), &floats(&s["nle"])));
            let fd = forward_dynamics_cholesky(&model, &mut data, &q, &v, &tau).unwrap().to_vec();
            worst[6] = worst[6].max(rel_err(&fd, &floats(&s["fd"])));
            let t = kinetic_energy(&model, &mut data, &q, &v);
            worst[7] = worst[7].max(rel_err(&[t], &[s["kinetic_energy"].as_f64().unwrap()]));
            let u = potential_energy(&model, &mut data, &q);
            worst[8] = worst[8].max(rel_err(&[u], &[s["potential_energy"].as_f64().unwrap()]));
        }
        let names = ["placements", "data.J", "joint J", "rnea", "crba", "nle", "fd", "kinetic", "potential"];
        for (name, w) in names.iter().zip(worst) {
            assert!(w < TOL, "{urdf}: {name} worst relative error {w:e}");
        }
        eprintln!("{urdf}: worst {:?}", worst.map(|w| format!("{w:.1e}")));
    }
}

#[test]
fn loader_refuses_what_pinocchio_refuses_and_sizes_agree() {
    let reference = reference();
    let refused = reference["refused"].as_array().unwrap();
    assert_eq!(refused.len(), 3, "romeo, talos_full_v2, talos_full_v2_box");
    for r in refused {
        let err = coupled(r["urdf"].as_str().unwrap()).unwrap_err();
        assert!(err.line > 0, "{err}");
        match *err.cause {
            UrdfCause::BadMimic { ref reason, .. } => assert!(reason.contains("later"), "{err}"),
            ref other => panic!("{other:?}"),
        }
    }
    for u in reference["uncoupled"].as_array().unwrap() {
        let model = coupled(u["urdf"].as_str().unwrap()).unwrap();
        assert!(model.mimic_joints().is_empty());
        assert_eq!(
            (pinocchio::nq(&model) as u64, model.nv() as u64),
            (u["nq"].as_u64().unwrap(), u["nv"].as_u64().unwrap())
        );
    }
}

#[test]
fn independent_by_default() {
    let text = gunzip(&testdata("robots/panda_description/urdf/panda.urdf.gz"));
    let model = parse_urdf(&text, &UrdfOptions::default()).unwrap();
    assert_eq!((model.nq(), model.nv(), model.nv_extended()), (9, 9, 9));
    assert!(model.mimic_joints().is_empty() && model.joints().iter().all(|j| j.mimic.is_none()));
    let coupled = parse_urdf(&text, &UrdfOptions::default().couple_mimic_joints(true)).unwrap();
    assert_eq!((coupled.nq(), coupled.nv(), coupled.nv_extended()), (8, 8, 9));
}

#[test]
fn coupled_panda_fingers_move_together() {
    let model = coupled("robots/panda_description/urdf/panda.urdf.gz").unwrap();
    let (f1, f2) =
        (model.joint_id("panda_finger_joint1").unwrap(), model.joint_id("panda_finger_joint2").unwrap());
    assert_eq!(model.joint(f2).mimic.unwrap().master, f1);
    assert_eq!(model.joint(f1).idx_q, model.joint(f2).idx_q);
    let mut data = Data::new(&model);
    let hand = model.joint(f1).parent;
    let mut q = vec![0.0; model.nq()];
    let gap = |data: &Data| {
        let l = data.world_placements[hand].inverse() * data.world_placements[f1];
        let r = data.world_placements[hand].inverse() * data.world_placements[f2];
        (l.translation - r.translation).length()
    };
    forward_kinematics(&model, &mut data, &q);
    let closed = gap(&data);
    q[model.joint(f1).idx_q] = 0.03;
    forward_kinematics(&model, &mut data, &q);
    // Each finger slides 3 cm outwards along its own axis: the gap opens by 6 cm.
    assert!((gap(&data) - closed - 0.06).abs() < 1e-12, "{} -> {}", closed, gap(&data));
}

fn two_link(mimic: &str) -> String {
    format!(
        r#"<robot name="t">
  <link name="base"/>
  <link name="l1"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1"/></inertial></link>
  <link name="l2"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1"/></inertial></link>
  <joint name="a" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1"/></joint>
  <joint name="b" type="revolute"><parent link="l1"/><child link="l2"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1"/>
    {mimic}
  </joint>
</robot>"#
    )
}

#[test]
fn bad_mimic_elements_are_errors_with_lines() {
    let options = UrdfOptions::default().couple_mimic_joints(true);
    let err = parse_urdf(&two_link(r#"<mimic joint="nope"/>"#), &options).unwrap_err();
    assert_eq!(err.line, 9, "{err}");
    assert!(matches!(*err.cause, UrdfCause::BadMimic { ref master, .. } if master == "nope"), "{err}");
    assert!(err.to_string().contains("no such joint"), "{err}");
    for bad in [r#"<mimic joint="a" multiplier="nan"/>"#, r#"<mimic joint="a" offset="inf"/>"#] {
        let err = parse_urdf(&two_link(bad), &options).unwrap_err();
        assert_eq!(err.line, 9, "{err}");
        assert!(matches!(*err.cause, UrdfCause::BadNumber { .. }), "{err}");
    }
    let err = parse_urdf(&two_link("<mimic/>"), &options).unwrap_err();
    assert!(matches!(*err.cause, UrdfCause::MissingAttribute("joint")), "{err}");
    // Ignored entirely when not coupling (Pinocchio's default).
    let model = parse_urdf(&two_link(r#"<mimic joint="nope"/>"#), &UrdfOptions::default()).unwrap();
    assert_eq!(model.nq(), 2);
    // The master locked: refused; the coupled joint locked too: nothing left to couple.
    let err =
        parse_urdf(&two_link(r#"<mimic joint="a"/>"#), &options.clone().lock_joint("a", 0.2)).unwrap_err();
    assert!(err.to_string().contains("locked"), "{err}");
    let model = parse_urdf(
        &two_link(r#"<mimic joint="a"/>"#),
        &options.clone().lock_joint("a", 0.2).lock_joint("b", 0.4),
    )
    .unwrap();
    assert_eq!(model.nq(), 0);
}

#[test]
fn chains_and_mixed_types_follow_pinocchio() {
    let options = UrdfOptions::default().couple_mimic_joints(true);
    let three = |b_mimic: &str, c_type: &str, c_mimic: &str| {
        two_link(b_mimic).replace(
            "</robot>",
            &format!(
                r#"<link name="l3"/><joint name="c" type="{c_type}"><parent link="l2"/><child link="l3"/>
                <axis xyz="1 0 0"/><limit lower="-1" upper="1"/>{c_mimic}</joint></robot>"#
            ),
        )
    };
    // A mimic of a mimic: Pinocchio refuses it (sizes differ), so do we, with the reason.
    let err = parse_urdf(&three(r#"<mimic joint="a"/>"#, "revolute", r#"<mimic joint="b"/>"#), &options)
        .unwrap_err();
    assert!(err.to_string().contains("chains"), "{err}");
    // A prismatic joint following a revolute one: accepted, as in Pinocchio.
    let model =
        parse_urdf(&three("", "prismatic", r#"<mimic joint="a" multiplier="0.5"/>"#), &options).unwrap();
    assert_eq!((model.nq(), model.nv(), model.nv_extended()), (2, 2, 3));
    // A continuous joint following a revolute one: Pinocchio's sizes differ, refused.
    let err = parse_urdf(&three("", "continuous", r#"<mimic joint="a"/>"#), &options).unwrap_err();
    assert!(err.to_string().contains("continuous"), "{err}");
    // <mimic> on a fixed joint: ignored, as in Pinocchio.
    let model = parse_urdf(&three("", "fixed", r#"<mimic joint="a"/>"#), &options).unwrap();
    assert!(model.mimic_joints().is_empty());
}

#[test]
fn aba_refused_and_simulation_takes_the_cholesky_path() {
    let model = coupled("robots/panda_description/urdf/panda.urdf.gz").unwrap();
    let mut data = Data::new(&model);
    let (q, v, tau) = (vec![0.1; model.nq()], vec![0.2; model.nv()], vec![0.3; model.nv()]);
    let err = anim_rigid::checked::aba(&model, &mut data, &q, &v, &tau).unwrap_err();
    assert!(matches!(err, InputError::Unsupported { algorithm: "aba", .. }), "{err}");
    let unchecked = std::panic::catch_unwind(|| {
        let mut data = Data::new(&model);
        anim_rigid::aba(&model, &mut data, &q, &v, &tau).to_vec()
    });
    assert!(unchecked.is_err());

    // The simulation's acceleration is the Cholesky forward dynamics with the system's forces.
    let mut sim = RigidSimulation::new(model.clone(), SimParams::default(), RigidIntegrator::Rk4).unwrap();
    let system = sim.system_mut();
    let mut forces = vec![0.0; model.nv()];
    system.joint_forces(&q, &v, &mut forces);
    let mut acc = vec![0.0; model.nv()];
    system.acceleration_into(&q, &v, &mut acc);
    let expected = forward_dynamics_cholesky(&model, &mut data, &q, &v, &forces).unwrap().to_vec();
    assert!(acc.iter().all(|x| x.is_finite()));
    assert!(rel_err(&acc, &expected) < 1e-14, "{acc:?} vs {expected:?}");
}

#[test]
fn jacobian_time_variation_matches_finite_differences_with_coupling() {
    // TIAGo Pro: ten coupled finger joints, multipliers ±1, masters on both grippers.
    let model = coupled("robots/tiago_pro_description/robots/tiago_pro.urdf.gz").unwrap();
    let mut data = Data::new(&model);
    let q: Vec<f64> = (0..model.nq()).map(|k| 0.3 * ((k as f64) * 1.7).sin()).collect();
    let v: Vec<f64> = (0..model.nv()).map(|k| ((k as f64) * 0.9).cos()).collect();
    let h = 1e-6;
    for name in ["gripper_left_fingertip_left_link", "gripper_right_inner_finger_right_link"] {
        let frame = model.frame_id(name).unwrap();
        for rf in [ReferenceFrame::World, ReferenceFrame::Local, ReferenceFrame::LocalWorldAligned] {
            anim_rigid::compute_joint_jacobians_time_variation(&model, &mut data, &q, &v);
            let mut jdot = Jacobian::zeros(model.nv());
            anim_rigid::frame_jacobian_time_variation(&model, &data, frame, rf, &mut jdot);
            let mut at = |dt: f64| {
                let qt = anim_rigid::config::integrate(&model, &q, &v, dt);
                compute_joint_jacobians(&model, &mut data, &qt);
                let mut j = Jacobian::zeros(model.nv());
                anim_rigid::frame_jacobian(&model, &data, frame, rf, &mut j);
                j.columns().iter().flat_map(|t| twist(*t)).collect::<Vec<f64>>()
            };
            let (plus, minus) = (at(h), at(-h));
            let fd: Vec<f64> = plus.iter().zip(&minus).map(|(a, b)| (a - b) / (2.0 * h)).collect();
            let ours: Vec<f64> = jdot.columns().iter().flat_map(|t| twist(*t)).collect();
            let err = rel_err(&ours, &fd);
            assert!(err < 1e-7, "{name} {rf:?}: {err:e}");
            // The coupled columns are really there: the master's column moves.
            assert!(ours.iter().any(|x| x.abs() > 1e-3));
        }
    }
}
