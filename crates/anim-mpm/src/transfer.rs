//! The transfers of one step: stress, particle-to-grid (P2G), the grid update, grid-to-particle
//! (G2P) with the deformation-gradient update, for APIC (seed 5.3.1) and MLS-MPM (seed 5.3.2).
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
//! The seed's MLS G2P prints `C_p = 1/dx^2 sum ...`; the factor is `D_p^-1 = 4/dx^2` (quadratic),
//! as in its APIC listing and in Hu et al. (2018). MLS-MPM's `F` update with `C_p` is done at
//! the end of G2P here rather than at the start of the next P2G: the same `C_p` is used, so the
//! result is identical, and every particle state is complete after a step.

use crate::boundary::{Boundary, Collider};
use crate::grid::{BLOCK, SparseGrid, WINDOW, pow};
use crate::kernel::Spline;
use crate::material::{Compiled, kirchhoff};
use crate::particles::Particles;
use crate::plasticity::project;
use crate::{Mat, Vector};
use rayon::prelude::*;

/// What a substep needs besides the particles and the grid.
#[derive(Clone, Copy)]
pub(crate) struct Ctx<'a, const D: usize> {
    pub h: f32,
    pub inv_h: f32,
    pub dt: f32,
    pub apic: bool,
    pub gravity: Vector<D>,
    pub wall_nodes: usize,
    pub wall: Boundary,
    pub colliders: &'a [Collider],
    /// Time at the start of the substep.
    pub time: f32,
    /// Allowed particle coordinate range (same on every axis).
    pub lo: f32,
    pub hi: f32,
    pub materials: &'a [Compiled],
}

/// Per-axis stencil data of one particle.
struct Stencil<const D: usize> {
    /// Window offset of the base node, per axis (0..=3).
    local: [usize; D],
    w: [[f32; 4]; D],
    dw: [[f32; 4]; D],
    /// `x_i - x_p` per axis and stencil node.
    dx: [[f32; 4]; D],
}

#[inline(always)]
fn stencil<const D: usize, K: Spline>(x: &[f32], inv_h: f32, h: f32, block: &[i32; D]) -> Stencil<D> {
    let mut s = Stencil { local: [0; D], w: [[0.0; 4]; D], dw: [[0.0; 4]; D], dx: [[0.0; 4]; D] };
    for a in 0..D {
        let xs = x[a] * inv_h;
        let (base, w, dw) = K::weights(xs);
        s.local[a] = (base - block[a] * BLOCK as i32).clamp(0, (WINDOW - K::N) as i32) as usize;
        s.w[a] = w;
        s.dw[a] = dw;
        let fx = xs - base as f32;
        for k in 0..K::N {
            s.dx[a][k] = (k as f32 - fx) * h;
        }
    }
    s
}

/// Calls `f` on every stencil node `k in [0, N)^D`, in the order `k_0` fastest, as nested
/// loops the compiler unrolls (`D` and `N` are constants).
#[inline(always)]
fn for_each_node<const D: usize, const N: usize>(mut f: impl FnMut([usize; D])) {
    let mut k = [0usize; D];
    if D == 2 {
        for j in 0..N {
            for i in 0..N {
                k[0] = i;
                k[1] = j;
                f(k);
            }
        }
    } else {
        for l in 0..N {
            for j in 0..N {
                for i in 0..N {
                    k[0] = i;
                    k[1] = j;
                    k[2] = l;
                    f(k);
                }
            }
        }
    }
}

/// Window strides per axis.
const fn wstride(a: usize) -> usize {
    pow(WINDOW, a)
}

/// P2G into the per-block windows; each particle's stress `-dt V_p tau_p` is computed here.
pub(crate) fn p2g<const D: usize, K: Spline>(grid: &mut SparseGrid<D>, st: &Particles<D>, ctx: &Ctx<'_, D>) {
    let stride = D + 1;
    let wlen = SparseGrid::<D>::WN * stride;
    let nb = grid.nb;
    let (pblocks, pstart, order) = (&grid.pblocks, &grid.pstart, &grid.order);
    let d_inv = K::D_INV * ctx.inv_h * ctx.inv_h;
    grid.windows.par_chunks_mut(wlen).enumerate().for_each(|(j, win)| {
        win.fill(0.0);
        let mut key = pblocks[j] as usize;
        let mut block = [0i32; D];
        for a in 0..D {
            block[a] = (key % nb) as i32;
            key /= nb;
        }
        for &p in &order[pstart[j] as usize..pstart[j + 1] as usize] {
            let p = p as usize;
            let s = stencil::<D, K>(&st.x[p * D..p * D + D], ctx.inv_h, ctx.h, &block);
            let m = st.mass[p];
            let mv = st.velocity(p) * m;
            // -dt V_p tau_p.
            let mat = &ctx.materials[st.material[p] as usize];
            let sp = kirchhoff(mat, &st.deformation(p), st.plastic[p]) * (-ctx.dt * st.volume[p]);
            let aff = if ctx.apic { st.affine(p) * m } else { st.affine(p) * m + sp * d_inv };
            let body = |k: [usize; D], win: &mut [f32]| {
                let mut w = 1.0f32;
                let mut idx = 0usize;
                let mut dx = Vector::<D>::zeros();
                for a in 0..D {
                    w *= s.w[a][k[a]];
                    idx += (s.local[a] + k[a]) * wstride(a);
                    dx[a] = s.dx[a][k[a]];
                }
                let mut mom = (mv + aff * dx) * w;
                if ctx.apic {
                    // grad w_ip = (N'_a / h) prod_{b != a} N_b.
                    let mut gw = Vector::<D>::zeros();
                    for a in 0..D {
                        let mut g = s.dw[a][k[a]] * ctx.inv_h;
                        for b in 0..D {
                            if b != a {
                                g *= s.w[b][k[b]];
                            }
                        }
                        gw[a] = g;
                    }
                    mom += sp * gw;
                }
                let node = &mut win[idx * stride..idx * stride + stride];
                node[0] += w * m;
                for a in 0..D {
                    node[1 + a] += mom[a];
                }
            };
            if K::N == 3 {
                for_each_node::<D, 3>(|k| body(k, win));
            } else {
                for_each_node::<D, 4>(|k| body(k, win));
            }
        }
    });
}

/// Sums the windows into the grid blocks (fixed order) and updates the grid velocities:
/// `v = (m v) / m + dt g`, boundary conditions; zero where there is no mass.
pub(crate) fn grid_update<const D: usize>(grid: &mut SparseGrid<D>, ctx: &Ctx<'_, D>) {
    let stride = D + 1;
    let blen = SparseGrid::<D>::BN * stride;
    let wlen = SparseGrid::<D>::WN * stride;
    let nb = grid.nb as i32;
    let n = grid.n;
    let corners = pow(2, D);
    let (gblocks, pblock_of, windows) = (&grid.gblocks, &grid.pblock_of, &grid.windows);
    let t_end = ctx.time + ctx.dt;
    grid.nodes.par_chunks_mut(blen).enumerate().for_each(|(g, nodes)| {
        nodes.fill(0.0);
        let mut key = gblocks[g] as i32;
        let mut block = [0i32; D];
        for a in 0..D {
            block[a] = key % nb;
            key /= nb;
        }
        for o in 0..corners {
            let mut pk = 0i32;
            let mut ok = true;
            for a in (0..D).rev() {
                let c = block[a] - ((o >> a) & 1) as i32;
                if c < 0 {
                    ok = false;
                }
                pk = pk * nb + c;
            }
            if !ok {
                continue;
            }
            let j = pblock_of[pk as usize];
            if j == crate::grid::NONE {
                continue;
            }
            let win = &windows[j as usize * wlen..(j as usize + 1) * wlen];
            // Node l of this block is node l + 4 o of the window.
            let mut off = 0;
            for a in 0..D {
                off += ((o >> a) & 1) * BLOCK * wstride(a);
            }
            for l in 0..SparseGrid::<D>::BN {
                let mut wi = off;
                let mut r = l;
                for a in 0..D {
                    wi += (r % BLOCK) * wstride(a);
                    r /= BLOCK;
                }
                let src = &win[wi * stride..wi * stride + stride];
                let dst = &mut nodes[l * stride..l * stride + stride];
                for c in 0..stride {
                    dst[c] += src[c];
                }
            }
        }
        for l in 0..SparseGrid::<D>::BN {
            let node = &mut nodes[l * stride..l * stride + stride];
            let m = node[0];
            if !(m > 0.0) {
                for c in 1..stride {
                    node[c] = 0.0;
                }
                continue;
            }
            let mut v = Vector::<D>::from_fn(|a, _| node[1 + a] / m) + ctx.gravity * ctx.dt;
            let mut idx = [0usize; D];
            let mut r = l;
            for a in 0..D {
                idx[a] = block[a] as usize * BLOCK + r % BLOCK;
                r /= BLOCK;
            }
            // Domain walls.
            for a in 0..D {
                let mut normal = Vector::<D>::zeros();
                if idx[a] < ctx.wall_nodes {
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
            for a in 0..D {
                node[1 + a] = v[a];
            }
        }
    });
}

/// Copies the grid velocities into each particle block's window.
pub(crate) fn gather<const D: usize>(grid: &mut SparseGrid<D>) {
    let stride = D + 1;
    let blen = SparseGrid::<D>::BN * stride;
    let wlen = SparseGrid::<D>::WN * stride;
    let nb = grid.nb;
    let corners = pow(2, D);
    let (pblocks, gblock_of, nodes) = (&grid.pblocks, &grid.gblock_of, &grid.nodes);
    grid.windows.par_chunks_mut(wlen).enumerate().for_each(|(j, win)| {
        let key = pblocks[j] as usize;
        for o in 0..corners {
            let mut gk = key;
            let mut s = 1;
            let mut off = 0;
            for a in 0..D {
                gk += ((o >> a) & 1) * s;
                s *= nb;
                off += ((o >> a) & 1) * BLOCK * wstride(a);
            }
            let g = gblock_of[gk] as usize;
            let src = &nodes[g * blen..(g + 1) * blen];
            for l in 0..SparseGrid::<D>::BN {
                let mut wi = off;
                let mut r = l;
                for a in 0..D {
                    wi += (r % BLOCK) * wstride(a);
                    r /= BLOCK;
                }
                win[wi * stride..wi * stride + stride].copy_from_slice(&src[l * stride..l * stride + stride]);
            }
        }
    });
}

/// What G2P found.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct G2pOutcome {
    /// Particles clamped back into (or flagged for removal from) the domain.
    pub outside: u64,
    /// First sorted slot with a non-finite result, if any (`u32::MAX` if none).
    pub first_bad: u32,
}

/// G2P: new velocities, affine matrices, positions, deformation gradients (with the return
/// maps), written in sorted order into `out`; `remove` flags particles that left the domain when
/// they are to be removed instead of clamped.
pub(crate) fn g2p<const D: usize, K: Spline>(
    grid: &SparseGrid<D>,
    st: &Particles<D>,
    out: &mut Particles<D>,
    remove: Option<&mut [bool]>,
    ctx: &Ctx<'_, D>,
) -> G2pOutcome {
    let stride = D + 1;
    let wlen = SparseGrid::<D>::WN * stride;
    let nb = grid.nb;
    let d_inv = K::D_INV * ctx.inv_h * ctx.inv_h;
    let dd = D * D;
    let (order, slot_block, pblocks, windows) = (&grid.order, &grid.slot_block, &grid.pblocks, &grid.windows);
    let flag_removal = remove.is_some();
    let mut dummy: [bool; 0] = [];
    let remove_flags: &mut [bool] = match remove {
        Some(r) => r,
        None => &mut dummy,
    };
    let outcome = |s: usize, x: &mut [f32], v: &mut [f32], c: &mut [f32], f: &mut [f32], pl: &mut f32| {
        let p = order[s] as usize;
        let j = slot_block[s] as usize;
        let mut key = pblocks[j] as usize;
        let mut block = [0i32; D];
        for a in 0..D {
            block[a] = (key % nb) as i32;
            key /= nb;
        }
        let win = &windows[j * wlen..(j + 1) * wlen];
        let xp = &st.x[p * D..p * D + D];
        let sten = stencil::<D, K>(xp, ctx.inv_h, ctx.h, &block);
        let mut vel = Vector::<D>::zeros();
        let mut b = Mat::<D>::zeros();
        let mut grad = Mat::<D>::zeros();
        let mut body = |k: [usize; D]| {
            let mut w = 1.0f32;
            let mut idx = 0usize;
            let mut dx = Vector::<D>::zeros();
            for a in 0..D {
                w *= sten.w[a][k[a]];
                idx += (sten.local[a] + k[a]) * wstride(a);
                dx[a] = sten.dx[a][k[a]];
            }
            let vi = Vector::<D>::from_column_slice(&win[idx * stride + 1..idx * stride + stride]);
            let wv = vi * w;
            vel += wv;
            b += wv * dx.transpose();
            if ctx.apic {
                let mut gw = Vector::<D>::zeros();
                for a in 0..D {
                    let mut g = sten.dw[a][k[a]] * ctx.inv_h;
                    for bb in 0..D {
                        if bb != a {
                            g *= sten.w[bb][k[bb]];
                        }
                    }
                    gw[a] = g;
                }
                grad += vi * gw.transpose();
            }
        };
        if K::N == 3 {
            for_each_node::<D, 3>(&mut body);
        } else {
            for_each_node::<D, 4>(&mut body);
        }
        let cmat = b * d_inv;
        let l = if ctx.apic { grad } else { cmat };
        let mat = &ctx.materials[st.material[p] as usize];
        let mut fnew = (Mat::<D>::identity() + l * ctx.dt) * st.deformation(p);
        let mut plastic = st.plastic[p];
        project(mat, &mut fnew, &mut plastic);
        let mut xnew = Vector::<D>::from_column_slice(xp) + vel * ctx.dt;
        // Any NaN or infinity makes the sum non-finite.
        let finite = (xnew.sum() + vel.sum() + fnew.sum() + cmat.sum() + plastic).is_finite();
        let mut outside = false;
        for a in 0..D {
            if !(xnew[a] >= ctx.lo && xnew[a] <= ctx.hi) && xnew[a].is_finite() {
                outside = true;
                xnew[a] = xnew[a].clamp(ctx.lo, ctx.hi);
            }
        }
        x.copy_from_slice(xnew.as_slice());
        v.copy_from_slice(vel.as_slice());
        c.copy_from_slice(cmat.as_slice());
        f.copy_from_slice(fnew.as_slice());
        *pl = plastic;
        (outside, finite)
    };
    let combine = |a: G2pOutcome, b: G2pOutcome| G2pOutcome {
        outside: a.outside + b.outside,
        first_bad: a.first_bad.min(b.first_bad),
    };
    let identity = || G2pOutcome { outside: 0, first_bad: u32::MAX };
    let n = st.len();
    let result = if flag_removal {
        (
            out.x.par_chunks_mut(D),
            out.v.par_chunks_mut(D),
            out.c.par_chunks_mut(dd),
            out.f.par_chunks_mut(dd),
            out.plastic.par_iter_mut(),
            remove_flags.par_iter_mut(),
        )
            .into_par_iter()
            .enumerate()
            .with_min_len(64)
            .map(|(s, (x, v, c, f, pl, rm))| {
                let (outside, finite) = outcome(s, x, v, c, f, pl);
                *rm = outside;
                G2pOutcome {
                    outside: u64::from(outside),
                    first_bad: if finite { u32::MAX } else { s as u32 },
                }
            })
            .reduce(identity, combine)
    } else {
        (
            out.x.par_chunks_mut(D),
            out.v.par_chunks_mut(D),
            out.c.par_chunks_mut(dd),
            out.f.par_chunks_mut(dd),
            out.plastic.par_iter_mut(),
        )
            .into_par_iter()
            .enumerate()
            .with_min_len(64)
            .map(|(s, (x, v, c, f, pl))| {
                let (outside, finite) = outcome(s, x, v, c, f, pl);
                G2pOutcome {
                    outside: u64::from(outside),
                    first_bad: if finite { u32::MAX } else { s as u32 },
                }
            })
            .reduce(identity, combine)
    };
    // The particle constants follow the sorted order.
    out.mass.par_iter_mut().zip(out.volume.par_iter_mut()).enumerate().with_min_len(1024).for_each(
        |(s, (m, vol))| {
            let p = order[s] as usize;
            *m = st.mass[p];
            *vol = st.volume[p];
        },
    );
    out.material.par_iter_mut().zip(out.id.par_iter_mut()).enumerate().with_min_len(1024).for_each(
        |(s, (mat, id))| {
            let p = order[s] as usize;
            *mat = st.material[p];
            *id = st.id[p];
        },
    );
    debug_assert!(n == out.len());
    result
}
