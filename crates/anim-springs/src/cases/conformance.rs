//! Conformance: the two-particle spring against its closed form and its convergence orders, the
//! hanging chain's static stretch, the force Jacobians against finite differences.

use super::CRATE;
use crate::analytic::{HangingChain, TwoParticleSpring};
use crate::{
    BuildError, Cloth, EARTH_GRAVITY, JacobianMode, NetworkBuilder, SpringNetwork, SpringParams,
    SpringSimulation,
};
use anim_core::cases::{Check, Ctx, Judge, fmt_num, nan_max};
use anim_core::integrate::study::fit_order;
use anim_core::integrate::{IntegratorKind, MechanicalSystem, NewtonParams, SecondOrderSystem, State};
use anim_core::linalg::LinearSolverKind;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub(super) fn tight() -> NewtonParams {
    NewtonParams::with_tolerance(1e-13)
}

pub(super) fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, nan_max)
}

/// Runs the two-particle spring with `kind` for `steps` steps to `t_end`; max error of (x, v).
pub(super) fn two_particle_run(
    case: &TwoParticleSpring,
    kind: IntegratorKind,
    steps: usize,
    t_end: f64,
) -> f64 {
    let Ok(net) = case.network() else { return f64::NAN };
    let Ok(mut sim) = SpringSimulation::new(net, kind, tight(), LinearSolverKind::Cg) else {
        return f64::NAN;
    };
    let mut state = case.initial_state();
    if sim.run(&mut state, t_end / steps as f64, steps).is_err() {
        return f64::NAN;
    }
    let (x, v) = case.exact(state.t);
    nan_max(max_abs_diff(&state.x, &x), max_abs_diff(&state.v, &v))
}

pub(super) fn two_particle(_ctx: &Ctx) -> Vec<Check> {
    let mut checks = Vec::new();
    for (label, case) in [
        ("undamped", TwoParticleSpring::example()),
        ("damped c = 0.8", TwoParticleSpring { damping: 0.8, ..TwoParticleSpring::example() }),
    ] {
        let t_end = 2.3 * case.period();
        let err = two_particle_run(&case, IntegratorKind::Rk4, 2000, t_end);
        checks.push(Check {
            crate_name: CRATE,
            case: format!("two-particle spring, {label}, RK4 dt = T/870, t = 2.3 T"),
            metric: "max |(x, v) - exact|".into(),
            measured: err,
            reference: 0.0,
            tolerance: 1e-9,
            judge: Judge::AtMost,
            source: "reduced-mass oscillator mu s'' = -k s - c s'",
        });
    }
    checks
}

pub(super) fn theory_order(kind: IntegratorKind) -> f64 {
    match kind {
        IntegratorKind::PositionVerlet
        | IntegratorKind::Leapfrog
        | IntegratorKind::VelocityVerlet
        | IntegratorKind::ImplicitMidpoint => 2.0,
        IntegratorKind::Rk4 => 4.0,
        _ => 1.0,
    }
}

pub(super) fn two_particle_orders(ctx: &Ctx) -> Vec<Check> {
    let case = TwoParticleSpring::example();
    let t_end = 1.3 * case.period();
    let doublings = if ctx.quick { 4 } else { 6 };
    IntegratorKind::ALL
        .iter()
        .map(|&kind| {
            let base = if kind == IntegratorKind::Rk4 { 40 } else { 400 };
            let (dts, errs): (Vec<f64>, Vec<f64>) = (0..doublings)
                .map(|i| {
                    let n = base << i;
                    (t_end / n as f64, two_particle_run(&case, kind, n, t_end))
                })
                .unzip();
            Check {
                crate_name: CRATE,
                case: format!("two-particle spring / {}", kind.label()),
                metric: format!("order (error {} at finest dt)", fmt_num(*errs.last().unwrap_or(&f64::NAN))),
                measured: fit_order(&dts, &errs),
                reference: theory_order(kind),
                tolerance: 0.15,
                judge: Judge::Near,
                source: "closed form, t = 1.3 periods",
            }
        })
        .collect()
}

pub(super) fn hanging_chain(_ctx: &Ctx) -> Vec<Check> {
    let chain = HangingChain {
        count: 20,
        mass: 0.05,
        stiffness: 40.0,
        damping: 0.5,
        rest_length: 0.05,
        gravity: 9.81,
    };
    let exact = chain.equilibrium();
    let mut checks = Vec::new();
    for linear in [LinearSolverKind::JacobiPcg, LinearSolverKind::Cholesky] {
        let measured = (|| {
            let net = chain.network().ok()?;
            let mut state = net.rest_state();
            let mut sim = SpringSimulation::new(
                net,
                IntegratorKind::BackwardEuler,
                NewtonParams::with_tolerance(1e-12),
                linear,
            )
            .ok()?;
            let mut steps = 0;
            // Backward Euler with damping, run to rest: its fixed point is f(x) = 0, v = 0.
            while state.v.iter().fold(0.0f64, |m, v| m.max(v.abs())) > 1e-13 || steps == 0 {
                sim.advance(&mut state, 0.05).ok()?;
                steps += 1;
                if steps > 50_000 {
                    return None;
                }
            }
            Some((max_abs_diff(&state.x, &exact) / chain.total_stretch(), steps))
        })();
        let (err, steps) = measured.unwrap_or((f64::NAN, 0));
        checks.push(Check {
            crate_name: CRATE,
            case: format!("hanging chain, 20 masses, backward Euler to rest / {linear:?}"),
            metric: format!("max position error / total stretch ({steps} steps of 0.05 s)"),
            measured: err,
            reference: 0.0,
            tolerance: 1e-9,
            judge: Judge::AtMost,
            source: "spring i carries the weight of the masses below it",
        });
    }
    checks
}

/// Exact-mode `K` and `D` of a perturbed, partly compressed cloth with ground contact against
/// central differences of the force.
pub(super) fn jacobian_fd(_ctx: &Ctx) -> Vec<Check> {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed);
    let built = (|| -> Result<(SpringNetwork, State), BuildError> {
        let mut b = NetworkBuilder::new();
        b.gravity(EARTH_GRAVITY);
        let p = SpringParams::new(50.0, 0.3);
        b.cloth(&Cloth {
            nx: 5,
            ny: 5,
            origin: [0.0, 0.0, 0.02],
            u: [0.5, 0.0, 0.0],
            v: [0.0, 0.5, 0.0],
            mass: 0.1,
            structural: p,
            shear: Some(p),
            bending: Some(p),
        })?;
        b.collider(
            crate::Collider::ground(0.0, 500.0).with_damping(0.2).with_friction(0.5).with_smoothing(0.01),
        );
        let net = b.build()?;
        let mut state = net.rest_state();
        for x in state.x.iter_mut() {
            *x += rng.random_range(-0.06..0.06);
        }
        for v in state.v.iter_mut() {
            *v = rng.random_range(-1.0..1.0);
        }
        Ok((net, state))
    })();
    let (mut net, state) = match built {
        Ok(x) => x,
        Err(e) => {
            // Both checks fail, with the reason, instead of vanishing.
            return ["K = df/dx", "D = df/dv"]
                .iter()
                .map(|name| Check {
                    crate_name: CRATE,
                    case: format!("5x5 cloth, random perturbation, ground contact: {name}"),
                    metric: format!("could not run: cloth did not build: {e}"),
                    measured: f64::NAN,
                    reference: 0.0,
                    tolerance: 1e-7,
                    judge: Judge::AtMost,
                    source: "central finite differences, h = 1e-6",
                })
                .collect();
        }
    };
    let n = net.dof();
    net.set_jacobian_mode(JacobianMode::Exact);
    net.linearize(0.0, &state.x, &state.v);
    let mut errs = [0.0f64; 2];
    let mut scales = [0.0f64; 2];
    let h = 1e-6;
    let (mut col, mut fp, mut fm, mut e) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for k in 0..n {
        for (which, (c_x, c_v)) in [(1.0, 0.0), (0.0, 1.0)].into_iter().enumerate() {
            e[k] = 1.0;
            net.jacobian_apply(c_x, c_v, &e, &mut col);
            e[k] = 0.0;
            let (mut xp, mut xm, mut vp, mut vm) =
                (state.x.clone(), state.x.clone(), state.v.clone(), state.v.clone());
            if which == 0 {
                xp[k] += h;
                xm[k] -= h;
            } else {
                vp[k] += h;
                vm[k] -= h;
            }
            net.force(0.0, &xp, &vp, &mut fp);
            net.force(0.0, &xm, &vm, &mut fm);
            for r in 0..n {
                let fd = (fp[r] - fm[r]) / (2.0 * h);
                errs[which] = nan_max(errs[which], (fd - col[r]).abs());
                scales[which] = nan_max(scales[which], col[r].abs());
            }
        }
    }
    ["K = df/dx", "D = df/dv"]
        .iter()
        .enumerate()
        .map(|(w, name)| Check {
            crate_name: CRATE,
            case: format!("5x5 cloth, random perturbation, ground contact: {name}"),
            metric: "max |J - central differences| / max |J|".into(),
            measured: errs[w] / scales[w],
            reference: 0.0,
            tolerance: 1e-7,
            judge: Judge::AtMost,
            source: "central finite differences, h = 1e-6",
        })
        .collect()
}
