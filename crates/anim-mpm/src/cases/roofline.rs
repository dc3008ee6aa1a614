//! The transfers as roofline kernels (`cargo xtask roofline`): P2G and G2P of the peer
//! benchmark scenes (`scenes::benchmark_2d` / `benchmark_3d`: Taichi's mpm88 / mpm3d fluid,
//! MLS-MPM, quadratic B-splines), each timed alone over the particles of a state sorted by one
//! step, so that the particle arrays stream in order as they do in every later step.
//!
//! Counts per particle, from the code of `particle_transfer` (the portable kernels; the AVX2
//! ones do the same operations per lane). A 4-lane `f32x4` operation counts 4 flops (lanes
//! that hold padding included), a scalar one 1, a square root or cube root 1.
//!
//! P2G (`p2g_prepare` + `p2g_particle`, MLS, fluid):
//! - bytes: reads `x` (4D), `v` (4D), `C` (4D^2), `F` (4D^2), plastic, mass, volume (4 each),
//!   material (2) and the sorted slot (4): 66 in 2D, 114 in 3D; plus the particle block's
//!   window (`8^D` nodes of 16 bytes) written back once per block, divided by the particles
//!   (measured from the grid). The window itself stays in L1/L2 while its block's particles
//!   scatter into it (1 KB in 2D, 8 KB in 3D), so its load-add-stores are not memory traffic.
//! - flops: stencil 24 per axis (scale, base, fraction, 3 weights and 3 derivatives, 3 offsets);
//!   stress and affine momentum (determinant, pressure, `-dt V tau`, `m C + D^-1 sp`, the
//!   columns) 36 in 2D, 78 in 3D; scatter per node `(r + a0 dx) (w0 wy)` then the add, 17, per
//!   stencil row 8 (+1 for `wy wz` in 3D), per 3D plane 8: 9 x 17 + 3 x 8 = 177 in 2D,
//!   27 x 17 + 9 x 9 + 3 x 8 = 564 in 3D. Total 261 (2D), 714 (3D).
//!
//! G2P (`g2p_chunk` + `g2p_gather`, MLS, fluid):
//! - bytes: reads slot and block (8), `x` (4D), material (2), `F` (4D^2), plastic (4), and
//!   mass, volume, material, id copied (14); writes `x`, `v` (4D each), `C`, `F` (4D^2 each),
//!   plastic (4), the removal flag (1) and the copies (14): 119 in 2D, 191 in 3D; plus the
//!   window read once per block, divided by the particles. Writes count once (a write-allocate
//!   cache reads the line first; non-temporal stores would not).
//! - flops: gather per node `w v` and `w dx v`, 16; per row 24 in 2D (`v`, `B` columns), 35 in
//!   3D; stencil 24 per axis; `w dx` 3 per axis; `C = D^-1 B` D^2 + 2; `F <- (I + dt C) F`
//!   2 D^2 + D^3 + D^2 (D - 1); the fluid's return map (determinant, root, diagonal) and the
//!   position 2D: 9 x 16 + 3 x 24 + 48 + 6 + 6 + 20 + 8 + 4 = 308 in 2D;
//!   27 x 16 + 9 x 35 + 72 + 9 + 11 + 63 + 24 + 6 = 932 in 3D.

use crate::scenes::{self, Scene};
use anim_core::cases::Registry;
use anim_core::cases::roofline::{Kernel, KernelRun, Precision};

const CRATE: &str = "anim-mpm";

/// Why the transfers stay further than 2x from the flop roof.
const WHY_P2G: &str = "scatter: each node update is a dependent load-add-store of a 128-bit \
    4-lane vector in the block's window (one node per instruction, no FMA, to stay bit-equal to \
    the portable kernel) after a scalar stencil and stress; the roof assumes 256-bit FMA";
const WHY_G2P: &str = "gather of 128-bit node vectors into short dependent sums, scalar stencil, \
    3x3 matrix products and the return map per particle (no FMA, bit-equal to the portable \
    kernel); the roof assumes 256-bit FMA";

/// Registers P2G and G2P in 2D and 3D.
pub fn register(r: &mut Registry) {
    let k = |name: &'static str, setup: fn(bool) -> Result<KernelRun, String>| Kernel {
        crate_name: CRATE,
        name,
        item: "particle",
        precision: Precision::F32,
        reason: if name.starts_with("P2G") { WHY_P2G } else { WHY_G2P },
        setup,
    };
    r.kernels.push(k("P2G 2D (MLS, mpm88 fluid)", |quick| p2g(scene_2d(quick)?, 2)));
    r.kernels.push(k("G2P 2D (MLS, mpm88 fluid)", |quick| g2p(scene_2d(quick)?, 2)));
    r.kernels.push(k("P2G 3D (MLS, mpm3d fluid)", |quick| p2g(scene_3d(quick)?, 3)));
    r.kernels.push(k("G2P 3D (MLS, mpm3d fluid)", |quick| g2p(scene_3d(quick)?, 3)));
}

/// mpm88 at 1024^2 cells, 524,288 particles (64 cells, 2,048 in quick mode), one step in.
fn scene_2d(quick: bool) -> Result<Scene<2>, String> {
    stepped(scenes::benchmark_2d(if quick { 64 } else { 1024 }).map_err(|e| e.to_string())?)
}

/// mpm3d at 128^3 cells, 524,288 particles (16 cells, 1,024 in quick mode), one step in.
fn scene_3d(quick: bool) -> Result<Scene<3>, String> {
    stepped(scenes::benchmark_3d(if quick { 16 } else { 128 }).map_err(|e| e.to_string())?)
}

/// The scene after one step: its particles in the sorted order every later step keeps.
fn stepped<const D: usize>(mut s: Scene<D>) -> Result<Scene<D>, String> {
    s.sim.advance(&mut s.state, s.dt).map_err(|e| e.to_string())?;
    Ok(s)
}

/// Bytes per particle of the particle arrays, without the windows (see the module docs).
fn particle_bytes(d: usize, p2g: bool) -> f64 {
    let (d, dd) = (d as f64, (d * d) as f64);
    if p2g {
        // x, v, C, F; plastic, mass, volume; material; sorted slot.
        4.0 * (2.0 * d + 2.0 * dd) + 12.0 + 2.0 + 4.0
    } else {
        // Reads: slot and block, x, material, F, plastic, the copied constants.
        let reads = 8.0 + 4.0 * d + 2.0 + 4.0 * dd + 4.0 + 14.0;
        // Writes: x, v, C, F, plastic, the removal flag, the copied constants.
        let writes = 4.0 * (2.0 * d + 2.0 * dd) + 4.0 + 1.0 + 14.0;
        reads + writes
    }
}

fn p2g<const D: usize>(mut s: Scene<D>, d: usize) -> Result<KernelRun, String> {
    let window = s.sim.prepare_transfers(&s.state, s.dt);
    let n = s.state.len();
    let flops = if d == 2 { 261.0 } else { 714.0 };
    Ok(KernelRun {
        items: n,
        bytes_per_item: particle_bytes(d, true) + window as f64 / n as f64,
        flops_per_item: flops,
        run: Box::new(move || s.sim.time_p2g(&s.state, s.dt)),
    })
}

fn g2p<const D: usize>(mut s: Scene<D>, d: usize) -> Result<KernelRun, String> {
    let window = s.sim.prepare_transfers(&s.state, s.dt);
    let n = s.state.len();
    let flops = if d == 2 { 308.0 } else { 932.0 };
    Ok(KernelRun {
        items: n,
        bytes_per_item: particle_bytes(d, false) + window as f64 / n as f64,
        flops_per_item: flops,
        run: Box::new(move || {
            std::hint::black_box(s.sim.time_g2p(&s.state, s.dt));
        }),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_particle_byte_counts_match_the_arrays() {
        // 2D P2G: x 8, v 8, C 16, F 16, plastic/mass/volume 12, material 2, slot 4.
        assert_eq!(particle_bytes(2, true), 66.0);
        assert_eq!(particle_bytes(3, true), 114.0);
        assert_eq!(particle_bytes(2, false), 119.0);
        assert_eq!(particle_bytes(3, false), 191.0);
    }
}
