//! anim-pbd's conformance checks: XPBD's static stretch of the hanging chain for every iteration
//! count and time step (against `alpha T_j` per link), PBD's effective stiffness against both
//! with and without Müller et al.'s (2007, 3.3) iteration-count correction
//! `k' = 1 - (1 - k)^(1/n)`, momentum conservation of every internal constraint with unequal
//! masses (a w-weighted projection along `grad C` moves no centre of mass and applies no
//! torque), constraint gradients against central finite differences, and bit-for-bit
//! determinism across thread counts.

use super::chain::CHAIN;
use crate::{
    AttachTarget, Bending, BuildError, Cloth, Collider, ConstraintFunction, ConstraintParams, EARTH_GRAVITY,
    Method, PbdBuilder, PbdModel, PbdParams, PbdSimulation, SolverKind,
};
use anim_core::cases::{Check, Ctx, Judge, fmt_num, nan_max};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub(super) const CRATE: &str = "anim-pbd";

/// A case that could not run: measured NaN (a failure), the error in the metric.
fn failed(case: &str, why: &str) -> Check {
    Check::could_not_run(CRATE, case, why)
}

const ITERATIONS: [usize; 3] = [5, 20, 100];
const DTS: [(f64, &str); 3] = [(1.0 / 30.0, "1/30"), (1.0 / 60.0, "1/60"), (1.0 / 240.0, "1/240")];

pub(super) fn xpbd_chain(_ctx: &Ctx) -> Vec<Check> {
    let c = &CHAIN;
    let alpha = 1e-2;
    let exact = c.exact(alpha);
    let total = alpha * (1..=c.n).map(|j| c.tension(j)).sum::<f64>();
    let mut checks = Vec::new();
    for iters in ITERATIONS {
        for (dt, label) in DTS {
            // XPBD damping beta = 5 N s/m (Macklin et al. 2016, eq. 26; a quarter of critical for
            // one link) shortens the settling; it vanishes at rest and does not move the static
            // solution (stronger damping slows each step's Gauss-Seidel convergence instead).
            let stretch = ConstraintParams::with_compliance(alpha).damping(5.0);
            let run = c.model(stretch).ok().and_then(|m| {
                c.settle(m, PbdParams::new(Method::Xpbd, SolverKind::GaussSeidel, iters, 1), dt, 1e-7, 300.0)
            });
            let (err, steps) = match run {
                Some((s, steps)) => {
                    let e = (1..=c.n).map(|j| (s.x[3 * j + 2] - exact[j - 1]).abs()).fold(0.0, nan_max);
                    (e / total, steps)
                }
                None => (f64::NAN, 0),
            };
            checks.push(Check {
                crate_name: CRATE,
                case: format!(
                    "XPBD chain of 10 (1 kg, 1 m links, alpha = 1e-2 m/N), {iters} iterations, dt = {label}"
                ),
                metric: format!(
                    "max position error / total stretch ({}) after {steps} steps",
                    fmt_num(total)
                ),
                measured: err,
                reference: 0.0,
                tolerance: 0.01,
                judge: Judge::AtMost,
                source: "link j stretches by alpha T_j, T_j the weight below it (XPBD, Macklin et al. 2016)",
            });
        }
    }
    checks
}

/// Top-link effective stiffness `T_1 / stretch_1` of the PBD chain at rest.
fn pbd_keff(iters: usize, dt: f64, correction: bool) -> f64 {
    let c = &CHAIN;
    let mut p = PbdParams::new(Method::Pbd, SolverKind::GaussSeidel, iters, 1);
    p.stiffness_correction = correction;
    let run =
        c.model(ConstraintParams::with_stiffness(0.5)).ok().and_then(|m| c.settle(m, p, dt, 1e-9, 100.0));
    match run {
        Some((s, _)) => c.tension(1) / (-s.x[5] - c.l),
        None => f64::NAN,
    }
}

pub(super) fn pbd_stiffness(_ctx: &Ctx) -> Vec<Check> {
    let mut checks = Vec::new();
    for correction in [true, false] {
        let mut table = Vec::new();
        let mut k = [[0.0; 3]; 3];
        for (a, iters) in ITERATIONS.iter().enumerate() {
            for (b, (dt, label)) in DTS.iter().enumerate() {
                k[a][b] = pbd_keff(*iters, *dt, correction);
                table.push(format!("{iters} it / dt {label}: {}", fmt_num(k[a][b])));
            }
        }
        let ratio = |v: &[f64]| {
            let (lo, hi) = v.iter().fold((f64::MAX, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
            hi / lo
        };
        let mut over_dt = (0..3).map(|a| ratio(&k[a])).fold(f64::MAX, f64::min);
        let mut over_it = (0..3).map(|b| ratio(&[k[0][b], k[1][b], k[2][b]])).fold(f64::MAX, f64::min);
        if k.iter().flatten().any(|x| x.is_nan()) {
            // A chain that did not settle (NaN cell) would be dropped by min/max: fail instead.
            (over_dt, over_it) = (f64::NAN, f64::NAN);
        }
        let name = if correction { "k = 0.5 with k' = 1 - (1 - k)^(1/n)" } else { "k = 0.5 used raw" };
        checks.push(Check {
            crate_name: CRATE,
            case: format!("PBD chain of 10, {name}: effective stiffness T/stretch of the top link (N/m)"),
            metric: format!(
                "smallest max/min ratio over dt at fixed iterations [{}]; XPBD with alpha = 1e-2 gives 100 in every cell",
                table.join("; ")
            ),
            measured: over_dt,
            reference: 1.0,
            tolerance: 10.0,
            judge: Judge::AtLeast,
            source: "Macklin et al. 2016: PBD gets stiffer with smaller dt and more iterations",
        });
        checks.push(Check {
            crate_name: CRATE,
            case: format!("PBD chain of 10, {name}: dependence on the iteration count"),
            metric: "smallest max/min ratio of the effective stiffness over iterations 5, 20, 100 at fixed dt".into(),
            measured: over_it,
            reference: 1.0,
            tolerance: if correction { 1.01 } else { 10.0 },
            judge: Judge::AtLeast,
            source: "Müller et al. 2007, 3.3: k' removes most of the iteration dependence, none of the dt dependence",
        });
    }
    checks
}

/// The "zoo": one constraint of every internal kind on six particles with masses over two decades.
fn zoo_model(seed: u64, stretch: ConstraintParams) -> Result<(PbdModel, Vec<usize>), BuildError> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut b = PbdBuilder::new();
    let base = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.3, 0.9, 0.1],
        [0.6, -0.8, 0.2],
        [0.4, 0.2, 0.9],
        [1.2, 0.7, -0.3],
    ];
    for p in base {
        let q = p.map(|c| c + rng.random_range(-0.1..0.1));
        b.particle(q, 10f64.powf(rng.random_range(-1.0..1.0)));
    }
    let mut ids = vec![
        b.distance(0, 1, stretch),
        b.dihedral([2, 3, 0, 1], stretch),
        b.isometric_bending([2, 3, 0, 1], stretch),
        b.tet_volume([0, 1, 2, 4], stretch),
        b.attach(5, AttachTarget::Point([1.5, 0.5, 0.0]), 0.1, stretch),
    ];
    ids.push(b.global_volume(&[[0, 2, 1], [0, 1, 4], [1, 2, 4], [2, 0, 4]], 1.2, stretch));
    Ok((b.build()?, ids))
}

/// A model with only constraint `j` of `model`, on the same particles.
fn single(model: &PbdModel, j: usize, params: ConstraintParams) -> Result<PbdModel, BuildError> {
    let mut b = PbdBuilder::new();
    for (p, part) in model.rest_positions().iter().zip(model.particles()) {
        b.particle(*p, part.mass);
    }
    match &model.constraints()[j].function {
        ConstraintFunction::Distance { particles: [a, c], .. } => {
            b.distance_with_rest(*a, *c, 0.3, params);
        }
        ConstraintFunction::DihedralBending { particles, .. } => {
            b.dihedral(*particles, params);
        }
        ConstraintFunction::IsometricBending(s) => {
            b.isometric_bending(s.particles, params);
        }
        ConstraintFunction::TetVolume { particles, .. } => {
            b.tet_volume(*particles, params);
        }
        ConstraintFunction::GlobalVolume { mesh, .. } => {
            let m = model.volume_mesh(*mesh);
            let tris: Vec<[usize; 3]> =
                m.triangles.iter().map(|t| t.map(|k| m.vertices[k as usize])).collect();
            b.global_volume(&tris, 1.2, params);
        }
        ConstraintFunction::Attachment { particle, target, distance } => {
            b.attach(*particle, *target, *distance, params);
        }
    }
    b.build()
}

pub(super) fn momentum(_ctx: &Ctx) -> Vec<Check> {
    let mut checks = Vec::new();
    // (1) Each projection alone: sum m dp and sum m p x dp against the size of the correction.
    'methods: for method in [Method::Pbd, Method::Xpbd] {
        let mut worst_lin = 0.0f64;
        let mut worst_ang = 0.0f64;
        let mut kinds = 0;
        let setup = format!("{method:?}: one projection of each internal constraint");
        for seed in 0..20 {
            let (zoo, ids) = match zoo_model(seed, ConstraintParams::with_compliance(1e-3)) {
                Ok(x) => x,
                Err(e) => {
                    checks.push(failed(&setup, &format!("constraint zoo, seed {seed}: {e}")));
                    continue 'methods;
                }
            };
            for &j in &ids {
                if matches!(zoo.constraints()[j].function, ConstraintFunction::Attachment { .. }) {
                    continue;
                }
                let m = match single(&zoo, j, ConstraintParams::with_compliance(1e-3).stiffness(0.7)) {
                    Ok(m) => m,
                    Err(e) => {
                        checks.push(failed(&setup, &format!("constraint {j} alone, seed {seed}: {e}")));
                        continue 'methods;
                    }
                };
                let mut state = m.rest_state();
                let mut rng = ChaCha8Rng::seed_from_u64(1000 + seed);
                for x in state.x.iter_mut() {
                    *x += rng.random_range(-0.2..0.2);
                }
                let x0 = state.x.clone();
                let mut p = PbdParams::new(method, SolverKind::GaussSeidel, 1, 1);
                p.max_stretch = f64::INFINITY;
                let mut sim = match PbdSimulation::new(m.clone(), p) {
                    Ok(sim) => sim,
                    Err(e) => {
                        checks.push(failed(&setup, &format!("simulation, constraint {j}, seed {seed}: {e}")));
                        continue 'methods;
                    }
                };
                if sim.advance(&mut state, 0.01).is_err() {
                    worst_lin = f64::NAN;
                    continue;
                }
                // Round-off scales of sum m dp and sum m p x dp: dp is measured as x_new - x_old.
                let (mut lin, mut ang, mut size, mut lin_eps, mut ang_eps) =
                    ([0.0f64; 3], [0.0f64; 3], 0.0f64, 0.0f64, 0.0f64);
                for (i, part) in m.particles().iter().enumerate() {
                    let p0 = [x0[3 * i], x0[3 * i + 1], x0[3 * i + 2]];
                    let d = [state.x[3 * i] - p0[0], state.x[3 * i + 1] - p0[1], state.x[3 * i + 2] - p0[2]];
                    for a in 0..3 {
                        lin[a] += part.mass * d[a];
                    }
                    ang[0] += part.mass * (p0[1] * d[2] - p0[2] * d[1]);
                    ang[1] += part.mass * (p0[2] * d[0] - p0[0] * d[2]);
                    ang[2] += part.mass * (p0[0] * d[1] - p0[1] * d[0]);
                    size = size.max(part.mass * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt());
                    let r = (p0[0] * p0[0] + p0[1] * p0[1] + p0[2] * p0[2]).sqrt();
                    lin_eps += f64::EPSILON * part.mass * r;
                    ang_eps += f64::EPSILON * part.mass * r * r;
                }
                if !(size > 0.0) {
                    continue;
                }
                let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                worst_lin = nan_max(worst_lin, norm(lin) / lin_eps);
                worst_ang = nan_max(worst_ang, norm(ang) / ang_eps);
                kinds += 1;
            }
        }
        if kinds == 0 {
            // No projection was measured: nothing bounds the impulses.
            (worst_lin, worst_ang) = (f64::NAN, f64::NAN);
        }
        for (what, v) in [
            ("linear impulse |sum m dp| / (eps sum m |p|)", worst_lin),
            ("angular impulse |sum m p x dp| / (eps sum m |p|^2)", worst_ang),
        ] {
            checks.push(Check {
                crate_name: CRATE,
                case: format!(
                    "{method:?}: one projection of each internal constraint (distance, dihedral, isometric, tet volume, global volume), masses over two decades, {kinds} cases"
                ),
                metric: format!("max {what}: in units of the round-off of the positions"),
                measured: v,
                reference: 0.0,
                tolerance: 16.0,
                judge: Judge::AtMost,
                source: "Müller et al. 2007: w-weighted projection along grad C has no ghost forces",
            });
        }
    }
    // (2) A free cloth with unequal masses and random velocities, 100 steps: linear momentum.
    // (p0, p1, L0, L1): linear and angular momentum before and after.
    type Momenta = ([f64; 3], [f64; 3], [f64; 3], [f64; 3]);
    let run = |dt: f64, steps: usize| -> Option<Momenta> {
        let mut b = PbdBuilder::new();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let n = 8;
        for iy in 0..n {
            for ix in 0..n {
                b.particle([ix as f64 * 0.1, iy as f64 * 0.1, 0.0], 10f64.powf(rng.random_range(-1.5..1.5)));
            }
        }
        let at = |ix: usize, iy: usize| iy * n + ix;
        for iy in 0..n {
            for ix in 0..n {
                if ix + 1 < n {
                    b.distance(at(ix, iy), at(ix + 1, iy), ConstraintParams::with_compliance(1e-4));
                }
                if iy + 1 < n {
                    b.distance(at(ix, iy), at(ix, iy + 1), ConstraintParams::with_compliance(1e-4));
                }
                if ix + 1 < n && iy + 1 < n {
                    b.distance(at(ix, iy), at(ix + 1, iy + 1), ConstraintParams::with_compliance(1e-4));
                    if ix + 2 < n {
                        b.dihedral(
                            [at(ix, iy + 1), at(ix + 2, iy), at(ix + 1, iy), at(ix + 1, iy + 1)],
                            ConstraintParams::with_compliance(0.1),
                        );
                    }
                }
            }
        }
        let model = b.build().ok()?;
        let mut state = model.rest_state();
        for v in state.v.iter_mut() {
            *v = rng.random_range(-1.0..1.0);
        }
        let p0 = model.linear_momentum(&state.v);
        let l0 = model.angular_momentum(&state.x, &state.v);
        let mut sim =
            PbdSimulation::new(model.clone(), PbdParams::new(Method::Xpbd, SolverKind::GaussSeidel, 5, 1))
                .ok()?;
        sim.run(&mut state, dt, steps).ok()?;
        Some((p0, model.linear_momentum(&state.v), l0, model.angular_momentum(&state.x, &state.v)))
    };
    let diff = |a: [f64; 3], b: [f64; 3]| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    let norm = |a: [f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let coarse = run(1.0 / 60.0, 60);
    let fine = run(1.0 / 120.0, 120);
    let (lin, ang_c, ang_f) = match (coarse, fine) {
        (Some((p0, p1, l0, l1)), Some((_, _, m0, m1))) => {
            (diff(p0, p1) / norm(p0), diff(l0, l1) / norm(l0), diff(m0, m1) / norm(m0))
        }
        _ => (f64::NAN, f64::NAN, f64::NAN),
    };
    checks.push(Check {
        crate_name: CRATE,
        case: "XPBD free cloth, 64 particles with masses over 3 decades, random velocities, 1 s at dt = 1/60".into(),
        metric: format!(
            "relative linear momentum drift (the trajectory's angular momentum is not conserved: each correction is torque-free where it is computed, but velocities come from positions; L drifts by {} at dt = 1/60, {} at 1/120 in this violent start)",
            fmt_num(ang_c),
            fmt_num(ang_f)
        ),
        measured: lin,
        reference: 0.0,
        tolerance: 1e-12,
        judge: Judge::AtMost,
        source: "sum m dp = 0 per projection; v = (p - x)/h",
    });
    checks
}

pub(super) fn gradients(_ctx: &Ctx) -> Vec<Check> {
    let mut worst = 0.0f64;
    let mut count = 0;
    for seed in 0..30 {
        let (model, ids) = match zoo_model(seed, ConstraintParams::rigid()) {
            Ok(x) => x,
            Err(e) => {
                let why = format!("constraint zoo, seed {seed}: {e}");
                return vec![failed("constraint gradients at random configurations", &why)];
            }
        };
        let mut x = model.rest_state().x;
        let mut rng = ChaCha8Rng::seed_from_u64(500 + seed);
        for c in x.iter_mut() {
            *c += rng.random_range(-0.15..0.15);
        }
        for &j in &ids {
            let Some((_, grad)) = model.evaluate(j, &x, 0.0) else { continue };
            let scale = grad.iter().flat_map(|(_, g)| g.iter()).fold(0.0f64, |m, g| nan_max(m, g.abs()));
            let h = 1e-6;
            for (p, g) in &grad {
                for a in 0..3 {
                    let (mut xp, mut xm) = (x.clone(), x.clone());
                    xp[3 * p + a] += h;
                    xm[3 * p + a] -= h;
                    let cp = model.evaluate(j, &xp, 0.0).map_or(f64::NAN, |r| r.0);
                    let cm = model.evaluate(j, &xm, 0.0).map_or(f64::NAN, |r| r.0);
                    worst = nan_max(worst, ((cp - cm) / (2.0 * h) - g[a]).abs() / scale);
                }
            }
            count += 1;
        }
    }
    if count == 0 {
        // No constraint was evaluated: nothing was compared.
        worst = f64::NAN;
    }
    vec![Check {
        crate_name: CRATE,
        case: format!(
            "{count} constraints (distance, dihedral, isometric, tet volume, attachment, global volume) at random configurations"
        ),
        metric: "max |grad C - central differences| / max |grad C|".into(),
        measured: worst,
        reference: 0.0,
        tolerance: 1e-7,
        judge: Judge::AtMost,
        source: "central finite differences of C, h = 1e-6",
    }]
}

/// The benchmark cloth with a sphere under it (contacts), for the determinism check.
pub(super) fn determinism(ctx: &Ctx) -> Vec<Check> {
    let n = if ctx.quick { 60 } else { 100 };
    let model = (|| -> Result<PbdModel, BuildError> {
        let mut b = PbdBuilder::new();
        b.gravity(EARTH_GRAVITY);
        let c = b.cloth(&Cloth {
            nx: n,
            ny: n,
            origin: [-0.5, -0.5, 0.3],
            u: [1.0, 0.0, 0.0],
            v: [0.0, 1.0, 0.0],
            particle_mass: 1e-3,
            stretch: ConstraintParams::with_compliance(1e-6),
            bending: Bending::Isometric(ConstraintParams::with_compliance(1.0)),
        })?;
        b.pin(c.at(0, 0)).pin(c.at(n - 1, 0));
        b.collider(Collider::sphere([0.0, 0.0, 0.0], 0.25).with_thickness(0.005).with_friction(0.4, 0.3));
        b.collider(Collider::ground(-0.3).with_restitution(0.2));
        b.build()
    })();
    let model = match model {
        Ok(m) => m,
        Err(e) => {
            return vec![failed(
                &format!("{n}x{n} cloth over a sphere, determinism"),
                &format!("build: {e}"),
            )];
        }
    };
    let steps = if ctx.quick { 10 } else { 30 };
    SolverKind::ALL
        .iter()
        .map(|&solver| {
            let bits = |threads: usize| -> Option<Vec<u64>> {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().ok()?;
                pool.install(|| {
                    let mut state = model.rest_state();
                    let mut sim =
                        PbdSimulation::new(model.clone(), PbdParams::new(Method::Xpbd, solver, 5, 2)).ok()?;
                    sim.run(&mut state, 1.0 / 60.0, steps).ok()?;
                    Some(state.x.iter().chain(&state.v).map(|v| v.to_bits()).collect())
                })
            };
            let differing = match (bits(1), bits(2), bits(4)) {
                (Some(a), Some(b), Some(c)) => {
                    a.iter().zip(&b).filter(|(x, y)| x != y).count()
                        + a.iter().zip(&c).filter(|(x, y)| x != y).count()
                }
                _ => usize::MAX,
            };
            Check {
                crate_name: CRATE,
                case: format!(
                    "{n}x{n} cloth over a sphere, {steps} steps, {} ({} constraints), rayon pools of 1, 2, 4",
                    solver.label(),
                    model.num_constraints()
                ),
                metric: "positions and velocities whose bits differ from the 1-thread run".into(),
                measured: if differing == usize::MAX { f64::NAN } else { differing as f64 },
                reference: 0.0,
                tolerance: 0.0,
                judge: Judge::AtMost,
                source: "disjoint writes per colour, fixed-order gathers",
            }
        })
        .collect()
}
