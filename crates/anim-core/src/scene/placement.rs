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

use glam::{DMat3, DVec3, EulerRot};

use super::BuildError;

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
}
