//! anim-mpm: conservation of mass, momentum and angular momentum by the transfers (APIC and
//! MLS-MPM, quadratic and cubic, 2D and 3D), determinism across thread counts, a resting elastic
//! block over 10 s, two colliding elastic disks, and the 2D dam break against Martin & Moyce
//! (1952); hard cases (CFL above 1, particles leaving the domain, extreme snow compression,
//! zero-mass nodes, an injected divergence, bad input); the dam-break work-precision study
//! (resolution and particles per cell, APIC vs MLS-MPM, quadratic vs cubic); and the timed runs
//! of `cargo xtask bench --peers`.

use crate::registry::{
    Check, ConformanceCase, Ctx, Judge, Outcome, Point, Registry, Series, StabilityCase, Study, StudyResult,
    fmt_num,
};
use anim_core::solver::Solver;
use anim_mpm::scenes::{self, fill};
use anim_mpm::{
    Boundary, Collider, Elastic, Fluid, Kernel, Material, MpmError, MpmParams, MpmSimulation, OutOfDomain,
    Particles, Shape, Snow, Transfer,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const CRATE: &str = "anim-mpm";

pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "MPM transfer conservation",
        run: Box::new(conservation),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "MPM determinism across thread counts",
        run: Box::new(determinism),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "MPM resting elastic block",
        run: Box::new(resting_block),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "MPM colliding elastic disks",
        run: Box::new(colliding_disks),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "MPM dam break vs Martin & Moyce (1952)",
        run: Box::new(dam_break_case),
    });

    let stable = || Outcome::Stable(String::new());
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "MPM CFL above 1 (adaptive substeps)",
        expected: stable,
        run: high_cfl,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "MPM soft block (E 1e4) hitting a wall at 40 m/s",
        expected: || Outcome::Diverged(String::new()),
        run: wall_impact,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "MPM particles leaving the domain",
        expected: stable,
        run: leaving_domain,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "MPM extreme snow compression",
        expected: stable,
        run: snow_compression,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "MPM zero-mass grid nodes",
        expected: stable,
        run: zero_mass_nodes,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "MPM divergence (overflowing deformation)",
        expected: || Outcome::Diverged(String::new()),
        run: divergence,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "MPM invalid input",
        expected: || Outcome::Rejected(String::new()),
        run: invalid_input,
    });

    r.studies.push(Study { crate_name: CRATE, name: "MPM dam break surge front", run: dam_break_study });
}

// ---------------------------------------------------------------------------------------------
// Conservation.

fn cloud<const D: usize>(n: usize, seed: u64) -> Particles<D> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut p = Particles::<D>::new();
    for _ in 0..n {
        let x: [f32; D] = std::array::from_fn(|_| rng.random_range(0.35f32..0.65));
        let v: [f32; D] = std::array::from_fn(|_| rng.random_range(-1.0f32..1.0));
        let m = rng.random_range(0.5f32..2.0) * 1e-3;
        if p.push(x, v, m, 1e-3, 0).is_err() {
            unreachable!("finite positive input");
        }
    }
    for c in p.c.iter_mut() {
        *c = rng.random_range(-3.0f32..3.0);
    }
    for (i, f) in p.f.iter_mut().enumerate() {
        let diag = (i % (D * D)).is_multiple_of(D + 1);
        *f = if diag { 1.0 } else { 0.0 } + rng.random_range(-0.05f32..0.05);
    }
    p
}

/// Relative errors over `steps` steps: mass, momentum (particles -> grid, grid -> particles,
/// max over steps) and angular momentum likewise.
fn conservation_errors<const D: usize>(
    transfer: Transfer,
    kernel: Kernel,
    steps: usize,
) -> Result<[f64; 3], MpmError> {
    let mut params = MpmParams::with_resolution(32);
    params.transfer = transfer;
    params.kernel = kernel;
    params.gravity = [0.0; 3];
    params.cfl = f64::INFINITY;
    params.wave_cfl = f64::INFINITY;
    let mut sim = MpmSimulation::<D>::new(params, vec![Material::Elastic(Elastic::default())])?;
    let mut p = cloud::<D>(500, 11);
    let mut errs = [0.0f64; 3];
    let norm = |a: [f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    for _ in 0..steps {
        let before = sim.totals(&p);
        sim.advance(&mut p, 2e-4)?;
        let after = sim.totals(&p);
        let (mut gm, mut gp, mut gl) = (0.0f64, [0.0f64; 3], [0.0f64; 3]);
        for (x, m, v) in sim.grid_nodes() {
            let m = f64::from(m);
            gm += m;
            let x3 = [f64::from(x[0]), f64::from(x[1]), if D == 3 { f64::from(x[2]) } else { 0.0 }];
            let v3 = [f64::from(v[0]), f64::from(v[1]), if D == 3 { f64::from(v[2]) } else { 0.0 }];
            for a in 0..3 {
                gp[a] += m * v3[a];
            }
            gl[0] += m * (x3[1] * v3[2] - x3[2] * v3[1]);
            gl[1] += m * (x3[2] * v3[0] - x3[0] * v3[2]);
            gl[2] += m * (x3[0] * v3[1] - x3[1] * v3[0]);
        }
        let (mut sp, mut sl) = (0.0, 0.0);
        for i in 0..p.len() {
            let m = f64::from(p.mass[i]);
            sp += m * f64::from(p.velocity(i).norm());
            sl += m * f64::from(p.velocity(i).norm()) * f64::from(p.position(i).norm());
        }
        errs[0] = errs[0].max(((after.mass - before.mass).abs() + (gm - before.mass).abs()) / before.mass);
        errs[1] = errs[1].max(norm(sub(gp, before.momentum)).max(norm(sub(after.momentum, gp))) / sp);
        errs[2] = errs[2]
            .max(norm(sub(gl, before.angular_momentum)).max(norm(sub(after.angular_momentum, gl))) / sl);
    }
    Ok(errs)
}

fn conservation(ctx: &Ctx) -> Vec<Check> {
    let steps = if ctx.quick { 5 } else { 50 };
    let mut checks = vec![];
    // f32 particles: a small multiple of eps_f32 = 1.19e-7.
    let tol = 2e-6;
    for transfer in [Transfer::Apic, Transfer::Mls] {
        for kernel in [Kernel::Quadratic, Kernel::Cubic] {
            for dim in [2, 3] {
                let errs = if dim == 2 {
                    conservation_errors::<2>(transfer, kernel, steps)
                } else {
                    conservation_errors::<3>(transfer, kernel, steps)
                };
                let errs = errs.unwrap_or([f64::NAN; 3]);
                for (metric, e) in ["mass", "linear momentum", "angular momentum"].iter().zip(errs) {
                    checks.push(Check {
                        crate_name: CRATE,
                        case: format!("{transfer:?} {kernel:?} {dim}D, elastic cloud, {steps} steps"),
                        metric: format!("max relative {metric} error P2G and G2P"),
                        measured: e,
                        reference: 0.0,
                        tolerance: tol,
                        judge: Judge::AtMost,
                        source: "exact conservation of the transfers (Jiang et al. 2015; Hu et al. 2018), f32 round-off",
                    });
                }
            }
        }
    }
    checks
}

fn determinism(ctx: &Ctx) -> Vec<Check> {
    let steps = if ctx.quick { 20 } else { 100 };
    let run = |threads: usize| -> Option<Particles<2>> {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().ok()?;
        pool.install(|| {
            let mut scene = scenes::three_materials(64).ok()?;
            for _ in 0..steps {
                scene.sim.step(&mut scene.state, scene.dt).ok()?;
            }
            Some(scene.state)
        })
    };
    let one = run(1);
    let mut checks = vec![];
    for threads in [2, 4] {
        let other = run(threads);
        let differing = match (&one, &other) {
            (Some(a), Some(b)) if a.len() == b.len() => {
                a.x.iter()
                    .zip(&b.x)
                    .chain(a.v.iter().zip(&b.v))
                    .chain(a.f.iter().zip(&b.f))
                    .filter(|(p, q)| p.to_bits() != q.to_bits())
                    .count() as f64
            }
            _ => f64::NAN,
        };
        checks.push(Check {
            crate_name: CRATE,
            case: format!("three-materials 64^2, {steps} steps, 1 vs {threads} threads"),
            metric: "floats differing in x, v, F".into(),
            measured: differing,
            reference: 0.0,
            tolerance: 0.0,
            judge: Judge::AtMost,
            source: "ordered block scatter, no float atomics",
        });
    }
    checks
}

// ---------------------------------------------------------------------------------------------
// Resting block.

/// A 2D elastic block resting on the floor for 10 s: drift of the centroid (mean over the
/// second second against the mean over the last second), its largest excursion after settling,
/// and the particle speeds in the last second.
fn resting_block(ctx: &Ctx) -> Vec<Check> {
    let n = if ctx.quick { 64 } else { 128 };
    let result = (|| -> Result<(f64, f64, f64, f64), MpmError> {
        let mut params = MpmParams::with_resolution(n);
        params.wall = Boundary::Sticky;
        let h = params.h();
        // Stiff enough that the static sag rho g H^2 / (2 E) = 2e-4 m stays far below a cell.
        let mat =
            Material::Elastic(Elastic { young: 1e6, poisson: 0.3, density: 1000.0, ..Elastic::default() });
        let mut sim = MpmSimulation::<2>::new(params, vec![mat])?;
        let mut p = Particles::<2>::new();
        // The floor's sticky nodes are y < 3h; the block sits on them.
        let y0 = 3.0 * h;
        fill(&mut p, h, 2, [0.4, y0], [0.6, y0 + 0.2], 0, 1000.0, [0.0; 2], |_| true)?;
        let dt = 5e-4;
        let centroid = |p: &Particles<2>| {
            let (mut cx, mut cy) = (0.0, 0.0);
            for i in 0..p.len() {
                cx += f64::from(p.x[2 * i]);
                cy += f64::from(p.x[2 * i + 1]);
            }
            (cx / p.len() as f64, cy / p.len() as f64)
        };
        let per_second = (1.0 / dt) as usize;
        let steps = 10 * per_second;
        let (mut early, mut late) = ((0.0, 0.0), (0.0, 0.0));
        let mut samples = vec![];
        let mut max_speed_late: f64 = 0.0;
        for s in 0..steps {
            sim.advance(&mut p, dt)?;
            let c = centroid(&p);
            if s >= per_second {
                samples.push(c);
            }
            if (per_second..2 * per_second).contains(&s) {
                early.0 += c.0 / per_second as f64;
                early.1 += c.1 / per_second as f64;
            }
            if s >= steps - per_second {
                late.0 += c.0 / per_second as f64;
                late.1 += c.1 / per_second as f64;
                for i in 0..p.len() {
                    max_speed_late = max_speed_late.max(f64::from(p.velocity(i).norm()));
                }
            }
        }
        let drift = ((late.0 - early.0).powi(2) + (late.1 - early.1).powi(2)).sqrt();
        let max_dev = samples
            .iter()
            .map(|c| ((c.0 - early.0).powi(2) + (c.1 - early.1).powi(2)).sqrt())
            .fold(0.0, f64::max);
        Ok((drift / h, max_dev / h, max_speed_late, late.1))
    })();
    let (drift, dev, speed, _) = result.unwrap_or((f64::NAN, f64::NAN, f64::NAN, f64::NAN));
    let case = format!("0.2 m elastic block (E 1e6, nu 0.3) on a sticky floor, {n}^2, MLS, 10 s");
    vec![
        Check {
            crate_name: CRATE,
            case: case.clone(),
            metric: "centroid drift, mean over 9-10 s vs 1-2 s (cells)".into(),
            measured: drift,
            reference: 0.0,
            tolerance: 0.01,
            judge: Judge::AtMost,
            source: "a body at rest stays at rest",
        },
        Check {
            crate_name: CRATE,
            case: case.clone(),
            metric: "max centroid excursion from its 1-2 s mean after t = 1 s (cells)".into(),
            measured: dev,
            reference: 0.0,
            tolerance: 0.05,
            judge: Judge::AtMost,
            source: "no jitter above 0.05 cell",
        },
        Check {
            crate_name: CRATE,
            case,
            metric: "max particle speed in the last second (m/s)".into(),
            measured: speed,
            reference: 0.0,
            tolerance: 0.01,
            judge: Judge::AtMost,
            source: "no jitter above 1 cm/s",
        },
    ]
}

// ---------------------------------------------------------------------------------------------
// Colliding disks.

fn colliding_disks(ctx: &Ctx) -> Vec<Check> {
    let n = if ctx.quick { 64 } else { 128 };
    let mut checks = vec![];
    for transfer in [Transfer::Mls, Transfer::Apic] {
        let result = (|| -> Result<(f64, f64, f64, f64, f64), MpmError> {
            let mut params = MpmParams::with_resolution(n);
            params.gravity = [0.0; 3];
            params.transfer = transfer;
            let h = params.h();
            let mat = Material::Elastic(Elastic {
                young: 1e4,
                poisson: 0.3,
                density: 1000.0,
                ..Elastic::default()
            });
            let mut sim = MpmSimulation::<2>::new(params, vec![mat, mat])?;
            let mut p = Particles::<2>::new();
            let v0 = 0.5f32;
            let r = 0.1;
            for (k, (cx, v)) in [(0.3, v0), (0.7, -v0)].into_iter().enumerate() {
                fill(&mut p, h, 2, [cx - r, 0.5 - r], [cx + r, 0.5 + r], k as u16, 1000.0, [v, 0.0], |x| {
                    (x[0] - cx).powi(2) + (x[1] - 0.5).powi(2) <= r * r
                })?;
            }
            let e0 = sim.totals(&p);
            let energy0 = e0.kinetic + e0.elastic;
            let dt = 5e-4;
            // Closing speed 1 m/s over a gap of 0.2 m: contact from 0.2 s to about 0.5 s; run to
            // 0.8 s, before the disks reach the walls.
            let mut min_energy = energy0;
            for _ in 0..(0.8 / dt) as usize {
                sim.advance(&mut p, dt)?;
                let t = sim.totals(&p);
                min_energy = min_energy.min(t.kinetic + t.elastic);
            }
            let t = sim.totals(&p);
            let mut vx = [0.0f64; 2];
            let mut mass = [0.0f64; 2];
            for i in 0..p.len() {
                let k = usize::from(p.material[i]);
                vx[k] += f64::from(p.mass[i]) * f64::from(p.v[2 * i]);
                mass[k] += f64::from(p.mass[i]);
            }
            let (v_left, v_right) = (vx[0] / mass[0], vx[1] / mass[1]);
            let p_scale = e0.mass * f64::from(v0);
            Ok((
                v_left / f64::from(v0),
                v_right / -f64::from(v0),
                (t.kinetic + t.elastic) / energy0,
                t.momentum[0].abs() / p_scale,
                min_energy / energy0,
            ))
        })();
        let (vl, vr, e_ratio, mom, e_min) =
            result.unwrap_or((f64::NAN, f64::NAN, f64::NAN, f64::NAN, f64::NAN));
        let case = format!("two elastic disks (r 0.1, E 1e4) at +-0.5 m/s, {n}^2, {transfer:?}, 0.8 s");
        let push =
            |checks: &mut Vec<Check>, metric: &str, measured: f64, tolerance: f64, judge: Judge, source| {
                checks.push(Check {
                    crate_name: CRATE,
                    case: case.clone(),
                    metric: metric.into(),
                    measured,
                    reference: 0.0,
                    tolerance,
                    judge,
                    source,
                })
            };
        push(
            &mut checks,
            "left disk velocity after / before (bounced back: < 0)",
            vl,
            -0.1,
            Judge::AtMost,
            "Sulsky et al. 1994: the disks separate",
        );
        push(
            &mut checks,
            "right disk velocity after / before (bounced back: < 0)",
            vr,
            -0.1,
            Judge::AtMost,
            "Sulsky et al. 1994: the disks separate",
        );
        push(
            &mut checks,
            "total energy at 0.8 s / initial (no energy gain)",
            e_ratio,
            1.0 + 1e-3,
            Judge::AtMost,
            "energy is conserved or dissipated, never created",
        );
        push(
            &mut checks,
            "minimum total energy / initial during the run (reported)",
            e_min,
            0.0,
            Judge::AtLeast,
            "report: dissipation of the transfers during contact",
        );
        push(
            &mut checks,
            "|total x momentum| / (M v0)",
            mom,
            1e-5,
            Judge::AtMost,
            "no external force: momentum conserved to f32 round-off",
        );
    }
    checks
}

// ---------------------------------------------------------------------------------------------
// Dam break.

/// Martin & Moyce (1952), tables 2 and 6 (REFERENCES.md), `a` = 2.25 in, `n^2 = 2`:
/// `T = t sqrt(2 g / a)` and `Z = x / a` (anim-mpm's copy, which `anim run` measures against).
pub(crate) const MARTIN_MOYCE: [(f64, f64); 15] = scenes::MARTIN_MOYCE;

/// The 2D dam break of `scenes::dam_break_2d` (a water column `a x 2a`, a = 0.2 m, collapsing
/// along a 1 m tank). Returns the surge front `Z = x / a` at the table's times `T` (steps end on
/// them), the whole history `(T, Z)` (every step), and the wall time.
pub(crate) fn dam_break(
    n: usize,
    per_cell: usize,
    transfer: Transfer,
    kernel: Kernel,
) -> Result<DamBreak, MpmError> {
    let scenes::Scene { mut sim, state: mut p, dt, .. } =
        scenes::dam_break_2d(n, per_cell, transfer, kernel)?;
    let t_scale = scenes::dam_break_time_scale();
    let front = |sim: &MpmSimulation<2>, p: &Particles<2>| scenes::surge_front(sim.params(), p);
    let start = std::time::Instant::now();
    let mut z = Vec::with_capacity(MARTIN_MOYCE.len());
    let mut history = vec![(0.0, front(&sim, &p))];
    for &(t_star, _) in &MARTIN_MOYCE {
        let t_end = t_star / t_scale;
        while sim.time() < t_end - 1e-12 {
            let step = dt.min(t_end - sim.time());
            sim.advance(&mut p, step)?;
            history.push((sim.time() * t_scale, front(&sim, &p)));
        }
        z.push(front(&sim, &p));
    }
    Ok(DamBreak { z, history, seconds: start.elapsed().as_secs_f64() })
}

pub(crate) struct DamBreak {
    pub(crate) z: Vec<f64>,
    pub(crate) history: Vec<(f64, f64)>,
    pub(crate) seconds: f64,
}

/// The study's error: `(max, rms)` relative surge-front error (anim-mpm's, which `anim run`
/// reports too).
pub(crate) fn front_errors(z: &[f64]) -> (f64, f64) {
    scenes::surge_front_errors(z)
}

/// The time-origin shift `dT` (the experiment's gate takes time to open, so its clock starts
/// early) minimising the rms error of `Z_sim(T - dT)` against the table, `dT` in [0, 0.6]; returns
/// `(dT, max error, rms error)`.
pub(crate) fn shifted_errors(history: &[(f64, f64)]) -> (f64, f64, f64) {
    let at = |t: f64| -> f64 {
        if t <= 0.0 {
            return history[0].1;
        }
        let i = history.partition_point(|(ti, _)| *ti < t).clamp(1, history.len() - 1);
        let ((t0, z0), (t1, z1)) = (history[i - 1], history[i]);
        if t1 > t0 { z0 + (z1 - z0) * (t - t0) / (t1 - t0) } else { z1 }
    };
    let mut best = (0.0, f64::INFINITY, f64::INFINITY);
    for k in 0..=60 {
        let shift = k as f64 * 0.01;
        let z: Vec<f64> = MARTIN_MOYCE.iter().map(|(t, _)| at(t - shift)).collect();
        let (max, rms) = front_errors(&z);
        if rms < best.2 {
            best = (shift, max, rms);
        }
    }
    best
}

fn dam_break_case(ctx: &Ctx) -> Vec<Check> {
    let runs: &[(usize, Transfer, Kernel)] = if ctx.quick {
        &[(96, Transfer::Mls, Kernel::Quadratic)]
    } else {
        &[
            (128, Transfer::Mls, Kernel::Quadratic),
            (128, Transfer::Apic, Kernel::Quadratic),
            (128, Transfer::Mls, Kernel::Cubic),
            (256, Transfer::Mls, Kernel::Quadratic),
        ]
    };
    let mut checks = vec![];
    for &(n, transfer, kernel) in runs {
        let (max, rms, shifted, detail) = match dam_break(n, 2, transfer, kernel) {
            Ok(r) => {
                let (m, r2) = front_errors(&r.z);
                let d = r.z.iter().map(|v| fmt_num(*v)).collect::<Vec<_>>().join(" ");
                (m, r2, shifted_errors(&r.history), d)
            }
            Err(e) => (f64::NAN, f64::NAN, (f64::NAN, f64::NAN, f64::NAN), e.to_string()),
        };
        let case = format!("2D dam break a = 0.2 m, {n}^2, 2x2 ppc, {transfer:?} {kernel:?}; Z = {detail}");
        let source = "Martin & Moyce (1952) tables 2 and 6 (REFERENCES.md)";
        checks.push(Check {
            crate_name: CRATE,
            case: case.clone(),
            metric: "max relative surge-front error over T = 0.41..3.33".into(),
            measured: max,
            reference: 0.0,
            tolerance: 0.10,
            judge: Judge::AtMost,
            source,
        });
        checks.push(Check {
            crate_name: CRATE,
            case: case.clone(),
            metric: "rms relative surge-front error".into(),
            measured: rms,
            reference: 0.0,
            tolerance: 0.10,
            judge: Judge::AtMost,
            source,
        });
        checks.push(Check {
            crate_name: CRATE,
            case,
            metric: format!(
                "max relative error with the time origin shifted by the best-fit dT = {} (gate opening; rms {})",
                fmt_num(shifted.0),
                fmt_num(shifted.2)
            ),
            measured: shifted.1,
            reference: 0.0,
            tolerance: 0.10,
            judge: Judge::AtMost,
            source: "Martin & Moyce (1952); time-origin shift as in Lethe's dam-break example (REFERENCES.md)",
        });
    }
    checks
}

fn dam_break_study(ctx: &Ctx) -> StudyResult {
    let resolutions: &[usize] = if ctx.quick { &[32, 48, 64] } else { &[32, 48, 64, 96, 128, 192] };
    let mut series = vec![];
    let variants: [(&str, Transfer, Kernel, usize); 5] = [
        ("MLS-MPM quadratic, 2x2 ppc", Transfer::Mls, Kernel::Quadratic, 2),
        ("MLS-MPM cubic, 2x2 ppc", Transfer::Mls, Kernel::Cubic, 2),
        ("APIC quadratic, 2x2 ppc", Transfer::Apic, Kernel::Quadratic, 2),
        ("APIC cubic, 2x2 ppc", Transfer::Apic, Kernel::Cubic, 2),
        ("MLS-MPM quadratic, 3x3 ppc", Transfer::Mls, Kernel::Quadratic, 3),
    ];
    for (label, transfer, kernel, ppc) in variants {
        let mut points = vec![];
        for &n in resolutions {
            if let Ok(r) = dam_break(n, ppc, transfer, kernel) {
                let (_, rms) = front_errors(&r.z);
                points.push(Point { param: n as f64, seconds: r.seconds, error: rms });
            }
        }
        series.push(Series { label: label.into(), points });
    }
    StudyResult {
        title: "MPM 2D dam break: surge front vs Martin & Moyce (1952)".into(),
        slug: "mpm_dam_break".into(),
        error_label: "rms relative surge-front error".into(),
        param_label: "grid cells per axis".into(),
        series,
    }
}

// ---------------------------------------------------------------------------------------------
// Hard cases.

fn high_cfl(_ctx: &Ctx) -> Outcome {
    let run = || -> Result<String, MpmError> {
        let mut params = MpmParams::with_resolution(64);
        params.gravity = [0.0; 3];
        let h = params.h();
        let mut sim = MpmSimulation::<2>::new(params, vec![Material::Elastic(Elastic::default())])?;
        let mut p = Particles::<2>::new();
        fill(&mut p, h, 2, [0.05, 0.4], [0.15, 0.5], 0, 1000.0, [40.0, 0.0], |_| true)?;
        let width = |p: &Particles<2>| {
            p.x.chunks_exact(2).map(|c| c[0]).fold(f32::MIN, f32::max)
                - p.x.chunks_exact(2).map(|c| c[0]).fold(f32::MAX, f32::min)
        };
        let w0 = width(&p);
        let mut max_sub = 0;
        let mut max_cfl: f64 = 0.0;
        for _ in 0..8 {
            let s = sim.advance(&mut p, 2e-3)?;
            max_sub = max_sub.max(s.substeps);
            max_cfl = max_cfl.max(s.cfl);
        }
        Ok(format!(
            "40 m/s block at dt = 2 ms: CFL {max_cfl:.2} per step, handled with up to {max_sub} substeps; particle span after 0.64 m of flight {:.6} m, at start {w0:.6} m",
            width(&p)
        ))
    };
    match run() {
        Ok(s) => Outcome::Stable(s),
        Err(e @ MpmError::NonFinite { .. }) => Outcome::Diverged(e.to_string()),
        Err(e) => Outcome::Rejected(e.to_string()),
    }
}

fn wall_impact(_ctx: &Ctx) -> Outcome {
    let run = || -> Result<String, MpmError> {
        let mut params = MpmParams::with_resolution(64);
        params.gravity = [0.0; 3];
        let h = params.h();
        let mut sim = MpmSimulation::<2>::new(params, vec![Material::Elastic(Elastic::default())])?;
        let mut p = Particles::<2>::new();
        fill(&mut p, h, 2, [0.1, 0.4], [0.2, 0.5], 0, 1000.0, [40.0, 0.0], |_| true)?;
        for _ in 0..40 {
            sim.advance(&mut p, 2e-3)?;
        }
        Ok("survived".into())
    };
    match run() {
        Ok(s) => Outcome::Stable(s),
        Err(e @ MpmError::NonFinite { .. }) => Outcome::Diverged(e.to_string()),
        Err(e) => Outcome::Rejected(e.to_string()),
    }
}

fn leaving_domain(_ctx: &Ctx) -> Outcome {
    let run = || -> Result<String, MpmError> {
        let mut text = vec![];
        for policy in [OutOfDomain::Clamp, OutOfDomain::Remove] {
            let mut params = MpmParams::with_resolution(32);
            params.gravity = [0.0; 3];
            params.out_of_domain = policy;
            params.cfl = f64::INFINITY;
            let soft = Material::Elastic(Elastic { young: 1e-3, ..Elastic::default() });
            let mut sim = MpmSimulation::<2>::new(params, vec![soft])?;
            let mut p = Particles::<2>::new();
            for k in 0..6 {
                let v = if k % 2 == 0 { [300.0, -100.0] } else { [-300.0, 250.0] };
                p.push([0.5, 0.2 + 0.12 * k as f32], v, 1e-3, 1e-3, 0)?;
            }
            let (mut out, mut removed) = (0, 0);
            for _ in 0..5 {
                let s = sim.advance(&mut p, 2e-3)?;
                out += s.out_of_domain;
                removed += s.removed;
            }
            let (lo, hi) = sim.params().particle_range();
            if !p.x.iter().all(|&x| f64::from(x) >= lo && f64::from(x) <= hi) {
                return Ok(format!("{policy:?}: a particle is outside the range"));
            }
            text.push(format!("{policy:?}: {out} exits counted, {removed} removed, {} left", p.len()));
        }
        Ok(text.join("; "))
    };
    match run() {
        Ok(s) if s.contains("outside") => Outcome::Diverged(s),
        Ok(s) => Outcome::Stable(s),
        Err(e @ MpmError::NonFinite { .. }) => Outcome::Diverged(e.to_string()),
        Err(e) => Outcome::Rejected(e.to_string()),
    }
}

fn snow_compression(ctx: &Ctx) -> Outcome {
    let run = || -> Result<String, MpmError> {
        // A sticky piston moves down at 1 m/s onto a snow block on the floor, crushing it to a
        // third of its height.
        let mut params = MpmParams::with_resolution(64);
        params.wall = Boundary::Sticky;
        params.colliders.push(Collider {
            shape: Shape::Box { center: [0.5, 0.55, 0.0], half_extents: [0.4, 0.05, 0.0] },
            velocity: [0.0, -1.0, 0.0],
            boundary: Boundary::Sticky,
        });
        let h = params.h();
        let mut sim = MpmSimulation::<2>::new(params, vec![Material::Snow(Snow::default())])?;
        let mut p = Particles::<2>::new();
        fill(&mut p, h, 2, [0.35, 3.0 * h], [0.65, 0.45], 0, 400.0, [0.0; 2], |_| true)?;
        let steps = if ctx.quick { 250 } else { 300 };
        let mut max_sub = 0;
        for _ in 0..steps {
            let s = sim.advance(&mut p, 1e-3)?;
            max_sub = max_sub.max(s.substeps);
        }
        let jp_min = p.plastic.iter().copied().fold(f32::INFINITY, f32::min);
        let hard = (10.0 * (1.0 - f64::from(jp_min))).exp();
        Ok(format!(
            "piston travel {:.2} m: min J_P {jp_min:.3} (hardening x{hard:.1}), up to {max_sub} substeps (elastic-wave CFL)",
            steps as f64 * 1e-3
        ))
    };
    match run() {
        Ok(s) => Outcome::Stable(s),
        Err(e @ MpmError::NonFinite { .. }) => Outcome::Diverged(e.to_string()),
        Err(e) => Outcome::Rejected(e.to_string()),
    }
}

fn zero_mass_nodes(_ctx: &Ctx) -> Outcome {
    let run = || -> Result<String, MpmError> {
        // Isolated particles 3 cells apart leave massless nodes between their stencils; a block
        // with holes does the same inside matter.
        let mut params = MpmParams::with_resolution(64);
        params.gravity = [0.0, -9.81, 0.0];
        let h = params.h() as f32;
        let mut sim = MpmSimulation::<3>::new(params, vec![Material::Fluid(Fluid::default())])?;
        let mut p = Particles::<3>::new();
        for i in 0..8 {
            for j in 0..8 {
                p.push(
                    [0.3 + 3.0 * h * i as f32, 0.5, 0.3 + 3.0 * h * j as f32],
                    [0.0, 0.0, 1.0],
                    1e-3,
                    1e-6,
                    0,
                )?;
            }
        }
        for _ in 0..100 {
            sim.advance(&mut p, 1e-3)?;
        }
        let zero = sim.grid_nodes().count();
        Ok(format!(
            "{} lone particles, 100 steps: finite; {zero} nodes with mass in {} allocated",
            p.len(),
            sim.stats().grid_nodes
        ))
    };
    match run() {
        Ok(s) => Outcome::Stable(s),
        Err(e @ MpmError::NonFinite { .. }) => Outcome::Diverged(e.to_string()),
        Err(e) => Outcome::Rejected(e.to_string()),
    }
}

fn divergence(_ctx: &Ctx) -> Outcome {
    let run = || -> Result<String, MpmError> {
        let mut sim =
            MpmSimulation::<2>::new(MpmParams::with_resolution(32), vec![Material::Fluid(Fluid::default())])?;
        let mut p = cloud::<2>(100, 5);
        sim.advance(&mut p, 1e-4)?;
        for c in &mut p.f[40..44] {
            *c = 1e30;
        }
        sim.advance(&mut p, 1e-4)?;
        Ok("no divergence detected".into())
    };
    match run() {
        Ok(s) => Outcome::Stable(s),
        Err(e @ MpmError::NonFinite { .. }) => Outcome::Diverged(e.to_string()),
        Err(e) => Outcome::Rejected(e.to_string()),
    }
}

fn invalid_input(_ctx: &Ctx) -> Outcome {
    let mut errors = vec![];
    let fluid = || vec![Material::Fluid(Fluid::default())];
    let mut params = MpmParams::with_resolution(32);
    params.cfl = -1.0;
    if let Err(e) = MpmSimulation::<2>::new(params, fluid()) {
        errors.push(e.to_string());
    }
    if let Err(e) = MpmSimulation::<3>::new(
        MpmParams::with_resolution(32),
        vec![Material::Snow(Snow { theta_c: 2.0, ..Snow::default() })],
    ) {
        errors.push(e.to_string());
    }
    if let Ok(mut sim) = MpmSimulation::<2>::new(MpmParams::with_resolution(32), fluid()) {
        let mut p = Particles::<2>::new();
        if p.push([0.5, 0.5], [0.0; 2], 1.0, 1.0, 0).is_ok() {
            p.x[1] = 5.0;
            if let Err(e) = sim.advance(&mut p, 1e-3) {
                errors.push(e.to_string());
            }
        }
    }
    if errors.len() == 3 {
        Outcome::Rejected(errors.join(" | "))
    } else {
        Outcome::Stable(format!("accepted bad input: {errors:?}"))
    }
}

// ---------------------------------------------------------------------------------------------
// Peer benchmark.

/// One timed run of a benchmark scene.
pub struct PeerRun {
    pub particles: usize,
    pub per_step_s: f64,
    pub mean_y: f64,
}

/// Times `steps` steps of `scenes::benchmark_2d(n)` (dim 2) or `benchmark_3d(n)` (dim 3) on a
/// pool of `threads`, after 50 warm-up steps; median over `repeats`.
pub fn peer_benchmark(
    dim: usize,
    n: usize,
    steps: usize,
    repeats: usize,
    threads: usize,
) -> Result<PeerRun, String> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| e.to_string())?;
    pool.install(|| {
        fn go<const D: usize>(
            mut s: scenes::Scene<D>,
            steps: usize,
            repeats: usize,
        ) -> Result<PeerRun, String> {
            for _ in 0..50 {
                s.sim.advance(&mut s.state, s.dt).map_err(|e| e.to_string())?;
            }
            let mut times = vec![];
            for _ in 0..repeats {
                let start = std::time::Instant::now();
                for _ in 0..steps {
                    s.sim.advance(&mut s.state, s.dt).map_err(|e| e.to_string())?;
                }
                times.push(start.elapsed().as_secs_f64() / steps as f64);
            }
            times.sort_by(f64::total_cmp);
            let mean_y =
                s.state.x.chunks_exact(D).map(|c| f64::from(c[1])).sum::<f64>() / s.state.len() as f64;
            Ok(PeerRun { particles: s.state.len(), per_step_s: times[times.len() / 2], mean_y })
        }
        if dim == 2 {
            go(scenes::benchmark_2d(n).map_err(|e| e.to_string())?, steps, repeats)
        } else {
            go(scenes::benchmark_3d(n).map_err(|e| e.to_string())?, steps, repeats)
        }
    })
}
