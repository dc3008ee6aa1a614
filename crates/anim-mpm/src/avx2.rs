//! AVX2 variants of the P2G and G2P kernels, chosen at run time when the CPU has AVX2 (see
//! [`Avx2::detect`](crate::simd::Avx2::detect)).
//!
//! The whole per-block P2G and per-chunk G2P loops are compiled with AVX2 enabled (VEX
//! encoding, wider registers for the scalar parts). In 2D the stencil rows use 256-bit
//! registers explicitly: P2G builds the contributions of two neighbouring nodes of a row in one
//! register (`[node i | node i + 1]`) and adds them to the window with one load and one store;
//! G2P multiplies each node, loaded into both halves of a register, by `[w_i | w_i dx_i]`, so the
//! sums `sum w v` and `sum w dx v` of a row advance together. Every lane does the operations of
//! the portable kernels in the same order (no fused multiply-adds), so the results are bitwise
//! identical to theirs; a test runs both paths and compares the states bit for bit.

use crate::grid::SparseGrid;
use crate::kernel::Spline;
use crate::particle_transfer::{
    ChunkOut, Ctx, G2pOutcome, Gathered, Stencil, g2p_gather, gathered, p2g_particle, p2g_prepare, span,
    splat, wstride,
};
use crate::particles::Particles;
use crate::simd::Avx2;
use std::arch::x86_64::{
    __m128, __m256, _mm_add_ps, _mm_mul_ps, _mm_set1_ps, _mm_setzero_ps, _mm256_add_ps,
    _mm256_castps256_ps128, _mm256_extractf128_ps, _mm256_mul_ps, _mm256_set_m128, _mm256_set1_ps,
    _mm256_setzero_ps,
};
use wide::f32x4;

#[inline(always)]
fn m128(v: f32x4) -> __m128 {
    bytemuck::cast(v)
}

#[inline(always)]
fn v4(m: __m128) -> f32x4 {
    bytemuck::cast(m)
}

/// P2G of one particle block, as [`crate::particle_transfer::p2g_block`].
#[allow(unsafe_code)]
pub(crate) fn p2g_block<const D: usize, K: Spline, const APIC: bool>(
    _cpu: Avx2,
    win: &mut [f32x4],
    st: &Particles<D>,
    slots: &[u32],
    block: &[i32; D],
    ctx: &Ctx<'_, D>,
) {
    // SAFETY: `p2g_block_k` only needs AVX2, whose presence `_cpu` proves: an `Avx2` is made by
    // `Avx2::detect` alone, after the run-time check.
    unsafe { p2g_block_k::<D, K, APIC>(win, st, slots, block, ctx) }
}

#[target_feature(enable = "avx2")]
fn p2g_block_k<const D: usize, K: Spline, const APIC: bool>(
    win: &mut [f32x4],
    st: &Particles<D>,
    slots: &[u32],
    block: &[i32; D],
    ctx: &Ctx<'_, D>,
) {
    win.fill(f32x4::ZERO);
    for &p in slots {
        if D == 2 {
            p2g_particle_2d::<D, K, APIC>(win, st, p as usize, block, ctx);
        } else {
            p2g_particle::<D, K, APIC>(win, st, p as usize, block, ctx);
        }
    }
}

/// `[lo | hi]`.
#[target_feature(enable = "avx2")]
#[inline]
fn pair(lo: __m128, hi: __m128) -> __m256 {
    _mm256_set_m128(hi, lo)
}

/// The 2D scatter (`D == 2`; generic only so that it fits the callers): the portable kernel's
/// operations, two nodes of a stencil row per register.
#[target_feature(enable = "avx2")]
#[inline]
fn p2g_particle_2d<const D: usize, K: Spline, const APIC: bool>(
    win: &mut [f32x4],
    st: &Particles<D>,
    p: usize,
    block: &[i32; D],
    ctx: &Ctx<'_, D>,
) {
    let (s, q, acol, scol) = p2g_prepare::<D, K, APIC>(st, p, block, ctx);
    let n = K::N;
    let win = &mut win[s.base..s.base + span(D, K::N)];
    let a0 = m128(acol[0]);
    let a0d = pair(a0, a0);
    // Per pair of x nodes (0, 1), (2, 3): dx, w, dw.
    let two = |v: &[f32; 4], k: usize| pair(_mm_set1_ps(v[2 * k]), _mm_set1_ps(v[2 * k + 1]));
    let dxp = [two(&s.dx[0], 0), two(&s.dx[0], 1)];
    let wp = [two(&s.w[0], 0), two(&s.w[0], 1)];
    let dwp = [two(&s.dw[0], 0), two(&s.dw[0], 1)];
    for j in 0..n {
        let wy = s.w[1][j];
        let r = q + acol[1] * splat(s.dx[1][j]);
        let (g0, g1) = if APIC { (scol[0] * splat(wy), scol[1] * splat(s.dw[1][j])) } else { (q, q) };
        let row = j * wstride(1);
        let rd = pair(m128(r), m128(r));
        let wyd = _mm256_set1_ps(wy);
        let mut i = 0;
        while i + 1 < n {
            let k = i / 2;
            let mut t =
                _mm256_mul_ps(_mm256_add_ps(rd, _mm256_mul_ps(a0d, dxp[k])), _mm256_mul_ps(wp[k], wyd));
            if APIC {
                let (g0, g1) = (m128(g0), m128(g1));
                t = _mm256_add_ps(
                    t,
                    _mm256_add_ps(_mm256_mul_ps(pair(g0, g0), dwp[k]), _mm256_mul_ps(pair(g1, g1), wp[k])),
                );
            }
            let cur: __m256 = bytemuck::cast([win[row + i], win[row + i + 1]]);
            let [lo, hi]: [f32x4; 2] = bytemuck::cast(_mm256_add_ps(cur, t));
            win[row + i] = lo;
            win[row + i + 1] = hi;
            i += 2;
        }
        if i < n {
            let mut t = (r + acol[0] * splat(s.dx[0][i])) * splat(s.w[0][i] * wy);
            if APIC {
                t += g0 * splat(s.dw[0][i]) + g1 * splat(s.w[0][i]);
            }
            win[row + i] += t;
        }
    }
}

/// G2P of one chunk, as the portable path of `transfer::g2p`.
#[allow(unsafe_code)]
pub(crate) fn g2p_chunk<const D: usize, K: Spline, const APIC: bool>(
    _cpu: Avx2,
    grid: &SparseGrid<D>,
    st: &Particles<D>,
    ctx: &Ctx<'_, D>,
    chunk: usize,
    o: ChunkOut<'_>,
) -> G2pOutcome {
    // SAFETY: `g2p_chunk_k` only needs AVX2, whose presence `_cpu` proves (see `p2g_block`).
    unsafe { g2p_chunk_k::<D, K, APIC>(grid, st, ctx, chunk, o) }
}

#[target_feature(enable = "avx2")]
fn g2p_chunk_k<const D: usize, K: Spline, const APIC: bool>(
    grid: &SparseGrid<D>,
    st: &Particles<D>,
    ctx: &Ctx<'_, D>,
    chunk: usize,
    o: ChunkOut<'_>,
) -> G2pOutcome {
    let inv_h = ctx.inv_h;
    crate::particle_transfer::g2p_chunk::<D, K, APIC>(grid, st, ctx, chunk, o, |win, s| {
        if D == 2 { gather_2d::<D, K, APIC>(win, s, inv_h) } else { g2p_gather::<D, K, APIC>(win, s, inv_h) }
    })
}

/// The 2D gather (`D == 2`): per row, `[sum w v | sum w dx v]` in one register.
#[target_feature(enable = "avx2")]
#[inline]
fn gather_2d<const D: usize, K: Spline, const APIC: bool>(
    win: &[f32x4],
    s: &Stencil<D>,
    inv_h: f32,
) -> Gathered<D> {
    let n = K::N;
    let mut wdx = [[0.0f32; 4]; 2];
    for a in 0..2 {
        for k in 0..n {
            wdx[a][k] = s.w[a][k] * s.dx[a][k];
        }
    }
    let win = &win[s.base..s.base + span(D, K::N)];
    let wx: [__m256; 4] = std::array::from_fn(|i| pair(_mm_set1_ps(s.w[0][i]), _mm_set1_ps(wdx[0][i])));
    // [vel | bcol[0]].
    let mut vb = _mm256_setzero_ps();
    let mut b1 = _mm_setzero_ps();
    let (mut g0, mut g1) = (_mm_setzero_ps(), _mm_setzero_ps());
    for j in 0..n {
        let row = j * wstride(1);
        let mut s01 = _mm256_setzero_ps();
        let mut s2 = _mm_setzero_ps();
        for i in 0..n {
            let node = m128(win[row + i]);
            s01 = _mm256_add_ps(s01, _mm256_mul_ps(pair(node, node), wx[i]));
            if APIC {
                s2 = _mm_add_ps(s2, _mm_mul_ps(node, _mm_set1_ps(s.dw[0][i])));
            }
        }
        let wy = _mm256_set1_ps(s.w[1][j]);
        vb = _mm256_add_ps(vb, _mm256_mul_ps(s01, wy));
        let s0 = _mm256_castps256_ps128(s01);
        b1 = _mm_add_ps(b1, _mm_mul_ps(s0, _mm_set1_ps(wdx[1][j])));
        if APIC {
            g0 = _mm_add_ps(g0, _mm_mul_ps(s2, _mm256_castps256_ps128(wy)));
            g1 = _mm_add_ps(g1, _mm_mul_ps(s0, _mm_set1_ps(s.dw[1][j])));
        }
    }
    let vel = v4(_mm256_castps256_ps128(vb));
    let b0 = v4(_mm256_extractf128_ps::<1>(vb));
    let (b1, g0, g1) = (v4(b1), v4(g0), v4(g1));
    let bcol: [f32x4; D] = std::array::from_fn(|a| if a == 0 { b0 } else { b1 });
    let gcol: [f32x4; D] = std::array::from_fn(|a| if a == 0 { g0 } else { g1 });
    gathered::<D, APIC>(vel, bcol, gcol, inv_h)
}
