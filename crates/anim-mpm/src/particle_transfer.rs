//! The transfers of one particle, the portable kernels: its stencil (per axis the B-spline
//! weights `w`, their derivatives and the offsets `x_i - x_p` of the nodes it reaches), its P2G
//! scatter into its particle block's window, and its G2P gather followed by the update of its
//! velocity, affine matrix, position and deformation gradient (with its material's return map).
//!
//! The stages that run these over every particle block, and their equations, are the module
//! `transfer`. The AVX2 kernels (module `avx2`) reuse the pieces here (the stencil, a particle's
//! P2G data, the gathered sums, the G2P chunk loop) and replace only the innermost loops, so both
//! do the same operations per particle.

use crate::boundary::{Boundary, GridCollider};
use crate::grid::{BLOCK, SparseGrid, WINDOW, pow};
use crate::kernel::Spline;
use crate::material::{Compiled, kirchhoff};
use crate::mesh_collider::MeshCollider;
use crate::particles::Particles;
use crate::plasticity::project;
use crate::simd::Avx2;
use crate::{Mat, Vector};
use wide::f32x4;

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
    pub colliders: &'a [GridCollider],
    /// The fixed triangle-mesh obstacles.
    pub meshes: &'a [MeshCollider],
    /// Time at the start of the substep.
    pub time: f32,
    /// Allowed particle coordinate range (same on every axis).
    pub lo: f32,
    pub hi: f32,
    pub materials: &'a [Compiled],
    /// The AVX2 kernels' token when they are to be used (x86-64 CPUs with AVX2), else `None`.
    pub simd: Option<Avx2>,
}

/// Per-axis stencil data of one particle.
pub(crate) struct Stencil<const D: usize> {
    /// Window index of the base node.
    pub base: usize,
    pub w: [[f32; 4]; D],
    pub dw: [[f32; 4]; D],
    /// `x_i - x_p` per axis and stencil node.
    pub dx: [[f32; 4]; D],
}

#[inline(always)]
pub(crate) fn stencil<const D: usize, K: Spline>(
    x: &[f32],
    inv_h: f32,
    h: f32,
    block: &[i32; D],
) -> Stencil<D> {
    let mut s = Stencil { base: 0, w: [[0.0; 4]; D], dw: [[0.0; 4]; D], dx: [[0.0; 4]; D] };
    for a in 0..D {
        let xs = x[a] * inv_h;
        // The base node `floor(xs - OFFSET)` lies in the particle's block, `origin + local` with
        // `local` in [0, 3]: `t` is exact (`xs - OFFSET` and `origin` are multiples of the ulp
        // of `xs`), so counting the integers it reaches gives `local` without a branch or a
        // float-to-int conversion, and `fx` is the one `K::weights` computes. Whatever the
        // input, `local` stays in [0, 3] and the window index in range.
        let origin = (block[a] * BLOCK as i32) as f32;
        let t = xs - K::OFFSET - origin;
        let local = usize::from(t >= 1.0) + usize::from(t >= 2.0) + usize::from(t >= 3.0);
        s.base += local * wstride(a);
        let fx = xs - (origin + local as f32);
        let (w, dw) = K::weights_at(fx);
        s.w[a] = w;
        s.dw[a] = dw;
        for k in 0..K::N {
            s.dx[a][k] = (k as f32 - fx) * h;
        }
    }
    s
}

/// Window strides per axis.
pub(crate) const fn wstride(a: usize) -> usize {
    pow(WINDOW, a)
}

/// Window nodes from a stencil's base node to its last node, inclusive: a particle's scatter
/// and gather stay in `base..base + span` (one bounds check per particle).
pub(crate) const fn span(d: usize, n: usize) -> usize {
    (n - 1) * (1 + wstride(1) + if d == 3 { wstride(2) } else { 0 }) + 1
}

/// Column `col` of `m`, times `scale`, in lanes `1..=D` of a node vector (lane 0, the mass, and
/// the lanes past `D` are zero).
#[inline(always)]
fn column<const D: usize>(m: &Mat<D>, col: usize, scale: f32) -> f32x4 {
    let mut a = [0.0f32; 4];
    for r in 0..D {
        a[1 + r] = m[(r, col)] * scale;
    }
    f32x4::new(a)
}

#[inline(always)]
pub(crate) fn splat(x: f32) -> f32x4 {
    f32x4::splat(x)
}

/// P2G of one particle block (`slots` its particles in sorted order) into its window.
#[inline(always)]
pub(crate) fn p2g_block<const D: usize, K: Spline, const APIC: bool>(
    win: &mut [f32x4],
    st: &Particles<D>,
    slots: &[u32],
    block: &[i32; D],
    ctx: &Ctx<'_, D>,
) {
    win.fill(f32x4::ZERO);
    for &p in slots {
        p2g_particle::<D, K, APIC>(win, st, p as usize, block, ctx);
    }
}

/// One particle's scatter into its block's window. Each node gets the 4-lane vector
/// `w (m_p, m_p v_p + A_p dx)` (`A_p` the affine momentum matrix), plus `-dt V_p tau_p grad w`
/// for APIC; the sum `m_p v_p + A_p dx` is built row by row (the part of the outer axes first).
#[inline(always)]
pub(crate) fn p2g_particle<const D: usize, K: Spline, const APIC: bool>(
    win: &mut [f32x4],
    st: &Particles<D>,
    p: usize,
    block: &[i32; D],
    ctx: &Ctx<'_, D>,
) {
    let (s, q, acol, scol) = p2g_prepare::<D, K, APIC>(st, p, block, ctx);
    let n = K::N;
    let win = &mut win[s.base..s.base + span(D, K::N)];
    if D == 2 {
        for j in 0..n {
            let wy = s.w[1][j];
            let r = q + acol[1] * splat(s.dx[1][j]);
            let (g0, g1) = if APIC { (scol[0] * splat(wy), scol[1] * splat(s.dw[1][j])) } else { (q, q) };
            let row = j * wstride(1);
            for i in 0..n {
                let mut t = (r + acol[0] * splat(s.dx[0][i])) * splat(s.w[0][i] * wy);
                if APIC {
                    t += g0 * splat(s.dw[0][i]) + g1 * splat(s.w[0][i]);
                }
                win[row + i] += t;
            }
        }
    } else {
        for k in 0..n {
            let wz = s.w[2][k];
            let rz = q + acol[2] * splat(s.dx[2][k]);
            for j in 0..n {
                let wy = s.w[1][j];
                let wyz = wy * wz;
                let r = rz + acol[1] * splat(s.dx[1][j]);
                let (g0, g1) = if APIC {
                    (
                        scol[0] * splat(wyz),
                        scol[1] * splat(s.dw[1][j] * wz) + scol[2] * splat(wy * s.dw[2][k]),
                    )
                } else {
                    (q, q)
                };
                let row = j * wstride(1) + k * wstride(2);
                for i in 0..n {
                    let mut t = (r + acol[0] * splat(s.dx[0][i])) * splat(s.w[0][i] * wyz);
                    if APIC {
                        t += g0 * splat(s.dw[0][i]) + g1 * splat(s.w[0][i]);
                    }
                    win[row + i] += t;
                }
            }
        }
    }
}

/// A particle's P2G data: its stencil, `(m_p, m_p v_p)` as a node vector, the columns of the
/// affine momentum matrix and (APIC) of `-dt V_p tau_p / h`, each in lanes `1..=D`.
#[inline(always)]
#[allow(clippy::type_complexity)]
pub(crate) fn p2g_prepare<const D: usize, K: Spline, const APIC: bool>(
    st: &Particles<D>,
    p: usize,
    block: &[i32; D],
    ctx: &Ctx<'_, D>,
) -> (Stencil<D>, f32x4, [f32x4; D], [f32x4; D]) {
    let s = stencil::<D, K>(&st.x[p * D..p * D + D], ctx.inv_h, ctx.h, block);
    let m = st.mass[p];
    let d_inv = K::D_INV * ctx.inv_h * ctx.inv_h;
    // -dt V_p tau_p.
    let mat = &ctx.materials[st.material[p] as usize];
    let sp = kirchhoff(mat, &st.deformation(p), st.plastic[p]) * (-ctx.dt * st.volume[p]);
    let cm = st.affine(p);
    let aff = if APIC { cm * m } else { cm * m + sp * d_inv };
    let mut q = [0.0f32; 4];
    q[0] = m;
    for a in 0..D {
        q[1 + a] = st.v[p * D + a] * m;
    }
    let q = f32x4::new(q);
    let acol: [f32x4; D] = std::array::from_fn(|c| column(&aff, c, 1.0));
    // APIC: sp grad w = sum_c sp[:, c] dN_c / h prod_{b != c} N_b.
    let scol: [f32x4; D] =
        std::array::from_fn(|c| if APIC { column(&sp, c, ctx.inv_h) } else { f32x4::ZERO });
    (s, q, acol, scol)
}

/// Particles per task of G2P.
pub(crate) const G2P_CHUNK: usize = 256;

/// What G2P found.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct G2pOutcome {
    /// Particles clamped back into (or flagged for removal from) the domain.
    pub outside: u64,
    /// First sorted slot with a non-finite result, if any (`u32::MAX` if none).
    pub first_bad: u32,
}

/// One particle's gather from its block's window: `(v_p, B_p, sum v_i grad w_ip^T)` with
/// `B_p = sum w_ip v_i dx^T` (the last one only for APIC, else zero). The sums over the
/// innermost axis are done first, per row of the stencil.
#[inline(always)]
pub(crate) fn g2p_gather<const D: usize, K: Spline, const APIC: bool>(
    win: &[f32x4],
    s: &Stencil<D>,
    inv_h: f32,
) -> Gathered<D> {
    let n = K::N;
    let mut wdx = [[0.0f32; 4]; D];
    for a in 0..D {
        for k in 0..n {
            wdx[a][k] = s.w[a][k] * s.dx[a][k];
        }
    }
    let win = &win[s.base..s.base + span(D, K::N)];
    let mut vel = f32x4::ZERO;
    let mut bcol = [f32x4::ZERO; D];
    let mut gcol = [f32x4::ZERO; D];
    // Sums along x of w v, w dx v and (APIC) dw v over one stencil row.
    let row_sums = |row: usize| {
        let (mut s0, mut s1, mut s2) = (f32x4::ZERO, f32x4::ZERO, f32x4::ZERO);
        for i in 0..n {
            let node = win[row + i];
            s0 += node * splat(s.w[0][i]);
            s1 += node * splat(wdx[0][i]);
            if APIC {
                s2 += node * splat(s.dw[0][i]);
            }
        }
        (s0, s1, s2)
    };
    if D == 2 {
        for j in 0..n {
            let (s0, s1, s2) = row_sums(j * wstride(1));
            let wy = splat(s.w[1][j]);
            vel += s0 * wy;
            bcol[0] += s1 * wy;
            bcol[1] += s0 * splat(wdx[1][j]);
            if APIC {
                gcol[0] += s2 * wy;
                gcol[1] += s0 * splat(s.dw[1][j]);
            }
        }
    } else {
        for k in 0..n {
            for j in 0..n {
                let (s0, s1, s2) = row_sums(j * wstride(1) + k * wstride(2));
                let (wy, wz) = (s.w[1][j], s.w[2][k]);
                let wyz = splat(wy * wz);
                vel += s0 * wyz;
                bcol[0] += s1 * wyz;
                bcol[1] += s0 * splat(wdx[1][j] * wz);
                bcol[2] += s0 * splat(wy * wdx[2][k]);
                if APIC {
                    gcol[0] += s2 * wyz;
                    gcol[1] += s0 * splat(s.dw[1][j] * wz);
                    gcol[2] += s0 * splat(wy * s.dw[2][k]);
                }
            }
        }
    }
    gathered::<D, APIC>(vel, bcol, gcol, inv_h)
}

/// The gather's result from its sums: `sum w v_i` (`vel`), the columns of `B_p` (`bcol`) and
/// (APIC) of `h sum v_i grad w_ip^T` (`gcol`), each in lanes `1..=D`.
#[inline(always)]
pub(crate) fn gathered<const D: usize, const APIC: bool>(
    vel: f32x4,
    bcol: [f32x4; D],
    gcol: [f32x4; D],
    inv_h: f32,
) -> Gathered<D> {
    let vel = vel.to_array();
    let bcol = bcol.map(f32x4::to_array);
    let gcol = gcol.map(f32x4::to_array);
    (
        Vector::<D>::from_fn(|r, _| vel[1 + r]),
        Mat::<D>::from_fn(|r, c| bcol[c][1 + r]),
        if APIC { Mat::<D>::from_fn(|r, c| gcol[c][1 + r] * inv_h) } else { Mat::<D>::zeros() },
    )
}

/// One G2P chunk's outputs (sorted slots `chunk * G2P_CHUNK ..`).
pub(crate) struct ChunkOut<'a> {
    pub x: &'a mut [f32],
    pub v: &'a mut [f32],
    pub c: &'a mut [f32],
    pub f: &'a mut [f32],
    pub plastic: &'a mut [f32],
    pub mass: &'a mut [f32],
    pub volume: &'a mut [f32],
    pub material: &'a mut [u16],
    pub id: &'a mut [u32],
    pub remove: &'a mut [bool],
}

/// A particle's gather: `(v_p, B_p, sum v_i grad w_ip^T)` from its window and stencil.
pub(crate) type Gathered<const D: usize> = (Vector<D>, Mat<D>, Mat<D>);

/// G2P of one chunk of sorted slots, with `gather` the particles' gather.
#[inline(always)]
pub(crate) fn g2p_chunk<const D: usize, K: Spline, const APIC: bool>(
    grid: &SparseGrid<D>,
    st: &Particles<D>,
    ctx: &Ctx<'_, D>,
    chunk: usize,
    o: ChunkOut<'_>,
    gather: impl Fn(&[f32x4], &Stencil<D>) -> Gathered<D>,
) -> G2pOutcome {
    let wn = SparseGrid::<D>::WN;
    let d_inv = K::D_INV * ctx.inv_h * ctx.inv_h;
    let dd = D * D;
    let (order, slot_block, pcoords, windows) = (&grid.order, &grid.slot_block, &grid.pcoords, &grid.windows);
    let ChunkOut { x, v, c, f, plastic: pl, mass, volume: vol, material: mat, id, remove: rm } = o;
    // Sorted slot `s` of the particle `order[s]`: its new state, and whether it left the domain.
    let particle = |s: usize, x: &mut [f32], v: &mut [f32], c: &mut [f32], f: &mut [f32], pl: &mut f32| {
        let p = order[s] as usize;
        let j = slot_block[s] as usize;
        let block = pcoords[j];
        let win = &windows[j * wn..(j + 1) * wn];
        let xp = &st.x[p * D..p * D + D];
        let sten = stencil::<D, K>(xp, ctx.inv_h, ctx.h, &block);
        let (vel, b, grad) = gather(win, &sten);
        let cmat = b * d_inv;
        let l = if APIC { grad } else { cmat };
        let mat = &ctx.materials[st.material[p] as usize];
        let mut fnew = (Mat::<D>::identity() + l * ctx.dt) * st.deformation(p);
        let mut plastic = st.plastic[p];
        project(mat, &mut fnew, &mut plastic);
        let mut xnew = Vector::<D>::from_column_slice(xp) + vel * ctx.dt;
        // A finite coordinate outside `[lo, hi]` is clamped (without a branch); a non-finite
        // one is left for the check below.
        let mut outside = false;
        for a in 0..D {
            let c = xnew[a];
            let out = (c < ctx.lo || c > ctx.hi) && c.is_finite();
            outside |= out;
            let clamped = if c < ctx.lo {
                ctx.lo
            } else if c > ctx.hi {
                ctx.hi
            } else {
                c
            };
            xnew[a] = if out { clamped } else { c };
        }
        x.copy_from_slice(xnew.as_slice());
        v.copy_from_slice(vel.as_slice());
        c.copy_from_slice(cmat.as_slice());
        f.copy_from_slice(fnew.as_slice());
        *pl = plastic;
        outside
    };
    let mut r = G2pOutcome { outside: 0, first_bad: u32::MAX };
    let s0 = chunk * G2P_CHUNK;
    for i in 0..pl.len() {
        let s = s0 + i;
        let outside = particle(
            s,
            &mut x[i * D..i * D + D],
            &mut v[i * D..i * D + D],
            &mut c[i * dd..i * dd + dd],
            &mut f[i * dd..i * dd + dd],
            &mut pl[i],
        );
        rm[i] = outside;
        r.outside += u64::from(outside);
    }
    // The particle constants follow the sorted order: a block copy where the chunk's
    // particles kept their order (most chunks, the state being sorted by the previous
    // step), else one by one.
    let n = pl.len();
    let order = &order[s0..s0 + n];
    let p0 = order[0] as usize;
    if order.iter().enumerate().all(|(i, &p)| p as usize == p0 + i) {
        mass.copy_from_slice(&st.mass[p0..p0 + n]);
        vol.copy_from_slice(&st.volume[p0..p0 + n]);
        mat.copy_from_slice(&st.material[p0..p0 + n]);
        id.copy_from_slice(&st.id[p0..p0 + n]);
    } else {
        for (i, &p) in order.iter().enumerate() {
            let p = p as usize;
            mass[i] = st.mass[p];
            vol[i] = st.volume[p];
            mat[i] = st.material[p];
            id[i] = st.id[p];
        }
    }
    // Non-finite results, checked once per chunk off the particles' dependency chains
    // (`|bits| >= 0x7f80_0000` is an infinity or a NaN).
    let worst = |a: &[f32]| a.iter().fold(0u32, |m, c| m.max(c.to_bits() & 0x7fff_ffff));
    if worst(x).max(worst(v)).max(worst(c)).max(worst(f)).max(worst(pl)) >= 0x7f80_0000 {
        let bad = (0..pl.len()).find(|&i| {
            worst(&x[i * D..i * D + D])
                .max(worst(&v[i * D..i * D + D]))
                .max(worst(&c[i * dd..i * dd + dd]))
                .max(worst(&f[i * dd..i * dd + dd]))
                .max(worst(std::slice::from_ref(&pl[i])))
                >= 0x7f80_0000
        });
        r.first_bad = bad.map_or(u32::MAX, |i| (s0 + i) as u32);
    }
    r
}
