//! Tetrahedral meshes, the soft bodies (a tetrahedralised box or blob from [`crate::shapes`], or
//! any `positions` + `tets` arrays): distance constraints on the unique edges and a volume
//! constraint `V - V_0` per tetrahedron, as [`TetMeshParams`] asks. Vertex masses are given per
//! vertex or lumped from a density per volume, each tetrahedron giving a quarter of its mass to
//! each corner. A tetrahedron with a repeated vertex or `|V| <= 1e-12 l^3` (`l` its longest edge)
//! is refused. The boundary faces are recorded, outward, for rendering.

use super::builder::{MeshMass, PbdBuilder, check_mass, key};
use super::error::{BuildError, InputError};
use crate::constraint::{ConstraintParams, tet_is_flat, tet_volume};
use anim_core::glam::DVec3;
use std::ops::Range;

/// Constraints made from a tetrahedral mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct TetMeshParams {
    /// Vertex masses.
    pub mass: MeshMass,
    /// A distance constraint on every unique tetrahedron edge, if any.
    pub stretch: Option<ConstraintParams>,
    /// A volume constraint per tetrahedron, if any.
    pub volume: Option<ConstraintParams>,
}

impl PbdBuilder {
    /// A tetrahedral mesh from any positions and tetrahedra: distance constraints on the unique
    /// edges and a volume constraint per tetrahedron, as `params` asks; the boundary faces are
    /// recorded (outward) for rendering, the tetrahedra for output. Returns the range of its
    /// particles.
    ///
    /// # Errors
    /// [`BuildError::TetIndex`], [`BuildError::DegenerateTet`] (repeated vertex or
    /// `|V| <= 1e-12 l^3` with `l` the longest edge), [`InputError::IsolatedVertex`] (mass by
    /// density), [`InputError::BadParameter`].
    pub fn tet_mesh(
        &mut self,
        positions: &[[f64; 3]],
        tets: &[[usize; 4]],
        params: &TetMeshParams,
    ) -> Result<Range<usize>, BuildError> {
        check_mass("tet mesh", params.mass)?;
        let nv = positions.len();
        let pos: Vec<DVec3> = positions.iter().map(|&p| DVec3::from_array(p)).collect();
        let mut vol = vec![0.0; nv];
        for (t, tet) in tets.iter().enumerate() {
            for &i in tet {
                if i >= nv {
                    return Err(BuildError::TetIndex { tet: t, index: i, vertices: nv });
                }
            }
            let p = tet.map(|i| pos[i]);
            let v = tet_volume(p).0;
            for a in 0..4 {
                for b in a + 1..4 {
                    if tet[a] == tet[b] {
                        return Err(BuildError::DegenerateTet {
                            tet: t,
                            vertices: *tet,
                            volume: v,
                            reason: "repeated vertex",
                        });
                    }
                }
            }
            if tet_is_flat(p, v) {
                return Err(BuildError::DegenerateTet {
                    tet: t,
                    vertices: *tet,
                    volume: v,
                    reason: "zero volume",
                });
            }
            for &i in tet {
                vol[i] += v.abs() / 4.0;
            }
        }
        let masses: Vec<f64> = match params.mass {
            MeshMass::PerVertex(m) => vec![m; nv],
            MeshMass::Density(rho) => {
                if let Some(v) = vol.iter().position(|&a| a == 0.0) {
                    return Err(BuildError::Input(InputError::IsolatedVertex {
                        vertex: v,
                        element: "tetrahedron",
                    }));
                }
                vol.iter().map(|a| rho * a).collect()
            }
        };
        let first = self.positions.len();
        for (p, m) in positions.iter().zip(&masses) {
            self.particle(*p, *m);
        }
        if let Some(stretch) = params.stretch {
            let mut seen = std::collections::HashSet::new();
            for tet in tets {
                for a in 0..4 {
                    for b in a + 1..4 {
                        if seen.insert(key(tet[a], tet[b])) {
                            self.distance(first + tet[a], first + tet[b], stretch);
                        }
                    }
                }
            }
        }
        if let Some(volume) = params.volume {
            for tet in tets {
                self.tet_volume(tet.map(|i| first + i), volume);
            }
        }
        for f in crate::shapes::tet_surface(positions, tets) {
            self.triangles.push(f.map(|i| first + i));
        }
        for t in tets {
            self.tets.push(t.map(|i| first + i));
        }
        Ok(first..first + nv)
    }
}
