//! A region of the scene: a placed [`Shape`] or the inside of a placed closed OBJ surface, with
//! its bounds, tested at points of the scene's frame (the tank's inside from the origin, y up).
//!
//! A 2D scene is the plane `z = 0`: its shapes are read in their first two components (the
//! convention of [`Shape::check_in`]: a sphere is a disk, a box a rectangle) and a mesh is cut
//! by that plane.

use anim_core::geometry::Shape;
use anim_core::glam::{DMat3, DVec3};
use anim_core::scene::{BuildContext, BuildError, Placement};
use anim_core::surface::ClosedSurface;
use anim_io::surface::read_closed_surface;
use std::path::Path;

/// A region of space: the inside of a shape or of a closed surface.
#[derive(Debug, Clone)]
pub(crate) struct Region {
    kind: Kind,
    /// Corners of a box holding the region (infinite for a plane).
    pub(crate) lo: [f64; 3],
    pub(crate) hi: [f64; 3],
}

#[derive(Debug, Clone)]
enum Kind {
    /// A shape and the inverse of its placement (`None`: not moved).
    Shape { shape: Shape, inverse: Option<Inverse> },
    /// The inside of a closed surface, already placed.
    Surface(Box<ClosedSurface>),
}

/// The inverse of a placement: `x -> R^T (x - t) / s`.
#[derive(Debug, Clone, Copy)]
struct Inverse {
    rotation_t: DMat3,
    translate: DVec3,
    inv_scale: f64,
}

impl Region {
    /// The inside of `shape` moved by `placement` (scale, then rotation, then translation, about
    /// the origin), in a `dim`-dimensional scene.
    pub(crate) fn shape(shape: Shape, placement: Placement, dim: usize) -> Self {
        let shape = if dim == 2 { shape.in_plane() } else { shape.normalized() };
        let (lo, hi) = placed_bounds(&shape, &placement);
        let inverse = (placement != Placement::default()).then(|| Inverse {
            rotation_t: placement.rotation().transpose(),
            translate: DVec3::from_array(placement.translate),
            inv_scale: 1.0 / placement.scale,
        });
        Region { kind: Kind::Shape { shape, inverse }, lo, hi }
    }

    /// The inside of the closed surface of the OBJ file `mesh` (as the scene file names it,
    /// resolved by `context`), placed. `table` is the scene-file table of the mesh
    /// (`bodies[0]`), for errors.
    ///
    /// # Errors
    /// [`BuildError::Invalid`] naming the file and `table.mesh` for a file that does not read
    /// (the line) or a surface that is not closed, manifold and consistently oriented after the
    /// placement (the triangle, edge or vertex at fault), `table.scale` for a surface placed too
    /// large to measure ([`read_closed_surface`]).
    pub(crate) fn mesh(
        mesh: &Path,
        placement: Placement,
        context: &BuildContext<'_>,
        table: &str,
    ) -> Result<Self, BuildError> {
        let surface = read_closed_surface(&context.resolve(mesh), &placement).map_err(|e| e.within(table))?;
        let (lo, hi) = surface.bounds();
        Ok(Region { kind: Kind::Surface(Box::new(surface)), lo, hi })
    }

    /// The closed surface of a mesh region (placed), `None` for a shape.
    pub(crate) fn surface(&self) -> Option<&ClosedSurface> {
        match &self.kind {
            Kind::Surface(surface) => Some(surface),
            Kind::Shape { .. } => None,
        }
    }

    /// Whether each point `(start + i + 1/2) spacing` of a `D`-dimensional lattice,
    /// `i < counts` per axis, is inside (z = 0 in 2D), x fastest. Points on a shape's boundary
    /// are outside; a surface classifies by rows ([`ClosedSurface::inside_lattice`]).
    ///
    /// # Errors
    /// The surface's refusal of the lattice (a spacing that is not positive and finite, more
    /// than 2^31 points), as a message.
    pub(crate) fn inside_lattice<const D: usize>(
        &self,
        start: [usize; D],
        counts: [usize; D],
        spacing: f64,
    ) -> Result<Vec<bool>, String> {
        let centre = |i: usize| (i as f64 + 0.5) * spacing;
        Ok(match &self.kind {
            Kind::Shape { .. } => {
                let total: usize = counts.iter().product();
                (0..total)
                    .map(|f| {
                        let idx = crate::mac::unflatten(counts, f);
                        let p = std::array::from_fn(|a| if a < D { centre(start[a] + idx[a]) } else { 0.0 });
                        self.contains(p)
                    })
                    .collect()
            }
            Kind::Surface(surface) => {
                let origin = std::array::from_fn(|a| if a < D { centre(start[a]) } else { 0.0 });
                let counts3 = std::array::from_fn(|a| if a < D { counts[a] } else { 1 });
                surface.inside_lattice(origin, spacing, counts3).map_err(|e| e.to_string())?
            }
        })
    }

    /// Whether the point `p` is inside (strictly, for shapes: the boundary is outside).
    fn contains(&self, p: [f64; 3]) -> bool {
        match &self.kind {
            Kind::Shape { shape, inverse } => {
                let mut x = DVec3::from_array(p);
                if let Some(i) = inverse {
                    x = i.rotation_t * (x - i.translate) * i.inv_scale;
                }
                shape.signed_distance(x).0 < 0.0
            }
            Kind::Surface(surface) => surface.contains(p),
        }
    }
}

/// Corners of a box that holds `shape` moved by `placement`: exact for spheres, boxes and
/// capsules (their extreme points are the placed centre, corners and ends); infinite for a
/// plane.
fn placed_bounds(shape: &Shape, placement: &Placement) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut grow = |p: [f64; 3], r: f64| {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k] - r);
            hi[k] = hi[k].max(p[k] + r);
        }
    };
    let s = placement.scale;
    match *shape {
        Shape::Plane { .. } => return ([f64::NEG_INFINITY; 3], [f64::INFINITY; 3]),
        Shape::Sphere { center, radius } => grow(placement.apply(center), s * radius),
        Shape::Capsule { a, b, radius } => {
            grow(placement.apply(a), s * radius);
            grow(placement.apply(b), s * radius);
        }
        Shape::Box { center, half_extents: e } => {
            for corner in 0..8 {
                let sign = |k: usize| if corner >> k & 1 == 1 { 1.0 } else { -1.0 };
                grow(placement.apply(std::array::from_fn(|k| center[k] + sign(k) * e[k])), 0.0);
            }
        }
    }
    (lo, hi)
}
