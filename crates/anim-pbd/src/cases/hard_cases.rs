//! anim-pbd's hard cases: a chain with a 1000:1 mass ratio, a chain started at 10x its rest
//! length, pinned particles next to free ones, a zero-compliance cloth at a large step,
//! coincident vertices and stencils collapsed at run time, a zero-area stencil at rest and
//! invalid input (both refused when built), and a NaN injected by an external force (reported,
//! the state kept).

use super::chain::HangingChain;
use crate::{
    Bending, Cloth, ConstraintFunction, ConstraintParams, EARTH_GRAVITY, Method, PbdBuilder, PbdError,
    PbdModel, PbdParams, PbdSimulation, SolverKind,
};
use anim_core::cases::{Ctx, Outcome, fmt_num, nan_max};
use anim_core::integrate::State;

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
            worst = nan_max(worst, (d - rest_length).abs() / rest_length);
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

pub(super) fn mass_ratio(_ctx: &Ctx) -> Outcome {
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

pub(super) fn over_stretched(_ctx: &Ctx) -> Outcome {
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

pub(super) fn pins_next_to_free(_ctx: &Ctx) -> Outcome {
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

pub(super) fn zero_compliance(_ctx: &Ctx) -> Outcome {
    let scene = match crate::scenes::cloth_drape(Some(24)) {
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

pub(super) fn coincident(_ctx: &Ctx) -> Outcome {
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

pub(super) fn degenerate_rest(_ctx: &Ctx) -> Outcome {
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

pub(super) fn invalid_input(_ctx: &Ctx) -> Outcome {
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

pub(super) fn injected_nan(_ctx: &Ctx) -> Outcome {
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
