//! RNEA, CRBA, the bias and gravity terms, ABA and the energies against Pinocchio 4.1 on the
//! Franka Panda (fingers locked), the UR5, the generated 32-joint chain and the Panda on a
//! free-flyer base, from the JSON written by `testdata/make_pinocchio_dynamics_reference.py`.
//! Errors are relative to the largest entry of the reference vector or matrix of each sample.

#![allow(clippy::unwrap_used, clippy::expect_used)] // integration tests: a failed unwrap is a failed test

use anim_core::glam::{DMat3, DVec3};
use anim_rigid::{
    Data, Model, UrdfOptions, aba, crba, crba_local, crba_world, forward_dynamics, forward_dynamics_cholesky,
    gravity_torques, kinetic_energy, load_urdf, nonlinear_effects, potential_energy, rnea,
};
use serde_json::Value;

/// The tolerance the issue asks for (relative).
const TOL: f64 = 1e-9;

fn testdata(file: &str) -> String {
    format!("{}/testdata/{file}", env!("CARGO_MANIFEST_DIR"))
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
}

fn load(name: &str) -> (Model, Value) {
    let text = std::fs::read_to_string(testdata(&format!("pinocchio_dynamics_{name}.json"))).unwrap();
    let v: Value = serde_json::from_str(&text).unwrap();
    let mut options = UrdfOptions::default().floating_base(v["floating_base"].as_bool().unwrap());
    for n in v["locked_joints"].as_array().unwrap() {
        options = options.lock_joint(n.as_str().unwrap(), 0.0);
    }
    let model = load_urdf(testdata(v["urdf"].as_str().unwrap()), &options).unwrap();
    (model, v)
}

fn rel_err(ours: &[f64], reference: &[f64]) -> f64 {
    assert_eq!(ours.len(), reference.len());
    let scale = reference.iter().fold(0.0_f64, |m, x| m.max(x.abs())).max(1e-300);
    ours.iter().zip(reference).fold(0.0_f64, |m, (a, b)| m.max((a - b).abs())) / scale
}

fn check_model(model: &Model, v: &Value) {
    assert_eq!(model.nq() as u64, v["nq"].as_u64().unwrap());
    assert_eq!(model.nv() as u64, v["nv"].as_u64().unwrap());
    assert_eq!(model.gravity(), DVec3::from_slice(&floats(&v["gravity"])));
    let joints = v["joints"].as_array().unwrap();
    assert_eq!(model.njoints(), joints.len());
    for (i, j) in joints.iter().enumerate() {
        if i > 0 {
            let ours = model.joint(i);
            assert_eq!(ours.name, j["name"].as_str().unwrap());
            assert_eq!(ours.parent as u64, j["parent"].as_u64().unwrap());
            assert_eq!(ours.idx_q as u64, j["idx_q"].as_u64().unwrap());
            assert_eq!(ours.idx_v as u64, j["idx_v"].as_u64().unwrap());
        }
        let inertia = &model.inertias()[i];
        assert!((inertia.mass - j["mass"].as_f64().unwrap()).abs() < 1e-12, "mass of body {i}");
        assert!((inertia.com - DVec3::from_slice(&floats(&j["com"]))).abs().max_element() < 1e-12);
        let rot = floats(&j["inertia"]);
        let reference = DMat3::from_cols_slice(&rot).transpose();
        assert!((inertia.rotational - reference).abs_diff_eq(DMat3::ZERO, 1e-12), "inertia of body {i}");
    }
}

#[derive(Debug, Default)]
struct Errors {
    rnea: f64,
    crba: f64,
    nle: f64,
    gravity: f64,
    aba: f64,
    cholesky: f64,
    forward: f64,
    energy: f64,
}

fn compare(name: &str) -> Errors {
    let (model, json) = load(name);
    check_model(&model, &json);
    let mut data = Data::new(&model);
    let mut e = Errors::default();
    let samples = json["samples"].as_array().unwrap();
    assert_eq!(samples.len(), 50);
    for s in samples {
        let (q, v, a, tau) = (floats(&s["q"]), floats(&s["v"]), floats(&s["a"]), floats(&s["tau"]));
        e.rnea = e.rnea.max(rel_err(rnea(&model, &mut data, &q, &v, &a), &floats(&s["rnea"])));
        let reference = floats(&s["crba"]);
        e.crba = e.crba.max(rel_err(crba(&model, &mut data, &q).as_slice(), &reference));
        e.crba = e.crba.max(rel_err(crba_local(&model, &mut data, &q).as_slice(), &reference));
        e.crba = e.crba.max(rel_err(crba_world(&model, &mut data, &q).as_slice(), &reference));
        e.nle = e.nle.max(rel_err(nonlinear_effects(&model, &mut data, &q, &v), &floats(&s["nle"])));
        e.gravity = e.gravity.max(rel_err(gravity_torques(&model, &mut data, &q), &floats(&s["gravity"])));
        let reference = floats(&s["aba"]);
        e.aba = e.aba.max(rel_err(aba(&model, &mut data, &q, &v, &tau), &reference));
        let chol = forward_dynamics_cholesky(&model, &mut data, &q, &v, &tau).unwrap();
        e.cholesky = e.cholesky.max(rel_err(chol, &reference));
        // The pick between the two, after a call at another configuration (no stale state).
        crba(&model, &mut data, &anim_rigid::config::neutral(&model));
        e.forward = e.forward.max(rel_err(forward_dynamics(&model, &mut data, &q, &v, &tau), &reference));
        let ke = kinetic_energy(&model, &mut data, &q, &v);
        let pe = potential_energy(&model, &mut data, &q);
        let (rke, rpe) = (s["kinetic_energy"].as_f64().unwrap(), s["potential_energy"].as_f64().unwrap());
        e.energy =
            e.energy.max((ke - rke).abs() / rke.abs().max(1.0)).max((pe - rpe).abs() / rpe.abs().max(1.0));
    }
    eprintln!("{name}: {e:?}");
    for (what, err) in [
        ("rnea", e.rnea),
        ("crba", e.crba),
        ("nle", e.nle),
        ("gravity", e.gravity),
        ("aba", e.aba),
        ("cholesky forward dynamics", e.cholesky),
        ("forward dynamics", e.forward),
        ("energies", e.energy),
    ] {
        assert!(err < TOL, "{name} {what}: relative error {err:e}");
    }
    e
}

#[test]
fn panda_dynamics_matches_pinocchio() {
    compare("panda");
}

#[test]
fn ur5_dynamics_matches_pinocchio() {
    compare("ur5");
}

#[test]
fn chain32_dynamics_matches_pinocchio() {
    compare("chain32");
}

#[test]
fn floating_panda_dynamics_matches_pinocchio() {
    compare("panda_floating");
}
