//! XPBD's constraint sweep as a roofline kernel (`cargo xtask roofline`): a 400 x 400 cloth of
//! stretch (distance) constraints only, stepped by XPBD with Gauss-Seidel at 20 iterations; one
//! item is one constraint projection, so a step counts `20 x constraints` items. The step also
//! predicts the positions and updates the velocities once per particle (about 3 constraints per
//! particle, so under 2% of the projections' work at 20 iterations), which the timing includes.
//!
//! Counts per projection, from the XPBD equality path of the distance constraint (undamped, the
//! common case written out in the projection code):
//! - flops: `d = x_i - x_j` 3, `|d|^2` 5, `alpha / h^2` 1, denominator 2, square root 1,
//!   `(rest - len - at lambda) / den` 4, `lambda += dl` 1, `d (dl / len)` 4, the two weighted
//!   corrections and their adds 12: 33.
//! - bytes: the compiled constraint (112 bytes as laid out: a 64-byte kernel enum, index,
//!   stiffness, compliance, damping, flags, threshold, relaxation) and its multiplier read and
//!   written (16), streamed once per iteration (the cloth's 478,800 constraints take 61 MB); the
//!   positions (24 read, 24 written) and inverse masses (8) of the particles, each touched by
//!   about 6 consecutive constraints in model order and so loaded once per sweep: 56 bytes per
//!   particle over the 2.99 constraints per particle. About 147 bytes in all.

use crate::{
    Bending, Cloth, ConstraintParams, EARTH_GRAVITY, Method, PbdBuilder, PbdParams, PbdSimulation, SolverKind,
};
use anim_core::cases::Registry;
use anim_core::cases::roofline::{Kernel, KernelRun, Precision};

/// Solver iterations per step.
const ITERATIONS: usize = 20;

/// Registers the stretch-constraint sweep.
pub fn register(r: &mut Registry) {
    r.kernels.push(Kernel {
        crate_name: "anim-pbd",
        name: "XPBD distance sweep (400 x 400 cloth, Gauss-Seidel)",
        item: "constraint",
        precision: Precision::F64,
        reason: "Gauss-Seidel in model order: each projection's square root and division wait for \
            the positions the previous one wrote (a latency chain, not a bandwidth limit), and the \
            sweep is sequential, so a second thread cannot help",
        setup: sweep,
    });
}

fn sweep(quick: bool) -> Result<KernelRun, String> {
    let n = if quick { 8 } else { 400 };
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    let c = b
        .cloth(&Cloth {
            nx: n,
            ny: n,
            origin: [0.0; 3],
            u: [1.0, 0.0, 0.0],
            v: [0.0, 1.0, 0.0],
            particle_mass: 1e-3,
            stretch: ConstraintParams::with_compliance(1e-8),
            bending: Bending::None,
        })
        .map_err(|e| e.to_string())?;
    b.pin(c.at(0, 0)).pin(c.at(n - 1, 0));
    let model = b.build().map_err(|e| e.to_string())?;
    let constraints = model.num_constraints();
    let particles = model.num_particles();
    let mut state = model.rest_state();
    let mut params = PbdParams::new(Method::Xpbd, SolverKind::GaussSeidel, ITERATIONS, 1);
    params.max_stretch = f64::INFINITY;
    let mut sim = PbdSimulation::new(model, params).map_err(|e| e.to_string())?;
    let dt = 1.0 / 60.0;
    // One step first: the scratch allocated and the cloth in motion.
    sim.advance(&mut state, dt).map_err(|e| e.to_string())?;
    let per_particle = particles as f64 / constraints as f64;
    Ok(KernelRun {
        items: ITERATIONS * constraints,
        bytes_per_item: 112.0 + 16.0 + 56.0 * per_particle,
        flops_per_item: 33.0,
        run: Box::new(move || {
            // A diverging cloth is refused by the step; the falling cloth never diverges, and a
            // refused step still did the sweep being timed.
            let _ = std::hint::black_box(sim.advance(&mut state, dt));
        }),
    })
}
