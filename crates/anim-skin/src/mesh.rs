//! Skinned meshes: rest positions and normals, per-vertex joint influences, triangles, as
//! structure-of-arrays.

use crate::SkinError;

/// The largest number of influences per vertex (glTF `JOINTS_0`/`WEIGHTS_0` plus `_1`).
pub const MAX_INFLUENCES: usize = 8;

/// A mesh bound to a skin: rest positions and normals as separate `x`, `y`, `z` arrays, and
/// `k` influence slots per vertex (`joints[v * k + i]`, `weights[v * k + i]`).
///
/// Weights are normalised to sum to 1 at construction; zero-weight slots are kept (their joint
/// index is set to 0) and skipped by the skinning kernels.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(from = "MeshData"))]
pub struct SkinnedMesh {
    /// Rest positions, x.
    pub x: Vec<f64>,
    /// Rest positions, y.
    pub y: Vec<f64>,
    /// Rest positions, z.
    pub z: Vec<f64>,
    /// Rest normals (unit), x.
    pub nx: Vec<f64>,
    /// Rest normals, y.
    pub ny: Vec<f64>,
    /// Rest normals, z.
    pub nz: Vec<f64>,
    influences: usize,
    joints: Vec<u16>,
    weights: Vec<f64>,
    triangles: Vec<[u32; 3]>,
    num_joints: usize,
    /// Each vertex's dominant influence slot (the first of largest weight), derived from the
    /// weights: DQS's hemisphere reference.
    #[cfg_attr(feature = "serde", serde(skip))]
    dominant: Vec<u8>,
}

/// The serialised fields of a [`SkinnedMesh`]; the derived ones are rebuilt on loading.
#[cfg_attr(feature = "serde", derive(serde::Deserialize))]
struct MeshData {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    nx: Vec<f64>,
    ny: Vec<f64>,
    nz: Vec<f64>,
    influences: usize,
    joints: Vec<u16>,
    weights: Vec<f64>,
    triangles: Vec<[u32; 3]>,
    num_joints: usize,
}

impl From<MeshData> for SkinnedMesh {
    fn from(m: MeshData) -> Self {
        let dominant = dominant_slots(m.x.len(), m.influences, &m.weights);
        let MeshData { x, y, z, nx, ny, nz, influences, joints, weights, triangles, num_joints } = m;
        Self { x, y, z, nx, ny, nz, influences, joints, weights, triangles, num_joints, dominant }
    }
}

/// The first slot of largest weight of each of `n` vertices with `k` slots (0 where the weights
/// are missing).
fn dominant_slots(n: usize, k: usize, weights: &[f64]) -> Vec<u8> {
    (0..n)
        .map(|v| {
            let ws = weights.get(v * k..(v + 1) * k).unwrap_or(&[]);
            let slot = (0..ws.len()).fold(0, |d, i| if ws[i] > ws[d] { i } else { d });
            u8::try_from(slot).unwrap_or(0)
        })
        .collect()
}

impl SkinnedMesh {
    /// A mesh with `influences` slots per vertex (`1..=8`) bound to a skin of `num_joints`
    /// joints. `normals = None` computes area-weighted vertex normals from the triangles.
    ///
    /// # Errors
    /// [`SkinError::BadMesh`] for mismatched lengths, a non-finite position or normal, a bad
    /// influence count, or a triangle index out of range; [`SkinError::BadWeight`] for a
    /// negative or non-finite weight or a vertex whose weights are all zero;
    /// [`SkinError::BadJoint`] for a non-zero weight on a joint index outside the skin.
    pub fn new(
        positions: &[[f64; 3]],
        normals: Option<&[[f64; 3]]>,
        influences: usize,
        joints: &[u16],
        weights: &[f64],
        triangles: Vec<[u32; 3]>,
        num_joints: usize,
    ) -> Result<Self, SkinError> {
        let n = positions.len();
        let bad = |why: String| Err(SkinError::BadMesh(why));
        if !(1..=MAX_INFLUENCES).contains(&influences) {
            return bad(format!("{influences} influences per vertex (1 to {MAX_INFLUENCES} supported)"));
        }
        if joints.len() != n * influences || weights.len() != n * influences {
            return bad(format!(
                "{n} vertices with {influences} influences need {} joints and weights, got {} and {}",
                n * influences,
                joints.len(),
                weights.len()
            ));
        }
        if let Some(v) = positions.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return bad(format!("position of vertex {v} is not finite"));
        }
        if let Some((t, tri)) = triangles.iter().enumerate().find(|(_, t)| t.iter().any(|&i| i as usize >= n))
        {
            return bad(format!("triangle {t} {tri:?} indexes beyond {n} vertices"));
        }
        let mut js = joints.to_vec();
        let mut ws = weights.to_vec();
        for v in 0..n {
            let slots = v * influences..(v + 1) * influences;
            let mut sum = 0.0;
            for i in slots.clone() {
                let w = ws[i];
                if !w.is_finite() || w < 0.0 {
                    return Err(SkinError::BadWeight { vertex: v, slot: i - v * influences, weight: w });
                }
                if w > 0.0 && js[i] as usize >= num_joints {
                    return Err(SkinError::BadJoint {
                        vertex: v,
                        slot: i - v * influences,
                        joint: js[i] as usize,
                        num_joints,
                    });
                }
                sum += w;
            }
            if !(sum > 0.0) {
                return Err(SkinError::BadWeight { vertex: v, slot: 0, weight: 0.0 });
            }
            for i in slots {
                ws[i] /= sum;
                if ws[i] == 0.0 {
                    js[i] = 0;
                }
            }
        }
        let (x, y, z) = split(positions);
        let (nx, ny, nz) = match normals {
            Some(nrm) => {
                if nrm.len() != n {
                    return bad(format!("{} normals for {n} vertices", nrm.len()));
                }
                if let Some(v) = nrm.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
                    return bad(format!("normal of vertex {v} is not finite"));
                }
                split(nrm)
            }
            None => split(&vertex_normals(positions, &triangles)),
        };
        let dominant = dominant_slots(n, influences, &ws);
        Ok(Self { x, y, z, nx, ny, nz, influences, joints: js, weights: ws, triangles, num_joints, dominant })
    }

    /// Number of vertices.
    #[must_use]
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether the mesh has no vertices.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Influence slots per vertex.
    #[must_use]
    pub fn influences(&self) -> usize {
        self.influences
    }

    /// Joint indices, `influences()` per vertex.
    #[must_use]
    pub fn joints(&self) -> &[u16] {
        &self.joints
    }

    /// Normalised weights, `influences()` per vertex.
    #[must_use]
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// Each vertex's dominant influence slot: the first slot of largest weight.
    #[must_use]
    pub fn dominant_slots(&self) -> &[u8] {
        &self.dominant
    }

    /// Triangles (counter-clockwise seen from outside).
    #[must_use]
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Number of joints of the skin the mesh is bound to.
    #[must_use]
    pub fn num_joints(&self) -> usize {
        self.num_joints
    }

    /// The rest position of vertex `v`.
    #[must_use]
    pub fn rest_position(&self, v: usize) -> [f64; 3] {
        [self.x[v], self.y[v], self.z[v]]
    }
}

fn split(p: &[[f64; 3]]) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    (p.iter().map(|a| a[0]).collect(), p.iter().map(|a| a[1]).collect(), p.iter().map(|a| a[2]).collect())
}

/// Area-weighted vertex normals (zero for vertices in no triangle).
fn vertex_normals(p: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[f64; 3]> {
    let mut n = vec![[0.0; 3]; p.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| p[i as usize]);
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let f = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        for &i in t {
            for d in 0..3 {
                n[i as usize][d] += f[d];
            }
        }
    }
    for v in &mut n {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if l > 0.0 {
            v.iter_mut().for_each(|c| *c /= l);
        }
    }
    n
}

/// Signed volume of a closed triangle mesh, `sum over triangles of a . (b x c) / 6` (positive
/// for outward, counter-clockwise triangles).
#[must_use]
pub fn signed_volume(x: &[f64], y: &[f64], z: &[f64], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| [x[i as usize], y[i as usize], z[i as usize]]);
            (a[0] * (b[1] * c[2] - b[2] * c[1])
                + a[1] * (b[2] * c[0] - b[0] * c[2])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}
