//! The 2D dam break against Martin & Moyce (1952): the surge front's error (conformance), and
//! the study of PIC, FLIP and APIC beside anim-mpm's weakly compressible fluid, each at several
//! resolutions.

use super::CRATE;
use crate::{FlipError, FlipParams, Particles, Transfer, scenes};
use anim_core::cases::{Check, Ctx, Judge, Point, Series, StudyResult, fmt_num};
use anim_mpm::cases::{MARTIN_MOYCE, front_errors, shifted_errors};

/// Surge front `Z` at the table's times, the history `(T, Z)` of every step, and the wall time.
type SurgeFront = (Vec<f64>, Vec<(f64, f64)>, f64);

/// Surge front `Z = (x_front - x0) / a` at the table's `T = t sqrt(2 g / a)`, and the history.
fn dam_break(n: usize, transfer: Transfer, no_slip: bool) -> Result<SurgeFront, FlipError> {
    let a = 0.2;
    let params = FlipParams::<2> { transfer, no_slip, ..FlipParams::default() };
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
/// 8.5% at 192 cells per axis, anim-mpm's dam-break case). What slows the experiment's front (the gate,
/// friction on the floor and the side walls of a narrow tank, an aerated tip) is not modelled,
/// and the table's readings come in steps of 0.11 in `Z` (a quarter inch), 10% of the first
/// reading. `examples/dam_break.rs` in anim-flip prints these runs.
pub(super) fn dam_break_case(ctx: &Ctx) -> Vec<Check> {
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
        let source = "Martin & Moyce (1952) tables 2 and 6";
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
            source: "Martin & Moyce (1952); time-origin shift as in Lethe's dam-break example",
        });
    }
    checks
}

/// Slug of the dam-break study (PIC, FLIP and APIC beside anim-mpm's fluid), which the report
/// gives its cheapest-method table.
pub const DAM_BREAK_SLUG: &str = "flip_dam_break";

/// Tolerances the dam-break study adds to the report's cheapest-method table: 5 %, the accuracy
/// the question "which method reaches 5 % cheapest?" asks about.
pub const DAM_BREAK_TOLERANCES: &[f64] = &[5e-2];

/// The 2D dam break of [`dam_break_case`] (a = 0.2 m, no-slip walls, 2x2 particles per cell,
/// steps of 2 ms split into CFL-1 substeps) with PIC, FLIP 0.97 and APIC, and the same column
/// in anim-mpm's weakly compressible fluid (the scene of anim-mpm's dam-break study: sticky walls,
/// 2x2 particles per cell, c = 50 m/s), at several grid resolutions. Error: the rms relative
/// surge-front error against Martin & Moyce (1952), the gated measure of both conformance cases;
/// time: one run to T = 3.33 (t = 0.34 s).
pub(super) fn dam_break_study(ctx: &Ctx) -> StudyResult {
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
