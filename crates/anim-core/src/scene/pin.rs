//! Which vertices of a body a scene file holds fixed: a box, a list of the mesh file's vertices,
//! or both, with one spelling in every kind that pins vertices:
//!
//! ```toml
//! pin = { vertices = [0, 40], box = { min = [-0.6, 0.49, 0.0], max = [0.6, 0.51, 2.0] } }
//! ```
//!
//! [`PinSpec::resolve`] turns the table and the placed vertices into the pinned vertex indices,
//! refusing, with one [`PinError`] in every kind, a table that pins nothing, an index past the
//! mesh's vertices, a box that is not finite with `min <= max` or that holds no vertex of the
//! placed body. A kind adds its own refusals to what it returns (a vertex that belongs to no
//! element, indices on a mesh whose vertices are not the file's). Every kind names a refusal
//! alike: the error's message, on the field [`PinError::field_under`] gives (`bodies[0].pin`,
//! or the part at fault, `bodies[0].pin.vertices[1]`, `bodies[0].pin.box`).
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

/// Why a `pin` table does not pin the vertices of a body. [`PinError::field`] names the part of
/// the table at fault, where one is.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PinError {
    /// Neither `vertices` nor `box`.
    #[error("give `vertices`, `box` or both")]
    Nothing,
    /// A listed vertex past the mesh's last one.
    #[error("vertex {vertex} is out of range: {file} has {count} vertices (0 to {last})", last = count.saturating_sub(1))]
    OutOfRange {
        /// Its place in `vertices` (0-based).
        index: usize,
        /// The vertex index given.
        vertex: usize,
        /// The mesh's vertices.
        count: usize,
        /// The mesh file, as the kind names it.
        file: String,
    },
    /// A box with a corner that is not finite, or `min > max` on an axis.
    #[error(
        "the box needs finite corners with min <= max on every axis, got min {:?}, max {:?}",
        region.min,
        region.max
    )]
    InvalidBox {
        /// The box given.
        region: PinBox,
    },
    /// A box that holds no vertex of the placed body.
    #[error("the box from {:?} to {:?} holds no vertex of {of} as placed (it spans {lo:?} to {hi:?})", region.min, region.max)]
    EmptyBox {
        /// The box given.
        region: PinBox,
        /// The body, as the kind names it (its mesh file).
        of: String,
        /// The lower corner of the body's placed vertices (infinite when it has none).
        lo: [f64; 3],
        /// The upper corner of the body's placed vertices.
        hi: [f64; 3],
    },
}

impl PinError {
    /// The part of the `pin` table at fault on its own: `vertices[i]` for an index out of
    /// range, `box` for a box that is not finite with `min <= max`; `None` when the table as a
    /// whole is (it pins nothing, or its box misses the body).
    #[must_use]
    pub fn field(&self) -> Option<String> {
        match self {
            PinError::OutOfRange { index, .. } => Some(format!("vertices[{index}]")),
            PinError::InvalidBox { .. } => Some("box".into()),
            PinError::Nothing | PinError::EmptyBox { .. } => None,
        }
    }

    /// The scene-file field at fault, under the kind's `pin` table `pin` (`bodies[0].pin`):
    /// `bodies[0].pin.vertices[1]`, `bodies[0].pin.box`, or `pin` itself when the table as a
    /// whole is at fault ([`field`](Self::field)). Every kind names a refusal by this field and
    /// the error's own message.
    ///
    /// ```
    /// use anim_core::scene::{PinBox, PinError, PinSpec};
    ///
    /// let e = PinSpec { vertices: vec![0, 7], region: None }.resolve(&[[0.0; 3]; 3], "tri.obj").unwrap_err();
    /// assert_eq!(e.field_under("bodies[2].pin"), "bodies[2].pin.vertices[1]");
    /// assert_eq!(PinError::Nothing.field_under("bodies[2].pin"), "bodies[2].pin");
    /// ```
    #[must_use]
    pub fn field_under(&self, pin: &str) -> String {
        self.field().map_or_else(|| pin.to_string(), |part| format!("{pin}.{part}"))
    }
}

impl PinBox {
    /// The indices of the `positions` inside or on the box, among those `among` admits, in
    /// increasing order.
    ///
    /// # Errors
    /// [`PinError::InvalidBox`] for corners that are not finite or `min > max` on an axis;
    /// [`PinError::EmptyBox`], naming `of` and the span of the admitted positions, when it holds
    /// none of them.
    pub fn select(
        &self,
        positions: &[[f64; 3]],
        of: &str,
        among: impl Fn(usize) -> bool,
    ) -> Result<Vec<usize>, PinError> {
        if !self.is_valid() {
            return Err(PinError::InvalidBox { region: *self });
        }
        let admitted = || positions.iter().enumerate().filter(|&(i, _)| among(i));
        let inside: Vec<usize> = admitted().filter(|(_, p)| self.contains(**p)).map(|(i, _)| i).collect();
        if inside.is_empty() {
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            for (_, p) in admitted() {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
            }
            return Err(PinError::EmptyBox { region: *self, of: of.to_string(), lo, hi });
        }
        Ok(inside)
    }
}

impl PinSpec {
    /// Checks the table on its own, before any mesh is read: something to pin, a box with finite
    /// corners and `min <= max`.
    ///
    /// # Errors
    /// [`PinError::Nothing`] or [`PinError::InvalidBox`].
    pub fn check(&self) -> Result<(), PinError> {
        match self.region {
            None if self.vertices.is_empty() => Err(PinError::Nothing),
            Some(region) if !region.is_valid() => Err(PinError::InvalidBox { region }),
            _ => Ok(()),
        }
    }

    /// The listed [`vertices`](Self::vertices) of a mesh of `count` vertices read from `file`, in
    /// increasing order without repeats.
    ///
    /// # Errors
    /// [`PinError::OutOfRange`] for the first index, in the list's order, that is `>= count`.
    pub fn listed(&self, count: usize, file: &str) -> Result<Vec<usize>, PinError> {
        if let Some((index, &vertex)) = self.vertices.iter().enumerate().find(|&(_, &v)| v >= count) {
            return Err(PinError::OutOfRange { index, vertex, count, file: file.to_string() });
        }
        let mut listed = self.vertices.clone();
        listed.sort_unstable();
        listed.dedup();
        Ok(listed)
    }

    /// The pinned vertices of a body whose placed vertices, in the mesh file's order, are
    /// `positions`, read from `file`: the listed ones and those inside or on the box, in
    /// increasing order without repeats.
    ///
    /// ```
    /// use anim_core::scene::{PinBox, PinError, PinSpec};
    ///
    /// let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
    /// let top = PinBox { min: [-0.1, 1.0, 0.0], max: [1.1, 1.1, 0.0] };
    /// let pin = PinSpec { vertices: vec![3, 0], region: Some(top) };
    /// assert_eq!(pin.resolve(&positions, "square.obj")?, [0, 2, 3]);
    ///
    /// let e = PinSpec { vertices: vec![4], region: None }.resolve(&positions, "square.obj").unwrap_err();
    /// assert_eq!(e.to_string(), "vertex 4 is out of range: square.obj has 4 vertices (0 to 3)");
    /// assert_eq!(e.field().as_deref(), Some("vertices[0]"));
    /// assert_eq!(PinSpec::default().resolve(&positions, "square.obj"), Err(PinError::Nothing));
    /// # Ok::<(), PinError>(())
    /// ```
    ///
    /// # Errors
    /// In this order: [`PinError::Nothing`] for a table with neither `vertices` nor `box`,
    /// [`PinError::OutOfRange`] for an index `>= positions.len()`, [`PinError::InvalidBox`],
    /// [`PinError::EmptyBox`] for a box that holds none of `positions`.
    pub fn resolve(&self, positions: &[[f64; 3]], file: &str) -> Result<Vec<usize>, PinError> {
        self.resolve_among(positions, file, |_| true)
    }

    /// As [`resolve`](Self::resolve), with the box taking only the vertices `among` admits (a
    /// kind that leaves the vertices no element uses out of the body); the listed ones are
    /// checked against `positions.len()` only, the kind refuses those not admitted.
    ///
    /// # Errors
    /// As [`resolve`](Self::resolve), the box empty when it holds no admitted vertex.
    pub fn resolve_among(
        &self,
        positions: &[[f64; 3]],
        file: &str,
        among: impl Fn(usize) -> bool,
    ) -> Result<Vec<usize>, PinError> {
        if self.vertices.is_empty() && self.region.is_none() {
            return Err(PinError::Nothing);
        }
        let mut pinned = self.listed(positions.len(), file)?;
        if let Some(region) = self.region {
            pinned.extend(region.select(positions, file, among)?);
            pinned.sort_unstable();
            pinned.dedup();
        }
        Ok(pinned)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3 x 3 grid of unit spacing in the plane z = 0, row by row: vertex `3 y + x` at `(x, y)`.
    fn grid() -> Vec<[f64; 3]> {
        (0..9).map(|i| [f64::from(i % 3), f64::from(i / 3), 0.0]).collect()
    }

    fn pin(vertices: &[usize], region: Option<([f64; 3], [f64; 3])>) -> PinSpec {
        PinSpec { vertices: vertices.to_vec(), region: region.map(|(min, max)| PinBox { min, max }) }
    }

    #[test]
    fn the_box_holds_the_vertices_on_its_faces_and_none_past_them() {
        let p = grid();
        // The box's faces pass exactly through the middle column and row: on them is inside.
        let middle = pin(&[], Some(([1.0, 1.0, 0.0], [1.0, 2.0, 0.0])));
        assert_eq!(middle.resolve(&p, "grid.obj"), Ok(vec![4, 7]));
        // Nudged past the vertices by one ulp on either side, it holds none of them.
        let past = pin(&[], Some(([1.0_f64.next_up(), 1.0, 0.0], [1.5, 2.0, 0.0])));
        assert!(matches!(past.resolve(&p, "grid.obj"), Err(PinError::EmptyBox { .. })));
        let below = pin(&[], Some(([0.0, 0.0, -1.0], [2.0, 2.0, 0.0_f64.next_down()])));
        assert!(matches!(below.resolve(&p, "grid.obj"), Err(PinError::EmptyBox { .. })));
    }

    #[test]
    fn listed_and_boxed_vertices_come_once_each_in_increasing_order() {
        let p = grid();
        // Listed out of order with a repeat, and a box over the last row that holds 8 again.
        let both = pin(&[8, 1, 8, 0], Some(([-0.5, 1.5, -1.0], [2.5, 2.5, 1.0])));
        assert_eq!(both.resolve(&p, "grid.obj"), Ok(vec![0, 1, 6, 7, 8]));
        assert_eq!(pin(&[5, 3, 5], None).resolve(&p, "grid.obj"), Ok(vec![3, 5]));
        assert_eq!(pin(&[5, 3, 5], None).listed(6, "grid.obj"), Ok(vec![3, 5]));
        assert_eq!(pin(&[], None).listed(0, "grid.obj"), Ok(vec![]));
    }

    #[test]
    fn the_box_takes_only_the_admitted_vertices_and_is_empty_without_one() {
        let p = grid();
        let left = pin(&[], Some(([-0.5, -0.5, -1.0], [0.5, 2.5, 1.0])));
        let odd = |i: usize| i % 2 == 1;
        assert_eq!(left.resolve_among(&p, "grid.obj", odd), Ok(vec![3]));
        // The first column's only odd vertex left out too: empty, spanning the admitted ones.
        let e = left.resolve_among(&p, "grid.obj", |i| odd(i) && i != 3).unwrap_err();
        assert_eq!(
            e,
            PinError::EmptyBox {
                region: left.region.unwrap(),
                of: "grid.obj".into(),
                lo: [1.0, 0.0, 0.0],
                hi: [2.0, 2.0, 0.0]
            }
        );
        assert_eq!(
            e.to_string(),
            "the box from [-0.5, -0.5, -1.0] to [0.5, 2.5, 1.0] holds no vertex of grid.obj as placed \
             (it spans [1.0, 0.0, 0.0] to [2.0, 2.0, 0.0])"
        );
        assert_eq!(e.field(), None);
        // A listed vertex is not filtered: the kind refuses those it does not admit.
        assert_eq!(pin(&[0], None).resolve_among(&p, "grid.obj", odd), Ok(vec![0]));
    }

    #[test]
    fn each_refusal_names_its_cause_and_its_part_of_the_table() {
        let p = grid();
        assert_eq!(pin(&[], None).resolve(&p, "grid.obj"), Err(PinError::Nothing));
        assert_eq!(PinError::Nothing.to_string(), "give `vertices`, `box` or both");
        // The first index out of range in the list's order, with its place in the list.
        let e = pin(&[2, 10, 9], None).resolve(&p, "grid.obj").unwrap_err();
        assert_eq!(e, PinError::OutOfRange { index: 1, vertex: 10, count: 9, file: "grid.obj".into() });
        assert_eq!(e.to_string(), "vertex 10 is out of range: grid.obj has 9 vertices (0 to 8)");
        assert_eq!(e.field().as_deref(), Some("vertices[1]"));
        // 9 is out of range too, before the box is looked at.
        let e = pin(&[9], Some(([1.0, 0.0, 0.0], [0.0, 1.0, 1.0]))).resolve(&p, "grid.obj").unwrap_err();
        assert!(matches!(e, PinError::OutOfRange { vertex: 9, .. }), "{e}");
        for (min, max) in [
            ([1.0, 0.0, 0.0], [0.0, 1.0, 1.0]),
            ([0.0, 0.0, f64::NAN], [1.0, 1.0, 1.0]),
            ([0.0, 0.0, 0.0], [1.0, f64::INFINITY, 1.0]),
        ] {
            let region = PinBox { min, max };
            let spec = PinSpec { vertices: vec![0], region: Some(region) };
            let e = spec.resolve(&p, "grid.obj").unwrap_err();
            // Compared by their bits: a NaN corner is not equal to itself.
            let bits = |b: PinBox| b.min.iter().chain(&b.max).map(|c| c.to_bits()).collect::<Vec<_>>();
            let refused = |e: &PinError| match e {
                PinError::InvalidBox { region: r } => bits(*r) == bits(region),
                _ => false,
            };
            assert!(refused(&e), "{min:?} {max:?}: {e}");
            assert!(spec.check().is_err_and(|c| refused(&c)));
            assert_eq!(e.field().as_deref(), Some("box"));
            assert!(e.to_string().starts_with("the box needs finite corners with min <= max"), "{e}");
        }
        // `check` looks at the table alone: it takes any index, and refuses an empty table.
        assert_eq!(pin(&[100], None).check(), Ok(()));
        assert_eq!(pin(&[], None).check(), Err(PinError::Nothing));
    }
}
