//! The transfers of one step: stress, particle-to-grid (P2G), the grid update, grid-to-particle
//! (G2P) with the deformation-gradient update, for APIC (Jiang et al. 2015) and MLS-MPM (Hu et
//! al. 2018).
//!
//! With `w_ip` the kernel weights, `dx = x_i - x_p`, `D_p^-1 = k/h^2` (`k = 4` quadratic, `3`
//! cubic) and `tau_p = P(F_p) F_p^T`:
//!
//! ```text
//! P2G, APIC:  m_i = sum w m_p,   (m v)_i = sum w m_p (v_p + C_p dx) - dt sum V_p tau_p grad w_ip
//! P2G, MLS:   (m v)_i = sum w [m_p v_p + (m_p C_p - dt D_p^-1 V_p tau_p) dx]
//! grid:       v_i = (m v)_i / m_i + dt g,  then BC (walls, colliders); v_i = 0 where m_i = 0
//! G2P:        v_p = sum w v_i,   C_p = D_p^-1 sum w v_i dx^T,   x_p += dt v_p
//!             F_p <- (I + dt L_p) F_p,  L_p = sum v_i grad w_ip^T (APIC) or C_p (MLS),
//!             then the material's return map
//! ```
//!
//! The MLS G2P sets `C_p = D_p^-1 sum ...` with `D_p^-1 = 4/dx^2` (quadratic), as in APIC and
//! in Hu et al. (2018). MLS-MPM's `F` update with `C_p` is done at
//! the end of G2P here rather than at the start of the next P2G: the same `C_p` is used, so the
//! result is identical, and every particle state is complete after a step.
//!
//! This module runs the four stages over the grid and the particle blocks. The work on one
//! particle is in `particle_transfer` (portable kernels) and `avx2` (AVX2 kernels), chosen once
//! per simulation by the CPU token of `simd`.

use crate::Vector;
use crate::grid::{BLOCK, SparseGrid, pow};
use crate::kernel::Spline;
use crate::particle_transfer::{
    ChunkOut, Ctx, G2P_CHUNK, G2pOutcome, g2p_chunk, g2p_gather, p2g_block, wstride,
};
use crate::particles::Particles;
use crate::simd::{Avx2, with_simd};
use rayon::prelude::*;
use wide::f32x4;

/// Block coordinates of a key.
#[inline(always)]
fn block_coords<const D: usize>(key: u32, nb: usize) -> [i32; D] {
    let mut key = key as usize;
    let mut block = [0i32; D];
    for a in 0..D {
        block[a] = (key % nb) as i32;
        key /= nb;
    }
    block
}

/// P2G into the per-block windows; each particle's stress `-dt V_p tau_p` is computed here.
pub(crate) fn p2g<const D: usize, K: Spline>(grid: &mut SparseGrid<D>, st: &Particles<D>, ctx: &Ctx<'_, D>) {
    if ctx.apic {
        p2g_with::<D, K, true>(grid, st, ctx);
    } else {
        p2g_with::<D, K, false>(grid, st, ctx);
    }
}

fn p2g_with<const D: usize, K: Spline, const APIC: bool>(
    grid: &mut SparseGrid<D>,
    st: &Particles<D>,
    ctx: &Ctx<'_, D>,
) {
    let wn = SparseGrid::<D>::WN;
    let (pcoords, pstart, order) = (&grid.pcoords, &grid.pstart, &grid.order);
    grid.windows.par_chunks_mut(wn).enumerate().for_each(|(j, win)| {
        let slots = &order[pstart[j] as usize..pstart[j + 1] as usize];
        match ctx.simd {
            #[cfg(target_arch = "x86_64")]
            Some(cpu) => crate::avx2::p2g_block::<D, K, APIC>(cpu, win, st, slots, &pcoords[j], ctx),
            _ => p2g_block::<D, K, APIC>(win, st, slots, &pcoords[j], ctx),
        }
    });
}

/// Calls `f(l, w)` for the nodes of a grid block (`l` its index in the block, `w` the index in a
/// particle window of the same node, given the offset `off` of the block's first node in that
/// window), in increasing `l`.
#[inline(always)]
fn for_block_nodes<const D: usize>(off: usize, mut f: impl FnMut(usize, usize)) {
    let zs = if D == 3 { BLOCK } else { 1 };
    let mut l = 0;
    for z in 0..zs {
        for y in 0..BLOCK {
            let w = off + y * wstride(1) + z * wstride(2);
            for x in 0..BLOCK {
                f(l, w + x);
                l += 1;
            }
        }
    }
}

/// Offset in a window of the grid block `o in {0,1}^D` (bit `a` for axis `a`) after the window's own block.
#[inline(always)]
fn corner_offset<const D: usize>(o: usize) -> usize {
    let mut off = 0;
    for a in 0..D {
        off += ((o >> a) & 1) * BLOCK * wstride(a);
    }
    off
}

/// Sums the windows into the grid blocks (fixed order) and updates the grid velocities:
/// `v = (m v) / m + dt g`, boundary conditions; zero where there is no mass.
pub(crate) fn grid_update<const D: usize>(grid: &mut SparseGrid<D>, ctx: &Ctx<'_, D>) {
    let bn = SparseGrid::<D>::BN;
    let wn = SparseGrid::<D>::WN;
    let nb = grid.nb;
    let n = grid.n;
    let corners = pow(2, D);
    let (gblocks, pblock_of, windows) = (&grid.gblocks, &grid.pblock_of, &grid.windows);
    let t_end = ctx.time + ctx.dt;
    let gdt = ctx.gravity * ctx.dt;
    let wall_lo = ctx.wall_nodes;
    let wall_hi = n + 1 - ctx.wall_nodes.min(n + 1);
    grid.nodes.par_chunks_mut(bn).enumerate().for_each(|(g, nodes)| {
        with_simd(
            ctx.simd,
            #[inline(always)]
            || {
                nodes.fill(f32x4::ZERO);
                let block = block_coords::<D>(gblocks[g], nb);
                for o in 0..corners {
                    let mut pk = 0usize;
                    let mut ok = true;
                    for a in (0..D).rev() {
                        let c = block[a] - ((o >> a) & 1) as i32;
                        if c < 0 {
                            ok = false;
                        }
                        pk = pk * nb + c.max(0) as usize;
                    }
                    if !ok {
                        continue;
                    }
                    let j = pblock_of[pk];
                    if j == crate::grid::NONE {
                        continue;
                    }
                    let win = &windows[j as usize * wn..(j as usize + 1) * wn];
                    for_block_nodes::<D>(corner_offset::<D>(o), |l, w| nodes[l] += win[w]);
                }
                let origin: [usize; D] = std::array::from_fn(|a| block[a] as usize * BLOCK);
                // Whether the block touches a wall layer or a collider may be present.
                let near_wall = (0..D).any(|a| origin[a] < wall_lo || origin[a] + BLOCK > wall_hi);
                let near_mesh = ctx.meshes.iter().any(|m| m.overlaps(&origin, BLOCK));
                for l in 0..bn {
                    let node = nodes[l].to_array();
                    let m = node[0];
                    if !(m > 0.0) {
                        nodes[l] = f32x4::new([m, 0.0, 0.0, 0.0]);
                        continue;
                    }
                    let mut v = Vector::<D>::from_fn(|a, _| node[1 + a] / m) + gdt;
                    if near_wall || near_mesh || !ctx.colliders.is_empty() {
                        let mut idx = [0usize; D];
                        let mut r = l;
                        for a in 0..D {
                            idx[a] = origin[a] + r % BLOCK;
                            r /= BLOCK;
                        }
                        // Domain walls.
                        for a in 0..D {
                            let mut normal = Vector::<D>::zeros();
                            if idx[a] < wall_lo {
                                normal[a] = 1.0;
                            } else if idx[a] + ctx.wall_nodes > n {
                                normal[a] = -1.0;
                            } else {
                                continue;
                            }
                            ctx.wall.apply(&mut v, &normal);
                        }
                        // Colliders, at the end of the substep.
                        if !ctx.colliders.is_empty() {
                            let xi = Vector::<D>::from_fn(|a, _| idx[a] as f32 * ctx.h);
                            for c in ctx.colliders {
                                let (phi, normal) = c.sdf(&xi, t_end);
                                if phi <= 0.0 {
                                    let vc = c.vel::<D>();
                                    let mut rel = v - vc;
                                    c.boundary.apply(&mut rel, &normal);
                                    v = rel + vc;
                                }
                            }
                        }
                        // Mesh obstacles (fixed): the table's normal, or stopped where it has none.
                        if near_mesh {
                            for m in ctx.meshes {
                                if let Some(normal) = m.contact(&idx) {
                                    if normal == Vector::<D>::zeros() {
                                        v = Vector::<D>::zeros();
                                    } else {
                                        m.boundary.apply(&mut v, &normal);
                                    }
                                }
                            }
                        }
                    }
                    let mut out = [m, 0.0, 0.0, 0.0];
                    for a in 0..D {
                        out[1 + a] = v[a];
                    }
                    nodes[l] = f32x4::new(out);
                }
            },
        );
    });
}

/// Copies the grid velocities into each particle block's window.
pub(crate) fn gather<const D: usize>(grid: &mut SparseGrid<D>, simd: Option<Avx2>) {
    let bn = SparseGrid::<D>::BN;
    let wn = SparseGrid::<D>::WN;
    let nb = grid.nb;
    let corners = pow(2, D);
    let (pblocks, gblock_of, nodes) = (&grid.pblocks, &grid.gblock_of, &grid.nodes);
    grid.windows.par_chunks_mut(wn).enumerate().for_each(|(j, win)| {
        with_simd(
            simd,
            #[inline(always)]
            || {
                let key = pblocks[j] as usize;
                for o in 0..corners {
                    let mut gk = key;
                    let mut s = 1;
                    for a in 0..D {
                        gk += ((o >> a) & 1) * s;
                        s *= nb;
                    }
                    let g = gblock_of[gk] as usize;
                    let src = &nodes[g * bn..(g + 1) * bn];
                    for_block_nodes::<D>(corner_offset::<D>(o), |l, w| win[w] = src[l]);
                }
            },
        );
    });
}

/// G2P: new velocities, affine matrices, positions, deformation gradients (with the return
/// maps), written in sorted order into `out`; `remove` flags the particles that left the domain
/// (for when they are to be removed instead of clamped).
pub(crate) fn g2p<const D: usize, K: Spline>(
    grid: &SparseGrid<D>,
    st: &Particles<D>,
    out: &mut Particles<D>,
    remove: &mut [bool],
    ctx: &Ctx<'_, D>,
) -> G2pOutcome {
    if ctx.apic {
        g2p_with::<D, K, true>(grid, st, out, remove, ctx)
    } else {
        g2p_with::<D, K, false>(grid, st, out, remove, ctx)
    }
}

fn g2p_with<const D: usize, K: Spline, const APIC: bool>(
    grid: &SparseGrid<D>,
    st: &Particles<D>,
    out: &mut Particles<D>,
    remove: &mut [bool],
    ctx: &Ctx<'_, D>,
) -> G2pOutcome {
    let dd = D * D;
    (
        out.x.par_chunks_mut(G2P_CHUNK * D),
        out.v.par_chunks_mut(G2P_CHUNK * D),
        out.c.par_chunks_mut(G2P_CHUNK * dd),
        out.f.par_chunks_mut(G2P_CHUNK * dd),
        out.plastic.par_chunks_mut(G2P_CHUNK),
        out.mass.par_chunks_mut(G2P_CHUNK),
        out.volume.par_chunks_mut(G2P_CHUNK),
        out.material.par_chunks_mut(G2P_CHUNK),
        out.id.par_chunks_mut(G2P_CHUNK),
        remove.par_chunks_mut(G2P_CHUNK),
    )
        .into_par_iter()
        .enumerate()
        .map(|(chunk, (x, v, c, f, plastic, mass, volume, material, id, remove))| {
            let o = ChunkOut { x, v, c, f, plastic, mass, volume, material, id, remove };
            match ctx.simd {
                #[cfg(target_arch = "x86_64")]
                Some(cpu) => crate::avx2::g2p_chunk::<D, K, APIC>(cpu, grid, st, ctx, chunk, o),
                _ => g2p_chunk::<D, K, APIC>(grid, st, ctx, chunk, o, |win, s| {
                    g2p_gather::<D, K, APIC>(win, s, ctx.inv_h)
                }),
            }
        })
        .reduce(
            || G2pOutcome { outside: 0, first_bad: u32::MAX },
            |a, b| G2pOutcome { outside: a.outside + b.outside, first_bad: a.first_bad.min(b.first_bad) },
        )
}
