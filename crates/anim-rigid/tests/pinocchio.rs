//! Forward kinematics, frame placements and Jacobians against Pinocchio 4.1 on the Franka Panda
//! (fingers locked) and the UR5, from the JSON written by `testdata/make_pinocchio_reference.py`.

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

use anim_core::glam::{DMat3, DVec3};
use anim_core::lie::Se3;
use anim_rigid::{
    Data, FrameKind, Jacobian, Model, ReferenceFrame, UrdfOptions, compute_joint_jacobians,
    compute_joint_jacobians_time_variation, frame_jacobian, frame_jacobian_time_variation,
    frames_forward_kinematics, load_urdf,
};
use serde_json::Value;

const TOL: f64 = 1e-12;

fn testdata(file: &str) -> String {
    format!("{}/testdata/{file}", env!("CARGO_MANIFEST_DIR"))
}

fn load(robot: &str) -> (Model, Value) {
    let text = std::fs::read_to_string(testdata(&format!("pinocchio_{robot}.json"))).unwrap();
    let v: Value = serde_json::from_str(&text).unwrap();
    let mut options = UrdfOptions::default();
    for n in v["locked_joints"].as_array().unwrap() {
        options = options.lock_joint(n.as_str().unwrap(), 0.0);
    }
    let model = load_urdf(testdata(v["urdf"].as_str().unwrap()), &options).unwrap();
    (model, v)
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

fn se3_of(v: &Value) -> Se3 {
    let a = floats(v);
    let r = DMat3::from_cols(
        DVec3::new(a[0], a[3], a[6]),
        DVec3::new(a[1], a[4], a[7]),
        DVec3::new(a[2], a[5], a[8]),
    );
    Se3::new(r, DVec3::new(a[9], a[10], a[11]))
}

fn se3_err(a: &Se3, b: &Se3) -> f64 {
    let r = (a.rotation - b.rotation).to_cols_array().iter().fold(0.0_f64, |m, e| m.max(e.abs()));
    r.max((a.translation - b.translation).abs().max_element())
}

fn jac_err(j: &Jacobian, reference: &Value) -> f64 {
    let r = floats(reference);
    let n = j.ncols();
    assert_eq!(r.len(), 6 * n);
    (0..6)
        .flat_map(|row| (0..n).map(move |c| (row, c)))
        .fold(0.0_f64, |m, (row, c)| m.max((j[(row, c)] - r[row * n + c]).abs()))
}

fn kind(name: &str) -> FrameKind {
    match name {
        "JOINT" => FrameKind::Joint,
        "FIXED_JOINT" => FrameKind::FixedJoint,
        "BODY" => FrameKind::Body,
        _ => FrameKind::Operational,
    }
}

fn rf(name: &str) -> ReferenceFrame {
    match name {
        "WORLD" => ReferenceFrame::World,
        "LOCAL" => ReferenceFrame::Local,
        _ => ReferenceFrame::LocalWorldAligned,
    }
}

fn check_model(model: &Model, v: &Value) {
    assert_eq!(model.nq() as u64, v["nq"].as_u64().unwrap());
    assert_eq!(model.nv() as u64, v["nv"].as_u64().unwrap());
    let joints = v["joints"].as_array().unwrap();
    assert_eq!(model.njoints(), joints.len());
    for (i, j) in joints.iter().enumerate().skip(1) {
        let ours = model.joint(i);
        assert_eq!(ours.name, j["name"].as_str().unwrap());
        assert_eq!(ours.parent as u64, j["parent"].as_u64().unwrap());
        assert_eq!(ours.idx_q as u64, j["idx_q"].as_u64().unwrap());
        assert!(se3_err(&ours.placement, &se3_of(&j["placement"])) < TOL, "placement of {}", ours.name);
        let lower = floats(&j["lower"]);
        assert_eq!(ours.limits.lower, lower[0], "lower limit of {}", ours.name);
    }
    for (i, j) in joints.iter().enumerate() {
        let inertia = &model.inertias()[i];
        let mass = j["mass"].as_f64().unwrap();
        assert!((inertia.mass - mass).abs() < TOL * mass.max(1.0), "mass of body {i}");
        let com = floats(&j["com"]);
        assert!((inertia.com - DVec3::from_slice(&com)).abs().max_element() < TOL, "com of body {i}");
        let rot = floats(&j["inertia"]);
        let ours = inertia.rotational.transpose().to_cols_array(); // row-major
        let err = ours.iter().zip(&rot).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(err < TOL, "rotational inertia of body {i}: {err}");
    }
    let frames = v["frames"].as_array().unwrap();
    for f in frames {
        let name = f["name"].as_str().unwrap();
        let id = model
            .frame_id_of_kind(name, kind(f["type"].as_str().unwrap()))
            .unwrap_or_else(|| panic!("frame {name}"));
        let ours = model.frame(id);
        assert_eq!(ours.parent_joint as u64, f["parent_joint"].as_u64().unwrap(), "frame {name}");
        assert!(se3_err(&ours.placement, &se3_of(&f["placement"])) < TOL, "frame {name}");
    }
}

fn check_samples(model: &Model, v: &Value) -> (f64, f64, f64) {
    let mut data = Data::new(model);
    let mut j = Jacobian::zeros(model.nv());
    let frames = v["frames"].as_array().unwrap();
    let frame_ids: Vec<usize> = frames
        .iter()
        .map(|f| {
            model.frame_id_of_kind(f["name"].as_str().unwrap(), kind(f["type"].as_str().unwrap())).unwrap()
        })
        .collect();
    let (mut max_place, mut max_jac, mut max_djac) = (0.0_f64, 0.0_f64, 0.0_f64);
    let samples = v["samples"].as_array().unwrap();
    assert_eq!(samples.len(), 50);
    for s in samples {
        let q = floats(&s["q"]);
        let vel = floats(&s["v"]);
        frames_forward_kinematics(model, &mut data, &q);
        for (i, p) in s["joint_placements"].as_array().unwrap().iter().enumerate() {
            max_place = max_place.max(se3_err(&data.world_placements[i], &se3_of(p)));
        }
        for (k, p) in s["frame_placements"].as_array().unwrap().iter().enumerate() {
            max_place = max_place.max(se3_err(&data.frame_placements[frame_ids[k]], &se3_of(p)));
        }
        compute_joint_jacobians(model, &mut data, &q);
        for (name, entry) in s["jacobians"].as_object().unwrap() {
            let fid = model.frame_id(name).unwrap();
            for (rf_name, reference) in entry.as_object().unwrap() {
                frame_jacobian(model, &data, fid, rf(rf_name), &mut j);
                let e = jac_err(&j, reference);
                assert!(e < TOL, "{name} {rf_name}: {e}");
                max_jac = max_jac.max(e);
            }
        }
        compute_joint_jacobians_time_variation(model, &mut data, &q, &vel);
        for (name, entry) in s["jacobian_dots"].as_object().unwrap() {
            let fid = model.frame_id(name).unwrap();
            for (rf_name, reference) in entry.as_object().unwrap() {
                frame_jacobian_time_variation(model, &data, fid, rf(rf_name), &mut j);
                let e = jac_err(&j, reference);
                assert!(e < TOL, "dJ {name} {rf_name}: {e}");
                max_djac = max_djac.max(e);
            }
        }
    }
    assert!(max_place < TOL, "placements: {max_place}");
    (max_place, max_jac, max_djac)
}

#[test]
fn panda_matches_pinocchio() {
    let (model, v) = load("panda");
    assert_eq!((model.nq(), model.nv()), (7, 7));
    check_model(&model, &v);
    let errs = check_samples(&model, &v);
    eprintln!("panda max errors: placements {:.2e}, J {:.2e}, dJ {:.2e}", errs.0, errs.1, errs.2);
}

#[test]
fn ur5_matches_pinocchio() {
    let (model, v) = load("ur5");
    assert_eq!((model.nq(), model.nv()), (6, 6));
    check_model(&model, &v);
    let errs = check_samples(&model, &v);
    eprintln!("ur5 max errors: placements {:.2e}, J {:.2e}, dJ {:.2e}", errs.0, errs.1, errs.2);
}
