//! Hard cases: the stability bounds `dt <= c sqrt(m/k)` of the explicit integrators, stiff
//! backward Euler on a cloth, degenerate springs, a detected divergence and a rejected mesh.

use crate::analytic::HangingChain;
use crate::{
    BuildError, Cloth, EARTH_GRAVITY, MeshMass, MeshSprings, NetworkBuilder, SpringError, SpringNetwork,
    SpringParams, SpringSimulation,
};
use anim_core::cases::{Ctx, Outcome, fmt_num};
use anim_core::integrate::{IntegratorKind, NewtonParams, State};
use anim_core::linalg::{IterativeParams, LinearSolverKind};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The explicit integrators whose stability bound is measured.
pub(super) const EXPLICIT: [IntegratorKind; 6] = [
    IntegratorKind::ExplicitEuler,
    IntegratorKind::SymplecticEuler,
    IntegratorKind::PositionVerlet,
    IntegratorKind::Leapfrog,
    IntegratorKind::VelocityVerlet,
    IntegratorKind::Rk4,
];

/// A chain of 8 masses (m = 0.01, l = 0.1) hanging from a pin under gravity, with damping of
/// ratio 0.05 (`c = 0.1 sqrt(k m)`, stiffness-proportional: every mode has the same explicit
/// Euler bound `dt < c / k = 0.1 sqrt(m/k)`), started at its exact static equilibrium with every
/// mode excited by a seeded random displacement of 1% of the rest length.
/// Returns the network, the start state and the equilibrium.
pub(super) fn sweep_chain(k: f64) -> Result<(SpringNetwork, State, Vec<f64>), BuildError> {
    let m = 0.01;
    let chain = HangingChain {
        count: 8,
        mass: m,
        stiffness: k,
        damping: 0.1 * (k * m).sqrt(),
        rest_length: 0.1,
        gravity: 9.81,
    };
    let net = chain.network()?;
    let eq = chain.equilibrium();
    let mut state = net.rest_state();
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    for (x, e) in state.x.iter_mut().zip(&eq).skip(3) {
        *x = e + rng.random_range(-1e-3..1e-3);
    }
    Ok((net, state, eq))
}

/// Whether `kind` runs `steps` steps of `dt` on the sweep chain without diverging: an unstable
/// mode grows geometrically from the 1% perturbation until a spring doubles its length (stretch
/// ratio 2, the divergence guard). A mode that grows by less than that factor in `steps` steps
/// counts as stable: the measured bound is slightly optimistic when growth is slow near it
/// (explicit Euler), and converges to the true bound as `steps` grows.
pub(super) fn runs_stably(kind: IntegratorKind, k: f64, dt: f64, steps: usize) -> bool {
    let Ok((net, mut state, _)) = sweep_chain(k) else { return false };
    let Ok(sim) = SpringSimulation::new(net, kind, NewtonParams::default(), LinearSolverKind::Cg) else {
        return false;
    };
    let mut sim = sim.with_max_stretch(2.0);
    sim.run(&mut state, dt, steps).is_ok()
}

pub(super) fn stable_dt_sweep(ctx: &Ctx, kind: IntegratorKind) -> Outcome {
    // k from 1e2: below it the chain sags by more than 10% of its rest length, and its transverse
    // (pendulum) modes, which damping along the springs does not reach, make explicit Euler
    // unstable at every dt (its amplification factor for an undamped mode exceeds 1).
    let (bisections, steps) = if ctx.quick { (20, 4000) } else { (30, 20_000) };
    let m: f64 = 0.01;
    let mut log_t = Vec::new();
    let mut log_dt = Vec::new();
    let mut cs = Vec::new();
    for decade in 2..=8 {
        let k = 10f64.powi(decade);
        let t = (m / k).sqrt();
        let (mut lo, mut hi) = (0.01 * t, 4.0 * t);
        if !runs_stably(kind, k, lo, steps) {
            return Outcome::Diverged(format!("unstable even at dt = 0.01 sqrt(m/k) for k = {k:e}"));
        }
        for _ in 0..bisections {
            let mid = (lo * hi).sqrt();
            if runs_stably(kind, k, mid, steps) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        log_t.push(t.ln());
        log_dt.push(lo.ln());
        cs.push(lo / t);
    }
    // Fit log dt = log c + s log sqrt(m/k); the explicit bound `dt <= c sqrt(m/k)` has s = 1.
    let n = log_t.len() as f64;
    let (mx, my) = (log_t.iter().sum::<f64>() / n, log_dt.iter().sum::<f64>() / n);
    let sxy: f64 = log_t.iter().zip(&log_dt).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = log_t.iter().map(|x| (x - mx) * (x - mx)).sum();
    let slope = sxy / sxx;
    let c = (my - mx).exp();
    let (cmin, cmax) = cs.iter().fold((f64::MAX, f64::MIN), |(a, b), &c| (a.min(c), b.max(c)));
    let detail = format!(
        "dt_max = c sqrt(m/k) with c = {} (range {} to {} over k = 1e2 to 1e8; fitted exponent {:.3}; chain of 8, m = 0.01, damping ratio 0.05, {} steps per trial; {})",
        fmt_num(c),
        fmt_num(cmin),
        fmt_num(cmax),
        slope,
        steps,
        match kind {
            IntegratorKind::ExplicitEuler => "theory 2 x 0.05 = 0.1 in the limit of a long run",
            IntegratorKind::Rk4 => "theory 2 sqrt(2) / 2 = 1.41 undamped, damping extends it",
            _ => "theory about 2 / 2 = 1 undamped (omega_max = 2 sqrt(k/m))",
        }
    );
    if (slope - 1.0).abs() < 0.05 {
        Outcome::Stable(detail)
    } else {
        Outcome::Diverged(format!("bound does not scale as sqrt(m/k): {detail}"))
    }
}

/// The stiff hard case: a 10x10 cloth of 0.1 kg with k = 1e6 springs, pinned at two corners, on
/// the linearised backward Euler of Baraff & Witkin 1998 (one Newton iteration:
/// `[M - h^2 K(x0) - h D] v1 = M v0 + h f(x0)`, the definite K solved by Jacobi-PCG).
pub(super) fn stiff_cloth() -> Result<(SpringSimulation, State), String> {
    let mut b = NetworkBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let p = SpringParams::new(1e6, 0.0);
    let n = 10;
    let r = b
        .cloth(&Cloth {
            nx: n,
            ny: n,
            origin: [0.0, 0.0, 1.0],
            u: [0.5, 0.0, 0.0],
            v: [0.0, 0.5, 0.0],
            mass: 1e-3 * (n * n) as f64,
            structural: p,
            shear: Some(p),
            bending: None,
        })
        .map_err(|e| e.to_string())?;
    b.pin(r.start).pin(r.start + n - 1);
    let net = b.build().map_err(|e| e.to_string())?;
    let state = net.rest_state();
    let mut newton = NewtonParams::linearized();
    newton.linear = IterativeParams::new(1e-8, 20_000);
    let sim = SpringSimulation::new(net, IntegratorKind::BackwardEuler, newton, LinearSolverKind::JacobiPcg)
        .map_err(|e| e.to_string())?;
    Ok((sim, state))
}

pub(super) fn stiff_backward_euler(_ctx: &Ctx) -> Outcome {
    let run = || -> Result<String, String> {
        let (mut sim, mut state) = stiff_cloth()?;
        let dt = 1.0 / 30.0;
        let e0 = sim.network_mut().energy_parts(&state.x, &state.v).total();
        let mut cg = 0;
        let steps = 60;
        for _ in 0..steps {
            let info = sim.advance(&mut state, dt).map_err(|e| e.to_string())?;
            cg = cg.max(info.linear_iterations);
        }
        let e1 = sim.network_mut().energy_parts(&state.x, &state.v).total();
        let stretch = sim.network().max_stretch(&state.x).map_or(f64::NAN, |s| s.ratio);
        if !(e1 <= e0 + 1e-9 * e0.abs()) || !(stretch < 1.01) {
            return Err(format!("energy {e0} -> {e1}, max stretch ratio {stretch}"));
        }
        Ok(format!(
            "linearised backward Euler (Baraff & Witkin 1998), {steps} steps (2 s), omega dt = {:.0}; energy {} -> {} J (dissipative), max stretch ratio {}, at most {cg} CG iterations per step",
            (1e6f64 / 1e-3).sqrt() * dt,
            fmt_num(e0),
            fmt_num(e1),
            fmt_num(stretch)
        ))
    };
    match run() {
        Ok(detail) => Outcome::Stable(detail),
        Err(e) => Outcome::Diverged(e),
    }
}

pub(super) fn degenerate_springs(_ctx: &Ctx) -> Outcome {
    let build = || -> Result<SpringNetwork, BuildError> {
        let mut b = NetworkBuilder::new();
        b.gravity(EARTH_GRAVITY);
        let p = SpringParams::new(100.0, 1.0);
        let a = b.particle([0.0, 0.0, 0.0], 1.0);
        let c = b.particle([0.0, 0.0, 0.0], 1.0);
        let d = b.particle([1.0, 0.0, 0.0], 1.0);
        let e = b.particle([1.0, 0.0, 0.0], 1.0);
        b.pin(a);
        b.spring_with_rest_length(a, c, 0.1, p);
        b.spring_with_rest_length(d, e, 0.0, p);
        b.spring(c, d, p);
        b.build()
    };
    let Ok(net) = build() else { return Outcome::Rejected("could not build".into()) };
    let mut worst_newton = 0;
    for kind in IntegratorKind::ALL {
        let mut newton = NewtonParams::default();
        newton.max_iterations = 200;
        let Ok(mut sim) = SpringSimulation::new(net.clone(), kind, newton, LinearSolverKind::Cg) else {
            return Outcome::Rejected(format!("{}: bad integrator", kind.label()));
        };
        let mut state = net.rest_state();
        for _ in 0..200 {
            match sim.advance(&mut state, 1e-3) {
                Ok(info) => worst_newton = worst_newton.max(info.newton_iterations),
                Err(e) => return Outcome::Diverged(format!("{}: {e}", kind.label())),
            }
        }
        if !state.x.iter().chain(&state.v).all(|v| v.is_finite()) {
            return Outcome::Diverged(format!("{}: non-finite state", kind.label()));
        }
    }
    Outcome::Stable(format!(
        "every integrator, 200 steps of 1 ms: finite; coincident pair separates along the rest-direction fallback; at most {worst_newton} Newton iterations in a step"
    ))
}

pub(super) fn explicit_divergence(_ctx: &Ctx) -> Outcome {
    let chain = HangingChain {
        count: 10,
        mass: 0.01,
        stiffness: 100.0,
        damping: 0.0,
        rest_length: 0.1,
        gravity: 9.81,
    };
    let Ok(net) = chain.network() else { return Outcome::Rejected("could not build".into()) };
    let mut state = net.rest_state();
    let dt = 3.0 * (chain.mass / chain.stiffness).sqrt();
    let Ok(mut sim) = SpringSimulation::new(
        net,
        IntegratorKind::SymplecticEuler,
        NewtonParams::default(),
        LinearSolverKind::Cg,
    ) else {
        return Outcome::Rejected("bad integrator".into());
    };
    for _ in 0..10_000 {
        if let Err(e) = sim.advance(&mut state, dt) {
            let finite = state.x.iter().chain(&state.v).all(|v| v.is_finite());
            return match e {
                SpringError::Diverged { .. } => {
                    Outcome::Diverged(format!("{e}; state kept at the last good step, finite: {finite}"))
                }
                other => Outcome::Diverged(format!("detected by the integrator: {other}")),
            };
        }
    }
    Outcome::Stable("ran 10^4 steps without diverging".into())
}

pub(super) fn degenerate_mesh(_ctx: &Ctx) -> Outcome {
    let pos = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [2.0, 0.0, 0.0]];
    let tris = [[0, 1, 2], [0, 1, 3]];
    let p = SpringParams::new(1.0, 0.0);
    let params = MeshSprings { mass: MeshMass::AreaDensity(1.0), edge: p, bending: None };
    match NetworkBuilder::new().mesh(&pos, &tris, &params) {
        Err(e) => Outcome::Rejected(e.to_string()),
        Ok(_) => Outcome::Stable("accepted a zero-area triangle".into()),
    }
}
