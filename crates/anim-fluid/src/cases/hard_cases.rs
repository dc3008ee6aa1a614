//! Hard cases: CFL 10, a huge buoyancy force, empty and 1-cell grids, non-positive parameters,
//! NaN sources; and the CFL-10 vortex as a soak run (`cargo xtask stability --long`).

use crate::advection::Advection;
use crate::mac::{MacFluid, MacParams, MacState};
use crate::scenes::{self, FluidSim};
use crate::stam::{StamFluid, StamParams};
use anim_core::cases::{
    Budget, Ctx, ENERGY_STRIDE, Outcome, Soak, drive, energy_exceeds, finish, fmt_num, nan_max, rejected,
};
use std::f64::consts::PI;

pub(super) fn cfl10(_ctx: &Ctx) -> Outcome {
    let (n, speed) = (64, 1.0);
    let params = MacParams { advection: Advection::Linear, ..MacParams::default() };
    let Ok((mut f, mut s)) = MacFluid::new([n, n, 1], 2, 1.0 / n as f64, params) else {
        return Outcome::Rejected("could not build".into());
    };
    f.set_velocity(&mut s, |p| [speed * (PI * p[1]).sin(), -speed * (PI * p[0]).sin(), 0.0]);
    for c in 0..s.density.len() {
        let (i, j) = (c % n, c / n);
        s.density[c] = if (i / 8 + j / 8) % 2 == 0 { 1.0 } else { 0.0 };
    }
    let dt = 10.0 / n as f64 / speed;
    for step in 0..100 {
        if let Err(e) = f.advance(&mut s, dt) {
            return Outcome::Diverged(format!("step {step}: {e}"));
        }
    }
    let vmax = s.vel.iter().flatten().fold(0.0f64, |m, x| nan_max(m, x.abs()));
    let (lo, hi) = s.density.iter().fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
    if vmax <= speed * 1.5 && lo >= -1e-12 && hi <= 1.0 + 1e-12 {
        Outcome::Stable(format!(
            "100 steps at CFL 10: max |u| {vmax:.3} (initial {speed}), density in [{lo:.2e}, {hi:.4}]"
        ))
    } else {
        Outcome::Diverged(format!("unbounded: max |u| {vmax}, density in [{lo}, {hi}]"))
    }
}

pub(super) fn huge_force(_ctx: &Ctx) -> Outcome {
    let mut scene = match scenes::smoke_plume_3d(12) {
        Ok(s) => s,
        Err(e) => return Outcome::Rejected(e.to_string()),
    };
    let FluidSim::Mac(f, s) = &mut scene.sim else { return Outcome::Rejected("not a MAC scene".into()) };
    let mut p = f.params().clone();
    p.buoyancy_temperature = 1e6;
    let (mut f2, _) = match MacFluid::new(f.dims(), 3, f.h(), p) {
        Ok(x) => x,
        Err(e) => return Outcome::Rejected(e.to_string()),
    };
    let _ = f2.set_solid(|q| (q[0] - 0.5).powi(2) + (q[1] - 0.45).powi(2) + (q[2] - 0.5).powi(2) < 0.0225);
    for step in 0..20 {
        if let Err(e) = f2.advance(s, scene.dt) {
            return Outcome::Diverged(format!("step {step}: {e}"));
        }
    }
    let vmax = s.vel.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let dmax = s.density.iter().fold(0.0f64, |m, x| m.max(*x));
    Outcome::Stable(format!(
        "20 steps: max |u| {vmax:.3e}, density max {dmax:.3} (<= source 1), divergence {:.2e}",
        f2.last_step().divergence
    ))
}

pub(super) fn empty_grid(_ctx: &Ctx) -> Outcome {
    match (MacFluid::new([0, 0, 1], 2, 0.1, MacParams::default()), StamFluid::new(0, StamParams::default())) {
        (Err(a), Err(b)) => Outcome::Rejected(format!("MAC: {a}; Stam: {b}")),
        _ => Outcome::Stable("accepted an empty grid".into()),
    }
}

pub(super) fn one_cell(_ctx: &Ctx) -> Outcome {
    match (MacFluid::new([1, 1, 1], 3, 0.1, MacParams::default()), StamFluid::new(1, StamParams::default())) {
        (Err(a), Err(b)) => Outcome::Rejected(format!("MAC: {a}; Stam: {b}")),
        _ => Outcome::Stable("accepted a 1-cell grid".into()),
    }
}

pub(super) fn non_positive(_ctx: &Ctx) -> Outcome {
    let mut msgs = Vec::new();
    // The case expects Rejected: a fluid that does not build leaves dt = 0 untested, a failure.
    let (mut f, mut s) = match MacFluid::new([8, 8, 1], 2, 0.1, MacParams::default()) {
        Ok(x) => x,
        Err(e) => return Outcome::Stable(format!("setup failed, dt = 0 not tested: {e}")),
    };
    match f.advance(&mut s, 0.0) {
        Err(e) => msgs.push(format!("dt = 0: {e}")),
        Ok(_) => return Outcome::Stable("accepted dt = 0".into()),
    }
    match MacFluid::new([8, 8, 1], 2, -0.1, MacParams::default()) {
        Err(e) => msgs.push(format!("h < 0: {e}")),
        Ok(_) => return Outcome::Stable("accepted h < 0".into()),
    }
    match MacFluid::new([8, 8, 1], 2, 0.1, MacParams { viscosity: -1.0, ..MacParams::default() }) {
        Err(e) => msgs.push(format!("{e}")),
        Ok(_) => return Outcome::Stable("accepted a negative viscosity".into()),
    }
    match MacFluid::new([8, 8, 1], 2, 0.1, MacParams { pressure_tolerance: 0.0, ..MacParams::default() }) {
        Err(e) => msgs.push(format!("{e}")),
        Ok(_) => return Outcome::Stable("accepted a zero tolerance".into()),
    }
    match StamFluid::new(8, StamParams { dt: -0.1, ..StamParams::default() }) {
        Err(e) => msgs.push(format!("Stam: {e}")),
        Ok(_) => return Outcome::Stable("Stam's solver accepted dt < 0".into()),
    }
    Outcome::Rejected(msgs.join("; "))
}

pub(super) fn nan_source(_ctx: &Ctx) -> Outcome {
    // The case expects Diverged: a solver that does not build, or a failed step that does not
    // leave the state as it was, is Rejected (a failure), not a detected divergence.
    let mut msgs = Vec::new();
    let mut stam = match StamFluid::new(16, StamParams::default()) {
        Ok(f) => f,
        Err(e) => return Outcome::Rejected(format!("setup failed, Stam not tested: {e}")),
    };
    stam.apply_source_pattern();
    stam.sources_mut().1[40] = f32::NAN;
    match stam.step() {
        Err(e) => msgs.push(format!("Stam: {e}")),
        Ok(()) => return Outcome::Stable("Stam's solver let NaN pass silently".into()),
    }
    let (mut f, mut s) = match MacFluid::new([16, 16, 1], 2, 1.0 / 16.0, MacParams::default()) {
        Ok(x) => x,
        Err(e) => return Outcome::Rejected(format!("setup failed, MAC not tested: {e}")),
    };
    s.density[100] = f64::NAN;
    let before = s.clone();
    match f.advance(&mut s, 0.01) {
        Err(e) if s.vel == before.vel && s.steps == before.steps => {
            msgs.push(format!("MAC: {e}; state restored: true"));
        }
        Err(e) => return Outcome::Rejected(format!("MAC: {e}, but the state was not restored")),
        Ok(_) => return Outcome::Stable("MAC NaN passed silently".into()),
    }
    Outcome::Diverged(msgs.join("; "))
}

/// The soak run: [`cfl10`]'s vortex stepped for the whole budget.
pub(super) fn soak_cfl10(budget: Budget) -> Soak {
    let (n, speed) = (64, 1.0);
    let params = MacParams { advection: Advection::Linear, ..MacParams::default() };
    let (mut f, mut s) = match MacFluid::new([n, n, 1], 2, 1.0 / n as f64, params) {
        Ok(x) => x,
        Err(e) => return rejected(budget, e),
    };
    f.set_velocity(&mut s, |p| [speed * (PI * p[1]).sin(), -speed * (PI * p[0]).sin(), 0.0]);
    for c in 0..s.density.len() {
        let (i, j) = (c % n, c / n);
        s.density[c] = if (i / 8 + j / 8) % 2 == 0 { 1.0 } else { 0.0 };
    }
    let kinetic = |s: &MacState| 0.5 * s.vel.iter().flatten().map(|u| u * u).sum::<f64>() / (n * n) as f64;
    let dt = 10.0 / n as f64 / speed;
    let e0 = kinetic(&s);
    let mut last = e0;
    let clock = match drive(budget, dt, |k| {
        f.advance(&mut s, dt).map_err(|e| e.to_string())?;
        if k.is_multiple_of(ENERGY_STRIDE) {
            last = kinetic(&s);
            let (lo, hi) = s.density.iter().fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
            if energy_exceeds(last, e0) || lo < -1e-12 || hi > 1.0 + 1e-12 {
                return Err(format!(
                    "step {k}: kinetic energy {last} (initial {e0}), density in [{lo}, {hi}]"
                ));
            }
        }
        Ok(())
    }) {
        Ok(c) => c,
        Err(s) => return s,
    };
    let d = format!(
        "kinetic energy per unit area {} -> {}, checked every {ENERGY_STRIDE} steps",
        fmt_num(e0),
        fmt_num(last)
    );
    finish(&clock, dt, true, d)
}
