//! The region of a source or an obstacle, and which cell and face centres lie inside it: a
//! collider shape tested analytically, or a closed OBJ surface tested by its winding number
//! ([`ClosedSurface::inside_lattice`]).

use std::path::Path;

use anim_core::geometry::Shape;
use anim_core::scene::{BuildContext, BuildError, Placement};
use anim_core::surface::ClosedSurface;
use anim_io::surface::read_closed_surface;

use crate::mac::MacFluid;

/// A region of space (see the [module](self)).
#[derive(Debug, Clone)]
pub(super) enum Region {
    /// A checked collider shape, read in the first `dim` components.
    Shape { shape: Shape, dim: usize },
    /// A closed surface, placed.
    Surface(Box<ClosedSurface>),
}

impl Region {
    /// The region of `shape` in a `dim`-dimensional scene, checked.
    ///
    /// # Errors
    /// The shape's problem ([`Shape::check_in`]).
    pub(super) fn shape(shape: Shape, dim: usize) -> Result<Self, String> {
        shape.check_in(dim)?;
        Ok(Region::Shape { shape, dim })
    }

    /// The closed surface of the OBJ file `mesh` (relative to the scene file), placed by
    /// `placement` ([`read_closed_surface`]).
    ///
    /// # Errors
    /// [`BuildError::Invalid`] naming `field.scale` (`rotate`, `translate`) for a bad placement
    /// or a surface placed too large to measure, and `field.mesh` for a file that cannot be read
    /// or is not a closed surface (the message names the file and the line, triangle, edge or
    /// vertex).
    pub(super) fn mesh(
        mesh: &Path,
        placement: Placement,
        context: &BuildContext<'_>,
        field: &str,
    ) -> Result<Self, BuildError> {
        let surface = read_closed_surface(&context.resolve(mesh), &placement).map_err(|e| e.within(field))?;
        Ok(Region::Surface(Box::new(surface)))
    }

    /// Per cell of `fluid` (x fastest), whether its centre lies inside.
    ///
    /// # Errors
    /// The surface's refusal of the lattice (never for a grid whose memory the scene's check
    /// let through: [`crate::memory`]).
    pub(super) fn cell_mask(&self, fluid: &MacFluid) -> Result<Vec<bool>, String> {
        self.mask(fluid.dims(), fluid.h(), |i, j, k| fluid.cell_centre(i, j, k))
    }

    /// Per velocity component of `fluid`, whether each face centre lies inside (empty for `w`
    /// in 2D).
    ///
    /// # Errors
    /// As [`Region::cell_mask`].
    pub(super) fn face_masks(&self, fluid: &MacFluid) -> Result<[Vec<bool>; 3], String> {
        let mut masks: [Vec<bool>; 3] = Default::default();
        for (a, mask) in masks.iter_mut().enumerate().take(fluid.dim()) {
            *mask = self.mask(fluid.face_dims(a), fluid.h(), |i, j, k| fluid.face_centre(a, i, j, k))?;
        }
        Ok(masks)
    }

    /// Whether each point `at(i, j, k)` of a lattice of `counts` points spaced `h` lies inside
    /// (x fastest): a shape at each point as the grid computes it, a surface row by row
    /// ([`ClosedSurface::inside_lattice`] from `at(0, 0, 0)`, the winding number by crossings
    /// along x).
    fn mask(
        &self,
        counts: [usize; 3],
        h: f64,
        at: impl Fn(usize, usize, usize) -> [f64; 3],
    ) -> Result<Vec<bool>, String> {
        match self {
            Region::Shape { shape, dim } => {
                let n = counts[0] * counts[1] * counts[2];
                let point =
                    |c: usize| at(c % counts[0], (c / counts[0]) % counts[1], c / (counts[0] * counts[1]));
                Ok((0..n).map(|c| shape_covers(shape, point(c), *dim)).collect())
            }
            Region::Surface(surface) => {
                surface.inside_lattice(at(0, 0, 0), h, counts).map_err(|e| e.to_string())
            }
        }
    }

    /// Why a region that covers no cell centre of the `dim`-dimensional domain `[lo, hi]`
    /// misses it: it lies outside the domain (or, in 2D, a mesh does not cross `z = 0`), or it
    /// falls between the cell centres of `grid` (a description of the grid).
    pub(super) fn misses(&self, (lo, hi): ([f64; 3], [f64; 3]), dim: usize, grid: &str) -> String {
        let domain: Vec<String> = (0..dim).map(|a| format!("[{}, {}]", lo[a], hi[a])).collect();
        let domain = domain.join(" x ");
        match self.bounds() {
            Some((a, b)) if (0..dim).any(|k| b[k] < lo[k] || a[k] > hi[k]) => {
                let at: Vec<String> = (0..dim).map(|k| format!("[{:.4}, {:.4}]", a[k], b[k])).collect();
                format!(
                    "lies outside the domain {domain} (m, the grid's axes, y up): it spans {}",
                    at.join(" x ")
                )
            }
            Some((a, b)) if dim == 2 && matches!(self, Region::Surface(_)) && (a[2] > 0.0 || b[2] < 0.0) => {
                format!("a 2D scene cuts meshes at z = 0, and this one spans z in [{:.4}, {:.4}]", a[2], b[2])
            }
            None => format!(
                "its solid side holds no cell centre of the {grid} in the domain {domain} (m, y up): \
                 the plane lies beyond the domain; move its `point` or turn its `normal`"
            ),
            _ => format!(
                "covers no cell centre of the {grid} in the domain {domain} (m, y up): it falls between \
                 cell centres; make it larger or raise `resolution`"
            ),
        }
    }

    /// The region's bounding box, if it has one (a plane's half-space has none).
    fn bounds(&self) -> Option<([f64; 3], [f64; 3])> {
        match self {
            Region::Surface(s) => Some(s.bounds()),
            Region::Shape { shape, .. } => match *shape {
                Shape::Plane { .. } => None,
                Shape::Sphere { center, radius } => {
                    Some((center.map(|c| c - radius), center.map(|c| c + radius)))
                }
                Shape::Box { center, half_extents } => Some((
                    std::array::from_fn(|a| center[a] - half_extents[a]),
                    std::array::from_fn(|a| center[a] + half_extents[a]),
                )),
                Shape::Capsule { a, b, radius } => Some((
                    std::array::from_fn(|k| a[k].min(b[k]) - radius),
                    std::array::from_fn(|k| a[k].max(b[k]) + radius),
                )),
            },
        }
    }
}

/// Whether `p` lies strictly inside `shape`, reading the first `dim` components of every vector
/// (in 2D a sphere is a disk, a capsule a stadium, a box a rectangle).
pub(super) fn shape_covers(shape: &Shape, p: [f64; 3], dim: usize) -> bool {
    let sub = |x: [f64; 3], y: [f64; 3]| -> [f64; 3] {
        std::array::from_fn(|a| if a < dim { x[a] - y[a] } else { 0.0 })
    };
    let dot = |x: [f64; 3], y: [f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    match *shape {
        Shape::Plane { point, normal } => dot(sub(p, point), sub(normal, [0.0; 3])) < 0.0,
        // The plume preset's expression, term for term, so that a sphere obstacle marks the same
        // cells as the preset's sphere.
        Shape::Sphere { center: [cx, cy, cz], radius: r } => {
            let dz2 = if dim == 3 { (p[2] - cz).powi(2) } else { 0.0 };
            (p[0] - cx).powi(2) + (p[1] - cy).powi(2) + dz2 < r * r
        }
        Shape::Box { center, half_extents } => (0..dim).all(|a| (p[a] - center[a]).abs() < half_extents[a]),
        Shape::Capsule { a, b, radius } => {
            let (ab, ap) = (sub(b, a), sub(p, a));
            let t = (dot(ap, ab) / dot(ab, ab)).clamp(0.0, 1.0);
            let d: [f64; 3] = std::array::from_fn(|k| ap[k] - t * ab[k]);
            dot(d, d) < radius * radius
        }
    }
}
