//! anim-springs: the two-particle spring against its closed form, convergence orders of every
//! integrator, the hanging chain's static stretch, the force Jacobian against finite differences;
//! stability bounds `dt <= c sqrt(m/k)` of the explicit methods, stiff backward Euler, degenerate
//! springs, a detected divergence; a work-precision study on the cloth.

use crate::registry::{
    Check, ConformanceCase, Ctx, Judge, Outcome, Point, Registry, Series, StabilityCase, Study, StudyResult,
    fmt_num, median_seconds,
};
use anim_core::integrate::study::fit_order;
use anim_core::integrate::{IntegratorKind, MechanicalSystem, NewtonParams, SecondOrderSystem, State};
use anim_core::linalg::{IterativeParams, LinearSolverKind};
use anim_springs::analytic::{HangingChain, TwoParticleSpring};
use anim_springs::{
    BuildError, Cloth, EARTH_GRAVITY, JacobianMode, MeshMass, MeshSprings, NetworkBuilder, SpringError,
    SpringNetwork, SpringParams, SpringSimulation,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const CRATE: &str = "anim-springs";

pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "two-particle spring vs closed form",
        run: Box::new(two_particle),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "two-particle spring convergence order",
        run: Box::new(two_particle_orders),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "hanging chain static stretch",
        run: Box::new(hanging_chain),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "spring network Jacobians vs finite differences",
        run: Box::new(jacobian_fd),
    });

    for kind in EXPLICIT {
        r.stability.push(StabilityCase {
            crate_name: CRATE,
            name: match kind {
                IntegratorKind::ExplicitEuler => {
                    "explicit Euler: largest stable dt on a chain, k over 6 decades"
                }
                IntegratorKind::SymplecticEuler => {
                    "symplectic Euler: largest stable dt on a chain, k over 6 decades"
                }
                IntegratorKind::PositionVerlet => {
                    "position Verlet: largest stable dt on a chain, k over 6 decades"
                }
                IntegratorKind::Leapfrog => "leapfrog: largest stable dt on a chain, k over 6 decades",
                IntegratorKind::VelocityVerlet => {
                    "velocity Verlet: largest stable dt on a chain, k over 6 decades"
                }
                _ => "RK4: largest stable dt on a chain, k over 6 decades",
            },
            expected: || Outcome::Stable(String::new()),
            run: match kind {
                IntegratorKind::ExplicitEuler => |ctx| stable_dt_sweep(ctx, IntegratorKind::ExplicitEuler),
                IntegratorKind::SymplecticEuler => {
                    |ctx| stable_dt_sweep(ctx, IntegratorKind::SymplecticEuler)
                }
                IntegratorKind::PositionVerlet => |ctx| stable_dt_sweep(ctx, IntegratorKind::PositionVerlet),
                IntegratorKind::Leapfrog => |ctx| stable_dt_sweep(ctx, IntegratorKind::Leapfrog),
                IntegratorKind::VelocityVerlet => |ctx| stable_dt_sweep(ctx, IntegratorKind::VelocityVerlet),
                _ => |ctx| stable_dt_sweep(ctx, IntegratorKind::Rk4),
            },
        });
    }
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "backward Euler, cloth with k = 1e6, m = 1e-3 at dt = 1/30 s",
        expected: || Outcome::Stable(String::new()),
        run: stiff_backward_euler,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "zero-length and coincident-particle springs, every integrator",
        expected: || Outcome::Stable(String::new()),
        run: degenerate_springs,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "symplectic Euler on a chain at dt = 3 sqrt(m/k)",
        expected: || Outcome::Diverged(String::new()),
        run: explicit_divergence,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "mesh with a zero-area triangle",
        expected: || Outcome::Rejected(String::new()),
        run: degenerate_mesh,
    });

    r.studies.push(Study {
        crate_name: CRATE,
        name: "integrators and linear solvers on the cloth",
        run: cloth_study,
    });
}

/// The explicit integrators whose stability bound is measured.
const EXPLICIT: [IntegratorKind; 6] = [
    IntegratorKind::ExplicitEuler,
    IntegratorKind::SymplecticEuler,
    IntegratorKind::PositionVerlet,
    IntegratorKind::Leapfrog,
    IntegratorKind::VelocityVerlet,
    IntegratorKind::Rk4,
];

fn tight() -> NewtonParams {
    NewtonParams::with_tolerance(1e-13)
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// Runs the two-particle spring with `kind` for `steps` steps to `t_end`; max error of (x, v).
fn two_particle_run(case: &TwoParticleSpring, kind: IntegratorKind, steps: usize, t_end: f64) -> f64 {
    let Ok(net) = case.network() else { return f64::NAN };
    let Ok(mut sim) = SpringSimulation::new(net, kind, tight(), LinearSolverKind::Cg) else {
        return f64::NAN;
    };
    let mut state = case.initial_state();
    if sim.run(&mut state, t_end / steps as f64, steps).is_err() {
        return f64::NAN;
    }
    let (x, v) = case.exact(state.t);
    max_abs_diff(&state.x, &x).max(max_abs_diff(&state.v, &v))
}

fn two_particle(_ctx: &Ctx) -> Vec<Check> {
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

fn theory_order(kind: IntegratorKind) -> f64 {
    match kind {
        IntegratorKind::PositionVerlet
        | IntegratorKind::Leapfrog
        | IntegratorKind::VelocityVerlet
        | IntegratorKind::ImplicitMidpoint => 2.0,
        IntegratorKind::Rk4 => 4.0,
        _ => 1.0,
    }
}

fn two_particle_orders(ctx: &Ctx) -> Vec<Check> {
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

fn hanging_chain(_ctx: &Ctx) -> Vec<Check> {
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
fn jacobian_fd(_ctx: &Ctx) -> Vec<Check> {
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
            anim_springs::Collider::ground(0.0, 500.0)
                .with_damping(0.2)
                .with_friction(0.5)
                .with_smoothing(0.01),
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
    let Ok((mut net, state)) = built else {
        return vec![];
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
                errs[which] = errs[which].max((fd - col[r]).abs());
                scales[which] = scales[which].max(col[r].abs());
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

/// A chain of 8 masses (m = 0.01, l = 0.1) hanging from a pin under gravity, with damping of
/// ratio 0.05 (`c = 0.1 sqrt(k m)`, stiffness-proportional: every mode has the same explicit
/// Euler bound `dt < c / k = 0.1 sqrt(m/k)`), started at its exact static equilibrium with every
/// mode excited by a seeded random displacement of 1% of the rest length.
/// Returns the network, the start state and the equilibrium.
fn sweep_chain(k: f64) -> Result<(SpringNetwork, State, Vec<f64>), BuildError> {
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
fn runs_stably(kind: IntegratorKind, k: f64, dt: f64, steps: usize) -> bool {
    let Ok((net, mut state, _)) = sweep_chain(k) else { return false };
    let Ok(sim) = SpringSimulation::new(net, kind, NewtonParams::default(), LinearSolverKind::Cg) else {
        return false;
    };
    let mut sim = sim.with_max_stretch(2.0);
    sim.run(&mut state, dt, steps).is_ok()
}

fn stable_dt_sweep(ctx: &Ctx, kind: IntegratorKind) -> Outcome {
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
    // Fit log dt = log c + s log sqrt(m/k); the seed's bound has s = 1.
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
/// the seed's linearised backward Euler (one Newton iteration:
/// `[M - h^2 K(x0) - h D] v1 = M v0 + h f(x0)`, the definite K solved by Jacobi-PCG).
pub fn stiff_cloth() -> Result<(SpringSimulation, State), String> {
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

fn stiff_backward_euler(_ctx: &Ctx) -> Outcome {
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
            "linearised backward Euler (seed 2.1), {steps} steps (2 s), omega dt = {:.0}; energy {} -> {} J (dissipative), max stretch ratio {}, at most {cg} CG iterations per step",
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

fn degenerate_springs(_ctx: &Ctx) -> Outcome {
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

fn explicit_divergence(_ctx: &Ctx) -> Outcome {
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

fn degenerate_mesh(_ctx: &Ctx) -> Outcome {
    let pos = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [2.0, 0.0, 0.0]];
    let tris = [[0, 1, 2], [0, 1, 3]];
    let p = SpringParams::new(1.0, 0.0);
    let params = MeshSprings { mass: MeshMass::AreaDensity(1.0), edge: p, bending: None };
    match NetworkBuilder::new().mesh(&pos, &tris, &params) {
        Err(e) => Outcome::Rejected(e.to_string()),
        Ok(_) => Outcome::Stable("accepted a zero-area triangle".into()),
    }
}

/// The study's cloth: 10 x 10 (quick: 6 x 6), 0.5 m, mass 0.1 kg, pinned at two corners, light
/// damping, falling from flat for 0.25 s.
fn study_cloth(n: usize) -> Option<(SpringNetwork, State)> {
    let mut b = NetworkBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let r = b
        .cloth(&Cloth {
            nx: n,
            ny: n,
            origin: [0.0, 0.0, 1.0],
            u: [STUDY_SIZE, 0.0, 0.0],
            v: [0.0, STUDY_SIZE, 0.0],
            mass: STUDY_MASS,
            structural: SpringParams::new(STUDY_STIFFNESS, 0.01),
            shear: Some(SpringParams::new(20.0, 0.002)),
            bending: Some(SpringParams::new(2.0, 0.0002)),
        })
        .ok()?;
    b.pin(r.start).pin(r.start + n - 1);
    let net = b.build().ok()?;
    let state = net.rest_state();
    Some((net, state))
}

const STUDY_T: f64 = 0.25;

fn study_newton() -> NewtonParams {
    let mut p = NewtonParams::with_tolerance(1e-10);
    p.linear = IterativeParams::new(1e-12, 20_000);
    p
}

/// Final positions after `steps` steps to `STUDY_T`, or `None` on failure.
fn cloth_run(n: usize, kind: IntegratorKind, linear: LinearSolverKind, steps: usize) -> Option<Vec<f64>> {
    let (net, mut state) = study_cloth(n)?;
    let mut sim = SpringSimulation::new(net, kind, study_newton(), linear).ok()?;
    sim.run(&mut state, STUDY_T / steps as f64, steps).ok()?;
    Some(state.x)
}

/// Side (m), total mass (kg) and structural stiffness (N/m) of the study cloth.
const STUDY_SIZE: f64 = 0.5;
const STUDY_MASS: f64 = 0.1;
const STUDY_STIFFNESS: f64 = 100.0;

/// Particles per side of the study cloth.
fn study_side(quick: bool) -> usize {
    if quick { 6 } else { 10 }
}

/// The study problem's parameters `anim run --tolerance` scales a picked step by: particles per
/// side, side length (m), total mass (kg), structural stiffness (N/m).
pub fn study_problem(quick: bool) -> Vec<(&'static str, f64)> {
    vec![
        ("n", study_side(quick) as f64),
        ("size", STUDY_SIZE),
        ("mass", STUDY_MASS),
        ("stiffness", STUDY_STIFFNESS),
    ]
}

fn cloth_study(ctx: &Ctx) -> StudyResult {
    let n = study_side(ctx.quick);
    let (batches, min_batch) = if ctx.quick { (3, 0.002) } else { (5, 0.02) };
    let points = if ctx.quick { 3 } else { 5 };
    let x0 = study_cloth(n).map(|(_, s)| s.x).unwrap_or_default();
    // Reference: RK4 at 64 times the finest explicit step.
    let reference = cloth_run(n, IntegratorKind::Rk4, LinearSolverKind::Cg, 64 * (400 << (points - 1)));
    let error = |x: Option<Vec<f64>>| -> f64 {
        match (&reference, x) {
            (Some(r), Some(x)) => {
                let num: f64 = x.iter().zip(r).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
                let den: f64 = r.iter().zip(&x0).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
                num / den
            }
            _ => f64::NAN,
        }
    };
    let mut series = Vec::new();
    let mut sweep = |label: String, kind: IntegratorKind, linear: LinearSolverKind, base: usize| {
        let pts = (0..points)
            .map(|i| {
                let steps = base << i;
                let err = error(cloth_run(n, kind, linear, steps));
                let seconds = if err.is_finite() {
                    median_seconds(batches, min_batch, || {
                        std::hint::black_box(cloth_run(n, kind, linear, steps));
                    })
                } else {
                    f64::NAN
                };
                Point { param: STUDY_T / steps as f64, seconds, error: err }
            })
            .collect();
        series.push(Series { label, points: pts });
    };
    for kind in EXPLICIT {
        sweep(kind.label(), kind, LinearSolverKind::Cg, 400);
    }
    for kind in [
        IntegratorKind::BackwardEuler,
        IntegratorKind::BetaBlend { beta: 0.5 },
        IntegratorKind::ImplicitMidpoint,
    ] {
        for linear in LinearSolverKind::ALL {
            let name = match linear {
                LinearSolverKind::Cg => "cg",
                LinearSolverKind::JacobiPcg => "jacobi-pcg",
                LinearSolverKind::JacobiPcgAssembled => "jacobi-pcg-assembled",
                LinearSolverKind::Jacobi => "jacobi",
                LinearSolverKind::GaussSeidel => "gauss-seidel",
                LinearSolverKind::Cholesky => "cholesky",
            };
            sweep(format!("{} / {name}", kind.label()), kind, linear, 25);
        }
    }
    // The issue asks which method reaches a relative error of 1e-3 cheapest; the report's tables
    // use other tolerances, so say it in the title.
    let cheapest = series
        .iter()
        .flat_map(|s| s.points.iter().map(move |p| (s, p)))
        .filter(|(_, p)| p.error <= 1e-3 && p.seconds.is_finite())
        .min_by(|a, b| a.1.seconds.total_cmp(&b.1.seconds))
        .map_or("none in the sweep".to_string(), |(s, p)| {
            format!("{} at dt = {}, {:.2} ms", s.label, fmt_num(p.param), p.seconds * 1e3)
        });
    StudyResult {
        title: format!(
            "Cloth {n}x{n} pinned at two corners, 0.25 s: relative position error against RK4 at a tiny step (cheapest to 1e-3: {cheapest})"
        ),
        slug: "springs-cloth".into(),
        error_label: "|x - x_ref| / |x_ref - x_0| at t = 0.25 s".into(),
        param_label: "dt".into(),
        series,
    }
}

/// One timed run of the benchmark cloth for the peer comparison (`cargo xtask bench --peers`).
#[derive(Debug, Clone, Copy)]
pub struct PeerRun {
    /// Median wall time of one step (s).
    pub per_step_s: f64,
    /// Sum of the final z coordinates (checksum against the peer).
    pub sum_z: f64,
    /// Lowest final z coordinate.
    pub min_z: f64,
}

/// Times `steps` symplectic Euler steps of the `n x n` benchmark cloth from rest on a rayon pool
/// of `threads` threads (median over `repeats` runs), with the integrator driven directly (no
/// divergence guard: the peer has none either; the integrator's NaN check stays).
pub fn peer_symplectic_cloth(
    n: usize,
    steps: usize,
    threads: usize,
    repeats: usize,
) -> Result<PeerRun, String> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| e.to_string())?;
    pool.install(|| {
        let scene = anim_springs::scenes::benchmark_cloth(n).map_err(|e| e.to_string())?;
        let mut times = Vec::new();
        let mut last = None;
        for rep in 0..=repeats {
            let mut net = scene.network.clone();
            let mut state = scene.state.clone();
            let mut integ = IntegratorKind::SymplecticEuler
                .build_explicit::<SpringNetwork>(net.dof())
                .ok_or("symplectic Euler is explicit")?;
            integ.step(&mut net, &mut state.clone(), scene.dt).map_err(|e| e.to_string())?; // warm up
            let start = std::time::Instant::now();
            for _ in 0..steps {
                integ.step(&mut net, &mut state, scene.dt).map_err(|e| e.to_string())?;
            }
            if rep > 0 {
                times.push(start.elapsed().as_secs_f64() / steps as f64);
            }
            last = Some(state);
        }
        times.sort_by(f64::total_cmp);
        let state = last.ok_or("no run")?;
        Ok(PeerRun {
            per_step_s: times[times.len() / 2],
            sum_z: state.x.chunks_exact(3).map(|p| p[2]).sum(),
            min_z: state.x.chunks_exact(3).map(|p| p[2]).fold(f64::INFINITY, f64::min),
        })
    })
}
