//! anim-rigid (kinematics): frame placements, Jacobians and their time derivatives against
//! Pinocchio on the Panda and the UR5; Jacobians against finite differences; the three forms of
//! forward kinematics; Paden-Kahan subproblems on random solvable instances; analytic IK
//! solutions reproducing their targets. Stability: IK at singularities, unreachable targets,
//! workspace-boundary targets, and the numerical IK success rate on the Panda. The dynamics
//! cases (RNEA, CRBA, ABA against Pinocchio, cross-checks, steppers, the T-handle, the
//! work-precision study) are in `rigid/dynamics.rs`.

mod dynamics;

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::registry::{Check, ConformanceCase, Ctx, Judge, Outcome, Registry, StabilityCase};
use anim_core::glam::{DMat3, DVec3};
use anim_core::lie::{Se3, Twist};
use anim_rigid::config::{integrate, random_configuration};
use anim_rigid::ik::pose_error;
use anim_rigid::paden_kahan::{
    DEFAULT_TOL, rotate_about, subproblem_plane, subproblem1, subproblem2, subproblem3, wrap_angle,
};
use anim_rigid::{
    AnalyticIk, Data, IkParams, Jacobian, Model, NumericalIk, PoeChain, ReferenceFrame, UrdfOptions,
    compute_joint_jacobians, compute_joint_jacobians_time_variation, frame_jacobian,
    frame_jacobian_time_variation, frames_forward_kinematics, load_urdf,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::Value;

const CRATE: &str = "anim-rigid";
const PINOCCHIO: &str = "Pinocchio 4.1.0 via crates/anim-rigid/testdata/make_pinocchio_reference.py";

pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "placements and Jacobians vs Pinocchio (Panda, UR5)",
        run: Box::new(pinocchio),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "Jacobians vs finite differences of FK",
        run: Box::new(jacobian_fd),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "FK three ways agree",
        run: Box::new(fk_three_ways),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "Paden-Kahan subproblems on random solvable instances",
        run: Box::new(paden_kahan),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "analytic IK solutions reproduce targets",
        run: Box::new(analytic_ik),
    });

    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "UR5 analytic IK, wrist aligned (theta5 = 0)",
        expected: || Outcome::Stable(String::new()),
        run: |_| ur5_singular(&[0.3, -1.0, 1.2, 0.5, 0.0, 0.1]),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "UR5 analytic IK, elbow straight (theta3 = 0, workspace boundary)",
        expected: || Outcome::Stable(String::new()),
        run: |_| ur5_singular(&[0.3, -1.0, 0.0, 0.5, 0.8, 0.1]),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PUMA-like analytic IK, wrist aligned (theta5 = 0)",
        expected: || Outcome::Stable(String::new()),
        run: |_| puma_singular(),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "analytic IK, unreachable target (3 m away)",
        expected: || Outcome::Rejected(String::new()),
        run: |_| analytic_unreachable(),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "Panda numerical IK, unreachable target (2 m away): failure with the closest pose",
        expected: || Outcome::Rejected(String::new()),
        run: |_| panda_unreachable(),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "Panda numerical IK near singularities (elbow at its limit, wrist aligned)",
        expected: || Outcome::Stable(String::new()),
        run: |_| panda_singular(),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "Panda numerical IK at the workspace boundary (arm stretched)",
        expected: || Outcome::Stable(String::new()),
        run: |_| panda_boundary(),
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "Panda numerical IK success rate, random reachable targets",
        expected: || Outcome::Stable(String::new()),
        run: panda_success_rate,
    });
    dynamics::register(r);
}

fn testdata(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../crates/anim-rigid/testdata").join(file)
}

fn panda() -> Result<Model, String> {
    let options =
        UrdfOptions::default().lock_joint("panda_finger_joint1", 0.0).lock_joint("panda_finger_joint2", 0.0);
    load_urdf(testdata("panda.urdf"), &options).map_err(|e| e.to_string())
}

fn ur5() -> Result<Model, String> {
    load_urdf(testdata("ur5_robot.urdf"), &UrdfOptions::default()).map_err(|e| e.to_string())
}

fn puma() -> Result<Model, String> {
    load_urdf(testdata("puma_like.urdf"), &UrdfOptions::default()).map_err(|e| e.to_string())
}

fn check(
    case: &str,
    metric: &str,
    measured: f64,
    tolerance: f64,
    judge: Judge,
    source: &'static str,
) -> Check {
    Check {
        crate_name: CRATE,
        case: case.to_string(),
        metric: metric.to_string(),
        measured,
        reference: 0.0,
        tolerance,
        judge,
        source,
    }
}

fn failed(case: &str, why: &str) -> Vec<Check> {
    eprintln!("{case}: {why}");
    vec![check(case, &format!("could not run: {why}"), f64::NAN, 0.0, Judge::AtMost, "-")]
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array().map(|a| a.iter().filter_map(Value::as_f64).collect()).unwrap_or_default()
}

fn se3_of(v: &Value) -> Se3 {
    let a = floats(v);
    if a.len() != 12 {
        return Se3::new(DMat3::from_diagonal(DVec3::splat(f64::NAN)), DVec3::NAN);
    }
    let r = DMat3::from_cols(
        DVec3::new(a[0], a[3], a[6]),
        DVec3::new(a[1], a[4], a[7]),
        DVec3::new(a[2], a[5], a[8]),
    );
    Se3::new(r, DVec3::new(a[9], a[10], a[11]))
}

fn se3_err(a: &Se3, b: &Se3) -> f64 {
    let r = (a.rotation - b.rotation).to_cols_array().iter().fold(0.0_f64, |m, e| m.max(e.abs()));
    let t = (a.translation - b.translation).abs().max_element();
    if r.is_nan() || t.is_nan() { f64::NAN } else { r.max(t) }
}

fn jac_err(j: &Jacobian, reference: &Value) -> f64 {
    let r = floats(reference);
    let n = j.ncols();
    if r.len() != 6 * n {
        return f64::NAN;
    }
    let mut m = 0.0_f64;
    for row in 0..6 {
        for c in 0..n {
            m = m.max((j[(row, c)] - r[row * n + c]).abs());
        }
    }
    m
}

fn rf_of(name: &str) -> ReferenceFrame {
    match name {
        "WORLD" => ReferenceFrame::World,
        "LOCAL" => ReferenceFrame::Local,
        _ => ReferenceFrame::LocalWorldAligned,
    }
}

/// Max errors (placements, J, dJ) of one robot against its Pinocchio JSON.
fn against_pinocchio(model: &Model, json: &Value) -> Result<(f64, f64, f64, usize), String> {
    let frames = json["frames"].as_array().ok_or("no frames in the JSON")?;
    let mut ids = Vec::new();
    for f in frames {
        let name = f["name"].as_str().unwrap_or("");
        let kind = match f["type"].as_str().unwrap_or("") {
            "JOINT" => anim_rigid::FrameKind::Joint,
            "FIXED_JOINT" => anim_rigid::FrameKind::FixedJoint,
            "BODY" => anim_rigid::FrameKind::Body,
            _ => anim_rigid::FrameKind::Operational,
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
    let samples = json["samples"].as_array().ok_or("no samples in the JSON")?;
    for s in samples {
        let q = floats(&s["q"]);
        let v = floats(&s["v"]);
        if q.len() != model.nq() || v.len() != model.nv() {
            return Err("configuration size differs from our model".into());
        }
        frames_forward_kinematics(model, &mut data, &q);
        for (i, p) in s["joint_placements"].as_array().into_iter().flatten().enumerate() {
            ep = ep.max(se3_err(&data.world_placements[i], &se3_of(p)));
        }
        for (k, p) in s["frame_placements"].as_array().into_iter().flatten().enumerate() {
            ep = ep.max(se3_err(&data.frame_placements[ids[k]], &se3_of(p)));
        }
        compute_joint_jacobians(model, &mut data, &q);
        for (name, entry) in s["jacobians"].as_object().into_iter().flatten() {
            let fid = model.frame_id(name).ok_or_else(|| format!("frame {name} missing"))?;
            for (rf, reference) in entry.as_object().into_iter().flatten() {
                frame_jacobian(model, &data, fid, rf_of(rf), &mut j);
                ej = ej.max(jac_err(&j, reference));
            }
        }
        compute_joint_jacobians_time_variation(model, &mut data, &q, &v);
        for (name, entry) in s["jacobian_dots"].as_object().into_iter().flatten() {
            let fid = model.frame_id(name).ok_or_else(|| format!("frame {name} missing"))?;
            for (rf, reference) in entry.as_object().into_iter().flatten() {
                frame_jacobian_time_variation(model, &data, fid, rf_of(rf), &mut j);
                ed = ed.max(jac_err(&j, reference));
            }
        }
    }
    Ok((ep, ej, ed, samples.len()))
}

fn pinocchio(_: &Ctx) -> Vec<Check> {
    let mut out = Vec::new();
    for (robot, model) in [("panda", panda()), ("ur5", ur5())] {
        let case = format!("{robot} vs Pinocchio");
        let model = match model {
            Ok(m) => m,
            Err(e) => return failed(&case, &e),
        };
        let text = match std::fs::read_to_string(testdata(&format!("pinocchio_{robot}.json"))) {
            Ok(t) => t,
            Err(e) => return failed(&case, &e.to_string()),
        };
        let json: Value = match serde_json::from_str(&text) {
            Ok(v) => v,
            Err(e) => return failed(&case, &e.to_string()),
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
            Err(e) => return failed(&case, &e),
        }
    }
    out
}

fn frame_at(model: &Model, data: &mut Data, q: &[f64], f: usize) -> Se3 {
    frames_forward_kinematics(model, data, q);
    data.frame_placements[f]
}

fn jacobian_fd(ctx: &Ctx) -> Vec<Check> {
    let mut out = Vec::new();
    let models =
        [("panda", panda(), "panda_hand_tcp"), ("ur5", ur5(), "tool0"), ("puma-like", puma(), "tool")];
    let samples = if ctx.quick { 5 } else { 50 };
    let mut rng = ChaCha8Rng::seed_from_u64(61);
    for (name, model, frame) in models {
        let case = format!("{name} Jacobian vs central differences (eps 1e-6)");
        let Ok(model) = model else { return failed(&case, "model did not load") };
        let Some(f) = model.frame_id(frame) else { return failed(&case, "no tool frame") };
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
                    worst = worst.max((a - b).abs());
                }
                for (a, b) in world.column(k).to_array().iter().zip(fd_world.to_array()) {
                    worst = worst.max((a - b).abs());
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

fn fk_three_ways(ctx: &Ctx) -> Vec<Check> {
    let mut out = Vec::new();
    let samples = if ctx.quick { 20 } else { 200 };
    let mut rng = ChaCha8Rng::seed_from_u64(62);
    for (name, model) in [("panda", panda()), ("ur5", ur5()), ("puma-like", puma())] {
        let case = format!("{name} PoE space/body vs joint composition");
        let Ok(model) = model else { return failed(&case, "model did not load") };
        let chains: Vec<PoeChain> = (0..model.frames().len()).map(|f| PoeChain::new(&model, f)).collect();
        let mut data = Data::new(&model);
        let mut worst = 0.0_f64;
        for _ in 0..samples {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            frames_forward_kinematics(&model, &mut data, &q);
            for (f, c) in chains.iter().enumerate() {
                worst = worst
                    .max(se3_err(&data.frame_placements[f], &c.forward_space(&q)))
                    .max(se3_err(&data.frame_placements[f], &c.forward_body(&q)));
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

fn unit(rng: &mut ChaCha8Rng) -> DVec3 {
    loop {
        let v =
            DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        let n = v.length();
        if n > 0.1 && n <= 1.0 {
            return v / n;
        }
    }
}

fn point(rng: &mut ChaCha8Rng) -> DVec3 {
    DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0))
}

fn paden_kahan(_: &Ctx) -> Vec<Check> {
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

fn analytic_ik(ctx: &Ctx) -> Vec<Check> {
    let n = if ctx.quick { 2000 } else { 10_000 };
    let mut out = Vec::new();
    let mut rng = ChaCha8Rng::seed_from_u64(64);
    for (name, model, frame) in
        [("UR5 (UR type)", ur5(), "tool0"), ("PUMA-like (spherical wrist)", puma(), "tool")]
    {
        let case = format!("{name} analytic IK, {n} random reachable targets");
        let Ok(model) = model else { return failed(&case, "model did not load") };
        let Some(f) = model.frame_id(frame) else { return failed(&case, "no tool frame") };
        let ik = match AnalyticIk::new(&model, f) {
            Ok(ik) => ik,
            Err(e) => return failed(&case, &e.to_string()),
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
                worst = worst.max(dp).max(dr);
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

fn solve_and_verify(model: &Model, frame: &str, q: &[f64]) -> Outcome {
    let Some(f) = model.frame_id(frame) else { return Outcome::Diverged("no tool frame".into()) };
    let ik = match AnalyticIk::new(model, f) {
        Ok(ik) => ik,
        Err(e) => return Outcome::Diverged(e.to_string()),
    };
    let mut data = Data::new(model);
    let target = frame_at(model, &mut data, q, f);
    let sols = ik.solve(&target);
    if sols.is_empty() {
        return Outcome::Diverged("no solution returned for a reachable target".into());
    }
    let mut worst = 0.0_f64;
    for s in &sols {
        let (dp, dr) = pose_error(&frame_at(model, &mut data, &s.q, f), &target);
        worst = worst.max(dp).max(dr);
    }
    let singular = sols.iter().filter(|s| s.singular).count();
    let detail =
        format!("{} solutions ({singular} flagged singular), max pose error {worst:.1e}", sols.len());
    if worst < 1e-9 { Outcome::Stable(detail) } else { Outcome::Diverged(detail) }
}

fn ur5_singular(q: &[f64]) -> Outcome {
    match ur5() {
        Ok(m) => solve_and_verify(&m, "tool0", q),
        Err(e) => Outcome::Diverged(e),
    }
}

fn puma_singular() -> Outcome {
    match puma() {
        Ok(m) => solve_and_verify(&m, "tool", &[0.3, -0.4, 0.9, 0.7, 0.0, -0.2]),
        Err(e) => Outcome::Diverged(e),
    }
}

fn analytic_unreachable() -> Outcome {
    let mut n = 0;
    for (model, frame) in [(ur5(), "tool0"), (puma(), "tool")] {
        let Ok(model) = model else { return Outcome::Diverged("model did not load".into()) };
        let Some(f) = model.frame_id(frame) else { return Outcome::Diverged("no tool frame".into()) };
        let Ok(ik) = AnalyticIk::new(&model, f) else { return Outcome::Diverged("no solver".into()) };
        let sols = ik.solve(&Se3::from_translation(DVec3::new(3.0, 0.0, 0.5)));
        if !sols.is_empty() {
            return Outcome::Stable(format!(
                "{} returned {} solutions for an unreachable target",
                model.name(),
                sols.len()
            ));
        }
        n += 1;
    }
    Outcome::Rejected(format!("no solution (empty list) on {n} robots, no NaN"))
}

fn numerical(model: &Model, frame: &str) -> Result<(NumericalIk, usize), String> {
    let f = model.frame_id(frame).ok_or("no tool frame")?;
    Ok((NumericalIk::new(model, f, IkParams::default()), f))
}

fn panda_unreachable() -> Outcome {
    let model = match panda() {
        Ok(m) => m,
        Err(e) => return Outcome::Diverged(e),
    };
    let Ok((mut ik, _)) = numerical(&model, "panda_hand_tcp") else {
        return Outcome::Diverged("no frame".into());
    };
    let q0 = ik.mid_configuration(&model);
    let target = Se3::from_translation(DVec3::new(2.0, 0.0, 0.5));
    let r = ik.solve(&model, &target, &q0);
    if r.success {
        return Outcome::Stable("reported success on an unreachable target".into());
    }
    if !r.error.is_finite() || r.q.iter().any(|x| !x.is_finite()) {
        return Outcome::Diverged(format!("non-finite result: error {}", r.error));
    }
    Outcome::Rejected(format!(
        "failure reported after {} iterations in {} attempts; closest pose {:.3} m / {:.3} rad from the target, tool at ({:.3}, {:.3}, {:.3})",
        r.iterations,
        r.attempts,
        r.position_error,
        r.rotation_error,
        r.placement.translation.x,
        r.placement.translation.y,
        r.placement.translation.z
    ))
}

fn numerical_from(model: &Model, q_target: &[f64], what: &str) -> Outcome {
    let Ok((mut ik, f)) = numerical(model, "panda_hand_tcp") else {
        return Outcome::Diverged("no frame".into());
    };
    let mut data = Data::new(model);
    let target = frame_at(model, &mut data, q_target, f);
    let q0 = ik.mid_configuration(model);
    let start = Instant::now();
    let r = ik.solve(model, &target, &q0);
    let us = start.elapsed().as_secs_f64() * 1e6;
    let detail = format!(
        "{what}: success {} after {} iterations ({} attempts, {us:.0} us), error {:.1e} m / {:.1e} rad",
        r.success, r.iterations, r.attempts, r.position_error, r.rotation_error
    );
    if r.success { Outcome::Stable(detail) } else { Outcome::Diverged(detail) }
}

fn panda_singular() -> Outcome {
    let model = match panda() {
        Ok(m) => m,
        Err(e) => return Outcome::Diverged(e),
    };
    // Joint 4 at its upper limit (-0.0698: the elbow almost straight) and joint 6 placing the
    // wrist so that joints 5 and 7 are nearly aligned.
    numerical_from(&model, &[0.2, 0.3, -0.1, -0.0698, 0.4, 0.0, 0.3], "elbow at limit, wrist aligned")
}

fn panda_boundary() -> Outcome {
    let model = match panda() {
        Ok(m) => m,
        Err(e) => return Outcome::Diverged(e),
    };
    numerical_from(&model, &[0.5, 1.0, 0.0, -0.0698, 0.0, 1.7, 0.8], "arm stretched at the edge of reach")
}

fn panda_success_rate(ctx: &Ctx) -> Outcome {
    let n = if ctx.quick { 1000 } else { 10_000 };
    let model = match panda() {
        Ok(m) => m,
        Err(e) => return Outcome::Diverged(e),
    };
    let Ok((mut ik, f)) = numerical(&model, "panda_hand_tcp") else {
        return Outcome::Diverged("no frame".into());
    };
    let q0 = ik.mid_configuration(&model);
    let mut data = Data::new(&model);
    let mut rng = ChaCha8Rng::seed_from_u64(65);
    let targets: Vec<Se3> = (0..n)
        .map(|_| {
            let q = random_configuration(&model, &mut || rng.random::<f64>());
            frame_at(&model, &mut data, &q, f)
        })
        .collect();
    let (mut ok, mut iterations, mut worst_success) = (0usize, 0usize, 0.0_f64);
    let start = Instant::now();
    for t in &targets {
        let r = ik.solve(&model, t, &q0);
        iterations += r.iterations;
        if r.success {
            ok += 1;
            worst_success = worst_success.max(r.position_error).max(r.rotation_error);
        } else if !r.error.is_finite() {
            return Outcome::Diverged("non-finite error reported".into());
        }
    }
    let secs = start.elapsed().as_secs_f64();
    let rate = ok as f64 / n as f64;
    let detail = format!(
        "{ok}/{n} = {:.2}% converged to 1e-10 from the mid-range configuration; {:.1} us and {:.1} iterations per solve; worst converged pose error {worst_success:.1e}",
        100.0 * rate,
        secs / n as f64 * 1e6,
        iterations as f64 / n as f64
    );
    if rate >= 0.99 { Outcome::Stable(detail) } else { Outcome::Diverged(detail) }
}
