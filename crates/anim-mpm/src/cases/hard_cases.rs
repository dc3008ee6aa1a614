//! Hard cases: CFL above 1, a wall impact, particles leaving the domain, extreme snow
//! compression, zero-mass nodes, an injected divergence and bad input.

use super::conservation::cloud;
use crate::scenes::fill;
use crate::{
    Boundary, Collider, Elastic, Fluid, Material, MpmError, MpmParams, MpmSimulation, OutOfDomain, Particles,
    Shape, Snow,
};
use anim_core::cases::{Ctx, Outcome};

pub(super) fn high_cfl(_ctx: &Ctx) -> Outcome {
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

pub(super) fn wall_impact(_ctx: &Ctx) -> Outcome {
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

pub(super) fn leaving_domain(_ctx: &Ctx) -> Outcome {
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

pub(super) fn snow_compression(ctx: &Ctx) -> Outcome {
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

pub(super) fn zero_mass_nodes(_ctx: &Ctx) -> Outcome {
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

pub(super) fn divergence(_ctx: &Ctx) -> Outcome {
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

pub(super) fn invalid_input(_ctx: &Ctx) -> Outcome {
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
