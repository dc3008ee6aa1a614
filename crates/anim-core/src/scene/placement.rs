//! Where a body of a scene file goes: a uniform scale about the asset's own origin, then a
//! rotation about that origin given as roll, pitch and yaw, then a translation. Every body table
//! of every scene kind spells it with the same three fields:
//!
//! ```toml
//! scale = 0.5                 # > 0, default 1
//! rotate = [0.3, 0.0, 1.57]   # roll, pitch, yaw (rad): Rz(yaw) Ry(pitch) Rx(roll); default none
//! translate = [0.0, 0.0, 1.0] # m, applied last; default none
//! ```
//!
//! ```
//! use anim_core::scene::Placement;
//!
//! let p = Placement { scale: 2.0, rotate: [0.0, 0.0, std::f64::consts::FRAC_PI_2], translate: [0.0, 0.0, 1.0] };
//! p.check()?;
//! let x = p.apply([1.0, 0.0, 0.0]);
//! assert!((x[0] - 0.0).abs() < 1e-12 && (x[1] - 2.0).abs() < 1e-12 && (x[2] - 1.0).abs() < 1e-12);
//! # Ok::<(), anim_core::scene::BuildError>(())
//! ```

use std::path::PathBuf;

use glam::{DMat3, DVec3, EulerRot};
use serde::{Deserialize, Serialize};

use super::{BuildError, is_default};
use crate::surface::{ClosedSurface, DistanceField};

/// Scale, rotation and translation of a body's asset, applied in that order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// Uniform scale about the asset's origin, positive and finite.
    pub scale: f64,
    /// Roll, pitch, yaw (rad): the rotation `Rz(yaw) Ry(pitch) Rx(roll)` about the asset's
    /// origin, applied after the scale.
    pub rotate: [f64; 3],
    /// Translation (m), applied last.
    pub translate: [f64; 3],
}

impl Default for Placement {
    fn default() -> Self {
        Placement { scale: 1.0, rotate: [0.0; 3], translate: [0.0; 3] }
    }
}

impl Placement {
    /// Checks the fields: a positive finite scale, finite angles and translation.
    ///
    /// # Errors
    /// [`BuildError::Invalid`] naming `scale`, `rotate` or `translate`.
    pub fn check(&self) -> Result<(), BuildError> {
        if !(self.scale > 0.0 && self.scale.is_finite()) {
            return Err(BuildError::invalid(
                "scale",
                format!("must be positive and finite, got {}", self.scale),
            ));
        }
        for (field, v) in [("rotate", self.rotate), ("translate", self.translate)] {
            if !v.iter().all(|x| x.is_finite()) {
                return Err(BuildError::invalid(field, format!("{v:?} holds a non-finite value")));
            }
        }
        Ok(())
    }

    /// The rotation matrix `Rz(yaw) Ry(pitch) Rx(roll)`.
    #[must_use]
    pub fn rotation(&self) -> DMat3 {
        let [roll, pitch, yaw] = self.rotate;
        DMat3::from_euler(EulerRot::ZYX, yaw, pitch, roll)
    }

    /// The placed position of the asset's point `p`.
    #[must_use]
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        (self.rotation() * (self.scale * DVec3::from_array(p)) + DVec3::from_array(self.translate)).to_array()
    }

    /// Places every point in place.
    pub fn apply_all(&self, points: &mut [[f64; 3]]) {
        let r = self.rotation();
        let t = DVec3::from_array(self.translate);
        for p in points {
            *p = (r * (self.scale * DVec3::from_array(*p)) + t).to_array();
        }
    }
}

/// A solid obstacle from a closed triangle surface, placed: a table of a scene file's
/// `obstacle_meshes`, spelled alike by every kind that takes one:
///
/// ```toml
/// obstacle_meshes = [ { mesh = "assets/rock.obj", scale = 0.5, rotate = [0.0, 0.0, 1.0], translate = [0.3, 0.0, 0.2] } ]
/// ```
///
/// Each kind reads the file (relative to the scene file) as a closed, manifold, consistently
/// oriented surface and says what it does in 2D. The grid kinds (mpm, flip, fluid) sample it on
/// their own grid; the particle and element kinds (fem, pbd, springs) on a
/// [`DistanceField`](crate::surface::DistanceField) of spacing `cell`
/// ([`ObstacleMesh::field`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleMesh {
    /// The surface, a Wavefront OBJ file relative to the scene file (polygons are
    /// fan-triangulated).
    pub mesh: PathBuf,
    /// Uniform scale about the mesh's origin, positive; default 1.
    #[serde(default = "unit_scale", skip_serializing_if = "is_unit_scale")]
    pub scale: f64,
    /// Roll, pitch, yaw (rad) about the mesh's origin after the scale, `Rz(yaw) Ry(pitch)
    /// Rx(roll)`; default none.
    #[serde(default, skip_serializing_if = "is_default")]
    pub rotate: [f64; 3],
    /// Translation (m), applied last; default none.
    #[serde(default, skip_serializing_if = "is_default")]
    pub translate: [f64; 3],
    /// The spacing (m) of the distance field the particle and element kinds sample the placed
    /// surface on; default the longest side of its bounds over
    /// [`DEFAULT_CELLS`](Self::DEFAULT_CELLS). The grid kinds use their grid's cells and refuse
    /// it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cell: Option<f64>,
}

impl ObstacleMesh {
    /// Cells along the longest side of the placed surface's bounds when `cell` is not given.
    pub const DEFAULT_CELLS: f64 = 64.0;

    /// The placement of the surface (unchecked: see [`Placement::check`]).
    #[must_use]
    pub fn placement(&self) -> Placement {
        Placement { scale: self.scale, rotate: self.rotate, translate: self.translate }
    }

    /// The distance field of the placed `surface` for a particle or element kind: spacing
    /// `cell` (or the default), over the surface's bounds widened by `margin` (m) plus two
    /// cells, so that a point within `margin` of the surface is in the field.
    ///
    /// # Errors
    /// A message naming `cell` for a cell that is not positive and finite or too fine for the
    /// surface (more than 2^24 nodes), or the margin's reason.
    pub fn field(&self, surface: &ClosedSurface, margin: f64) -> Result<DistanceField, String> {
        let (lo, hi) = surface.bounds();
        let longest = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
        let cell = self.cell.unwrap_or(longest / Self::DEFAULT_CELLS);
        if !(cell > 0.0 && cell.is_finite()) {
            return Err(format!("cell must be positive and finite (m), got {cell}"));
        }
        DistanceField::around(surface, cell, margin + 2.0 * cell).map_err(|e| match self.cell {
            Some(_) => format!("cell = {cell} m: {e}"),
            None => format!("the default cell ({cell} m, the longest side over 64): {e}; set `cell`"),
        })
    }

    /// Refuses `cell` in a kind that samples the surface on its own grid.
    ///
    /// # Errors
    /// A message saying why, when `cell` is set.
    pub fn refuse_cell(&self) -> Result<(), String> {
        match self.cell {
            Some(cell) => Err(format!(
                "cell = {cell}: this kind samples mesh obstacles on its own grid (`cell` sets the \
                 distance field of the fem, pbd and springs kinds)"
            )),
            None => Ok(()),
        }
    }
}

/// The default `scale` of a scene file's body or mesh: 1 (for `#[serde(default = ...)]`).
#[must_use]
pub fn unit_scale() -> f64 {
    1.0
}

/// Whether a `scale` is the default 1 (for `#[serde(skip_serializing_if = ...)]`).
#[must_use]
#[allow(clippy::trivially_copy_pass_by_ref)]
pub fn is_unit_scale(scale: &f64) -> bool {
    *scale == 1.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Roll, pitch and yaw each turn the axes as right-handed rotations about x, y and z, and
    /// the yaw is applied last (the URDF `rpy` convention).
    #[test]
    fn roll_pitch_yaw_turn_about_x_then_y_then_z() {
        let q = std::f64::consts::FRAC_PI_2;
        let close = |a: [f64; 3], b: [f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-12);
        let at = |rotate| Placement { rotate, ..Placement::default() };
        assert!(close(at([q, 0.0, 0.0]).apply([0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]));
        assert!(close(at([0.0, q, 0.0]).apply([0.0, 0.0, 1.0]), [1.0, 0.0, 0.0]));
        assert!(close(at([0.0, 0.0, q]).apply([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]));
        // Roll first, then yaw: y goes to z under the roll and stays there under the yaw.
        assert!(close(at([q, 0.0, q]).apply([0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]));
        // Scale before translation: the origin lands on the translation.
        let p = Placement { scale: 3.0, rotate: [0.0; 3], translate: [1.0, 2.0, 3.0] };
        assert!(close(p.apply([0.0; 3]), [1.0, 2.0, 3.0]));
        assert!(close(p.apply([1.0, 0.0, 0.0]), [4.0, 2.0, 3.0]));
    }

    #[test]
    fn a_bad_scale_or_a_non_finite_angle_is_refused_by_field() {
        let bad = Placement { scale: 0.0, ..Placement::default() };
        assert!(matches!(bad.check(), Err(BuildError::Invalid { field, .. }) if field == "scale"));
        let bad = Placement { rotate: [f64::NAN, 0.0, 0.0], ..Placement::default() };
        assert!(matches!(bad.check(), Err(BuildError::Invalid { field, .. }) if field == "rotate"));
    }

    /// A mesh obstacle's field: 64 cells along the longest side by default, `cell` when given,
    /// covering the surface widened by the margin and two cells; bad cells named.
    #[test]
    fn a_mesh_obstacle_field_takes_its_cell_or_the_longest_side_over_64() {
        let (p, t) = crate::surface::icosphere(2);
        let p: Vec<[f64; 3]> = p.iter().map(|v| [2.0 * v[0], v[1], v[2]]).collect();
        let surface = ClosedSurface::new(p, t).unwrap();
        let mut mesh = ObstacleMesh {
            mesh: PathBuf::from("egg.obj"),
            scale: 1.0,
            rotate: [0.0; 3],
            translate: [0.0; 3],
            cell: None,
        };
        let field = mesh.field(&surface, 0.1).unwrap();
        let (lo, hi) = surface.bounds();
        assert_eq!(field.spacing(), (hi[0] - lo[0]) / 64.0);
        let reach = 0.1 + 2.0 * field.spacing();
        for a in 0..3 {
            assert!((field.origin()[a] - (lo[a] - reach)).abs() < 1e-12);
            assert!(field.far_corner()[a] >= hi[a] + reach - 1e-12);
        }
        mesh.cell = Some(0.25);
        assert_eq!(mesh.field(&surface, 0.0).unwrap().spacing(), 0.25);
        mesh.cell = Some(-1.0);
        assert!(mesh.field(&surface, 0.0).unwrap_err().contains("cell must be positive"));
        mesh.cell = Some(1e-4);
        let message = mesh.field(&surface, 0.0).unwrap_err();
        assert!(message.starts_with("cell = 0.0001 m") && message.contains("2^24"), "{message}");
        assert!(mesh.refuse_cell().unwrap_err().contains("own grid"));
    }
}
