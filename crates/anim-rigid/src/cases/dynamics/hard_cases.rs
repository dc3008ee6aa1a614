//! Hard cases of the dynamics: the torque-free spinning body per stepper, long and mass-ratio
//! chains, joints driven into their limits, a massless leaf.

use std::time::Instant;

use crate::scenes::pendulum_chain_model;
use crate::sim::{RigidIntegrator, RigidSimulation, SimError, SimParams};
use crate::{Axis, Inertia, JointLimits, JointType, Model, ModelBuilder};
use anim_core::cases::{Ctx, Outcome, nan_max};
use anim_core::glam::{DMat3, DVec3};
use anim_core::lie::Se3;
use anim_core::solver::Solver;

use super::conformance::spinning;

pub(super) fn spinning_drift(integrator: RigidIntegrator) -> Outcome {
    // A setup failure is Rejected, which no stepper's case expects (some expect Diverged).
    let (mut sim, mut state) = match spinning(integrator) {
        Ok(x) => x,
        Err(e) => return Outcome::Rejected(format!("setup failed: {e}")),
    };
    let e0 = sim.energy(&state);
    let l0 = sim.system_mut().momentum_of(&state.q, &state.v).angular;
    let start = Instant::now();
    let (mut de, mut dl) = (0.0_f64, 0.0_f64);
    let mut newton = 0usize;
    for k in 0..100_000 {
        match sim.step(&mut state, 1e-3) {
            Ok(r) => newton += r.iterations,
            Err(e) => return Outcome::Diverged(format!("step {k}: {e}")),
        }
        if k % 100 == 99 {
            let e = sim.energy(&state);
            let l = sim.system_mut().momentum_of(&state.q, &state.v).angular;
            de = nan_max(de, (e - e0).abs() / e0);
            dl = nan_max(dl, (l - l0).length() / l0.length());
        }
    }
    let detail = format!(
        "max relative drift over 100 s: energy {de:.2e}, angular momentum {dl:.2e}; {:.2} us per step{}",
        start.elapsed().as_secs_f64() * 10.0,
        if newton > 0 {
            format!(", {:.2} Newton iterations per step", newton as f64 / 1e5)
        } else {
            String::new()
        }
    );
    let bound = if integrator == RigidIntegrator::FreeBodyMidpoint { 1e-6 } else { 1e-2 };
    if de.is_finite() && dl.is_finite() && de < bound && dl < bound {
        Outcome::Stable(format!("{detail} (bound {bound:.0e})"))
    } else {
        Outcome::Diverged(format!("{detail}: beyond {bound:.0e}, detected"))
    }
}

/// Runs a scene-like chain for `seconds`; Stable with the energy drift, or what went wrong.
pub(super) fn run_chain(model: Model, integrator: RigidIntegrator, dt: f64, seconds: f64) -> Outcome {
    let nv = model.nv();
    let mut sim = match RigidSimulation::new(model, SimParams::default(), integrator) {
        Ok(s) => s,
        Err(e) => return Outcome::Diverged(e.to_string()),
    };
    let Ok(mut state) = sim.initial_state(vec![0.0; nv], vec![0.0; nv]) else {
        return Outcome::Diverged("bad initial state".into());
    };
    let e0 = sim.energy(&state);
    let start = Instant::now();
    let (mut iterations, steps) = (0usize, (seconds / dt).round() as usize);
    let (mut max_speed, mut max_kinetic, mut max_drift) = (0.0_f64, 0.0_f64, 0.0_f64);
    for k in 0..steps {
        match sim.step(&mut state, dt) {
            Ok(r) => {
                iterations += r.iterations;
                max_drift = nan_max(max_drift, (r.energy.unwrap_or(f64::NAN) - e0).abs());
            }
            Err(e) => return Outcome::Diverged(format!("step {k}: {e}")),
        }
        max_speed = nan_max(max_speed, state.v.iter().fold(0.0_f64, |m, x| nan_max(m, x.abs())));
        if k % 10 == 0 {
            max_kinetic = nan_max(max_kinetic, sim.system_mut().energy_of(&state.q, &state.v).kinetic);
        }
    }
    if !(max_drift.is_finite() && max_speed.is_finite() && max_kinetic.is_finite()) {
        return Outcome::Diverged(format!(
            "not finite (energy missing or NaN): max |E - E0| {max_drift}, max kinetic {max_kinetic}, max joint rate {max_speed}, detected"
        ));
    }
    // The chain starts at rest at zero potential energy: drift relative to the largest kinetic
    // energy reached.
    Outcome::Stable(format!(
        "finite; max |E - E0| / max kinetic energy {:.1e} (max kinetic {max_kinetic:.3} J), max joint rate {max_speed:.1} rad/s, {:.1} Newton iterations per step, {:.2} ms per step",
        max_drift / max_kinetic.max(f64::MIN_POSITIVE),
        iterations as f64 / steps as f64,
        start.elapsed().as_secs_f64() * 1e3 / steps as f64
    ))
}

pub(super) fn long_chain(ctx: &Ctx) -> Outcome {
    let seconds = if ctx.quick { 0.25 } else { 1.0 };
    match pendulum_chain_model(&[0.05; 100], 0.05) {
        Ok(m) => run_chain(m, RigidIntegrator::ImplicitMidpoint, 1e-3, seconds),
        Err(e) => Outcome::Diverged(e.to_string()),
    }
}

pub(super) fn mass_ratio_chain(ctx: &Ctx) -> Outcome {
    let seconds = if ctx.quick { 0.25 } else { 1.0 };
    let masses: Vec<f64> = (0..10).map(|k| if k % 2 == 0 { 1.0 } else { 1e-4 }).collect();
    match pendulum_chain_model(&masses, 0.1) {
        Ok(m) => run_chain(m, RigidIntegrator::ImplicitMidpoint, 1e-3, seconds),
        Err(e) => Outcome::Diverged(e.to_string()),
    }
}

pub(super) fn panda_at_limits() -> Outcome {
    let model = match crate::cases::panda() {
        Ok(m) => m,
        Err(e) => return Outcome::Diverged(e),
    };
    // Every joint at a limit, moving into it at 1 rad/s, with gravity and 5 N m pushing further.
    let mut q = Vec::new();
    let mut v = Vec::new();
    let mut tau = Vec::new();
    for j in &model.joints()[1..] {
        let upper = j.idx_v % 2 == 0;
        q.push(if upper { j.limits.upper } else { j.limits.lower });
        v.push(if upper { 1.0 } else { -1.0 });
        tau.push(if upper { 5.0 } else { -5.0 });
    }
    let limits: Vec<(f64, f64)> =
        model.joints()[1..].iter().map(|j| (j.limits.lower, j.limits.upper)).collect();
    let params = SimParams::default().with_torque(tau);
    let mut sim = match RigidSimulation::new(model, params, RigidIntegrator::ImplicitMidpoint) {
        Ok(s) => s,
        Err(e) => return Outcome::Diverged(e.to_string()),
    };
    let Ok(mut state) = sim.initial_state(q, v) else { return Outcome::Diverged("bad state".into()) };
    let mut worst = 0.0_f64;
    for k in 0..2000 {
        if let Err(e) = sim.step(&mut state, 1e-3) {
            return Outcome::Diverged(format!("step {k}: {e}"));
        }
        for (x, (lo, hi)) in state.q.iter().zip(&limits) {
            worst = nan_max(nan_max(worst, lo - x), x - hi);
        }
    }
    let detail = format!(
        "finite; deepest excursion beyond a limit {worst:.3} rad (penalty k = 1000 N m/rad, c = 5), final speed {:.2e} rad/s",
        state.v.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
    );
    if worst < 0.1 { Outcome::Stable(detail) } else { Outcome::Diverged(detail) }
}

pub(super) fn massless_leaf_model() -> Result<Model, crate::ModelError> {
    let mut b = ModelBuilder::new("massless-leaf");
    let j = b.add_joint(0, "a", JointType::Revolute(Axis::Y), Se3::IDENTITY, JointLimits::UNBOUNDED)?;
    b.append_body(j, &Inertia::new(1.0, DVec3::X, DMat3::IDENTITY), &Se3::IDENTITY)?;
    b.add_joint(
        j,
        "b",
        JointType::Revolute(Axis::Y),
        Se3::from_translation(DVec3::X),
        JointLimits::UNBOUNDED,
    )?;
    Ok(b.build())
}

pub(super) fn massless_leaf() -> Outcome {
    // The case expects Diverged (detected at the first step): a setup failure is Rejected.
    let model = match massless_leaf_model() {
        Ok(m) => m,
        Err(e) => return Outcome::Rejected(format!("setup failed: model: {e}")),
    };
    let mut sim = match RigidSimulation::new(model, SimParams::default(), RigidIntegrator::SymplecticEuler) {
        Ok(s) => s,
        Err(e) => return Outcome::Rejected(format!("setup failed: simulation: {e}")),
    };
    let Ok(mut state) = sim.initial_state(vec![0.1, 0.2], vec![0.0, 0.0]) else {
        return Outcome::Rejected("setup failed: bad initial state".into());
    };
    let before = state.clone();
    match sim.step(&mut state, 1e-3) {
        Err(e @ SimError::NonFinite(_)) if state == before => {
            Outcome::Diverged(format!("detected at the first step, state kept: {e}"))
        }
        Err(e) => Outcome::Stable(format!("an error, but not the expected one or the state changed: {e}")),
        Ok(_) => Outcome::Stable("stepped a singular system without complaint".into()),
    }
}
