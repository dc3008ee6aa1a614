//! The mass-spring force loop as a roofline kernel (`cargo xtask roofline`): the force of a
//! 400 x 400 cloth with structural, shear and bending springs (956,002 springs on 160,000
//! particles), evaluated by [`MechanicalSystem::force`]: per-spring forces into a buffer, then
//! each particle's sum of its incident springs' forces in a fixed order. One item is one spring.
//!
//! Counts per spring, from the two passes of the force evaluation (with `r = particles /
//! springs`, 0.167 here):
//! - flops: `d`, `u` 6, `|d|` 6 (dot, square root), `1 / len` 1, `n` 3, `n . u` 5, Hooke and
//!   damping magnitudes 4, times `n` 3: 28 per spring; its force added to both particles' sums
//!   6; per particle the signed sums, gravity and total 9: `34 + 9 r`.
//! - bytes: spring ends (8) and parameters (24) read, its force written (24) and read back once
//!   (24; the particles that read a spring's force are at most a cloth row apart, within the
//!   L2 cache), its two incidences (16): 96 per spring; per particle positions and velocities
//!   (48, read once per pass thanks to the cloth's index locality), incidence offsets (16), the
//!   particle record (16) and its force written (24): `96 + 104 r`.

use crate::{Cloth, EARTH_GRAVITY, NetworkBuilder, SpringParams};
use anim_core::cases::Registry;
use anim_core::cases::roofline::{Kernel, KernelRun, Precision};
use anim_core::integrate::MechanicalSystem;

/// Registers the force loop.
pub fn register(r: &mut Registry) {
    r.kernels.push(Kernel {
        crate_name: "anim-springs",
        name: "spring forces (400 x 400 cloth)",
        item: "spring",
        precision: Precision::F64,
        reason: "one square root and one division per spring in scalar f64 (the roof counts each \
            as one flop; the divider's throughput is several cycles each), about as costly as the \
            spring's bytes at the measured bandwidth",
        setup: forces,
    });
}

fn forces(quick: bool) -> Result<KernelRun, String> {
    let n = if quick { 8 } else { 400 };
    let springs = SpringParams::new(1e4, 0.1);
    let mut b = NetworkBuilder::new();
    b.gravity(EARTH_GRAVITY);
    b.cloth(&Cloth {
        nx: n,
        ny: n,
        origin: [0.0; 3],
        u: [1.0, 0.0, 0.0],
        v: [0.0, 1.0, 0.0],
        mass: 1.0,
        structural: springs,
        shear: Some(springs),
        bending: Some(springs),
    })
    .map_err(|e| e.to_string())?;
    let mut net = b.build().map_err(|e| e.to_string())?;
    let (m, p) = (net.num_springs(), net.num_particles());
    let mut state = net.rest_state();
    // A deformed, moving cloth: every spring stretched and damped.
    for (i, x) in state.x.iter_mut().enumerate() {
        *x *= 1.0 + 1e-3 * (i % 7) as f64;
    }
    for (i, v) in state.v.iter_mut().enumerate() {
        *v = 1e-2 * (i % 5) as f64;
    }
    let mut f = vec![0.0; state.x.len()];
    let r = p as f64 / m as f64;
    Ok(KernelRun {
        items: m,
        bytes_per_item: 96.0 + 104.0 * r,
        flops_per_item: 34.0 + 9.0 * r,
        run: Box::new(move || {
            net.force(0.0, &state.x, &state.v, &mut f);
            std::hint::black_box(&f);
        }),
    })
}
