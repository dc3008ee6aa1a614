//! Linear blend skinning (LBS) and dual-quaternion skinning (DQS).
//!
//! With skinning matrices `M_j = G_j B_j^-1` and a vertex's normalised weights `w_i` on joints
//! `j_i`:
//!
//! - **LBS**: `p' = (sum_i w_i M_{j_i}) p`. Normals: `n' ∝ A^-T n` with `A` the blended 3x3
//!   block (computed as `sign(det A) cof(A) n`, then normalised), correct for non-uniform scale.
//!   Blending matrices is not a rotation: under large twists the blend shrinks towards the axis
//!   (the "candy-wrapper" collapse, see [`crate::scenes::twisted_cylinder`]).
//! - **DQS** (Kavan et al. 2008): each rigid `M_j` becomes a unit dual quaternion `q_j + ε d_j`;
//!   the vertex blends `b = sum_i s_i w_i (q_{j_i} + ε d_{j_i})` with `s_i = ±1` chosen so every
//!   `q_{j_i}` lies in the hemisphere of the dominant (largest-weight) influence's quaternion
//!   (antipodal quaternions describe the same rotation, and blending them unaligned cancels),
//!   then normalises by `|b_0|` and applies the rigid motion. Normals are rotated by the blended
//!   rotation. DQS needs rigid joint transforms: a skinning matrix whose 3x3 block is not a
//!   rotation within a tolerance (scale, shear, reflection) is rejected with
//!   [`SkinError::NonRigidJoint`]; use LBS for scaled joints. The tolerance bounds the largest
//!   entry of `|R^T R - I|` of the 3x3 block `R` ([`RIGID_TOLERANCE`] by default, set per mesh
//!   with [`Skinned::set_rigid_tolerance`]); a block within it is replaced by its nearest
//!   rotation (the polar decomposition's rotation factor) before conversion, so exporter noise
//!   (a joint scale of `1.00001`, inverse bind matrices stored in f32) is absorbed rather than
//!   refused. LBS uses the matrices as they are, so on such data the two differ at single-influence
//!   vertices by about the deviation times the vertex's distance from the joint.
//!
//! Both run in parallel over fixed chunks of [`CHUNK`] vertices; each vertex is computed by the
//! same sequence of operations whatever the chunk's thread, so results are bitwise identical for
//! any thread count. [`Skinned`] holds the per-joint blend data and the outputs, sized once per
//! mesh: skinning allocates nothing.
//!
//! ## Kernels
//!
//! Two implementations, chosen once per call: AVX2 + FMA kernels (module `avx2`, x86-64 CPUs
//! that have both, detected at run time) and portable kernels (every target, and
//! [`skin_portable`] on any CPU). Their results differ by rounding only (fused multiply-adds
//! round once); each is bitwise identical for any thread count.
//!
//! The portable kernels process vertices in pairs, one per lane of a two-wide f64 SIMD register
//! (`wide`'s `f64x2`: SSE2 on x86-64). Each vertex first blends its joints' data along the
//! matrix rows (LBS: 3x4 matrix as six register pairs) or quaternion components (DQS: four
//! pairs); the pair's blends are transposed so the rest (transform, cofactor normal, rotations,
//! normalisation) runs one vertex per lane with no branches: the DQS hemisphere test is a sign
//! bit flip, zero-weight slots add `0 * M_0`, zero normals are kept by a select. DQS uses the
//! unnormalised blend directly (`q v q* / |q|^2`), so one square root and one division per
//! vertex normalise both the rigid motion and the normal. Lanes never mix, and an odd
//! vertex is computed in both lanes, so a vertex's result does not depend on its neighbour.
//!
//! The AVX2 kernels do the same four vertices at a time: an LBS matrix row is one register (three
//! fused multiply-adds per influence). For DQS the hemisphere tests are made once per pose for
//! every joint pair (a `J x J` table of `u16`, skins of up to [`SIGN_TABLE_JOINTS`] joints; larger
//! skins use the portable kernel), each joint's dual quaternion is kept with both signs, and each
//! vertex's dominant slot is derived once from its weights ([`SkinnedMesh::dominant_slots`]): the
//! blend is then two loads and two fused multiply-adds per influence, with no shuffles.
//!
//! Throughput (100,000 vertices, 4 influences, the mesh of `benches/benches/skin.rs`; `cargo
//! bench -p anim-benches --bench skin` prints these comparisons): the time of each kernel over
//! the time of a pass that only streams the same 136 bytes per vertex, on this project's 2-core
//! machine. Criterion medians, 1 thread: AVX2 LBS 771 us and DQS 1009 us against the stream's
//! 658 us (1.17x, 1.53x); 2 threads: 385 and 524 us against 311 us (1.24x, 1.69x). Fastest of
//! 200 interleaved rounds, four runs: AVX2 LBS 0.99-1.18x (1 thread), 1.16-1.39x (2 threads);
//! DQS 1.24-1.42x and 1.50-1.76x; the portable kernels 2.09-2.59x (LBS) and 2.84-3.54x (DQS)
//! on 1 thread.

use crate::SkinError;
use crate::mesh::{MAX_INFLUENCES, SkinnedMesh};
use anim_core::glam::{DMat3, DMat4, DQuat};
use anim_core::linalg::svd::polar;
use anim_core::par::prelude::*;
use wide::f64x2;

#[cfg(target_arch = "x86_64")]
mod avx2;
mod outputs;

use outputs::Outputs;

/// Vertices per parallel task.
pub const CHUNK: usize = 2048;

/// Default largest entry of `|R^T R - I|` (and of the bottom row's deviation from `(0, 0, 0, 1)`)
/// accepted as rigid by DQS; `R` is then re-orthonormalised. A uniform scale `s` gives
/// `|s^2 - 1|`, so `1e-4` admits scales within about `5e-5` of 1 and refuses real scaling.
pub const RIGID_TOLERANCE: f64 = 1e-4;

/// DQS's rigidity tolerance of one [`Skinned`] (default [`RIGID_TOLERANCE`]).
#[derive(Debug, Clone, Copy, PartialEq)]
struct RigidTolerance(f64);

impl Default for RigidTolerance {
    fn default() -> Self {
        Self(RIGID_TOLERANCE)
    }
}

/// Which skinning algorithm.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum SkinningMethod {
    /// Linear blend skinning: fast, handles scale, collapses under twist.
    Lbs,
    /// Dual-quaternion skinning: keeps volume under twist, rigid joints only.
    Dqs,
}

impl std::str::FromStr for SkinningMethod {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "lbs" | "linear" => Ok(Self::Lbs),
            "dqs" | "dual-quaternion" => Ok(Self::Dqs),
            _ => Err(format!("unknown skinning method {s:?} (lbs or dqs)")),
        }
    }
}

/// Outputs and per-joint scratch of skinning one mesh: posed positions and unit normals as
/// structure-of-arrays.
#[derive(Debug, Clone, Default)]
pub struct Skinned {
    /// Posed positions, x.
    pub x: Vec<f64>,
    /// Posed positions, y.
    pub y: Vec<f64>,
    /// Posed positions, z.
    pub z: Vec<f64>,
    /// Posed unit normals, x.
    pub nx: Vec<f64>,
    /// Posed unit normals, y.
    pub ny: Vec<f64>,
    /// Posed unit normals, z.
    pub nz: Vec<f64>,
    /// Row-major 3x4 skinning matrices, two entries per SIMD value.
    mats: Vec<[f64x2; 6]>,
    /// Dual quaternions `(qx, qy | qz, qw | dx, dy | dz, dw)`.
    dqs: Vec<[f64x2; 4]>,
    /// Each joint's dual quaternion and its negation: entry `2 j` is `+(q_j, d_j)`, `2 j + 1`
    /// is `-(q_j, d_j)`, for the AVX2 DQS kernel.
    signed: Vec<[[f64; 4]; 2]>,
    /// `pairs[a * J + b]` is `2 b + 1` where joint `b`'s rotation quaternion is in the other
    /// hemisphere from joint `a`'s (`q_a . q_b < 0`), else `2 b`: the entry of `signed` a vertex
    /// dominated by joint `a` blends for joint `b`. The AVX2 DQS kernel's hemisphere test, made
    /// once per pose for all joint pairs; empty for skins of more than [`SIGN_TABLE_JOINTS`]
    /// joints.
    pairs: Vec<u16>,
    /// DQS's rigidity tolerance.
    rigid_tolerance: RigidTolerance,
}

/// Largest skin (in joints) for which the AVX2 DQS kernel keeps a joint-pair sign table
/// (`2 J^2` bytes, 128 KiB at most); larger skins use the portable DQS kernel.
pub const SIGN_TABLE_JOINTS: usize = 256;

impl Skinned {
    /// Buffers sized for `mesh`.
    #[must_use]
    pub fn new(mesh: &SkinnedMesh) -> Self {
        let n = mesh.len();
        Self {
            x: mesh.x.clone(),
            y: mesh.y.clone(),
            z: mesh.z.clone(),
            nx: mesh.nx.clone(),
            ny: mesh.ny.clone(),
            nz: mesh.nz.clone(),
            mats: vec![[f64x2::ZERO; 6]; mesh.num_joints()],
            dqs: vec![[f64x2::ZERO; 4]; mesh.num_joints()],
            signed: vec![[[0.0; 4]; 2]; 2 * mesh.num_joints()],
            pairs: if mesh.num_joints() <= SIGN_TABLE_JOINTS {
                vec![0; mesh.num_joints() * mesh.num_joints()]
            } else {
                Vec::new()
            },
            rigid_tolerance: RigidTolerance::default(),
        }
        .resized(n)
    }

    fn resized(mut self, n: usize) -> Self {
        for v in [&mut self.x, &mut self.y, &mut self.z, &mut self.nx, &mut self.ny, &mut self.nz] {
            v.resize(n, 0.0);
        }
        self
    }

    /// DQS's rigidity tolerance: the largest entry of `|R^T R - I|` of a skinning matrix's 3x3
    /// block `R` that DQS accepts (re-orthonormalising `R`) rather than refuses with
    /// [`SkinError::NonRigidJoint`].
    #[must_use]
    pub fn rigid_tolerance(&self) -> f64 {
        self.rigid_tolerance.0
    }

    /// Sets DQS's rigidity tolerance (default [`RIGID_TOLERANCE`]).
    ///
    /// # Errors
    /// [`SkinError::BadTolerance`] unless `0 <= tolerance < 1`.
    pub fn set_rigid_tolerance(&mut self, tolerance: f64) -> Result<(), SkinError> {
        if !(0.0..1.0).contains(&tolerance) {
            return Err(SkinError::BadTolerance { tolerance });
        }
        self.rigid_tolerance = RigidTolerance(tolerance);
        Ok(())
    }

    /// Posed position of vertex `v`.
    #[must_use]
    pub fn position(&self, v: usize) -> [f64; 3] {
        [self.x[v], self.y[v], self.z[v]]
    }

    /// Posed normal of vertex `v`.
    #[must_use]
    pub fn normal(&self, v: usize) -> [f64; 3] {
        [self.nx[v], self.ny[v], self.nz[v]]
    }
}

/// Skins `mesh` with the skinning matrices of its skin (one per skin joint) into `out`.
///
/// # Errors
/// [`SkinError::NonFiniteJoint`] if a skinning matrix is not finite;
/// [`SkinError::NonRigidJoint`] for DQS when a matrix has scale, shear or reflection;
/// [`SkinError::BadMesh`] if the mesh's influence arrays are inconsistent (possible only for a
/// mesh deserialised without [`SkinnedMesh::new`]'s checks).
///
/// # Panics
/// If `matrices` does not have one entry per skin joint or `out` was made for another mesh
/// (API misuse).
#[track_caller]
pub fn skin(
    mesh: &SkinnedMesh,
    matrices: &[DMat4],
    method: SkinningMethod,
    out: &mut Skinned,
) -> Result<(), SkinError> {
    skin_with(mesh, matrices, method, out, true)
}

/// [`skin`] with the portable kernels whatever the CPU: the results every x86-64 CPU (and
/// every other target) reproduces bit for bit, at the portable kernels' speed.
///
/// # Errors
/// As [`skin`].
///
/// # Panics
/// As [`skin`].
#[track_caller]
pub fn skin_portable(
    mesh: &SkinnedMesh,
    matrices: &[DMat4],
    method: SkinningMethod,
    out: &mut Skinned,
) -> Result<(), SkinError> {
    skin_with(mesh, matrices, method, out, false)
}

/// [`skin`], with the AVX2 kernels allowed (`simd`, used when the CPU has them) or not (the
/// portable kernels).
#[track_caller]
fn skin_with(
    mesh: &SkinnedMesh,
    matrices: &[DMat4],
    method: SkinningMethod,
    out: &mut Skinned,
    simd: bool,
) -> Result<(), SkinError> {
    assert_eq!(matrices.len(), mesh.num_joints(), "one skinning matrix per skin joint");
    assert_eq!(out.x.len(), mesh.len(), "Skinned buffers made for another mesh");
    assert_eq!(out.mats.len(), mesh.num_joints(), "Skinned buffers made for another mesh");
    let (n, k) = (mesh.len(), mesh.influences());
    if !(1..=MAX_INFLUENCES).contains(&k)
        || mesh.joints().len() != n * k
        || mesh.weights().len() != n * k
        || mesh.dominant_slots().len() != n
    {
        return Err(SkinError::BadMesh(format!(
            "{n} vertices with {k} influences (1 to {MAX_INFLUENCES}) but {} joints and {} weights",
            mesh.joints().len(),
            mesh.weights().len()
        )));
    }
    for (j, m) in matrices.iter().enumerate() {
        if !m.is_finite() {
            return Err(SkinError::NonFiniteJoint { joint: j });
        }
        let c = m.to_cols_array();
        // Row-major 3x4 from glam's column-major 4x4.
        out.mats[j] =
            [[c[0], c[4]], [c[8], c[12]], [c[1], c[5]], [c[9], c[13]], [c[2], c[6]], [c[10], c[14]]]
                .map(f64x2::new);
    }
    if method == SkinningMethod::Dqs {
        for (j, m) in matrices.iter().enumerate() {
            let d = to_dual_quat(j, m, out.rigid_tolerance.0)?;
            out.dqs[j] = [[d[0], d[1]], [d[2], d[3]], [d[4], d[5]], [d[6], d[7]]].map(f64x2::new);
        }
    }
    let nj = mesh.num_joints();
    // The AVX2 kernels, where the CPU has them; DQS needs the sign table too.
    #[cfg(target_arch = "x86_64")]
    let cpu = if simd && (method == SkinningMethod::Lbs || out.pairs.len() == nj * nj) {
        avx2::Avx2Fma::detect()
    } else {
        None
    };
    #[cfg(target_arch = "x86_64")]
    if cpu.is_some() && method == SkinningMethod::Dqs {
        fill_sign_table(out);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = simd;
    let Skinned { x, y, z, nx, ny, nz, mats, dqs, signed, pairs, rigid_tolerance: _ } = out;
    #[cfg(target_arch = "x86_64")]
    let tables = avx2::Tables { mats: bytemuck::cast_slice(mats), signed, pairs, joints: nj };
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (signed, pairs);
    let (lbs, dqs) = (Lbs(mats), Dqs(dqs));
    x.par_chunks_mut(CHUNK)
        .zip(y.par_chunks_mut(CHUNK))
        .zip(z.par_chunks_mut(CHUNK))
        .zip(nx.par_chunks_mut(CHUNK))
        .zip(ny.par_chunks_mut(CHUNK))
        .zip(nz.par_chunks_mut(CHUNK))
        .enumerate()
        .for_each(|(c, (((((x, y), z), nx), ny), nz))| {
            let o = Outputs { x, y, z, nx, ny, nz };
            #[cfg(target_arch = "x86_64")]
            if let Some(cpu) = cpu {
                let lbs = method == SkinningMethod::Lbs;
                return avx2::chunk(cpu, lbs, k, &tables, mesh, c * CHUNK, o);
            }
            match method {
                SkinningMethod::Lbs => chunk_k(k, &lbs, mesh, c * CHUNK, o),
                SkinningMethod::Dqs => chunk_k(k, &dqs, mesh, c * CHUNK, o),
            }
        });
    Ok(())
}

/// One quantity of two vertices, one per SIMD lane (SSE2 on x86-64). Each lane performs the
/// same IEEE operations in the same order as a lone vertex would; the odd vertex at the end of
/// a chunk runs in both lanes. Results therefore do not depend on how vertices are paired.
type P = f64x2;
type P3 = [P; 3];

/// A skinning method as a kernel over a pair of vertices with `K` influences each: `js[l]` and
/// `ws[l]` are lane `l`'s joint indices and weights, `p` and `n` the rest positions and normals;
/// returns posed positions and unit normals.
trait Kernel: Sync {
    fn pair<const K: usize>(&self, js: [&[u16]; 2], ws: [&[f64]; 2], p: P3, n: P3) -> (P3, P3);
}

/// Monomorphises the chunk loop for the mesh's influence count (`1..=MAX_INFLUENCES`, checked
/// by [`skin`]).
fn chunk_k<Kr: Kernel>(k: usize, kr: &Kr, mesh: &SkinnedMesh, start: usize, o: Outputs<'_>) {
    match k {
        1 => chunk::<1, Kr>(kr, mesh, start, o),
        2 => chunk::<2, Kr>(kr, mesh, start, o),
        3 => chunk::<3, Kr>(kr, mesh, start, o),
        4 => chunk::<4, Kr>(kr, mesh, start, o),
        5 => chunk::<5, Kr>(kr, mesh, start, o),
        6 => chunk::<6, Kr>(kr, mesh, start, o),
        7 => chunk::<7, Kr>(kr, mesh, start, o),
        _ => chunk::<MAX_INFLUENCES, Kr>(kr, mesh, start, o),
    }
}

fn chunk<const K: usize, Kr: Kernel>(kr: &Kr, mesh: &SkinnedMesh, start: usize, o: Outputs<'_>) {
    let len = o.x.len();
    let end = start + len;
    let (js, ws) = (&mesh.joints()[start * K..end * K], &mesh.weights()[start * K..end * K]);
    let input = [&mesh.x, &mesh.y, &mesh.z, &mesh.nx, &mesh.ny, &mesh.nz].map(|s| &s[start..end]);
    let mut output = [o.x, o.y, o.z, o.nx, o.ny, o.nz];
    let pairs = len / 2;
    let (js2, ws2) = (js.chunks_exact(2 * K), ws.chunks_exact(2 * K));
    for (i, (js, ws)) in js2.zip(ws2).enumerate().take(pairs) {
        let ld = |d: usize| match input[d][2 * i..2 * i + 2] {
            [a, b] => P::new([a, b]),
            _ => P::ZERO,
        };
        let (js, ws) = (js.split_at(K), ws.split_at(K));
        let (q, m) = kr.pair::<K>([js.0, js.1], [ws.0, ws.1], [ld(0), ld(1), ld(2)], [ld(3), ld(4), ld(5)]);
        for (out, v) in output.iter_mut().zip([q[0], q[1], q[2], m[0], m[1], m[2]]) {
            out[2 * i..2 * i + 2].copy_from_slice(v.as_array());
        }
    }
    if len % 2 == 1 {
        // The last vertex of an odd chunk is computed in both lanes.
        let v = len - 1;
        let (j, w) = (&js[v * K..v * K + K], &ws[v * K..v * K + K]);
        let ld = |d: usize| P::splat(input[d][v]);
        let (q, m) = kr.pair::<K>([j, j], [w, w], [ld(0), ld(1), ld(2)], [ld(3), ld(4), ld(5)]);
        for (out, v2) in output.into_iter().zip([q[0], q[1], q[2], m[0], m[1], m[2]]) {
            out[v] = v2.as_array()[0];
        }
    }
}

/// `m / |m| * sign` per lane, `m` unchanged where `|m| = 0`.
#[inline(always)]
fn normalized(m: P3, sign: P) -> P3 {
    let len = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
    let s = len.simd_gt(P::ZERO).select(sign / len, P::ONE);
    [m[0] * s, m[1] * s, m[2] * s]
}

/// LBS over row-major 3x4 skinning matrices, two values per SIMD register.
struct Lbs<'a>(&'a [[P; 6]]);

impl Lbs<'_> {
    /// `sum_i w_i M_{j_i}` of one vertex, vectorised along the matrix rows. A zero-weight slot
    /// adds `0 * M_0`, which changes nothing.
    #[inline(always)]
    fn blend<const K: usize>(&self, js: &[u16], ws: &[f64]) -> [P; 6] {
        let (js, ws) = (&js[..K], &ws[..K]);
        let (m, w) = (&self.0[usize::from(js[0])], P::splat(ws[0]));
        let mut b = [P::ZERO; 6];
        for e in 0..6 {
            b[e] = w * m[e];
        }
        for i in 1..K {
            let (m, w) = (&self.0[usize::from(js[i])], P::splat(ws[i]));
            for e in 0..6 {
                b[e] += w * m[e];
            }
        }
        b
    }
}

impl Kernel for Lbs<'_> {
    #[inline(always)]
    fn pair<const K: usize>(&self, js: [&[u16]; 2], ws: [&[f64]; 2], p: P3, n: P3) -> (P3, P3) {
        let (b0, b1) = (self.blend::<K>(js[0], ws[0]), self.blend::<K>(js[1], ws[1]));
        // Transpose to one matrix entry per register, one vertex per lane.
        let mut a = [P::ZERO; 12];
        for e in 0..6 {
            [a[2 * e], a[2 * e + 1]] = P::transpose([b0[e], b1[e]]);
        }
        let q = [
            a[0] * p[0] + a[1] * p[1] + a[2] * p[2] + a[3],
            a[4] * p[0] + a[5] * p[1] + a[6] * p[2] + a[7],
            a[8] * p[0] + a[9] * p[1] + a[10] * p[2] + a[11],
        ];
        // Cofactor matrix of the 3x3 block: cof(A) = det(A) A^-T.
        let (a00, a01, a02, a10, a11, a12, a20, a21, a22) =
            (a[0], a[1], a[2], a[4], a[5], a[6], a[8], a[9], a[10]);
        let c00 = a11 * a22 - a12 * a21;
        let c01 = a12 * a20 - a10 * a22;
        let c02 = a10 * a21 - a11 * a20;
        let c10 = a02 * a21 - a01 * a22;
        let c11 = a00 * a22 - a02 * a20;
        let c12 = a01 * a20 - a00 * a21;
        let c20 = a01 * a12 - a02 * a11;
        let c21 = a02 * a10 - a00 * a12;
        let c22 = a00 * a11 - a01 * a10;
        let det = a00 * c00 + a01 * c01 + a02 * c02;
        let m = [
            c00 * n[0] + c01 * n[1] + c02 * n[2],
            c10 * n[0] + c11 * n[1] + c12 * n[2],
            c20 * n[0] + c21 * n[1] + c22 * n[2],
        ];
        (q, normalized(m, det.signum()))
    }
}

/// DQS over unit dual quaternions `(qx, qy | qz, qw | dx, dy | dz, dw)`.
struct Dqs<'a>(&'a [[P; 4]]);

impl Dqs<'_> {
    /// `sum_i s_i w_i (q_{j_i} + ε d_{j_i})` of one vertex, `s_i = ±1` putting each `q_{j_i}` in
    /// the hemisphere of the dominant influence's (the first slot of largest weight). Selects and
    /// a sign-bit flip, no branches.
    #[inline(always)]
    fn blend<const K: usize>(&self, js: &[u16], ws: &[f64]) -> [P; 4] {
        let (js, ws) = (&js[..K], &ws[..K]);
        let d: [&[P; 4]; K] = std::array::from_fn(|i| &self.0[usize::from(js[i])]);
        let (mut q0, mut best) = (d[0], ws[0]);
        for i in 1..K {
            let take = ws[i] > best;
            q0 = if take { d[i] } else { q0 };
            best = if take { ws[i] } else { best };
        }
        let sign_bit = P::splat(-0.0);
        let signed = |i: usize| {
            let prod = d[i][0] * q0[0] + d[i][1] * q0[1];
            let [lo, hi] = P::transpose([prod, prod]);
            // `dot < 0` in both lanes flips the weight's sign bit.
            let flip = (lo + hi).simd_lt(P::ZERO) & sign_bit;
            P::splat(ws[i]) ^ flip
        };
        let mut b = [P::ZERO; 4];
        let s = signed(0);
        for e in 0..4 {
            b[e] = s * d[0][e];
        }
        for i in 1..K {
            let s = signed(i);
            for e in 0..4 {
                b[e] += s * d[i][e];
            }
        }
        b
    }
}

impl Kernel for Dqs<'_> {
    #[inline(always)]
    fn pair<const K: usize>(&self, js: [&[u16]; 2], ws: [&[f64]; 2], p: P3, n: P3) -> (P3, P3) {
        let (b0, b1) = (self.blend::<K>(js[0], ws[0]), self.blend::<K>(js[1], ws[1]));
        let mut b = [P::ZERO; 8];
        for e in 0..4 {
            [b[2 * e], b[2 * e + 1]] = P::transpose([b0[e], b1[e]]);
        }
        // With the blend b = (r, w) + ε (d, w_d) unnormalised and l2 = |b_0|^2, the rigid motion
        // of the normalised dual quaternion is
        //   p' = [ (w^2 - r.r) p + 2 (r.p) r + 2 w (r x p) + 2 (w d - w_d r + r x d) ] / l2,
        // and the normal n' ∝ (w^2 - r.r) n + 2 (r.n) r + 2 w (r x n), normalised. One square
        // root and one division serve both: z = 1 / (l2 |n'|) gives 1/l2 = z |n'| and
        // 1/|n'| = z l2.
        let (rx, ry, rz, rw) = (b[0], b[1], b[2], b[3]);
        let (dx, dy, dz, dw) = (b[4], b[5], b[6], b[7]);
        let two = P::splat(2.0);
        let rr = rx * rx + ry * ry + rz * rz;
        let l2 = rr + rw * rw;
        let c = rw * rw - rr;
        let tw = two * rw;
        let rotate = |v: P3| {
            let rv = two * (rx * v[0] + ry * v[1] + rz * v[2]);
            let cross = [ry * v[2] - rz * v[1], rz * v[0] - rx * v[2], rx * v[1] - ry * v[0]];
            [
                c * v[0] + rv * rx + tw * cross[0],
                c * v[1] + rv * ry + tw * cross[1],
                c * v[2] + rv * rz + tw * cross[2],
            ]
        };
        let t = [
            two * (rw * dx - dw * rx + ry * dz - rz * dy),
            two * (rw * dy - dw * ry + rz * dx - rx * dz),
            two * (rw * dz - dw * rz + rx * dy - ry * dx),
        ];
        let r = rotate(p);
        let m = rotate(n);
        let len = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
        let nonzero = len.simd_gt(P::ZERO);
        let len = nonzero.select(len, P::ONE);
        let z = P::ONE / (l2 * len);
        let inv_l2 = z * len;
        let inv_len = nonzero.select(z * l2, P::ONE);
        (
            [(r[0] + t[0]) * inv_l2, (r[1] + t[1]) * inv_l2, (r[2] + t[2]) * inv_l2],
            [m[0] * inv_len, m[1] * inv_len, m[2] * inv_len],
        )
    }
}

/// The AVX2 DQS kernel's per-pose tables: each joint's dual quaternion with both signs, and the
/// hemisphere test of every joint pair, `q_a . q_b < 0`, summed in the portable kernel's order
/// `(qx qx' + qz qz') + (qy qy' + qw qw')`.
#[cfg(target_arch = "x86_64")]
fn fill_sign_table(out: &mut Skinned) {
    let nj = out.dqs.len();
    for (s, d) in out.signed.chunks_exact_mut(2).zip(&out.dqs) {
        let plus = [d[0].to_array(), d[1].to_array(), d[2].to_array(), d[3].to_array()];
        let q = [plus[0][0], plus[0][1], plus[1][0], plus[1][1]];
        let dual = [plus[2][0], plus[2][1], plus[3][0], plus[3][1]];
        s[0] = [q, dual];
        s[1] = [q.map(|v| -v), dual.map(|v| -v)];
    }
    for a in 0..nj {
        let qa = out.signed[2 * a][0];
        for b in 0..nj {
            let qb = out.signed[2 * b][0];
            let dot = (qb[0] * qa[0] + qb[2] * qa[2]) + (qb[1] * qa[1] + qb[3] * qa[3]);
            // At most 2 * SIGN_TABLE_JOINTS - 1, which fits.
            out.pairs[a * nj + b] = u16::try_from(2 * b).unwrap_or(u16::MAX - 1) + u16::from(dot < 0.0);
        }
    }
}

/// The unit dual quaternion of a skinning matrix rigid within `tolerance`: its 3x3 block is
/// replaced by the nearest rotation (polar decomposition) first.
fn to_dual_quat(joint: usize, m: &DMat4, tolerance: f64) -> Result<[f64; 8], SkinError> {
    let r = DMat3::from_mat4(*m);
    let e = r.transpose() * r - DMat3::IDENTITY;
    let deviation = e.to_cols_array().iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let det = r.determinant();
    let bottom = m.row(3) - anim_core::glam::DVec4::W;
    if !(deviation <= tolerance) || !(det > 0.0) || !(bottom.abs().max_element() <= tolerance) {
        return Err(SkinError::NonRigidJoint { joint, deviation, determinant: det, tolerance });
    }
    let (rotation, _) = polar(r);
    let q = DQuat::from_mat3(&rotation).normalize();
    let t = m.w_axis.truncate();
    // d = 1/2 (t, 0) q
    let qv = anim_core::glam::DVec3::new(q.x, q.y, q.z);
    let dv = 0.5 * (q.w * t + t.cross(qv));
    let dw = -0.5 * t.dot(qv);
    Ok([q.x, q.y, q.z, q.w, dv.x, dv.y, dv.z, dw])
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;
    use anim_core::glam::DVec3;

    /// The AVX2 kernels (where the CPU has them) and the portable ones agree to rounding, for
    /// every influence count, scaled LBS joints, antipodal DQS quaternions, zero normals and
    /// chunk tails of every length.
    #[test]
    fn simd_and_portable_kernels_agree() {
        let mut s = 4242u64;
        let mut rnd = move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let joints = 11;
        for k in 1..=MAX_INFLUENCES {
            let n = CHUNK + 4 + k % 4;
            let pos: Vec<[f64; 3]> = (0..n).map(|_| [rnd() - 0.5, rnd() - 0.5, rnd() - 0.5]).collect();
            let nrm: Vec<[f64; 3]> = (0..n)
                .map(|v| if v % 13 == 0 { [0.0; 3] } else { [rnd() - 0.5, rnd() - 0.5, rnd() + 0.1] })
                .collect();
            let js: Vec<u16> = (0..n * k).map(|_| (rnd() * joints as f64) as u16).collect();
            let ws: Vec<f64> = (0..n * k)
                .map(|i| if i % k == k - 1 && i % 3 == 0 && k > 1 { 0.0 } else { rnd() + 0.01 })
                .collect();
            let mesh = SkinnedMesh::new(&pos, Some(&nrm), k, &js, &ws, vec![], joints).unwrap();
            for method in [SkinningMethod::Lbs, SkinningMethod::Dqs] {
                let m: Vec<DMat4> = (0..joints)
                    .map(|j| {
                        let a = j as f64;
                        let scale = if method == SkinningMethod::Lbs {
                            DVec3::new(1.0 + 0.1 * a, 0.8, 1.2)
                        } else {
                            DVec3::ONE
                        };
                        // Odd joints get the antipodal quaternion of a nearby rotation.
                        let q = DQuat::from_axis_angle(DVec3::new(0.3, 1.0, -a).normalize(), 0.4 * a - 1.0);
                        let q = if j % 2 == 1 { -q } else { q };
                        DMat4::from_scale_rotation_translation(scale, q, DVec3::new(a, 1.0, -0.5 * a))
                    })
                    .collect();
                let (mut a, mut b) = (Skinned::new(&mesh), Skinned::new(&mesh));
                skin_with(&mesh, &m, method, &mut a, true).unwrap();
                skin_with(&mesh, &m, method, &mut b, false).unwrap();
                let mut worst = 0.0f64;
                for v in 0..n {
                    for d in 0..3 {
                        let scale = 1.0 + b.position(v)[d].abs();
                        worst = worst.max((a.position(v)[d] - b.position(v)[d]).abs() / scale);
                        worst = worst.max((a.normal(v)[d] - b.normal(v)[d]).abs());
                    }
                    if v % 13 == 0 {
                        assert_eq!(a.normal(v), [0.0; 3], "{method:?} k = {k}: zero normal kept");
                    }
                }
                assert!(worst < 1e-13, "{method:?} k = {k}: {worst:e}");
            }
        }
    }

    /// A mesh read back from its serialised form has the same derived data (dominant slots)
    /// and skins to the same bits.
    #[cfg(feature = "serde")]
    #[test]
    fn a_deserialised_mesh_skins_like_the_original() {
        let pos: Vec<[f64; 3]> = (0..50).map(|v| [v as f64, 1.0, 2.0]).collect();
        let js: Vec<u16> = (0..150).map(|i| u16::try_from(i % 5).unwrap()).collect();
        let ws: Vec<f64> = (0..150).map(|i| ((i * 37) % 11) as f64 + 0.5).collect();
        let mesh = SkinnedMesh::new(&pos, None, 3, &js, &ws, vec![], 5).unwrap();
        let back: SkinnedMesh = serde_json::from_str(&serde_json::to_string(&mesh).unwrap()).unwrap();
        assert_eq!(back, mesh);
        for (v, &d) in mesh.dominant_slots().iter().enumerate() {
            let w = &mesh.weights()[3 * v..3 * v + 3];
            let first_max = (0..3).find(|&i| w.iter().all(|&o| o <= w[i])).unwrap();
            assert_eq!(usize::from(d), first_max, "vertex {v}");
        }
        let m: Vec<DMat4> = (0..5)
            .map(|j| DMat4::from_rotation_translation(DQuat::from_rotation_x(0.9 * j as f64 - 1.5), DVec3::Y))
            .collect();
        for method in [SkinningMethod::Lbs, SkinningMethod::Dqs] {
            let (mut a, mut b) = (Skinned::new(&mesh), Skinned::new(&back));
            skin(&mesh, &m, method, &mut a).unwrap();
            skin(&back, &m, method, &mut b).unwrap();
            assert!(
                a.x.iter().chain(&a.nz).zip(b.x.iter().chain(&b.nz)).all(|(p, q)| p.to_bits() == q.to_bits())
            );
        }
    }

    /// A skin of more joints than the DQS sign table holds runs the portable DQS kernel: the
    /// same bits as `skin_portable`.
    #[test]
    fn dqs_on_a_large_skin_falls_back_to_the_portable_kernel() {
        let joints = SIGN_TABLE_JOINTS + 44;
        let n = 1001;
        let pos: Vec<[f64; 3]> = (0..n).map(|v| [v as f64 * 1e-3, 0.5, -0.25]).collect();
        let js: Vec<u16> = (0..n * 2).map(|i| u16::try_from(i * 7 % joints).unwrap()).collect();
        let ws: Vec<f64> = (0..n * 2).map(|i| 1.0 + (i % 3) as f64).collect();
        let mesh = SkinnedMesh::new(&pos, None, 2, &js, &ws, vec![], joints).unwrap();
        let m: Vec<DMat4> = (0..joints)
            .map(|j| DMat4::from_rotation_translation(DQuat::from_rotation_z(0.01 * j as f64), DVec3::X))
            .collect();
        let (mut a, mut b) = (Skinned::new(&mesh), Skinned::new(&mesh));
        assert!(a.pairs.is_empty());
        skin(&mesh, &m, SkinningMethod::Dqs, &mut a).unwrap();
        skin_portable(&mesh, &m, SkinningMethod::Dqs, &mut b).unwrap();
        assert!(a.x.iter().chain(&a.y).zip(b.x.iter().chain(&b.y)).all(|(p, q)| p.to_bits() == q.to_bits()));
        // And the result is the motion it should be: vertex 0 has joints 0 and 7 with weights 1/3
        // and 2/3, rotations about z by 0 and 0.07 then the same translation; the blend keeps
        // the translation and rotates by 2 atan2(sum w sin(a/2), sum w cos(a/2)).
        let half = 0.035f64;
        let angle = 2.0 * (2.0 / 3.0 * half.sin()).atan2(1.0 / 3.0 + 2.0 / 3.0 * half.cos());
        let expected = DMat4::from_rotation_translation(DQuat::from_rotation_z(angle), DVec3::X);
        let p = expected.transform_point3(DVec3::from_array(pos[0]));
        assert!((DVec3::from_array(a.position(0)) - p).length() < 1e-12, "{:?} vs {p}", a.position(0));
    }
}
