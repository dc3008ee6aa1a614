//! Which vertices of a body a scene file holds fixed: a box, a list of the mesh file's vertices,
//! or both, with one spelling in every kind that pins vertices:
//!
//! ```toml
//! pin = { vertices = [0, 40], box = { min = [-0.6, 0.49, 0.0], max = [0.6, 0.51, 2.0] } }
//! ```
//!
//! Each kind checks the indices against its mesh and refuses a box that holds no vertex of the
//! placed body.
//!
//! ```
//! use anim_core::scene::PinBox;
//!
//! let b = PinBox { min: [0.0, 0.0, 0.0], max: [1.0, 1.0, 0.1] };
//! assert!(b.contains([0.5, 1.0, 0.1]) && !b.contains([0.5, 1.0, 0.2]));
//! assert!(b.is_valid() && !PinBox { min: [2.0, 0.0, 0.0], ..b }.is_valid());
//! ```

use serde::{Deserialize, Serialize};

/// An axis-aligned box in the scene's coordinates, after the body's placement (m).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PinBox {
    /// The lower corner.
    pub min: [f64; 3],
    /// The upper corner (`>= min` on every axis).
    pub max: [f64; 3],
}

impl PinBox {
    /// Whether `p` is inside or on the box.
    #[must_use]
    pub fn contains(&self, p: [f64; 3]) -> bool {
        (0..3).all(|k| p[k] >= self.min[k] && p[k] <= self.max[k])
    }

    /// Whether the corners are finite.
    #[must_use]
    pub fn is_finite(&self) -> bool {
        self.min.iter().chain(&self.max).all(|c| c.is_finite())
    }

    /// Whether the corners are finite with `min <= max` on every axis.
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.is_finite() && (0..3).all(|k| self.min[k] <= self.max[k])
    }
}

/// The vertices of a body held fixed: those listed, those in the box, or both. Pinned vertices
/// start at rest, whatever the body's `velocity`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PinSpec {
    /// Vertex indices of the mesh file, 0-based in the file's order (the first vertex is 0);
    /// default none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub vertices: Vec<usize>,
    /// The vertices inside or on this box, after the placement; it must hold at least one.
    /// Default none. Written `box` in a scene file.
    #[serde(default, rename = "box", skip_serializing_if = "Option::is_none")]
    pub region: Option<PinBox>,
}
