//! Hard cases of inverse kinematics: analytic IK at singularities and at the workspace boundary,
//! unreachable targets (analytic and numerical), the numerical IK near singularities, at the
//! boundary, and its success rate on random reachable targets.

use super::kinematics::frame_at;
use super::{panda, puma, ur5};
use std::time::Instant;

use crate::config::random_configuration;
use crate::ik::pose_error;
use crate::{AnalyticIk, Data, IkParams, Model, NumericalIk};
use anim_core::cases::{Ctx, Outcome};
use anim_core::glam::DVec3;
use anim_core::lie::Se3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub(super) fn solve_and_verify(model: &Model, frame: &str, q: &[f64]) -> Outcome {
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

pub(super) fn ur5_singular(q: &[f64]) -> Outcome {
    match ur5() {
        Ok(m) => solve_and_verify(&m, "tool0", q),
        Err(e) => Outcome::Diverged(e),
    }
}

pub(super) fn puma_singular() -> Outcome {
    match puma() {
        Ok(m) => solve_and_verify(&m, "tool", &[0.3, -0.4, 0.9, 0.7, 0.0, -0.2]),
        Err(e) => Outcome::Diverged(e),
    }
}

pub(super) fn analytic_unreachable() -> Outcome {
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

pub(super) fn numerical(model: &Model, frame: &str) -> Result<(NumericalIk, usize), String> {
    let f = model.frame_id(frame).ok_or("no tool frame")?;
    Ok((NumericalIk::new(model, f, IkParams::default()), f))
}

pub(super) fn panda_unreachable() -> Outcome {
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

pub(super) fn numerical_from(model: &Model, q_target: &[f64], what: &str) -> Outcome {
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

pub(super) fn panda_singular() -> Outcome {
    let model = match panda() {
        Ok(m) => m,
        Err(e) => return Outcome::Diverged(e),
    };
    // Joint 4 at its upper limit (-0.0698: the elbow almost straight) and joint 6 placing the
    // wrist so that joints 5 and 7 are nearly aligned.
    numerical_from(&model, &[0.2, 0.3, -0.1, -0.0698, 0.4, 0.0, 0.3], "elbow at limit, wrist aligned")
}

pub(super) fn panda_boundary() -> Outcome {
    let model = match panda() {
        Ok(m) => m,
        Err(e) => return Outcome::Diverged(e),
    };
    numerical_from(&model, &[0.5, 1.0, 0.0, -0.0698, 0.0, 1.7, 0.8], "arm stretched at the edge of reach")
}

pub(super) fn panda_success_rate(ctx: &Ctx) -> Outcome {
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
