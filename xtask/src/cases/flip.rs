//! anim-flip: the incompressible particle fluid (PIC / FLIP / APIC on a MAC grid). Conformance:
//! fluid volume over 10 s of sloshing, divergence after every projection against the solver
//! tolerance, angular momentum of a rotating disk over the transfers (APIC keeps it, PIC does
//! not), and the 2D dam-break surge front against Martin & Moyce (1952) (the table of
//! [`anim_mpm::cases`]). Hard cases: CFL 10 (large steps split into adaptive substeps) and particles
//! driven into an obstacle (pushed out, counted). Study: the dam break's surge-front error
//! against wall time for PIC, FLIP and APIC and for anim-mpm's weakly compressible fluid, each at
//! several resolutions.

use crate::registry::{
    Check, ConformanceCase, Ctx, Judge, Outcome, Point, Registry, Series, StabilityCase, Study, StudyResult,
    fmt_num,
};
use anim_flip::{
    Contour, FlipError, FlipParams, FlipSimulation, ParticleSurface, Particles, Reseed, SurfaceParams,
    Transfer, scenes,
};
use anim_mpm::cases::{MARTIN_MOYCE, front_errors, shifted_errors};

const CRATE: &str = "anim-flip";

pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "FLIP fluid volume over 10 s",
        run: Box::new(volume),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "FLIP divergence after projection",
        run: Box::new(divergence),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "FLIP rotating disk angular momentum over transfers",
        run: Box::new(angular_momentum),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "FLIP dam break vs Martin & Moyce (1952)",
        run: Box::new(dam_break_case),
    });
    let stable = || Outcome::Stable(String::new());
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "FLIP dam break at CFL 10 (adaptive substeps)",
        expected: stable,
        run: cfl_ten,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "FLIP particles driven into a solid obstacle",
        expected: stable,
        run: into_obstacle,
    });
    r.studies.push(Study {
        crate_name: CRATE,
        name: "PIC/FLIP/APIC and MPM dam break",
        run: dam_break_study,
    });
}

fn outcome(r: Result<String, FlipError>) -> Outcome {
    match r {
        Ok(s) => Outcome::Stable(s),
        Err(e @ FlipError::NonFinite { .. }) => Outcome::Diverged(e.to_string()),
        Err(e) => Outcome::Rejected(e.to_string()),
    }
}

/// A column `a x 2a` (a = 0.25 m) sloshing in a 1 m box for 10 s with volume correction 1 (the
/// projection's target outflow removes a cell's whole excess density in one substep; 0.5, half
/// of it, left the largest change at 1.5-3.4%). Two measures of the fluid volume against their
/// initial values, sampled every 20 ms:
/// - the density estimate `h^2 sum_c min(1, rho_c / 4)` (`FlipSimulation::volume_estimate`):
///   particle mass per cell, capped at the rest density (the gate);
/// - the area enclosed by the particle surface (Zhu & Bridson's level set, `anim_flip::surface`,
///   marching squares on an `h / 2` lattice), full suite only. It counts the space the
///   particles span, so a fluffy, under-dense surface layer raises it (it ends 4-10% above its
///   start while the density estimate ends within 0.2%): it measures sampling quality as much
///   as volume, and is reported rather than tuned.
///
/// Reseeding (`FlipParams::reseed`) is not used: with bounds 2..8 or 3..5 per cell it adds
/// mass in every run (cells under the lower bound from sampling noise are topped up), and the
/// fluid grows until it fills the box (see `anim_flip::reseed`).
///
/// (Without the correction the density estimate falls by about a third at 32^2: particles
/// compressed in the collapse are never spread apart by a divergence-free projection alone.)
///
/// The estimate's largest drop comes at the impacts on the side walls (0.3-1 s), where particles
/// pile up faster than one substep's correction spreads them. Two choices keep it within 1%:
/// particles are advected through the multilinear interpolant of the face velocities
/// ([`anim_flip::Sampling::Linear`]), which sees the walls' zero normal velocity exactly, and PIC
/// runs at CFL 0.5 (at CFL 1 its drop is 1.0-1.1%; APIC and FLIP meet 1% at CFL 1).
/// With the kernel-weighted sampling of earlier versions the drops were APIC 1.26%, PIC 1.29%.
/// A position correction after advection (the same Poisson problem for a displacement that
/// removes the excess density, as Kugelstadt et al. 2019 do) was tried and left out: with linear
/// sampling it cut APIC's drop by 0.02 points and PIC's not at all, for a second pressure solve
/// per substep.
fn volume(ctx: &Ctx) -> Vec<Check> {
    let runs: &[(usize, Transfer, f64, bool)] = if ctx.quick {
        &[(32, Transfer::Flip(0.97), 1.0, false)]
    } else {
        &[
            (32, Transfer::Flip(0.97), 1.0, false),
            (64, Transfer::Flip(0.97), 1.0, false),
            (64, Transfer::Apic, 1.0, false),
            (64, Transfer::Pic, 0.5, false),
        ]
    };
    let mut checks = vec![];
    for &(n, transfer, cfl, reseed) in runs {
        let run = || -> Result<VolumeRun, FlipError> {
            let mut params = FlipParams::<2>::default();
            params.transfer = transfer;
            params.cfl = cfl;
            params.volume_correction = 1.0;
            params.reseed = reseed.then(|| Reseed::around(4));
            let h = 1.0 / n as f64;
            let mut sim = FlipSimulation::<2>::new([n, n], h, params)?;
            let (lo, _) = sim.fluid_box();
            let mut p = Particles::new();
            scenes::fill_box(&mut p, h, 2, lo, [lo[0] + 0.25, lo[1] + 0.5], |_| [0.0; 2]);
            let mut surface = ParticleSurface::<2>::new(SurfaceParams::for_grid(h, 2))?;
            let mut contour = Contour::default();
            let mut area = |p: &Particles<2>| -> Result<f64, FlipError> {
                surface.contour_into(&p.x, &mut contour)?;
                Ok(contour.area())
            };
            let v0 = sim.volume_estimate(&p, 4.0);
            let a0 = area(&p)?;
            let mut out = VolumeRun { v0, a0, particles: (p.len(), p.len()), ..VolumeRun::default() };
            for _ in 0..500 {
                let info = sim.advance(&mut p, 0.02)?;
                out.seeded += info.seeded;
                out.removed += info.removed;
                let v = sim.volume_estimate(&p, 4.0);
                out.density_max = out.density_max.max((v - v0).abs() / v0);
                out.density_end = (v - v0).abs() / v0;
                let a = area(&p)?;
                out.area_max = out.area_max.max((a - a0).abs() / a0);
                out.area_end = (a - a0).abs() / a0;
            }
            out.particles.1 = p.len();
            Ok(out)
        };
        let (r, detail) = match run() {
            Ok(r) => {
                let d = format!(
                    "V0 = {} m^2 (density), {} m^2 (surface){}",
                    fmt_num(r.v0),
                    fmt_num(r.a0),
                    if reseed {
                        format!(
                            ", {} seeded, {} removed, {} -> {} particles",
                            r.seeded, r.removed, r.particles.0, r.particles.1
                        )
                    } else {
                        String::new()
                    }
                );
                (r, d)
            }
            Err(e) => (VolumeRun::failed(), e.to_string()),
        };
        let case = format!(
            "2D column 0.25 x 0.5 m sloshing 10 s, {n}^2, {}, CFL {cfl}, volume correction 1, {}; {detail}",
            transfer.name(),
            if reseed { "reseeding 2..8 per cell" } else { "no reseeding" }
        );
        let source = "incompressibility: volume is conserved";
        for (measure, end, max) in [
            ("density-estimated volume", r.density_end, r.density_max),
            ("surface-enclosed area", r.area_end, r.area_max),
        ] {
            // The surface measure is reported by the full suite only (see above).
            if ctx.quick && measure.starts_with("surface") {
                continue;
            }
            checks.push(Check {
                crate_name: CRATE,
                case: case.clone(),
                metric: format!("relative change of the {measure} at t = 10 s"),
                measured: end,
                reference: 0.0,
                tolerance: 0.01,
                judge: Judge::AtMost,
                source,
            });
            // The acceptance targets this solver does not meet yet (the largest change during
            // the run, the dam-break front's max error) are measured by the full suite only;
            // CI's quick suite gates on what it meets, so that a regression there fails the build.
            if ctx.quick {
                continue;
            }
            checks.push(Check {
                crate_name: CRATE,
                case: case.clone(),
                metric: format!("largest relative change of the {measure} over 10 s (sampled every 20 ms)"),
                measured: max,
                reference: 0.0,
                tolerance: 0.01,
                judge: Judge::AtMost,
                source,
            });
        }
    }
    checks
}

/// What one sloshing run measured.
#[derive(Default)]
struct VolumeRun {
    v0: f64,
    a0: f64,
    density_end: f64,
    density_max: f64,
    area_end: f64,
    area_max: f64,
    seeded: usize,
    removed: usize,
    /// Particle count at the start and the end.
    particles: (usize, usize),
}

impl VolumeRun {
    fn failed() -> Self {
        Self {
            density_end: f64::NAN,
            density_max: f64::NAN,
            area_end: f64::NAN,
            area_max: f64::NAN,
            ..Self::default()
        }
    }
}

/// `max |div u|` after each projection over a dam break, relative to the divergence before it:
/// at most the solver's relative tolerance (the post-projection outflow is the solve residual).
fn divergence(ctx: &Ctx) -> Vec<Check> {
    let mut checks = vec![];
    for tol in [1e-6, 1e-10] {
        let run = || -> Result<(f64, usize), FlipError> {
            let mut params = FlipParams::<2>::default();
            params.tolerance = tol;
            let (mut sim, mut p, _) = scenes::dam_break(64, 0.2, params)?;
            let mut worst: f64 = 0.0;
            let steps = if ctx.quick { 20 } else { 60 };
            let mut subs = 0;
            for _ in 0..steps {
                let info = sim.advance(&mut p, 0.01)?;
                subs += info.substeps;
                worst = worst.max(info.max_divergence / info.max_divergence_before.max(f64::MIN_POSITIVE));
            }
            Ok((worst, subs))
        };
        let (worst, subs) = run().unwrap_or((f64::NAN, 0));
        checks.push(Check {
            crate_name: CRATE,
            case: format!("2D dam break 64 cells/m, MGPCG tolerance {tol:e}, {subs} projections"),
            metric: "max over projections of max|div u| after / before".into(),
            measured: worst,
            reference: 0.0,
            tolerance: tol * 1.0001,
            judge: Judge::AtMost,
            source: "discrete identity: outflow after projection = pressure residual",
        });
    }
    checks
}

/// A disk (r = 0.3 m) in rigid rotation at 2 rad/s, 20 P2G/G2P round trips with no forces.
fn angular_momentum(_ctx: &Ctx) -> Vec<Check> {
    let run = |transfer| -> Result<f64, FlipError> {
        let mut params = FlipParams::<2>::default();
        params.transfer = transfer;
        let (mut sim, mut p) = scenes::rotating_disk(64, 0.3, 2.0, params)?;
        let l0 = p.angular_momentum([0.5, 0.5])[2];
        for _ in 0..20 {
            sim.transfer_round_trip(&mut p);
        }
        Ok((p.angular_momentum([0.5, 0.5])[2] - l0) / l0)
    };
    let source = "APIC (Jiang et al. 2015; seed 5.3.1): exact for affine fields";
    let apic = run(Transfer::Apic).unwrap_or(f64::NAN);
    let pic = run(Transfer::Pic).unwrap_or(f64::NAN);
    vec![
        Check {
            crate_name: CRATE,
            case: "rotating disk r = 0.3 m, 64^2, 20 round trips, APIC".into(),
            metric: "|relative angular momentum change|".into(),
            measured: apic.abs(),
            reference: 0.0,
            tolerance: 1e-12,
            judge: Judge::AtMost,
            source,
        },
        Check {
            crate_name: CRATE,
            case: "rotating disk r = 0.3 m, 64^2, 20 round trips, PIC".into(),
            metric: "relative angular momentum lost (PIC is dissipative)".into(),
            measured: -pic,
            reference: 0.0,
            tolerance: 0.01,
            judge: Judge::AtLeast,
            source,
        },
    ]
}

/// Surge front `Z` at the table's times, the history `(T, Z)` of every step, and the wall time.
type SurgeFront = (Vec<f64>, Vec<(f64, f64)>, f64);

/// Surge front `Z = (x_front - x0) / a` at the table's `T = t sqrt(2 g / a)`, and the history.
fn dam_break(n: usize, transfer: Transfer, no_slip: bool) -> Result<SurgeFront, FlipError> {
    let a = 0.2;
    let mut params = FlipParams::<2>::default();
    params.transfer = transfer;
    params.no_slip = no_slip;
    let (mut sim, mut p, x0) = scenes::dam_break(n, a, params)?;
    let t_scale = (2.0 * 9.81 / a).sqrt();
    let front = |p: &Particles<2>| (p.x.iter().map(|x| x[0]).fold(f64::MIN, f64::max) - x0) / a;
    let start = std::time::Instant::now();
    let mut z = Vec::with_capacity(MARTIN_MOYCE.len());
    let mut history = vec![(0.0, front(&p))];
    let dt: f64 = 2e-3;
    for &(t_star, _) in &MARTIN_MOYCE {
        let t_end = t_star / t_scale;
        while sim.time() < t_end - 1e-12 {
            let step = dt.min(t_end - sim.time());
            sim.advance(&mut p, step)?;
            history.push((sim.time() * t_scale, front(&p)));
        }
        z.push(front(&p));
    }
    Ok((z, history, start.elapsed().as_secs_f64()))
}

/// The 2D dam break against Martin & Moyce's surge front: the rms error (gated in CI), and in
/// the full suite the largest error over the table, plain and with a fitted time origin.
///
/// The largest error within 5% is not met, and grid refinement does not approach it. The
/// converged inviscid solution runs ahead of the experiment: with free-slip walls FLIP 0.97 has
/// max errors of 12.9%, 17.1% and 19.0% at 80, 120 and 160 cells per metre (APIC 14.0%, 17.5%
/// and 19.0%), rms 10-13%. A time-origin shift for the gate's opening does not close the gap
/// either: the best shift leaves 7.2-7.5% at every one of those resolutions, because the
/// simulated front also moves faster late in the run (`dZ/dT` about 1.56 against the
/// experiment's 1.34 over `T = 2.83..3.33`). No-slip walls slow the front by a drag of one cell's
/// width, which shrinks with the cell: FLIP 0.97 has 6.0% at 80 cells per metre but 12.8% at 160.
/// anim-mpm's weakly compressible fluid (sticky walls) converges to the same lead (rms 5.6% at 128,
/// 8.5% at 192 cells per axis, [`anim_mpm::cases`]). What slows the experiment's front (the gate,
/// friction on the floor and the side walls of a narrow tank, an aerated tip) is not modelled,
/// and the table's readings come in steps of 0.11 in `Z` (a quarter inch), 10% of the first
/// reading. `examples/dam_break.rs` in anim-flip prints these runs.
fn dam_break_case(ctx: &Ctx) -> Vec<Check> {
    let runs: &[(usize, Transfer, bool)] = if ctx.quick {
        &[(80, Transfer::Flip(0.97), true)]
    } else {
        &[
            (80, Transfer::Flip(0.97), true),
            (80, Transfer::Flip(0.97), false),
            (80, Transfer::Apic, true),
            (80, Transfer::Pic, true),
            (160, Transfer::Flip(0.97), true),
            (160, Transfer::Flip(0.97), false),
        ]
    };
    let mut checks = vec![];
    for &(n, transfer, no_slip) in runs {
        let (max, rms, shifted, detail) = match dam_break(n, transfer, no_slip) {
            Ok((z, history, secs)) => {
                let (m, r) = front_errors(&z);
                let d = z.iter().map(|v| fmt_num(*v)).collect::<Vec<_>>().join(" ");
                (m, r, shifted_errors(&history), format!("{d}; {secs:.2} s"))
            }
            Err(e) => (f64::NAN, f64::NAN, (f64::NAN, f64::NAN, f64::NAN), e.to_string()),
        };
        let walls = if no_slip { "no-slip" } else { "free-slip" };
        let case = format!(
            "2D dam break a = 0.2 m, {n} cells/m, 2x2 ppc, {}, {walls} walls; Z = {detail}",
            transfer.name()
        );
        let source = "Martin & Moyce (1952) tables 2 and 6 (REFERENCES.md)";
        checks.push(Check {
            crate_name: CRATE,
            case: case.clone(),
            metric: "rms relative surge-front error".into(),
            measured: rms,
            reference: 0.0,
            tolerance: 0.05,
            judge: Judge::AtMost,
            source,
        });
        // Max errors: full suite only (see `volume`).
        if ctx.quick {
            continue;
        }
        checks.push(Check {
            crate_name: CRATE,
            case: case.clone(),
            metric: "max relative surge-front error over T = 0.41..3.33".into(),
            measured: max,
            reference: 0.0,
            tolerance: 0.05,
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
            tolerance: 0.05,
            judge: Judge::AtMost,
            source: "Martin & Moyce (1952); time-origin shift as in Lethe's dam-break example (REFERENCES.md)",
        });
    }
    checks
}

/// Slug of [`dam_break_study`].
pub(crate) const DAM_BREAK_SLUG: &str = "flip_dam_break";

/// Tolerances the dam-break study adds to the report's cheapest-method table: 5 %, the accuracy
/// the question "which method reaches 5 % cheapest?" asks about.
pub(crate) const DAM_BREAK_TOLERANCES: &[f64] = &[5e-2];

/// The 2D dam break of [`dam_break_case`] (a = 0.2 m, no-slip walls, 2x2 particles per cell,
/// steps of 2 ms split into CFL-1 substeps) with PIC, FLIP 0.97 and APIC, and the same column
/// in anim-mpm's weakly compressible fluid (the scene of [`anim_mpm::cases`]'s study: sticky walls,
/// 2x2 particles per cell, c = 50 m/s), at several grid resolutions. Error: the rms relative
/// surge-front error against Martin & Moyce (1952), the gated measure of both conformance cases;
/// time: one run to T = 3.33 (t = 0.34 s).
fn dam_break_study(ctx: &Ctx) -> StudyResult {
    let flip_cells: &[usize] = if ctx.quick { &[32, 48] } else { &[24, 32, 48, 64, 80, 112, 160] };
    let mpm_cells: &[usize] = if ctx.quick { &[32, 48, 64] } else { &[32, 48, 64, 96, 128, 192] };
    // A run that fails shows in the table with a NaN error (and stays off the plot).
    let failed = |n: usize| Point { param: n as f64, seconds: f64::NAN, error: f64::NAN };
    let mut series = vec![];
    for transfer in [Transfer::Pic, Transfer::Flip(0.97), Transfer::Apic] {
        let points = flip_cells
            .iter()
            .map(|&n| match dam_break(n, transfer, true) {
                Ok((z, _, seconds)) => Point { param: n as f64, seconds, error: front_errors(&z).1 },
                Err(_) => failed(n),
            })
            .collect();
        series.push(Series { label: format!("{} (anim-flip)", transfer.name()), points });
    }
    for (label, transfer) in [
        ("MPM fluid, MLS-MPM (anim-mpm)", anim_mpm::Transfer::Mls),
        ("MPM fluid, APIC (anim-mpm)", anim_mpm::Transfer::Apic),
    ] {
        let points = mpm_cells
            .iter()
            .map(|&n| match anim_mpm::cases::dam_break(n, 2, transfer, anim_mpm::Kernel::Quadratic) {
                Ok(r) => Point { param: n as f64, seconds: r.seconds, error: front_errors(&r.z).1 },
                Err(_) => failed(n),
            })
            .collect();
        series.push(Series { label: label.into(), points });
    }
    StudyResult {
        title: "2D dam break: incompressible PIC/FLIP/APIC vs weakly compressible MPM, surge front vs Martin & Moyce (1952)"
            .into(),
        slug: DAM_BREAK_SLUG.into(),
        error_label: "rms relative surge-front error over T = 0.41..3.33".into(),
        param_label: "grid cells per metre".into(),
        series,
    }
}

/// The dam break advanced in 0.05 s steps with `cfl = 10`: each step is split into substeps that
/// move no particle more than 10 cells; the particles must stay finite and inside the box.
fn cfl_ten(_ctx: &Ctx) -> Outcome {
    outcome((|| {
        let mut params = FlipParams::<2>::default();
        params.cfl = 10.0;
        params.transfer = Transfer::Flip(0.97);
        let (mut sim, mut p, _) = scenes::dam_break(64, 0.2, params)?;
        let v0 = sim.volume_estimate(&p, 4.0);
        let (mut subs, mut max_sub, mut pushed, mut max_div) = (0, 0, 0, 0.0f64);
        for _ in 0..20 {
            let info = sim.advance(&mut p, 0.05)?;
            subs += info.substeps;
            max_sub = max_sub.max(info.substeps);
            pushed += info.pushed_out;
            max_div = max_div.max(info.max_divergence);
        }
        let (lo, hi) = sim.fluid_box();
        let inside = p.x.iter().all(|x| (0..2).all(|a| x[a] >= lo[a] && x[a] <= hi[a]));
        let v1 = sim.volume_estimate(&p, 4.0);
        Ok(format!(
            "1 s in 20 steps of 50 ms: {subs} substeps (at most {max_sub} per step), {pushed} wall push-outs, max |div u| after projection {} 1/s, all particles inside: {inside}, volume change {:.2}%, max speed {:.2} m/s",
            fmt_num(max_div),
            100.0 * (v1 - v0) / v0,
            p.max_speed()
        ))
    })())
}

/// A 0.15 x 0.2 m slab at 5 m/s (no gravity) driven into a square obstacle: particles that enter
/// solid cells are pushed back out and counted; none may remain inside.
fn into_obstacle(_ctx: &Ctx) -> Outcome {
    outcome((|| {
        let mut params = FlipParams::<2>::default();
        params.gravity = [0.0; 2];
        params.cfl = 2.0;
        let n = 64;
        let h = 1.0 / n as f64;
        let mut sim = FlipSimulation::<2>::new([n, n], h, params)?;
        sim.set_solid(|x| (x[0] - 0.6).abs() < 0.1 && (x[1] - 0.5).abs() < 0.1);
        let mut p = Particles::new();
        scenes::fill_box(&mut p, h, 2, [0.2, 0.4], [0.35, 0.6], |_| [5.0, 0.0]);
        let mut pushed = 0;
        for _ in 0..20 {
            pushed += sim.advance(&mut p, 0.01)?.pushed_out;
        }
        let inside =
            p.x.iter().filter(|x| sim.solid()[(x[0] / h) as usize + n * (x[1] / h) as usize]).count();
        if inside > 0 {
            return Ok(format!("{inside} particles left inside solid cells"));
        }
        Ok(format!(
            "{pushed} push-outs over 0.2 s, no particle left in a solid cell, max speed {:.2} m/s",
            p.max_speed()
        ))
    })())
}
