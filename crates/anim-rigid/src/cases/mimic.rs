//! Coupled (mimic) joints against Pinocchio 4.1 built with `mimic=True`: for every robot of the
//! example-robot-data collection with coupled joints (Panda, Baxter, PR2, TIAGo Pro), the
//! worst relative errors of the joint placements, the extended and per-joint Jacobians, RNEA,
//! CRBA, the bias term, Cholesky forward dynamics and the energies over the reference's samples
//! (`testdata/pinocchio_mimic.json.gz`).

use std::io::Read;

use anim_core::cases::{Check, Ctx, Judge, nan_max};
use anim_core::lie::Twist;
use serde_json::Value;

use crate::cases::{check, failed, floats, testdata};
use crate::{
    Data, Jacobian, Model, ReferenceFrame, UrdfOptions, compute_joint_jacobians, crba,
    forward_dynamics_cholesky, forward_kinematics, joint_jacobian, kinetic_energy, nonlinear_effects,
    parse_urdf, pinocchio, potential_energy, rnea,
};

const SOURCE: &str =
    "Pinocchio 4.1.0 (mimic=True) via crates/anim-rigid/testdata/make_pinocchio_mimic_reference.py";
/// Relative tolerance: to the largest reference entry of each quantity and sample, at least 1.
const TOL: f64 = 1e-12;
const METRICS: [&str; 9] = [
    "joint placements (data.oMi)",
    "extended Jacobian columns (data.J)",
    "WORLD Jacobians of the coupled joints",
    "RNEA tau",
    "CRBA H (all entries)",
    "bias C(q, v)",
    "forward dynamics by Cholesky vs solve(H, tau - C)",
    "kinetic energy",
    "potential energy",
];

fn gunzip(file: &str) -> Result<String, String> {
    let f = std::fs::File::open(testdata(file)).map_err(|e| format!("{file}: {e}"))?;
    let mut text = String::new();
    flate2::read::GzDecoder::new(f).read_to_string(&mut text).map_err(|e| format!("{file}: {e}"))?;
    Ok(text)
}

fn rel_err(ours: &[f64], reference: &[f64]) -> f64 {
    if ours.len() != reference.len() {
        return f64::NAN;
    }
    let scale = reference.iter().fold(1.0_f64, |m, x| nan_max(m, x.abs()));
    ours.iter().zip(reference).fold(0.0_f64, |m, (a, b)| nan_max(m, (a - b).abs())) / scale
}

fn twist(t: Twist) -> [f64; 6] {
    [t.v.x, t.v.y, t.v.z, t.w.x, t.w.y, t.w.z]
}

/// The worst errors of one robot (`METRICS` order) and its sample count.
fn robot(robot: &Value) -> Result<([f64; 9], usize), String> {
    let urdf = robot["urdf"].as_str().ok_or("no urdf")?;
    let model: Model = parse_urdf(&gunzip(urdf)?, &UrdfOptions::default().couple_mimic_joints(true))
        .map_err(|e| e.to_string())?;
    let joints = robot["joints"].as_array().ok_or("no joints")?;
    if joints.len() != model.njoints()
        || Some(model.nv() as u64) != robot["nv"].as_u64()
        || Some(pinocchio::nq(&model) as u64) != robot["nq"].as_u64()
        || Some(model.nv_extended() as u64) != robot["nv_extended"].as_u64()
    {
        return Err("the model's sizes differ from Pinocchio's".into());
    }
    let mut columns = Vec::new();
    for (i, j) in joints.iter().enumerate().skip(1) {
        let ours = model.joint(i);
        let first = ours.mimic.map_or(ours.idx_v, |m| m.column);
        let pin_first = j["idx_v_extended"].as_u64().ok_or("no idx_v_extended")? as usize;
        for k in 0..j["nv_extended"].as_u64().ok_or("no nv_extended")? as usize {
            columns.push((first + k, pin_first + k));
        }
    }
    let mut data = Data::new(&model);
    let mut out = Jacobian::zeros(model.nv());
    let mut e = [0.0_f64; 9];
    let samples = robot["samples"].as_array().map(Vec::as_slice).unwrap_or(&[]);
    for s in samples {
        let q = pinocchio::from_pinocchio(&model, &floats(&s["q"])).map_err(|e| e.to_string())?;
        let (v, a, tau) = (floats(&s["v"]), floats(&s["a"]), floats(&s["tau"]));
        if v.len() != model.nv() || a.len() != model.nv() || tau.len() != model.nv() {
            return Err("sample sizes differ from the model".into());
        }
        forward_kinematics(&model, &mut data, &q);
        let placements: Vec<f64> =
            s["placements"].as_array().map(|p| p.iter().flat_map(floats).collect()).unwrap_or_default();
        let ours: Vec<f64> = data
            .world_placements
            .iter()
            .flat_map(|m| {
                let r = m.rotation.transpose();
                [r.x_axis, r.y_axis, r.z_axis, m.translation].into_iter().flat_map(|c| c.to_array())
            })
            .collect();
        e[0] = nan_max(e[0], rel_err(&ours, &placements));
        compute_joint_jacobians(&model, &mut data, &q);
        let jref = floats(&s["jacobian"]);
        let (mut ours, mut theirs) = (Vec::new(), Vec::new());
        for &(c, p) in &columns {
            ours.extend(twist(data.jacobian.column(c)));
            theirs.extend(jref.get(6 * p..6 * p + 6).unwrap_or(&[f64::NAN; 6]));
        }
        e[1] = nan_max(e[1], rel_err(&ours, &theirs));
        for (name, jj) in s["joint_jacobians"].as_object().into_iter().flatten() {
            let i = model.joint_id(name).ok_or_else(|| format!("no joint {name}"))?;
            joint_jacobian(&model, &data, i, ReferenceFrame::World, &mut out);
            let ours: Vec<f64> = out.columns().iter().flat_map(|t| twist(*t)).collect();
            e[2] = nan_max(e[2], rel_err(&ours, &floats(jj)));
        }
        e[3] = nan_max(e[3], rel_err(rnea(&model, &mut data, &q, &v, &a), &floats(&s["rnea"])));
        e[4] = nan_max(e[4], rel_err(crba(&model, &mut data, &q).as_slice(), &floats(&s["crba"])));
        e[5] = nan_max(e[5], rel_err(nonlinear_effects(&model, &mut data, &q, &v), &floats(&s["nle"])));
        let fd = forward_dynamics_cholesky(&model, &mut data, &q, &v, &tau).map_err(|e| e.to_string())?;
        e[6] = nan_max(e[6], rel_err(fd, &floats(&s["fd"])));
        let t = kinetic_energy(&model, &mut data, &q, &v);
        e[7] = nan_max(e[7], rel_err(&[t], &[s["kinetic_energy"].as_f64().unwrap_or(f64::NAN)]));
        let u = potential_energy(&model, &mut data, &q);
        e[8] = nan_max(e[8], rel_err(&[u], &[s["potential_energy"].as_f64().unwrap_or(f64::NAN)]));
    }
    if samples.is_empty() {
        e = [f64::NAN; 9];
    }
    Ok((e, samples.len()))
}

pub(super) fn pinocchio_mimic(_: &Ctx) -> Vec<Check> {
    let json: Value = match gunzip("pinocchio_mimic.json.gz")
        .and_then(|t| serde_json::from_str(&t).map_err(|e| e.to_string()))
    {
        Ok(v) => v,
        Err(e) => return failed("coupled joints vs Pinocchio", &e),
    };
    let mut out = Vec::new();
    for r in json["robots"].as_array().into_iter().flatten() {
        let name =
            r["urdf"].as_str().unwrap_or("?").rsplit('/').next().unwrap_or("?").trim_end_matches(".urdf.gz");
        let case = format!("{name} coupled (mimic) joints vs Pinocchio");
        match robot(r) {
            Err(e) => out.extend(failed(&case, &e)),
            Ok((e, n)) => {
                for (what, err) in METRICS.iter().zip(e) {
                    let metric = format!("max relative error of {what}, {n} random (q, v, a, tau)");
                    out.push(check(&case, &metric, err, TOL, Judge::AtMost, SOURCE));
                }
            }
        }
    }
    // The robots Pinocchio refuses (a master later in the depth-first order) are refused here.
    let refused = json["refused"].as_array().map(Vec::as_slice).unwrap_or(&[]);
    let agree = refused
        .iter()
        .filter(|r| {
            let Some(urdf) = r["urdf"].as_str() else { return false };
            gunzip(urdf)
                .is_ok_and(|t| parse_urdf(&t, &UrdfOptions::default().couple_mimic_joints(true)).is_err())
        })
        .count();
    out.push(check(
        "URDFs Pinocchio refuses with mimic=True",
        &format!("refused here too, of {}", refused.len()),
        agree as f64,
        refused.len() as f64,
        Judge::AtLeast,
        SOURCE,
    ));
    out
}
