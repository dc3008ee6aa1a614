//! The transfers as a roofline kernel (`cargo xtask roofline`): one P2G + G2P round trip
//! ([`FlipSimulation::transfer_round_trip`], APIC, quadratic B-splines) of the benchmark dam
//! break (`scenes::benchmark_dam_break_3d`) at 64 cells per axis, 131,072 particles (16 MB of
//! particles and 27 MB of faces: together beyond the 32 MB last-level cache of the machines
//! measured, and a run short enough to time several times). One item is
//! one particle. Besides the two transfers the round trip bins the particles, classifies the
//! cells, marks the weighted faces, extrapolates the face velocities by three layers, mirrors
//! them behind the walls and copies them for FLIP; their bytes are counted below, their few
//! flops are not.
//!
//! Counts per particle, from the transfer code (`n^3 / 2` particles and `3 (n + 1) n^2` faces,
//! so about 6 faces per particle):
//! - flops, P2G (gathered per face over the particles of the `4^3` cells around it, so each
//!   particle is visited 64 times per axis, 27 of them with a non-zero weight): per visit the
//!   weight `prod_b N(x_b / h - q_b)` 18; per weighted visit the APIC velocity `v + C (x_i - x)`
//!   12 and the sums 3: `3 (64 x 18 + 27 x 15) = 4671`, plus per face its position and box,
//!   12 over 6 faces: 72. G2P per axis: the stencil 48 (scaled position, 9 weights), per node
//!   the weight 3, the two velocity sums 4 and the affine moment 12, over 27 nodes 513, the
//!   affine row 6: `3 x 648 + 2 = 1946`. About 6,690 in all.
//! - bytes: P2G reads the particles' positions, velocities and affine matrices (120) once per
//!   axis (a sweep over one axis's faces keeps a few cell planes of particles in the cache):
//!   360; G2P reads the positions (24) and reads and writes velocities and affine matrices
//!   (192): 216; binning 44 (positions, cell indices, the sort); cell labels 4. The grid, per
//!   face: P2G writes velocity and weight (16), marking reads the weight and writes the flag
//!   (9), extrapolation reads velocity and flag and writes both (18) three times (54), the copy
//!   for FLIP (16), G2P reads velocity and old velocity (16): 111 per face, 666 per particle.
//!   About 1,290 in all.

use crate::scenes::benchmark_dam_break_3d;
use crate::{FlipParams, FlipSimulation};
use anim_core::cases::Registry;
use anim_core::cases::roofline::{Kernel, KernelRun, Precision};

/// Registers the round trip.
pub fn register(r: &mut Registry) {
    r.kernels.push(Kernel {
        crate_name: "anim-flip",
        name: "P2G + G2P round trip 3D (APIC, dam break 64^3)",
        item: "particle",
        precision: Precision::F64,
        reason: "scalar f64 with a branch per stencil node (no vector lanes: the roof assumes \
            4-wide FMA); P2G gathers per face over all particles of 4^3 cells, so 37 of every \
            64 weight evaluations give zero",
        setup: round_trip,
    });
}

fn round_trip(quick: bool) -> Result<KernelRun, String> {
    let n = if quick { 8 } else { 64 };
    let (mut sim, mut particles): (FlipSimulation<3>, _) =
        benchmark_dam_break_3d(n, FlipParams::default()).map_err(|e| e.to_string())?;
    let count = particles.x.len();
    let faces_per_particle = 3.0 * ((n + 1) * n * n) as f64 / count as f64;
    sim.transfer_round_trip(&mut particles);
    Ok(KernelRun {
        items: count,
        bytes_per_item: 360.0 + 216.0 + 44.0 + 4.0 + 111.0 * faces_per_particle,
        flops_per_item: 4671.0 + 12.0 * faces_per_particle + 1946.0,
        run: Box::new(move || sim.transfer_round_trip(&mut particles)),
    })
}
