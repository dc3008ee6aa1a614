//! Kinematics conformance: frame placements, Jacobians and their time derivatives against
//! Pinocchio on the Panda and the UR5; Jacobians against finite differences of forward
//! kinematics; the three forms of forward kinematics; Paden-Kahan subproblems on random solvable
//! instances; analytic IK solutions reproducing their targets.

use super::{PINOCCHIO, check, failed, floats, jac_err, panda, puma, rf_of, se3_err, se3_of, testdata, ur5};
use std::f64::consts::PI;

use crate::config::{integrate, random_configuration};
use crate::ik::pose_error;
use crate::model::FrameIndex;
use crate::paden_kahan::{
    DEFAULT_TOL, rotate_about, subproblem_plane, subproblem1, subproblem2, subproblem3, wrap_angle,
};
use crate::{
    AnalyticIk, Data, Jacobian, Model, PoeChain, ReferenceFrame, compute_joint_jacobians,
    compute_joint_jacobians_time_variation, frame_jacobian, frame_jacobian_time_variation,
    frames_forward_kinematics,
};
use anim_core::cases::{Check, Ctx, Judge, nan_max};
use anim_core::glam::DVec3;
use anim_core::lie::{Se3, Twist};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::Value;

/// Max errors (placements, J, dJ) of one robot against its Pinocchio JSON.
fn against_pinocchio(model: &Model, json: &Value) -> Result<(f64, f64, f64, usize), String> {
    let frames = json["frames"].as_array().ok_or("no frames in the JSON")?;
    let mut ids = Vec::new();
    for f in frames {
        let name = f["name"].as_str().unwrap_or("");
        let kind = match f["type"].as_str().unwrap_or("") {
            "JOINT" => crate::FrameKind::Joint,
            "FIXED_JOINT" => crate::FrameKind::FixedJoint,
            "BODY" => crate::FrameKind::Body,
            _ => crate::FrameKind::Operational,
        };
        ids.push(
            model
                .frame_id_of_kind(name, kind)
                .ok_or_else(|| format!("frame {name} missing from our model"))?,
        );
    }
    let mut data = Data::new(model);
    let mut j = Jacobian::zeros(model.nv());
    let (mut ep, mut ej, mut ed) = (0.0_f64, 0.0_f64, 0.0_f64);
    // Entries compared of each kind: a section missing from every sample compares nothing.
    let (mut np, mut nj, mut nd) = (0usize, 0usize, 0usize);
    let samples = json["samples"].as_array().ok_or("no samples in the JSON")?;
    for s in samples {
        let q = floats(&s["q"]);
        let v = floats(&s["v"]);
        if q.len() != model.nq() || v.len() != model.nv() {
            return Err("configuration size differs from our model".into());
        }
        frames_forward_kinematics(model, &mut data, &q);
        for (i, p) in s["joint_placements"].as_array().into_iter().flatten().enumerate() {
            ep = nan_max(ep, se3_err(&data.world_placements[i], &se3_of(p)));
            np += 1;
        }
        for (k, p) in s["frame_placements"].as_array().into_iter().flatten().enumerate() {
            let Some(&id) = ids.get(k) else { return Err("more frame placements than frames".into()) };
            ep = nan_max(ep, se3_err(&data.frame_placements[id], &se3_of(p)));
            np += 1;
        }
        compute_joint_jacobians(model, &mut data, &q);
        for (name, entry) in s["jacobians"].as_object().into_iter().flatten() {
            let fid = model.frame_id(name).ok_or_else(|| format!("frame {name} missing"))?;
            for (rf, reference) in entry.as_object().into_iter().flatten() {
                frame_jacobian(model, &data, fid, rf_of(rf), &mut j);
                ej = nan_max(ej, jac_err(&j, reference));
                nj += 1;
            }
        }
        compute_joint_jacobians_time_variation(model, &mut data, &q, &v);
        for (name, entry) in s["jacobian_dots"].as_object().into_iter().flatten() {
            let fid = model.frame_id(name).ok_or_else(|| format!("frame {name} missing"))?;
            for (rf, reference) in entry.as_object().into_iter().flatten() {
                frame_jacobian_time_variation(model, &data, fid, rf_of(rf), &mut j);
                ed = nan_max(ed, jac_err(&j, reference));
                nd += 1;
            }
        }
    }
    let none_is_nan = |e: f64, n: usize| if n == 0 { f64::NAN } else { e };
    Ok((none_is_nan(ep, np), none_is_nan(ej, nj), none_is_nan(ed, nd), samples.len()))
}

pub(super) fn pinocchio(_: &Ctx) -> Vec<Check> {
    let mut out = Vec::new();
    for (robot, model) in [("panda", panda()), ("ur5", ur5())] {
        let case = format!("{robot} vs Pinocchio");
        let model = match model {
            Ok(m) => m,
            Err(e) => {
                out.extend(failed(&case, &e));
                continue;
            }
        };
        let text = match std::fs::read_to_string(testdata(&format!("pinocchio_{robot}.json"))) {
            Ok(t) => t,
            Err(e) => {
                out.extend(failed(&case, &e.to_string()));
                continue;
            }
        };
        let json: Value = match serde_json::from_str(&text) {
            Ok(v) => v,
            Err(e) => {
                out.extend(failed(&case, &e.to_string()));
                continue;
            }
        };
        match against_pinocchio(&model, &json) {
            Ok((ep, ej, ed, n)) => {
                out.push(check(
                    &case,
                    &format!("max |placement error|, every frame, {n} configurations"),
                    ep,
                    1e-12,
                    Judge::AtMost,
                    PINOCCHIO,
                ));
                out.push(check(
                    &case,
                    "max |J error| (WORLD, LOCAL, LOCAL_WORLD_ALIGNED)",
                    ej,
                    1e-12,
                    Judge::AtMost,
                    PINOCCHIO,
                ));
                out.push(check(
                    &case,
                    "max |dJ/dt error| (tool frames, three frames)",
                    ed,
                    1e-12,
                    Judge::AtMost,
                    PINOCCHIO,
                ));
            }
            Err(e) => out.extend(failed(&case, &e)),
        }
    }
    out
}

pub(super) fn frame_at(model: &Model, data: &mut Data, q: &[f64], f: usize) -> Se3 {
    frames_forward_kinematics(model, data, q);
    data.frame_placements[f]
}

pub(super) fn jacobian_fd(ctx: &Ctx) -> Vec<Check> {
    let mut out = Vec::new();
    let models =
        [("panda", panda(), "panda_hand_tcp"), ("ur5", ur5(), "tool0"), ("puma-like", puma(), "tool")];
    let samples = if ctx.quick { 5 } else { 50 };
    let mut rng = ChaCha8Rng::seed_from_u64(61);
    for (name, model, frame) in models {
        let case = format!("{name} Jacobian vs central differences (eps 1e-6)");
        let (model, f) = match with_tool(model, frame) {
            Ok(x) => x,
            Err(why) => {
                out.extend(failed(&case, why));
                continue;
            }
        };
        let mut data = Data::new(&model);
        let mut j = Jacobian::zeros(model.nv());
        let mut worst = 0.0_f64;
        let eps = 1e-6;
        for _ in 0..samples {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            compute_joint_jacobians(&model, &mut data, &q);
            frame_jacobian(&model, &data, f, ReferenceFrame::Local, &mut j);
            let local = j.clone();
            frame_jacobian(&model, &data, f, ReferenceFrame::World, &mut j);
            let world = j.clone();
            let t = frame_at(&model, &mut data, &q, f);
            for k in 0..model.nv() {
                let mut dv = vec![0.0; model.nv()];
                dv[k] = eps;
                let plus = frame_at(&model, &mut data, &integrate(&model, &q, &dv, 1.0), f);
                let minus = frame_at(&model, &mut data, &integrate(&model, &q, &dv, -1.0), f);
                let fd: Twist = ((t.inverse() * plus).log() - (t.inverse() * minus).log()).scale(0.5 / eps);
                let fd_world = t.adjoint(fd);
                for (a, b) in local.column(k).to_array().iter().zip(fd.to_array()) {
                    worst = nan_max(worst, (a - b).abs());
                }
                for (a, b) in world.column(k).to_array().iter().zip(fd_world.to_array()) {
                    worst = nan_max(worst, (a - b).abs());
                }
            }
        }
        out.push(check(
            &case,
            &format!("max |J - J_fd| (LOCAL, WORLD), {samples} configurations"),
            worst,
            1e-8,
            Judge::AtMost,
            "central differences of FK on the manifold",
        ));
    }
    out
}

pub(super) fn fk_three_ways(ctx: &Ctx) -> Vec<Check> {
    let mut out = Vec::new();
    let samples = if ctx.quick { 20 } else { 200 };
    let mut rng = ChaCha8Rng::seed_from_u64(62);
    for (name, model) in [("panda", panda()), ("ur5", ur5()), ("puma-like", puma())] {
        let case = format!("{name} PoE space/body vs joint composition");
        let Ok(model) = model else {
            out.extend(failed(&case, "model did not load"));
            continue;
        };
        let chains: Vec<PoeChain> = (0..model.frames().len()).map(|f| PoeChain::new(&model, f)).collect();
        let mut data = Data::new(&model);
        let mut worst = 0.0_f64;
        for _ in 0..samples {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            frames_forward_kinematics(&model, &mut data, &q);
            for (f, c) in chains.iter().enumerate() {
                worst = nan_max(worst, se3_err(&data.frame_placements[f], &c.forward_space(&q)));
                worst = nan_max(worst, se3_err(&data.frame_placements[f], &c.forward_body(&q)));
            }
        }
        out.push(check(
            &case,
            &format!("max |difference|, every frame, {samples} configurations"),
            worst,
            1e-13,
            Judge::AtMost,
            "three formulations of the same map",
        ));
    }
    out
}

pub(super) fn unit(rng: &mut ChaCha8Rng) -> DVec3 {
    loop {
        let v =
            DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        let n = v.length();
        if n > 0.1 && n <= 1.0 {
            return v / n;
        }
    }
}

pub(super) fn point(rng: &mut ChaCha8Rng) -> DVec3 {
    DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0))
}

pub(super) fn paden_kahan(_: &Ctx) -> Vec<Check> {
    let n = 100_000;
    let mut rng = ChaCha8Rng::seed_from_u64(63);
    let source = "instances built from known angles (rotate, then solve back)";
    let (mut r1, mut r2, mut r3, mut r4) = (0.0_f64, 0.0_f64, 0.0_f64, 0.0_f64);
    let (mut u1, mut u2, mut u3, mut u4) = (0usize, 0usize, 0usize, 0usize);
    for _ in 0..n {
        let (w, r, p) = (unit(&mut rng), point(&mut rng), point(&mut rng));
        let q = rotate_about(w, r, rng.random_range(-PI..PI), p);
        match subproblem1(w, r, p, q, DEFAULT_TOL) {
            Some(s) => r1 = r1.max((rotate_about(w, r, s.angle(), p) - q).length()),
            None => u1 += 1,
        }
        let (w1, w2, r, p) = (unit(&mut rng), unit(&mut rng), point(&mut rng), point(&mut rng));
        let q =
            rotate_about(w1, r, rng.random_range(-PI..PI), rotate_about(w2, r, rng.random_range(-PI..PI), p));
        match subproblem2(w1, w2, r, p, q, DEFAULT_TOL) {
            Some(s) => {
                for (a, b) in s.solutions() {
                    r2 = r2.max((rotate_about(w1, r, a, rotate_about(w2, r, b, p)) - q).length());
                }
            }
            None => u2 += 1,
        }
        let (w, r, p, q) = (unit(&mut rng), point(&mut rng), point(&mut rng), point(&mut rng));
        let delta = (rotate_about(w, r, rng.random_range(-PI..PI), p) - q).length();
        match subproblem3(w, r, p, q, delta, DEFAULT_TOL) {
            Some(s) => {
                for t in s.solutions() {
                    r3 = r3.max(((rotate_about(w, r, t, p) - q).length() - delta).abs());
                }
            }
            None => u3 += 1,
        }
        let (w, r, p, nrm) = (unit(&mut rng), point(&mut rng), point(&mut rng), unit(&mut rng));
        let d = nrm.dot(rotate_about(w, r, rng.random_range(-PI..PI), p));
        match subproblem_plane(w, r, p, nrm, d, DEFAULT_TOL) {
            Some(s) => {
                for t in s.solutions() {
                    r4 = r4.max((nrm.dot(rotate_about(w, r, t, p)) - d).abs());
                }
            }
            None => u4 += 1,
        }
    }
    let mut out = Vec::new();
    for (name, res, unsolved) in [
        ("subproblem 1", r1, u1),
        ("subproblem 2", r2, u2),
        ("subproblem 3", r3, u3),
        ("point onto plane (UR helper)", r4, u4),
    ] {
        let case = format!("Paden-Kahan {name}, {n} random solvable instances");
        out.push(check(&case, "max residual of every returned solution", res, 1e-10, Judge::AtMost, source));
        out.push(check(&case, "instances reported unsolvable", unsolved as f64, 0.0, Judge::AtMost, source));
    }
    out
}

pub(super) fn analytic_ik(ctx: &Ctx) -> Vec<Check> {
    let n = if ctx.quick { 2000 } else { 10_000 };
    let mut out = Vec::new();
    let mut rng = ChaCha8Rng::seed_from_u64(64);
    for (name, model, frame) in
        [("UR5 (UR type)", ur5(), "tool0"), ("PUMA-like (spherical wrist)", puma(), "tool")]
    {
        let case = format!("{name} analytic IK, {n} random reachable targets");
        let (model, f) = match with_tool(model, frame) {
            Ok(x) => x,
            Err(why) => {
                out.extend(failed(&case, why));
                continue;
            }
        };
        let ik = match AnalyticIk::new(&model, f) {
            Ok(ik) => ik,
            Err(e) => {
                out.extend(failed(&case, &e.to_string()));
                continue;
            }
        };
        let mut data = Data::new(&model);
        let (mut worst, mut total, mut found) = (0.0_f64, 0usize, 0usize);
        for _ in 0..n {
            let q: Vec<f64> = random_configuration(&model, &mut || rng.random::<f64>())
                .iter()
                .map(|x| wrap_angle(*x))
                .collect();
            let target = frame_at(&model, &mut data, &q, f);
            let sols = ik.solve(&target);
            total += sols.len();
            for s in &sols {
                let (dp, dr) = pose_error(&frame_at(&model, &mut data, &s.q, f), &target);
                worst = nan_max(nan_max(worst, dp), dr);
            }
            if sols.iter().any(|s| s.q.iter().zip(&q).all(|(a, b)| wrap_angle(a - b).abs() < 1e-6)) {
                found += 1;
            }
        }
        let src = "forward kinematics of the returned solutions";
        out.push(check(&case, "max pose error of every solution (m, rad)", worst, 1e-10, Judge::AtMost, src));
        out.push(check(
            &case,
            "fraction of targets whose generating q is among the solutions",
            found as f64 / n as f64,
            1.0,
            Judge::AtLeast,
            src,
        ));
        out.push(check(
            &case,
            "mean number of solutions (at most 8)",
            total as f64 / n as f64,
            6.0,
            Judge::AtLeast,
            src,
        ));
    }
    out
}

/// A loaded model with its tool frame `frame`, or why the case cannot run.
fn with_tool(model: Result<Model, String>, frame: &str) -> Result<(Model, FrameIndex), &'static str> {
    let model = model.map_err(|_| "model did not load")?;
    let f = model.frame_id(frame).ok_or("no tool frame")?;
    Ok((model, f))
}
