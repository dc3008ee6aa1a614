//! Divergence after projection per pressure solver, Taylor-Green decay per advection scheme and
//! splitting, and the MAC solver's determinism across thread counts.

use super::check;
use crate::FluidError;
use crate::advection::{Advection, Splitting};
use crate::mac::{MacFluid, MacParams, MacState};
use crate::pressure::PressureMethod;
use crate::scenes;
use anim_core::cases::{Check, Ctx, Judge};
use std::f64::consts::PI;
use std::time::Instant;

// ---------------------------------------------------------------- divergence

/// A 2D or 3D box with a spherical obstacle and a smooth, divergent velocity.
pub(super) fn divergent_field(
    n: usize,
    dim: usize,
    method: PressureMethod,
    tol: f64,
    max_it: usize,
) -> Result<(MacFluid, MacState), FluidError> {
    let dims = if dim == 2 { [n, n, 1] } else { [n, n, n] };
    let params = MacParams {
        pressure: method,
        pressure_tolerance: tol,
        pressure_max_iterations: max_it,
        require_convergence: false,
        ..MacParams::default()
    };
    let (mut f, mut s) = MacFluid::new(dims, dim, 1.0 / n as f64, params)?;
    f.set_solid(|p| {
        let dz = if dim == 3 { p[2] - 0.5 } else { 0.0 };
        (p[0] - 0.6).powi(2) + (p[1] - 0.45).powi(2) + dz * dz < 0.04
    })?;
    f.set_velocity(&mut s, |p| {
        [(3.0 * p[1]).sin() + (5.0 * p[0] * p[2]).cos(), (2.0 * p[0]).cos() * p[1], (4.0 * p[1]).sin() * p[0]]
    });
    Ok((f, s))
}

/// Sweeps damped Jacobi needs on an `n^dim` box with solid walls to bring the smoothest
/// error mode down by `tol` (see [`crate::pressure::JACOBI_WEIGHT`]): `ln(1/tol) 2 dim /
/// (w lambda)` with `lambda = 4 sin^2(pi / (2 n))`, times 1.5 for the obstacle and the mode's
/// share of the initial residual. 2D, 1e-6: the estimate is 115,000 at N = 128 and 459,000 at
/// N = 256 (the box with a sphere took 115,190 and 428,490 sweeps); the cap 172,000 and 688,000.
pub(super) fn jacobi_sweeps_needed(n: usize, dim: usize, tol: f64) -> usize {
    let lambda = 4.0 * (PI / (2.0 * n as f64)).sin().powi(2);
    let rate = crate::pressure::JACOBI_WEIGHT * lambda / (2.0 * dim as f64);
    (1.5 * (1.0 / tol).ln() / rate).ceil() as usize
}

pub(super) fn divergence(ctx: &Ctx) -> Vec<Check> {
    let tol = 1e-6;
    let mut out = Vec::new();
    let cases: &[(usize, usize)] =
        if ctx.quick { &[(2, 64), (3, 16)] } else { &[(2, 128), (2, 256), (3, 32)] };
    for &(dim, n) in cases {
        // Jacobi's sweep count grows as N^2 (688,000 at 2D N = 256); every solver gets that cap.
        let cap = jacobi_sweeps_needed(n, dim, tol).max(200_000);
        for method in PressureMethod::ALL {
            let res = divergent_field(n, dim, method, tol, cap).and_then(|(mut f, mut s)| {
                let before = f.max_divergence(&s);
                let t = Instant::now();
                let info = f.advance(&mut s, 1e-3)?;
                Ok((info, before, t.elapsed().as_secs_f64()))
            });
            let (measured, metric) = match res {
                Ok((info, before, secs)) => (
                    info.pressure.residual,
                    format!(
                        "{dim}D N = {n}, {}: relative residual ({} its, {:.3} s; max|div u| {:.2e} -> {:.2e})",
                        method.name(),
                        info.pressure.iterations,
                        secs,
                        before,
                        info.divergence
                    ),
                ),
                Err(e) => (f64::INFINITY, format!("{dim}D N = {n}, {}: {e}", method.name())),
            };
            out.push(check(
                "divergence after projection (sphere obstacle)",
                metric,
                measured,
                0.0,
                tol,
                Judge::AtMost,
                "solver tolerance 1e-6",
            ));
        }
    }
    out
}

// ---------------------------------------------------------------- Taylor-Green

/// Taylor-Green vortex in the unit box with free-slip walls, `u = sin(pi x) cos(pi y)`,
/// `v = -cos(pi x) sin(pi y)`; returns the amplitude after `t_end` and the analytic
/// `exp(-2 nu pi^2 t_end)`.
pub(super) fn taylor_green_run(
    n: usize,
    advection: Advection,
    splitting: Splitting,
    nu: f64,
    t_end: f64,
    cfl: f64,
) -> Result<(f64, f64), FluidError> {
    let r = scenes::taylor_green_decay(n, advection, splitting, nu, t_end, cfl)?;
    Ok((r.amplitude, r.exact))
}

pub(super) fn taylor_green(ctx: &Ctx) -> Vec<Check> {
    let (nu, t_end) = (0.01, 1.0);
    // The full suite runs N = 128: every scheme under advection-reflection at CFL 2, and the
    // three higher-order schemes under advect-then-project at CFL 0.5. Linear semi-Lagrangian
    // advection under advect-then-project is not a check: its numerical viscosity plus the
    // first-order splitting error leave it at 2.66-2.95% for every CFL from 0.25 to 1.5 (table in
    // docs/guides/anim-fluid.md). CI runs N = 64: MacCormack advect-then-project at CFL 0.5 and
    // linear reflection at CFL 4.
    let runs: Vec<(usize, Advection, Splitting, f64)> = if ctx.quick {
        vec![
            (64, Advection::MacCormack, Splitting::AdvectProject, 0.5),
            (64, Advection::Linear, Splitting::Reflection, 4.0),
        ]
    } else {
        let mut runs: Vec<_> = Advection::ALL.iter().map(|&a| (128, a, Splitting::Reflection, 2.0)).collect();
        runs.extend(
            [Advection::MonotoneCubic, Advection::Bfecc, Advection::MacCormack]
                .map(|a| (128, a, Splitting::AdvectProject, 0.5)),
        );
        runs
    };
    runs.into_iter()
        .map(|(n, scheme, splitting, cfl)| {
            let what = format!("N = {n}, {}, {}, CFL {cfl}", scheme.name(), splitting.name());
            let (measured, metric) = match taylor_green_run(n, scheme, splitting, nu, t_end, cfl) {
                Ok((a, exact)) => (
                    (a / exact - 1.0).abs(),
                    format!("{what}: |A/A_exact - 1| at t = 1 (A = {a:.5}, exact {exact:.5})"),
                ),
                Err(e) => (f64::INFINITY, format!("{what}: {e}")),
            };
            check(
                "Taylor-Green decay, nu = 0.01",
                metric,
                measured,
                0.0,
                0.02,
                Judge::AtMost,
                "analytic exp(-2 nu k^2 t), k = pi",
            )
        })
        .collect()
}

// ---------------------------------------------------------------- determinism

pub(super) fn determinism(ctx: &Ctx) -> Vec<Check> {
    let n = if ctx.quick { 12 } else { 20 };
    let run = |threads: usize| -> Vec<u64> {
        let pool = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
            Ok(p) => p,
            Err(_) => return Vec::new(),
        };
        pool.install(|| {
            let Some(Ok(mut scene)) = scenes::by_name("smoke-plume-3d", Some(n)) else { return Vec::new() };
            for _ in 0..5 {
                if scene.step().is_err() {
                    return Vec::new();
                }
            }
            let (d, _) = scene.density();
            let (v, _) = scene.velocity();
            d.iter().map(|x| x.to_bits()).chain(v.iter().flat_map(|c| c.map(f64::to_bits))).collect()
        })
    };
    let one = run(1);
    [2, 4]
        .into_iter()
        .map(|t| {
            let other = run(t);
            let differing = if one.is_empty() || other.len() != one.len() {
                f64::INFINITY
            } else {
                one.iter().zip(&other).filter(|(a, b)| a != b).count() as f64
            };
            check(
                "3D smoke plume, 5 steps",
                format!("values differing, 1 vs {t} threads"),
                differing,
                0.0,
                0.0,
                Judge::AtMost,
                "bitwise determinism",
            )
        })
        .collect()
}
