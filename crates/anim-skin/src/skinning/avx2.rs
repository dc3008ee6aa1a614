//! AVX2 + FMA kernels: four vertices per 256-bit register, chosen at run time when the CPU has
//! both extensions (see [`Avx2Fma::detect`]).
//!
//! The structure follows the portable kernels of the parent module: each vertex blends its
//! joints' data along the matrix rows (LBS: a row of the 3x4 matrix is one register, three
//! fused multiply-adds per influence) or along the dual quaternion (DQS: two registers per
//! influence, the hemisphere signs of four influences found by one horizontal reduction);
//! four vertices' blends are transposed so the transform runs one vertex per lane. Lanes never
//! mix, and the vertices past the end of a chunk that is not a multiple of four repeat its last
//! vertex, so a vertex's result does not depend on its neighbours or on the chunking. Results
//! differ from the portable kernels' by rounding only (fused multiply-adds round once).

use crate::mesh::{MAX_INFLUENCES, SkinnedMesh};
use crate::skinning::outputs::Outputs;
use std::arch::x86_64::{
    __m256d, _CMP_GT_OQ, _mm256_add_pd, _mm256_and_pd, _mm256_blendv_pd, _mm256_cmp_pd, _mm256_div_pd,
    _mm256_fmadd_pd, _mm256_fmsub_pd, _mm256_mul_pd, _mm256_or_pd, _mm256_permute2f128_pd, _mm256_set1_pd,
    _mm256_setzero_pd, _mm256_sqrt_pd, _mm256_sub_pd, _mm256_unpackhi_pd, _mm256_unpacklo_pd,
};

type V = __m256d;
type V3 = [V; 3];

/// Proof that the running CPU has AVX2 and FMA: only [`Avx2Fma::detect`] makes one.
#[derive(Debug, Clone, Copy)]
pub(super) struct Avx2Fma(());

impl Avx2Fma {
    /// `Some` when the CPU supports AVX2 and FMA (detected once and cached by `std`).
    pub(super) fn detect() -> Option<Self> {
        (std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma")).then_some(Self(()))
    }
}

/// The per-pose joint data the kernels read.
pub(super) struct Tables<'a> {
    /// Row-major 3x4 skinning matrices, one row per register.
    pub(super) mats: &'a [[[f64; 4]; 3]],
    /// Each joint's dual quaternion `[(qx, qy, qz, qw), (dx, dy, dz, dw)]` (entry `2 j`) and
    /// its negation (entry `2 j + 1`).
    pub(super) signed: &'a [[[f64; 4]; 2]],
    /// `pairs[a * joints + b]`: the entry of `signed` for joint `b` in joint `a`'s hemisphere.
    pub(super) pairs: &'a [u16],
    /// Joints in the skin.
    pub(super) joints: usize,
}

/// Skins one chunk of vertices starting at mesh vertex `start` with the AVX2 kernels.
/// `mats` are the row-major 3x4 skinning matrices, `dqs` the dual quaternions
/// `(qx, qy, qz, qw, dx, dy, dz, dw)`, one per skin joint.
#[allow(unsafe_code)]
pub(super) fn chunk(
    _cpu: Avx2Fma,
    lbs: bool,
    k: usize,
    t: &Tables<'_>,
    mesh: &SkinnedMesh,
    start: usize,
    o: Outputs<'_>,
) {
    // SAFETY: `chunk_k` only needs AVX2 and FMA, whose presence `_cpu` proves: an `Avx2Fma` is
    // made by `Avx2Fma::detect` alone, after the run-time check.
    unsafe { chunk_k(lbs, k, t, mesh, start, o) }
}

#[target_feature(enable = "avx2,fma")]
fn chunk_k(lbs: bool, k: usize, t: &Tables<'_>, mesh: &SkinnedMesh, start: usize, o: Outputs<'_>) {
    macro_rules! by_k {
        ($($n:literal),*) => {
            match (lbs, k) {
                $((true, $n) => run::<$n, true>(t, mesh, start, o),
                  (false, $n) => run::<$n, false>(t, mesh, start, o),)*
                (true, _) => run::<MAX_INFLUENCES, true>(t, mesh, start, o),
                (false, _) => run::<MAX_INFLUENCES, false>(t, mesh, start, o),
            }
        };
    }
    by_k!(1, 2, 3, 4, 5, 6, 7);
}

#[inline]
#[target_feature(enable = "avx2,fma")]
fn run<const K: usize, const LBS: bool>(t: &Tables<'_>, mesh: &SkinnedMesh, start: usize, o: Outputs<'_>) {
    let len = o.x.len();
    let end = start + len;
    let (js, ws) = (&mesh.joints()[start * K..end * K], &mesh.weights()[start * K..end * K]);
    let dominant = &mesh.dominant_slots()[start..end];
    let input = [&mesh.x, &mesh.y, &mesh.z, &mesh.nx, &mesh.ny, &mesh.nz].map(|s| &s[start..end]);
    let full = len / 4 * 4;
    let [ox, oy, oz, onx, ony, onz] = [o.x, o.y, o.z, o.nx, o.ny, o.nz];
    let (ox, ox_tail) = ox.split_at_mut(full);
    let (oy, oy_tail) = oy.split_at_mut(full);
    let (oz, oz_tail) = oz.split_at_mut(full);
    let (onx, onx_tail) = onx.split_at_mut(full);
    let (ony, ony_tail) = ony.split_at_mut(full);
    let (onz, onz_tail) = onz.split_at_mut(full);
    groups::<K, LBS>(
        t,
        input.map(|s| &s[..full]),
        (&js[..full * K], &ws[..full * K], &dominant[..full]),
        [ox, oy, oz, onx, ony, onz],
    );
    if full < len {
        // The last vertices of a chunk whose length is not a multiple of four: one group, the
        // last vertex repeated in the unused lanes.
        let (mut jt, mut wt) = ([0u16; 4 * MAX_INFLUENCES], [0.0; 4 * MAX_INFLUENCES]);
        let (mut pt, mut dt, mut out) = ([[0.0; 4]; 6], [0u8; 4], [[0.0; 4]; 6]);
        for l in 0..4 {
            let v = (full + l).min(len - 1);
            jt[l * K..(l + 1) * K].copy_from_slice(&js[v * K..(v + 1) * K]);
            wt[l * K..(l + 1) * K].copy_from_slice(&ws[v * K..(v + 1) * K]);
            dt[l] = dominant[v];
            for (d, s) in input.iter().enumerate() {
                pt[d][l] = s[v];
            }
        }
        let [o0, o1, o2, o3, o4, o5] = &mut out;
        groups::<K, LBS>(
            t,
            [&pt[0], &pt[1], &pt[2], &pt[3], &pt[4], &pt[5]],
            (&jt[..4 * K], &wt[..4 * K], &dt),
            [o0, o1, o2, o3, o4, o5],
        );
        for (tail, o) in [ox_tail, oy_tail, oz_tail, onx_tail, ony_tail, onz_tail].into_iter().zip(&out) {
            tail.copy_from_slice(&o[..len - full]);
        }
    }
}

/// Skins whole groups of four vertices: `input` (rest positions and normals), the joints,
/// weights and dominant slots, and `output` all hold a multiple of four vertices.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn groups<const K: usize, const LBS: bool>(
    t: &Tables<'_>,
    input: [&[f64]; 6],
    (js, ws, dominant): (&[u16], &[f64], &[u8]),
    output: [&mut [f64]; 6],
) {
    let [x, y, z, nx, ny, nz] = input;
    let [ox, oy, oz, onx, ony, onz] = output;
    let ins = x
        .chunks_exact(4)
        .zip(y.chunks_exact(4))
        .zip(z.chunks_exact(4))
        .zip(nx.chunks_exact(4))
        .zip(ny.chunks_exact(4))
        .zip(nz.chunks_exact(4));
    let outs = ox
        .chunks_exact_mut(4)
        .zip(oy.chunks_exact_mut(4))
        .zip(oz.chunks_exact_mut(4))
        .zip(onx.chunks_exact_mut(4))
        .zip(ony.chunks_exact_mut(4))
        .zip(onz.chunks_exact_mut(4));
    let infl = js.chunks_exact(4 * K).zip(ws.chunks_exact(4 * K)).zip(dominant.chunks_exact(4));
    for (((((((x, y), z), nx), ny), nz), (((((ox, oy), oz), onx), ony), onz)), ((jg, wg), dg)) in
        ins.zip(outs).zip(infl)
    {
        let p = [load4(x), load4(y), load4(z)];
        let n = [load4(nx), load4(ny), load4(nz)];
        let (q, m) = if LBS {
            lbs_group::<K>(t.mats, jg, wg, p, n)
        } else {
            dqs_group::<K>(t, jg, wg, [dg[0], dg[1], dg[2], dg[3]], p, n)
        };
        store4(ox, q[0]);
        store4(oy, q[1]);
        store4(oz, q[2]);
        store4(onx, m[0]);
        store4(ony, m[1]);
        store4(onz, m[2]);
    }
}

/// A four-value slice as one register.
#[inline]
fn load4(s: &[f64]) -> V {
    s.first_chunk::<4>().map_or(bytemuck::cast([0.0f64; 4]), load)
}

/// A register into a four-value slice.
#[inline]
fn store4(out: &mut [f64], r: V) {
    if let Some(o) = out.first_chunk_mut::<4>() {
        *o = lanes(r);
    }
}

/// Four contiguous values as one register (one unaligned vector load).
#[inline]
fn load(s: &[f64; 4]) -> V {
    bytemuck::cast(*s)
}

#[inline]
fn lanes(v: V) -> [f64; 4] {
    bytemuck::cast(v)
}

/// Transposes four registers: lane `l` of output `c` is lane `c` of input `l`.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn transpose(r: [V; 4]) -> [V; 4] {
    let t0 = _mm256_unpacklo_pd(r[0], r[1]);
    let t1 = _mm256_unpackhi_pd(r[0], r[1]);
    let t2 = _mm256_unpacklo_pd(r[2], r[3]);
    let t3 = _mm256_unpackhi_pd(r[2], r[3]);
    [
        _mm256_permute2f128_pd::<0x20>(t0, t2),
        _mm256_permute2f128_pd::<0x20>(t1, t3),
        _mm256_permute2f128_pd::<0x31>(t0, t2),
        _mm256_permute2f128_pd::<0x31>(t1, t3),
    ]
}

/// `a b + c`.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn fma(a: V, b: V, c: V) -> V {
    _mm256_fmadd_pd(a, b, c)
}

/// `a . b` of two 3-vectors, one per lane.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn dot3(a: V3, b: V3) -> V {
    fma(a[0], b[0], fma(a[1], b[1], _mm256_mul_pd(a[2], b[2])))
}

/// `m |m|^-1 s` per lane (`m` unchanged where `|m| = 0`).
#[inline]
#[target_feature(enable = "avx2,fma")]
fn normalized(m: V3, sign: V) -> V3 {
    let len = _mm256_sqrt_pd(dot3(m, m));
    let nonzero = _mm256_cmp_pd::<_CMP_GT_OQ>(len, _mm256_setzero_pd());
    let s = _mm256_blendv_pd(_mm256_set1_pd(1.0), _mm256_div_pd(sign, len), nonzero);
    [_mm256_mul_pd(m[0], s), _mm256_mul_pd(m[1], s), _mm256_mul_pd(m[2], s)]
}

/// LBS of four vertices: `jg`, `wg` hold their `K` joints and weights each, one after another.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn lbs_group<const K: usize>(mats: &[[[f64; 4]; 3]], jg: &[u16], wg: &[f64], p: V3, n: V3) -> (V3, V3) {
    let (jg, wg) = (&jg[..4 * K], &wg[..4 * K]);
    let mut rows = [[_mm256_setzero_pd(); 4]; 3];
    for l in 0..4 {
        let (js, ws) = (&jg[l * K..(l + 1) * K], &wg[l * K..(l + 1) * K]);
        let m = &mats[usize::from(js[0])];
        let w = _mm256_set1_pd(ws[0]);
        let mut b =
            [_mm256_mul_pd(w, load(&m[0])), _mm256_mul_pd(w, load(&m[1])), _mm256_mul_pd(w, load(&m[2]))];
        for i in 1..K {
            let m = &mats[usize::from(js[i])];
            let w = _mm256_set1_pd(ws[i]);
            b = [fma(w, load(&m[0]), b[0]), fma(w, load(&m[1]), b[1]), fma(w, load(&m[2]), b[2])];
        }
        for r in 0..3 {
            rows[r][l] = b[r];
        }
    }
    let [a00, a01, a02, a03] = transpose(rows[0]);
    let [a10, a11, a12, a13] = transpose(rows[1]);
    let [a20, a21, a22, a23] = transpose(rows[2]);
    let q = [
        fma(a00, p[0], fma(a01, p[1], fma(a02, p[2], a03))),
        fma(a10, p[0], fma(a11, p[1], fma(a12, p[2], a13))),
        fma(a20, p[0], fma(a21, p[1], fma(a22, p[2], a23))),
    ];
    // Cofactor matrix of the 3x3 block: cof(A) = det(A) A^-T.
    let c = |a: V, b: V, c: V, d: V| _mm256_fmsub_pd(a, b, _mm256_mul_pd(c, d));
    let c00 = c(a11, a22, a12, a21);
    let c01 = c(a12, a20, a10, a22);
    let c02 = c(a10, a21, a11, a20);
    let c10 = c(a02, a21, a01, a22);
    let c11 = c(a00, a22, a02, a20);
    let c12 = c(a01, a20, a00, a21);
    let c20 = c(a01, a12, a02, a11);
    let c21 = c(a02, a10, a00, a12);
    let c22 = c(a00, a11, a01, a10);
    let det = dot3([a00, a01, a02], [c00, c01, c02]);
    let m = [dot3([c00, c01, c02], n), dot3([c10, c11, c12], n), dot3([c20, c21, c22], n)];
    // sign(det) as +-1 (copysign(1, det)).
    let sign = _mm256_or_pd(_mm256_and_pd(det, _mm256_set1_pd(-0.0)), _mm256_set1_pd(1.0));
    (q, normalized(m, sign))
}

/// DQS of four vertices.
#[inline]
#[target_feature(enable = "avx2,fma")]
fn dqs_group<const K: usize>(t: &Tables<'_>, jg: &[u16], wg: &[f64], dom: [u8; 4], p: V3, n: V3) -> (V3, V3) {
    let (jg, wg) = (&jg[..4 * K], &wg[..4 * K]);
    let zero = _mm256_setzero_pd();
    let mut bq = [zero; 4];
    let mut bd = [zero; 4];
    for l in 0..4 {
        let (js, ws) = (&jg[l * K..(l + 1) * K], &wg[l * K..(l + 1) * K]);
        let dominant = usize::from(js[usize::from(dom[l]).min(K - 1)]);
        // Each influence's dual quaternion taken with the sign that puts it in the dominant
        // one's hemisphere (the pose's sign table), so the blend needs no shuffles.
        let row = dominant * t.joints;
        // Two accumulators each (even and odd slots) halve the chain of dependent additions.
        let mut acc = [[zero; 2]; 2];
        for i in 0..K {
            let e = &t.signed[usize::from(t.pairs[row + usize::from(js[i])])];
            let w = _mm256_set1_pd(ws[i]);
            let a = &mut acc[i % 2];
            if i < 2 {
                *a = [_mm256_mul_pd(w, load(&e[0])), _mm256_mul_pd(w, load(&e[1]))];
            } else {
                *a = [fma(w, load(&e[0]), a[0]), fma(w, load(&e[1]), a[1])];
            }
        }
        let (q, d) = if K == 1 {
            (acc[0][0], acc[0][1])
        } else {
            (_mm256_add_pd(acc[0][0], acc[1][0]), _mm256_add_pd(acc[0][1], acc[1][1]))
        };
        bq[l] = q;
        bd[l] = d;
    }
    let [rx, ry, rz, rw] = transpose(bq);
    let [dx, dy, dz, dw] = transpose(bd);
    // As the portable kernel: p' = [(w^2 - r.r) p + 2 (r.p) r + 2 w (r x p)
    //   + 2 (w d - w_d r + r x d)] / l2, n' ∝ (w^2 - r.r) n + 2 (r.n) r + 2 w (r x n).
    let two = _mm256_set1_pd(2.0);
    let r3 = [rx, ry, rz];
    let rr = dot3(r3, r3);
    let l2 = fma(rw, rw, rr);
    let c = _mm256_fmsub_pd(rw, rw, rr);
    let tw = _mm256_mul_pd(two, rw);
    let rotate = |v: V3| {
        let rv = _mm256_mul_pd(two, dot3(r3, v));
        let cross = [
            _mm256_fmsub_pd(ry, v[2], _mm256_mul_pd(rz, v[1])),
            _mm256_fmsub_pd(rz, v[0], _mm256_mul_pd(rx, v[2])),
            _mm256_fmsub_pd(rx, v[1], _mm256_mul_pd(ry, v[0])),
        ];
        [
            fma(c, v[0], fma(rv, rx, _mm256_mul_pd(tw, cross[0]))),
            fma(c, v[1], fma(rv, ry, _mm256_mul_pd(tw, cross[1]))),
            fma(c, v[2], fma(rv, rz, _mm256_mul_pd(tw, cross[2]))),
        ]
    };
    let t = |rw_d: V, dw_r: V, a: V, b: V, c2: V, d2: V| {
        // 2 (rw d - dw r + a b - c d)
        let u = _mm256_fmsub_pd(a, b, _mm256_mul_pd(c2, d2));
        _mm256_mul_pd(two, _mm256_add_pd(_mm256_sub_pd(rw_d, dw_r), u))
    };
    let tr = [
        t(_mm256_mul_pd(rw, dx), _mm256_mul_pd(dw, rx), ry, dz, rz, dy),
        t(_mm256_mul_pd(rw, dy), _mm256_mul_pd(dw, ry), rz, dx, rx, dz),
        t(_mm256_mul_pd(rw, dz), _mm256_mul_pd(dw, rz), rx, dy, ry, dx),
    ];
    let r = rotate(p);
    let m = rotate(n);
    let len = _mm256_sqrt_pd(dot3(m, m));
    let one = _mm256_set1_pd(1.0);
    let nonzero = _mm256_cmp_pd::<_CMP_GT_OQ>(len, zero);
    let len = _mm256_blendv_pd(one, len, nonzero);
    let z = _mm256_div_pd(one, _mm256_mul_pd(l2, len));
    let inv_l2 = _mm256_mul_pd(z, len);
    let inv_len = _mm256_blendv_pd(one, _mm256_mul_pd(z, l2), nonzero);
    (
        [
            _mm256_mul_pd(_mm256_add_pd(r[0], tr[0]), inv_l2),
            _mm256_mul_pd(_mm256_add_pd(r[1], tr[1]), inv_l2),
            _mm256_mul_pd(_mm256_add_pd(r[2], tr[2]), inv_l2),
        ],
        [_mm256_mul_pd(m[0], inv_len), _mm256_mul_pd(m[1], inv_len), _mm256_mul_pd(m[2], inv_len)],
    )
}
