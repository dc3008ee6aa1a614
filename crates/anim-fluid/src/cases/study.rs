//! Work-precision studies: the pressure solvers' divergence residual and Ghia error against
//! wall time, and the advection schemes and splittings on the Taylor-Green vortex.

use super::conformance::{divergent_field, taylor_green_run};
use super::ghia::{cavity_run, ghia_errors};
use crate::advection::{Advection, Splitting};
use crate::pressure::PressureMethod;
use anim_core::cases::{Ctx, Frontier, Point, Series, StudyResult};
use std::time::Instant;

/// A solver's next point is not run when it is known to take longer than this (its previous,
/// looser point did) and a solver already measured at the same N beats it in both time and
/// error; nor are the series' tighter points after it. Without this rule, red-black
/// Gauss-Seidel at N = 512 spent 164 s per run reaching 1e-3, a residual multigrid-preconditioned
/// CG reaches below 1e-8 in 0.4 s, and the study took 36 minutes.
const SKIP_BEATEN_ABOVE: f64 = 2.0;

pub(super) fn study_divergence(ctx: &Ctx) -> StudyResult {
    let sizes: &[usize] = if ctx.quick { &[64, 128] } else { &[64, 128, 256, 512] };
    let tols = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-8];
    // The fast solvers run first at each N, so that the slow ones' beaten points are known; the
    // series are listed in the order of `PressureMethod::ALL`, each method's sizes ascending.
    let mut found = Vec::new();
    for (k, &n) in sizes.iter().enumerate() {
        let mut frontier = Frontier::default();
        for (m, method) in PressureMethod::ALL.into_iter().enumerate().rev() {
            let mut points: Vec<Point> = Vec::new();
            for &tol in &tols {
                let at_least = points.last().map_or(0.0, |p| p.seconds);
                if at_least > SKIP_BEATEN_ABOVE && frontier.beaten(at_least, tol).is_some() {
                    break;
                }
                // Quick mode: slow solvers stop at a smaller cap and time budget (a tolerance they
                // do not reach ends their series), so the quick report stays within minutes.
                let (cap, budget) = if ctx.quick { (20_000, 2.0) } else { (200_000, 20.0) };
                let Ok((f0, s0)) = divergent_field(n, 2, method, tol, cap) else { continue };
                let run = || {
                    let (mut f, mut s) = (f0.clone(), s0.clone());
                    let t = Instant::now();
                    let residual = f.advance(&mut s, 1e-3).map_or(f64::NAN, |info| info.pressure.residual);
                    (t.elapsed().as_secs_f64(), residual)
                };
                // The median of three runs; a run past the budget is timed once (its noise is
                // small beside it) and ends the series.
                let (first, residual) = run();
                let budget_ok = first < budget;
                let secs = if ctx.quick || !budget_ok {
                    first
                } else {
                    let mut t = [first, run().0, run().0];
                    t.sort_by(f64::total_cmp);
                    t[1]
                };
                let reached = residual.is_finite() && residual <= tol * 1.0001;
                if reached {
                    points.push(Point { param: tol, seconds: secs, error: residual });
                    frontier.add(secs, residual);
                }
                if !budget_ok || (ctx.quick && !reached) {
                    break;
                }
            }
            found.push((m, k, Series { label: format!("{} N={n}", method.name()), points }));
        }
    }
    found.sort_by_key(|&(m, k, _)| (m, k));
    StudyResult {
        title: "anim-fluid: pressure projection, relative divergence residual vs wall time (2D box with a sphere; \
                a solver's points past 2 s that another beats in time and error are not run)"
            .into(),
        slug: "fluid_pressure_divergence".into(),
        error_label: "relative residual max|b - A p| / max|b|".into(),
        param_label: "tolerance".into(),
        series: found.into_iter().map(|(_, _, s)| s).collect(),
    }
}

/// Pressure-solver tolerance of the cavity study.
const GHIA_STUDY_PRESSURE_TOLERANCE: f64 = 1e-5;

/// The cavity study's parameters `anim run --tolerance` uses: its pressure tolerance.
pub fn ghia_study_problem(_quick: bool) -> Vec<(&'static str, f64)> {
    vec![("pressure_tolerance", GHIA_STUDY_PRESSURE_TOLERANCE)]
}

pub(super) fn study_ghia(ctx: &Ctx) -> StudyResult {
    let sizes: &[usize] = if ctx.quick { &[16, 32] } else { &[16, 32, 64] };
    let mut series = Vec::new();
    for method in PressureMethod::ALL {
        let mut points = Vec::new();
        for &n in sizes {
            let t = Instant::now();
            if let Ok((f, s, _)) = cavity_run(n, Advection::MacCormack, method, GHIA_STUDY_PRESSURE_TOLERANCE)
            {
                let (eu, ev) = ghia_errors(&f, &s);
                points.push(Point { param: n as f64, seconds: t.elapsed().as_secs_f64(), error: eu.max(ev) });
            }
        }
        series.push(Series { label: method.name().into(), points });
    }
    StudyResult {
        title: "anim-fluid: lid-driven cavity Re = 100, max error vs Ghia 1982 against wall time (to steady state)".into(),
        slug: "fluid_cavity_ghia".into(),
        error_label: "max |error| over Ghia's centreline points".into(),
        param_label: "N".into(),
        series,
    }
}

/// Every advection scheme under both splittings on the Taylor-Green vortex (`nu = 0.01`, to
/// `t = 1`, MGPCG to 1e-10), swept over the CFL number at a fixed grid: the amplitude's
/// relative error against `exp(-2 nu pi^2 t)` against the wall time of the run.
pub(super) fn study_taylor_green(ctx: &Ctx) -> StudyResult {
    let (n, cfls): (usize, &[f64]) =
        if ctx.quick { (32, &[1.0, 2.0, 4.0]) } else { (64, &[0.5, 1.0, 2.0, 4.0]) };
    let mut series = Vec::new();
    for splitting in Splitting::ALL {
        for advection in Advection::ALL {
            let mut points = Vec::new();
            for &cfl in cfls {
                let t = Instant::now();
                if let Ok((a, exact)) = taylor_green_run(n, advection, splitting, 0.01, 1.0, cfl) {
                    points.push(Point {
                        param: cfl,
                        seconds: t.elapsed().as_secs_f64(),
                        error: (a / exact - 1.0).abs(),
                    });
                }
            }
            series.push(Series { label: format!("{} {}", advection.name(), splitting.name()), points });
        }
    }
    StudyResult {
        title: format!(
            "anim-fluid: Taylor-Green vortex at N = {n}, amplitude error at t = 1 against wall time, per advection scheme and splitting"
        ),
        slug: "fluid_taylor_green".into(),
        error_label: "|A / A_exact - 1|".into(),
        param_label: "CFL".into(),
        series,
    }
}
