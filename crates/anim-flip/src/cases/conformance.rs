//! Fluid volume over 10 s of sloshing, divergence after every projection against the solver
//! tolerance, and the angular momentum of a rotating disk over the transfers (APIC keeps it, PIC
//! does not).

use super::CRATE;
use crate::{
    Contour, FlipError, FlipParams, FlipSimulation, ParticleSurface, Particles, Reseed, SurfaceParams,
    Transfer, scenes,
};
use anim_core::cases::{Check, Ctx, Judge, fmt_num};

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
pub(super) fn volume(ctx: &Ctx) -> Vec<Check> {
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
            let params = FlipParams::<2> {
                transfer,
                cfl,
                volume_correction: 1.0,
                reseed: reseed.then(|| Reseed::around(4)),
                ..FlipParams::default()
            };
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
pub(super) fn divergence(ctx: &Ctx) -> Vec<Check> {
    let mut checks = vec![];
    for tol in [1e-6, 1e-10] {
        let run = || -> Result<(f64, usize), FlipError> {
            let params = FlipParams::<2> { tolerance: tol, ..FlipParams::default() };
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
pub(super) fn angular_momentum(_ctx: &Ctx) -> Vec<Check> {
    let run = |transfer| -> Result<f64, FlipError> {
        let params = FlipParams::<2> { transfer, ..FlipParams::default() };
        let (mut sim, mut p) = scenes::rotating_disk(64, 0.3, 2.0, params)?;
        let l0 = p.angular_momentum([0.5, 0.5])[2];
        for _ in 0..20 {
            sim.transfer_round_trip(&mut p);
        }
        Ok((p.angular_momentum([0.5, 0.5])[2] - l0) / l0)
    };
    let source = "APIC (Jiang et al. 2015): exact for affine fields";
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
