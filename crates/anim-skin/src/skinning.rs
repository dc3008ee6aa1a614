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
//!   rotation within [`RIGID_TOLERANCE`] (scale, shear, reflection) is rejected with
//!   [`SkinError::NonRigidJoint`]; use LBS for scaled joints.
//!
//! Both run in parallel over fixed chunks of [`CHUNK`] vertices; each vertex is computed by the
//! same sequence of operations whatever the chunk's thread, so results are bitwise identical for
//! any thread count. [`Skinned`] holds the per-joint blend data and the outputs, sized once per
//! mesh: skinning allocates nothing.

use crate::SkinError;
use crate::mesh::SkinnedMesh;
use anim_core::glam::{DMat3, DMat4, DQuat};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Vertices per parallel task.
pub const CHUNK: usize = 2048;

/// Largest `max |R^T R - I|` entry (and smallest determinant slack) accepted as rigid by DQS.
pub const RIGID_TOLERANCE: f64 = 1e-5;

/// Which skinning algorithm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
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
    /// Row-major 3x4 skinning matrices.
    mats: Vec<[f64; 12]>,
    /// Dual quaternions `(qx, qy, qz, qw, dx, dy, dz, dw)`.
    dqs: Vec<[f64; 8]>,
}

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
            mats: vec![[0.0; 12]; mesh.num_joints()],
            dqs: vec![[0.0; 8]; mesh.num_joints()],
        }
        .resized(n)
    }

    fn resized(mut self, n: usize) -> Self {
        for v in [&mut self.x, &mut self.y, &mut self.z, &mut self.nx, &mut self.ny, &mut self.nz] {
            v.resize(n, 0.0);
        }
        self
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
/// [`SkinError::NonRigidJoint`] for DQS when a matrix has scale, shear or reflection.
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
    assert_eq!(matrices.len(), mesh.num_joints(), "one skinning matrix per skin joint");
    assert_eq!(out.x.len(), mesh.len(), "Skinned buffers made for another mesh");
    assert_eq!(out.mats.len(), mesh.num_joints(), "Skinned buffers made for another mesh");
    for (j, m) in matrices.iter().enumerate() {
        if !m.is_finite() {
            return Err(SkinError::NonFiniteJoint { joint: j });
        }
        let c = m.to_cols_array();
        // Row-major 3x4 from glam's column-major 4x4.
        out.mats[j] = [c[0], c[4], c[8], c[12], c[1], c[5], c[9], c[13], c[2], c[6], c[10], c[14]];
    }
    if method == SkinningMethod::Dqs {
        for (j, m) in matrices.iter().enumerate() {
            out.dqs[j] = to_dual_quat(j, m)?;
        }
    }
    let Skinned { x, y, z, nx, ny, nz, mats, dqs } = out;
    let k = mesh.influences();
    x.par_chunks_mut(CHUNK)
        .zip(y.par_chunks_mut(CHUNK))
        .zip(z.par_chunks_mut(CHUNK))
        .zip(nx.par_chunks_mut(CHUNK))
        .zip(ny.par_chunks_mut(CHUNK))
        .zip(nz.par_chunks_mut(CHUNK))
        .enumerate()
        .for_each(|(c, (((((ox, oy), oz), onx), ony), onz))| {
            let start = c * CHUNK;
            for i in 0..ox.len() {
                let v = start + i;
                let js = &mesh.joints()[v * k..(v + 1) * k];
                let ws = &mesh.weights()[v * k..(v + 1) * k];
                let p = [mesh.x[v], mesh.y[v], mesh.z[v]];
                let n = [mesh.nx[v], mesh.ny[v], mesh.nz[v]];
                let (q, m) = match method {
                    SkinningMethod::Lbs => lbs_vertex(mats, js, ws, p, n),
                    SkinningMethod::Dqs => dqs_vertex(dqs, js, ws, p, n),
                };
                (ox[i], oy[i], oz[i]) = (q[0], q[1], q[2]);
                (onx[i], ony[i], onz[i]) = (m[0], m[1], m[2]);
            }
        });
    Ok(())
}

#[inline(always)]
fn lbs_vertex(mats: &[[f64; 12]], js: &[u16], ws: &[f64], p: [f64; 3], n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let mut a = [0.0; 12];
    for (&j, &w) in js.iter().zip(ws) {
        if w == 0.0 {
            continue;
        }
        let m = &mats[j as usize];
        for e in 0..12 {
            a[e] += w * m[e];
        }
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
    let mut m = [
        c00 * n[0] + c01 * n[1] + c02 * n[2],
        c10 * n[0] + c11 * n[1] + c12 * n[2],
        c20 * n[0] + c21 * n[1] + c22 * n[2],
    ];
    normalize(&mut m, det.signum());
    (q, m)
}

#[inline(always)]
fn normalize(m: &mut [f64; 3], sign: f64) {
    let l = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
    if l > 0.0 {
        let s = sign / l;
        m.iter_mut().for_each(|c| *c *= s);
    }
}

#[inline(always)]
fn dqs_vertex(dqs: &[[f64; 8]], js: &[u16], ws: &[f64], p: [f64; 3], n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    // Dominant influence: the first slot of largest weight.
    let mut dom = 0;
    for i in 1..ws.len() {
        if ws[i] > ws[dom] {
            dom = i;
        }
    }
    let q0 = &dqs[js[dom] as usize];
    let mut b = [0.0; 8];
    for (&j, &w) in js.iter().zip(ws) {
        if w == 0.0 {
            continue;
        }
        let d = &dqs[j as usize];
        let dot = d[0] * q0[0] + d[1] * q0[1] + d[2] * q0[2] + d[3] * q0[3];
        let s = if dot < 0.0 { -w } else { w };
        for e in 0..8 {
            b[e] += s * d[e];
        }
    }
    let len = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + b[3] * b[3]).sqrt();
    let inv = 1.0 / len;
    let (rx, ry, rz, rw) = (b[0] * inv, b[1] * inv, b[2] * inv, b[3] * inv);
    let (dx, dy, dz, dw) = (b[4] * inv, b[5] * inv, b[6] * inv, b[7] * inv);
    let rotate = |v: [f64; 3]| {
        // v + 2 r x (r x v + w v)
        let t = [
            ry * v[2] - rz * v[1] + rw * v[0],
            rz * v[0] - rx * v[2] + rw * v[1],
            rx * v[1] - ry * v[0] + rw * v[2],
        ];
        [
            v[0] + 2.0 * (ry * t[2] - rz * t[1]),
            v[1] + 2.0 * (rz * t[0] - rx * t[2]),
            v[2] + 2.0 * (rx * t[1] - ry * t[0]),
        ]
    };
    // Translation 2 (w_r d_v - w_d r_v + r_v x d_v).
    let t = [
        2.0 * (rw * dx - dw * rx + ry * dz - rz * dy),
        2.0 * (rw * dy - dw * ry + rz * dx - rx * dz),
        2.0 * (rw * dz - dw * rz + rx * dy - ry * dx),
    ];
    let r = rotate(p);
    let mut m = rotate(n);
    normalize(&mut m, 1.0);
    ([r[0] + t[0], r[1] + t[1], r[2] + t[2]], m)
}

/// The unit dual quaternion of a rigid skinning matrix.
fn to_dual_quat(joint: usize, m: &DMat4) -> Result<[f64; 8], SkinError> {
    let r = DMat3::from_mat4(*m);
    let e = r.transpose() * r - DMat3::IDENTITY;
    let deviation = e.to_cols_array().iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let det = r.determinant();
    let bottom = m.row(3) - anim_core::glam::DVec4::W;
    if !(deviation <= RIGID_TOLERANCE) || !(det > 0.0) || bottom.abs().max_element() > RIGID_TOLERANCE {
        return Err(SkinError::NonRigidJoint { joint, deviation, determinant: det });
    }
    let q = DQuat::from_mat3(&r).normalize();
    let t = m.w_axis.truncate();
    // d = 1/2 (t, 0) q
    let qv = anim_core::glam::DVec3::new(q.x, q.y, q.z);
    let dv = 0.5 * (q.w * t + t.cross(qv));
    let dw = -0.5 * t.dot(qv);
    Ok([q.x, q.y, q.z, q.w, dv.x, dv.y, dv.z, dw])
}
