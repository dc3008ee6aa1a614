//! anim-pbd: XPBD's static stretch of a hanging chain for every iteration count and time step,
//! PBD's effective stiffness against both, momentum conservation of every internal constraint
//! with unequal masses, constraint gradients against finite differences, determinism across
//! thread counts; hard cases (1000:1 mass ratio, 10x over-stretch, pins next to free particles,
//! zero compliance, coincident and degenerate stencils, bad input, an injected NaN); a
//! work-precision study on the hanging cloth (PBD vs XPBD, iterations vs substeps); and the
//! timed runs of `cargo xtask bench --peers`.

use crate::registry::{
    Check, ConformanceCase, Ctx, Judge, Outcome, Point, Registry, Series, StabilityCase, Study, StudyResult,
    fmt_num, median_seconds,
};
use anim_core::integrate::State;
use anim_pbd::{
    AttachTarget, Bending, BuildError, Chain, Cloth, Collider, ConstraintFunction, ConstraintParams,
    EARTH_GRAVITY, Method, PbdBuilder, PbdError, PbdModel, PbdParams, PbdSimulation, SolverKind,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const CRATE: &str = "anim-pbd";

pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "XPBD hanging chain static stretch",
        run: Box::new(xpbd_chain),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "PBD effective stiffness vs iterations and dt",
        run: Box::new(pbd_stiffness),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "PBD/XPBD momentum with unequal masses",
        run: Box::new(momentum),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "PBD constraint gradients vs finite differences",
        run: Box::new(gradients),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "PBD determinism across thread counts",
        run: Box::new(determinism),
    });

    let stable = || Outcome::Stable(String::new());
    let rejected = || Outcome::Rejected(String::new());
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD chain with a 1000:1 mass ratio",
        expected: stable,
        run: mass_ratio,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD chain started at 10x its rest length",
        expected: stable,
        run: over_stretched,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD pinned particles next to free ones",
        expected: stable,
        run: pins_next_to_free,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD zero compliance cloth at dt = 1/30 s",
        expected: stable,
        run: zero_compliance,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD coincident vertices and stencils collapsed at run time",
        expected: stable,
        run: coincident,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD zero-area bending stencil at rest",
        expected: rejected,
        run: degenerate_rest,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD invalid input (mass, k, compliance, index)",
        expected: rejected,
        run: invalid_input,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "PBD NaN injected by an external force",
        expected: || Outcome::Diverged(String::new()),
        run: injected_nan,
    });

    r.studies.push(Study {
        crate_name: CRATE,
        name: "PBD hanging cloth: position error",
        run: cloth_position_study,
    });
    r.studies.push(Study {
        crate_name: CRATE,
        name: "PBD hanging cloth: constraint error",
        run: cloth_constraint_study,
    });
}

// ---------------------------------------------------------------------------------------------
// The hanging chain.

/// A vertical chain of `n` free particles of mass `m` below a pin, links of rest length `l`.
struct HangingChain {
    n: usize,
    m: f64,
    l: f64,
    g: f64,
}

const CHAIN: HangingChain = HangingChain { n: 10, m: 1.0, l: 1.0, g: 9.81 };

impl HangingChain {
    fn model(&self, stretch: ConstraintParams) -> Result<PbdModel, BuildError> {
        let mut b = PbdBuilder::new();
        b.gravity([0.0, 0.0, -self.g]);
        let r = b.chain(&Chain {
            count: self.n + 1,
            start: [0.0; 3],
            end: [0.0, 0.0, -(self.n as f64) * self.l],
            mass: self.m,
            stretch,
        })?;
        b.pin(r.start);
        b.build()
    }

    /// Tension of link `j` (1 = top): the weight of the particles below it.
    fn tension(&self, j: usize) -> f64 {
        (self.n - j + 1) as f64 * self.m * self.g
    }

    /// Exact heights of particles 1..=n for compliance `alpha`: link j stretches by `alpha T_j`.
    fn exact(&self, alpha: f64) -> Vec<f64> {
        let mut z = 0.0;
        (1..=self.n)
            .map(|j| {
                z -= self.l + alpha * self.tension(j);
                z
            })
            .collect()
    }

    /// Runs to rest (max |v| below `tol` m/s, at most `max_t` s); returns the state and steps.
    fn settle(
        &self,
        model: PbdModel,
        params: PbdParams,
        dt: f64,
        tol: f64,
        max_t: f64,
    ) -> Option<(State, usize)> {
        let mut state = model.rest_state();
        let mut sim = PbdSimulation::new(model, params).ok()?;
        let max_steps = (max_t / dt) as usize;
        for k in 1..=max_steps {
            sim.advance(&mut state, dt).ok()?;
            if k > 10 && state.v.iter().fold(0.0f64, |a, v| a.max(v.abs())) < tol {
                return Some((state, k));
            }
        }
        Some((state, max_steps))
    }
}

const ITERATIONS: [usize; 3] = [5, 20, 100];
const DTS: [(f64, &str); 3] = [(1.0 / 30.0, "1/30"), (1.0 / 60.0, "1/60"), (1.0 / 240.0, "1/240")];

fn xpbd_chain(_ctx: &Ctx) -> Vec<Check> {
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
                    let e = (1..=c.n).map(|j| (s.x[3 * j + 2] - exact[j - 1]).abs()).fold(0.0, f64::max);
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
                source: "link j stretches by alpha T_j, T_j the weight below it (seed 3.1)",
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

fn pbd_stiffness(_ctx: &Ctx) -> Vec<Check> {
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
        let over_dt = (0..3).map(|a| ratio(&k[a])).fold(f64::MAX, f64::min);
        let over_it = (0..3).map(|b| ratio(&[k[0][b], k[1][b], k[2][b]])).fold(f64::MAX, f64::min);
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
            source: "seed 3.1: PBD gets stiffer with smaller dt and more iterations",
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

fn momentum(_ctx: &Ctx) -> Vec<Check> {
    let mut checks = Vec::new();
    // (1) Each projection alone: sum m dp and sum m p x dp against the size of the correction.
    for method in [Method::Pbd, Method::Xpbd] {
        let mut worst_lin = 0.0f64;
        let mut worst_ang = 0.0f64;
        let mut kinds = 0;
        for seed in 0..20 {
            let Ok((zoo, ids)) = zoo_model(seed, ConstraintParams::with_compliance(1e-3)) else {
                return vec![];
            };
            for &j in &ids {
                if matches!(zoo.constraints()[j].function, ConstraintFunction::Attachment { .. }) {
                    continue;
                }
                let Ok(m) = single(&zoo, j, ConstraintParams::with_compliance(1e-3).stiffness(0.7)) else {
                    return vec![];
                };
                let mut state = m.rest_state();
                let mut rng = ChaCha8Rng::seed_from_u64(1000 + seed);
                for x in state.x.iter_mut() {
                    *x += rng.random_range(-0.2..0.2);
                }
                let x0 = state.x.clone();
                let mut p = PbdParams::new(method, SolverKind::GaussSeidel, 1, 1);
                p.max_stretch = f64::INFINITY;
                let Ok(mut sim) = PbdSimulation::new(m.clone(), p) else { return vec![] };
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
                worst_lin = worst_lin.max(norm(lin) / lin_eps);
                worst_ang = worst_ang.max(norm(ang) / ang_eps);
                kinds += 1;
            }
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
                source: "seed 3: w-weighted projection along grad C has no ghost forces",
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

fn gradients(_ctx: &Ctx) -> Vec<Check> {
    let mut worst = 0.0f64;
    let mut count = 0;
    for seed in 0..30 {
        let Ok((model, ids)) = zoo_model(seed, ConstraintParams::rigid()) else { return vec![] };
        let mut x = model.rest_state().x;
        let mut rng = ChaCha8Rng::seed_from_u64(500 + seed);
        for c in x.iter_mut() {
            *c += rng.random_range(-0.15..0.15);
        }
        for &j in &ids {
            let Some((_, grad)) = model.evaluate(j, &x, 0.0) else { continue };
            let scale = grad.iter().flat_map(|(_, g)| g.iter()).fold(0.0f64, |m, g| m.max(g.abs()));
            let h = 1e-6;
            for (p, g) in &grad {
                for a in 0..3 {
                    let (mut xp, mut xm) = (x.clone(), x.clone());
                    xp[3 * p + a] += h;
                    xm[3 * p + a] -= h;
                    let cp = model.evaluate(j, &xp, 0.0).map_or(f64::NAN, |r| r.0);
                    let cm = model.evaluate(j, &xm, 0.0).map_or(f64::NAN, |r| r.0);
                    worst = worst.max(((cp - cm) / (2.0 * h) - g[a]).abs() / scale);
                }
            }
            count += 1;
        }
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
fn determinism(ctx: &Ctx) -> Vec<Check> {
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
    let Ok(model) = model else { return vec![] };
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

// ---------------------------------------------------------------------------------------------
// Hard cases.

fn finite(s: &State) -> bool {
    s.x.iter().chain(&s.v).all(|v| v.is_finite())
}

/// Largest relative stretch `|C_j| / l_j` of the distance constraints.
fn max_strain(model: &PbdModel, x: &[f64]) -> f64 {
    let mut worst = 0.0f64;
    for c in model.constraints() {
        if let ConstraintFunction::Distance { particles: [i, j], rest_length } = c.function
            && rest_length > 0.0
        {
            let d = ((x[3 * i] - x[3 * j]).powi(2)
                + (x[3 * i + 1] - x[3 * j + 1]).powi(2)
                + (x[3 * i + 2] - x[3 * j + 2]).powi(2))
            .sqrt();
            worst = worst.max((d - rest_length).abs() / rest_length);
        }
    }
    worst
}

/// Runs `steps` steps; the largest relative stretch at the end, or the error.
fn run_checked(
    model: &PbdModel,
    state: &mut State,
    params: PbdParams,
    dt: f64,
    steps: usize,
) -> Result<f64, String> {
    let mut sim = PbdSimulation::new(model.clone(), params).map_err(|e| e.to_string())?;
    sim.run(state, dt, steps).map_err(|e| e.to_string())?;
    if !finite(state) {
        return Err("non-finite state returned without an error".into());
    }
    Ok(max_strain(model, &state.x))
}

fn mass_ratio(_ctx: &Ctx) -> Outcome {
    // A chain of 20 light particles (1 g) ending in a 1 kg mass, and one alternating 1 kg / 1 g.
    let mut details = Vec::new();
    for alternating in [false, true] {
        let mut b = PbdBuilder::new();
        b.gravity(EARTH_GRAVITY);
        let mut prev = b.particle([0.0; 3], 1.0);
        b.pin(prev);
        for k in 1..=20 {
            let m = if alternating {
                if k % 2 == 0 { 1.0 } else { 1e-3 }
            } else if k == 20 {
                1.0
            } else {
                1e-3
            };
            let p = b.particle([0.05 * k as f64, 0.0, 0.0], m);
            b.distance(prev, p, ConstraintParams::rigid());
            prev = p;
        }
        let Ok(model) = b.build() else { return Outcome::Rejected("could not build".into()) };
        for method in [Method::Pbd, Method::Xpbd] {
            let mut strains = Vec::new();
            for (iters, subs) in [(20, 2), (1, 40)] {
                let mut state = model.rest_state();
                match run_checked(
                    &model,
                    &mut state,
                    PbdParams::new(method, SolverKind::GaussSeidel, iters, subs),
                    1.0 / 60.0,
                    300,
                ) {
                    Ok(v) => strains.push(format!("{} with {iters} it x {subs} substeps", fmt_num(v))),
                    Err(e) => return Outcome::Diverged(e),
                }
            }
            details.push(format!(
                "{} {method:?}: max stretch {}",
                if alternating { "alternating 1 kg / 1 g" } else { "1 g links, 1 kg end" },
                strains.join(", ")
            ));
        }
    }
    Outcome::Stable(format!(
        "rigid links, 5 s at dt = 1/60, relative stretch |C|/l after it (the heavy mass converges slowly under Gauss-Seidel; small steps help): {}",
        details.join("; ")
    ))
}

fn over_stretched(_ctx: &Ctx) -> Outcome {
    let c = HangingChain { n: 10, m: 0.1, l: 0.1, g: 9.81 };
    let Ok(model) = c.model(ConstraintParams::with_compliance(1e-6)) else {
        return Outcome::Rejected("could not build".into());
    };
    let mut details = Vec::new();
    for method in [Method::Pbd, Method::Xpbd] {
        let mut state = model.rest_state();
        for (k, z) in state.x.chunks_exact_mut(3).enumerate() {
            z[2] = -10.0 * c.l * k as f64; // every link 10x its rest length
        }
        let Ok(mut sim) =
            PbdSimulation::new(model.clone(), PbdParams::new(method, SolverKind::GaussSeidel, 10, 1))
        else {
            return Outcome::Rejected("bad params".into());
        };
        if let Err(e) = sim.advance(&mut state, 1.0 / 60.0) {
            return Outcome::Diverged(e.to_string());
        }
        let after1 = max_strain(&model, &state.x);
        if let Err(e) = sim.run(&mut state, 1.0 / 60.0, 299) {
            return Outcome::Diverged(e.to_string());
        }
        let after = max_strain(&model, &state.x);
        if !(after < 0.05) {
            return Outcome::Diverged(format!("{method:?}: still stretched by {after} m after 5 s"));
        }
        details.push(format!(
            "{method:?}: max relative stretch 9 -> {} after 1 step -> {} after 5 s",
            fmt_num(after1),
            fmt_num(after)
        ));
    }
    Outcome::Stable(details.join("; "))
}

fn pins_next_to_free(_ctx: &Ctx) -> Outcome {
    // A cloth whose every other particle of the top two rows is pinned (constraints between two
    // pinned particles have zero denominator and are skipped).
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let n = 12;
    let Ok(c) = b.cloth(&Cloth {
        nx: n,
        ny: n,
        origin: [0.0, 0.0, 1.0],
        u: [1.0, 0.0, 0.0],
        v: [0.0, 0.0, -1.0],
        particle_mass: 1e-3,
        stretch: ConstraintParams::rigid(),
        bending: Bending::Dihedral(ConstraintParams::with_compliance(1.0)),
    }) else {
        return Outcome::Rejected("could not build".into());
    };
    for iy in 0..2 {
        for ix in (0..n).step_by(2) {
            b.pin(c.at(ix, iy));
        }
    }
    b.pin(c.at(1, 0)).pin(c.at(1, 1));
    let Ok(model) = b.build() else { return Outcome::Rejected("could not build".into()) };
    let mut details = Vec::new();
    for solver in SolverKind::ALL {
        let mut state = model.rest_state();
        match run_checked(&model, &mut state, PbdParams::new(Method::Xpbd, solver, 10, 2), 1.0 / 60.0, 180) {
            Ok(v) => details.push(format!("{}: max stretch {}", solver.label(), fmt_num(v))),
            Err(e) => return Outcome::Diverged(e),
        }
    }
    Outcome::Stable(format!("3 s, every solver: {}", details.join(", ")))
}

fn zero_compliance(_ctx: &Ctx) -> Outcome {
    let scene = match anim_pbd::scenes::cloth_drape(Some(24)) {
        Ok(s) => s,
        Err(e) => return Outcome::Rejected(e.to_string()),
    };
    let mut details = Vec::new();
    for solver in SolverKind::ALL {
        let state = scene.state.clone();
        // Rigid distances (alpha = 0: XPBD's update reduces to PBD's with k = 1, no division by
        // alpha anywhere) with the scene's soft bending, at twice the scene's step.
        let mut b = PbdBuilder::new();
        for (p, part) in scene.model.rest_positions().iter().zip(scene.model.particles()) {
            b.particle(*p, part.mass);
        }
        b.gravity(EARTH_GRAVITY);
        for c in scene.model.constraints() {
            match &c.function {
                ConstraintFunction::Distance { particles: [i, j], .. } => {
                    b.distance(*i, *j, ConstraintParams::rigid());
                }
                ConstraintFunction::IsometricBending(s) => {
                    b.isometric_bending(s.particles, c.params);
                }
                _ => {}
            }
        }
        for col in scene.model.colliders() {
            b.collider(*col);
        }
        let Ok(model) = b.build() else { return Outcome::Rejected("could not build".into()) };
        let mut strains = Vec::new();
        for (iters, subs) in [(10, 1), (1, 10)] {
            let mut s = state.clone();
            match run_checked(
                &model,
                &mut s,
                PbdParams::new(Method::Xpbd, solver, iters, subs),
                1.0 / 30.0,
                90,
            ) {
                Ok(v) => strains.push(format!("{} ({iters} it x {subs} substeps)", fmt_num(v))),
                Err(e) => return Outcome::Diverged(e),
            }
        }
        details.push(format!("{}: max stretch {}", solver.label(), strains.join(", ")));
    }
    Outcome::Stable(format!(
        "24x24 cloth draped on a sphere, alpha = 0 for every distance, 3 s at dt = 1/30: {}. With one substep, positional static friction evaluated every iteration can lock a stretched edge on the sphere; substeps reduce it",
        details.join("; ")
    ))
}

fn coincident(_ctx: &Ctx) -> Outcome {
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    for p in [
        [0.5, 1.0, 0.0],
        [0.5, -1.0, 0.0],
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [2.0, 0.0, 1.0],
        [3.0, 0.0, 1.0],
    ] {
        b.particle(p, 1.0);
    }
    b.pin(5);
    b.distance(4, 5, ConstraintParams::rigid());
    b.distance(0, 1, ConstraintParams::rigid());
    b.distance_with_rest(2, 3, 0.0, ConstraintParams::with_compliance(1e-3));
    b.dihedral([0, 1, 2, 3], ConstraintParams::with_compliance(0.1));
    b.isometric_bending([0, 1, 2, 3], ConstraintParams::with_compliance(0.1));
    b.tet_volume([0, 1, 2, 4], ConstraintParams::rigid());
    let Ok(model) = b.build() else { return Outcome::Rejected("could not build".into()) };
    let mut start = model.rest_state();
    // Particles 0 and 1 coincide on the edge midpoint; 2 sits on 3: every stencil is degenerate.
    for i in [0, 1] {
        start.x[3 * i..3 * i + 3].copy_from_slice(&[0.5, 0.0, 0.0]);
    }
    start.x[6..9].copy_from_slice(&[1.0, 0.0, 0.0]);
    let mut runs = 0;
    for method in [Method::Pbd, Method::Xpbd] {
        for solver in SolverKind::ALL {
            let mut s = start.clone();
            if let Err(e) = run_checked(&model, &mut s, PbdParams::new(method, solver, 5, 1), 1.0 / 60.0, 60)
            {
                return Outcome::Diverged(format!("{method:?} {}: {e}", solver.label()));
            }
            runs += 1;
        }
    }
    Outcome::Stable(format!(
        "{runs} runs (PBD/XPBD x 3 solvers), 1 s: coincident distance endpoints separate along their rest direction; zero-area dihedral, isometric and tet stencils are skipped until they open; finite throughout"
    ))
}

fn degenerate_rest(_ctx: &Ctx) -> Outcome {
    let mut b = PbdBuilder::new();
    for p in [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.5, 1.0, 0.0]] {
        b.particle(p, 1.0);
    }
    b.distance(0, 1, ConstraintParams::rigid());
    b.isometric_bending([2, 3, 0, 1], ConstraintParams::with_compliance(1.0));
    match b.build() {
        Err(e) => Outcome::Rejected(e.to_string()),
        Ok(_) => Outcome::Stable("accepted a zero-area stencil".into()),
    }
}

fn invalid_input(_ctx: &Ctx) -> Outcome {
    let base = || {
        let mut b = PbdBuilder::new();
        b.particle([0.0; 3], 1.0);
        b.particle([1.0, 0.0, 0.0], 1.0);
        b
    };
    let mut msgs = Vec::new();
    let mut b = base();
    b.particle([0.0, 1.0, 0.0], -2.0);
    msgs.push(b.build().err());
    let mut b = base();
    b.distance(0, 1, ConstraintParams::with_stiffness(1.5));
    msgs.push(b.build().err());
    let mut b = base();
    b.distance(0, 1, ConstraintParams::with_compliance(-1e-6));
    msgs.push(b.build().err());
    let mut b = base();
    b.distance(0, 7, ConstraintParams::rigid());
    msgs.push(b.build().err());
    if msgs.iter().any(Option::is_none) {
        return Outcome::Stable("some invalid input was accepted".into());
    }
    Outcome::Rejected(msgs.into_iter().flatten().map(|e| e.to_string()).collect::<Vec<_>>().join("; "))
}

fn injected_nan(_ctx: &Ctx) -> Outcome {
    let c = HangingChain { n: 5, m: 0.1, l: 0.1, g: 9.81 };
    let Ok(model) = c.model(ConstraintParams::with_compliance(1e-6)) else {
        return Outcome::Rejected("could not build".into());
    };
    let mut state = model.rest_state();
    let Ok(mut sim) = PbdSimulation::new(model, PbdParams::default()) else {
        return Outcome::Rejected("bad params".into());
    };
    if sim.run(&mut state, 0.01, 5).is_err() {
        return Outcome::Stable("failed before the injection".into());
    }
    let before = state.x.clone();
    sim.set_external_force(3, [0.0, f64::INFINITY, 0.0]);
    match sim.advance(&mut state, 0.01) {
        Err(e @ PbdError::NonFinite { .. }) => {
            Outcome::Diverged(format!("{e}; state kept: {}", state.x == before && finite(&state)))
        }
        Err(e) => Outcome::Diverged(format!("other error: {e}")),
        Ok(_) => Outcome::Stable("an infinite force went unnoticed".into()),
    }
}

// ---------------------------------------------------------------------------------------------
// The work-precision study: a hanging cloth.

pub(crate) const STUDY_T: f64 = 0.5;
const STUDY_DT: f64 = 1.0 / 60.0;

/// The study cloth: anim-pbd's `hanging-cloth` preset (`n x n`, 0.5 m, 0.1 kg, pinned at two
/// corners, stiff distances (`alpha = 1e-7` m/N; PBD `k = 1`), soft isometric bending
/// (`alpha = 5`; PBD `k = 0.1`)), which `anim run --tolerance` maps to this study.
fn study_model(n: usize) -> Option<PbdModel> {
    anim_pbd::scenes::hanging_cloth(Some(n)).ok().map(|s| s.model)
}

/// The study cloth's side in particles.
fn study_side(quick: bool) -> usize {
    if quick { 8 } else { 14 }
}

/// The study problem's parameters `anim run --tolerance` transfers from: the cloth's side `n`
/// and the step `dt` (s).
pub fn study_problem(quick: bool) -> Vec<(&'static str, f64)> {
    vec![("n", study_side(quick) as f64), ("dt", STUDY_DT)]
}

fn study_run(model: &PbdModel, method: Method, iters: usize, subs: usize) -> Option<Vec<f64>> {
    let mut state = model.rest_state();
    let mut sim =
        PbdSimulation::new(model.clone(), PbdParams::new(method, SolverKind::GaussSeidel, iters, subs))
            .ok()?;
    sim.run(&mut state, STUDY_DT, (STUDY_T / STUDY_DT).round() as usize).ok()?;
    Some(state.x)
}

/// Mean relative stretch `|C_j| / l_j` of the distance constraints.
fn mean_strain(model: &PbdModel, x: &[f64]) -> f64 {
    let (mut s, mut k) = (0.0, 0);
    for c in model.constraints() {
        if let ConstraintFunction::Distance { particles: [i, j], rest_length } = c.function {
            let d = ((x[3 * i] - x[3 * j]).powi(2)
                + (x[3 * i + 1] - x[3 * j + 1]).powi(2)
                + (x[3 * i + 2] - x[3 * j + 2]).powi(2))
            .sqrt();
            s += (d - rest_length).abs() / rest_length;
            k += 1;
        }
    }
    s / k.max(1) as f64
}

fn cloth_study(ctx: &Ctx, constraint_error: bool) -> StudyResult {
    let n = study_side(ctx.quick);
    let (batches, min_batch) = if ctx.quick { (3, 0.002) } else { (5, 0.02) };
    let sweep: Vec<usize> = if ctx.quick { vec![1, 4, 16] } else { vec![1, 2, 4, 8, 16, 32, 64] };
    let model = study_model(n);
    // The converged reference: XPBD with 512 substeps of 4 iterations (256 x 4 in quick mode).
    let reference =
        model.as_ref().and_then(|m| study_run(m, Method::Xpbd, 4, if ctx.quick { 256 } else { 512 }));
    let x0 = model.as_ref().map(|m| m.rest_state().x).unwrap_or_default();
    let error = |x: &Option<Vec<f64>>| -> f64 {
        match (&model, &reference, x) {
            (Some(m), Some(r), Some(x)) => {
                if constraint_error {
                    (mean_strain(m, x) - mean_strain(m, r)).abs()
                } else {
                    let num: f64 = x.iter().zip(r).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
                    let den: f64 = r.iter().zip(&x0).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
                    num / den
                }
            }
            _ => f64::NAN,
        }
    };
    let mut series = Vec::new();
    for method in [Method::Xpbd, Method::Pbd] {
        for substeps in [false, true] {
            let label = format!(
                "{method:?} {}",
                if substeps { "substeps (1 iteration)" } else { "iterations (1 substep)" }
            );
            let points = sweep
                .iter()
                .map(|&k| {
                    let (it, sub) = if substeps { (1, k) } else { (k, 1) };
                    let x = model.as_ref().and_then(|m| study_run(m, method, it, sub));
                    let err = error(&x);
                    let seconds = match &model {
                        Some(m) if err.is_finite() => median_seconds(batches, min_batch, || {
                            std::hint::black_box(study_run(m, method, it, sub));
                        }),
                        _ => f64::NAN,
                    };
                    Point { param: k as f64, seconds, error: err }
                })
                .collect();
            series.push(Series { label, points });
        }
    }
    let (title, slug, error_label) = if constraint_error {
        (
            format!(
                "Hanging cloth {n}x{n}, 0.5 s at dt = 1/60: stretch error against a converged XPBD run (512 substeps x 4 iterations); PBD stiffness is k = 1 (stretch), 0.1 (bending)"
            ),
            "pbd-cloth-constraint",
            "|mean |C_j|/l_j - reference| (distance constraints)",
        )
    } else {
        (
            format!(
                "Hanging cloth {n}x{n}, 0.5 s at dt = 1/60: position error against a converged XPBD run (512 substeps x 4 iterations); PBD converges to a different, iteration-dependent material"
            ),
            "pbd-cloth-position",
            "|x - x_ref| / |x_ref - x_0| at t = 0.5 s",
        )
    };
    StudyResult {
        title,
        slug: slug.into(),
        error_label: error_label.into(),
        param_label: "iterations or substeps".into(),
        series,
    }
}

fn cloth_position_study(ctx: &Ctx) -> StudyResult {
    cloth_study(ctx, false)
}

fn cloth_constraint_study(ctx: &Ctx) -> StudyResult {
    cloth_study(ctx, true)
}

// ---------------------------------------------------------------------------------------------
// Peer runs (`cargo xtask bench --peers`).

/// One timed run of the benchmark cloth.
#[derive(Debug, Clone, Copy)]
pub struct PeerRun {
    /// Median wall time of one step (s).
    pub per_step_s: f64,
    /// Number of constraints.
    pub constraints: usize,
    /// Lowest height after the timed steps (sanity check).
    pub min_height: f64,
}

/// Times `steps` steps of the `n x n` benchmark cloth (XPBD, dt = 1/60, `iterations` iterations,
/// isometric or dihedral bending) with `solver` on a pool of `threads` threads; median of
/// `repeats` runs, each from the rest state after one warm-up step.
pub fn peer_cloth(
    n: usize,
    iterations: usize,
    dihedral: bool,
    solver: SolverKind,
    threads: usize,
    steps: usize,
    repeats: usize,
) -> Result<PeerRun, String> {
    use anim_pbd::scenes::benchmark::*;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| e.to_string())?;
    pool.install(|| {
        let mut b = PbdBuilder::new();
        b.gravity(EARTH_GRAVITY);
        let bending = ConstraintParams::with_compliance(BENDING_COMPLIANCE);
        let c = b
            .cloth(&Cloth {
                nx: n,
                ny: n,
                origin: [0.0; 3],
                u: [SIZE, 0.0, 0.0],
                v: [0.0, SIZE, 0.0],
                particle_mass: PARTICLE_MASS,
                stretch: ConstraintParams::with_compliance(STRETCH_COMPLIANCE),
                bending: if dihedral { Bending::Dihedral(bending) } else { Bending::Isometric(bending) },
            })
            .map_err(|e| e.to_string())?;
        b.pin(c.at(0, 0)).pin(c.at(n - 1, 0));
        let model = b.build().map_err(|e| e.to_string())?;
        let mut times = Vec::new();
        let mut min_height = f64::NAN;
        for rep in 0..=repeats {
            let mut state = model.rest_state();
            let mut params = PbdParams::new(Method::Xpbd, solver, iterations, 1);
            params.max_stretch = f64::INFINITY;
            let mut sim = PbdSimulation::new(model.clone(), params).map_err(|e| e.to_string())?;
            sim.advance(&mut state, DT).map_err(|e| e.to_string())?;
            let start = std::time::Instant::now();
            sim.run(&mut state, DT, steps).map_err(|e| e.to_string())?;
            if rep > 0 {
                times.push(start.elapsed().as_secs_f64() / steps as f64);
            }
            min_height = state.x.chunks_exact(3).map(|p| p[2]).fold(f64::INFINITY, f64::min);
        }
        times.sort_by(f64::total_cmp);
        Ok(PeerRun { per_step_s: times[times.len() / 2], constraints: model.num_constraints(), min_height })
    })
}
