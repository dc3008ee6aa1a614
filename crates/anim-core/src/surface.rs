//! Closed triangle surfaces, the shape of a user's body: the check that a surface encloses a
//! volume, the inside test, the points of a lattice inside it, and a tetrahedral mesh of its
//! inside.
//!
//! - [`ClosedSurface::new`] checks a triangle soup: finite positions, indices in range, no
//!   zero-area triangle, and every edge shared by exactly two triangles that run along it in
//!   opposite directions (closed, manifold, consistently oriented). An error names the triangle,
//!   the edge or the vertex. A surface whose triangles all face inward is accepted: only the
//!   consistency matters, and the enclosed volume is reported positive.
//! - [`ClosedSurface::winding_number`] is the generalized winding number of Jacobson, Kavan and
//!   Sorkine-Hornung (2013): the sum of the solid angles of the triangles seen from the point,
//!   over 4 pi (each by the formula of Van Oosterom and Strackee 1983). It is 1 inside and 0
//!   outside, and jumps across the surface; [`ClosedSurface::contains`] thresholds it at 1/2.
//! - [`ClosedSurface::inside_lattice`] classifies a whole lattice at once by casting one ray per
//!   lattice row along x and counting signed crossings (the winding number again, for a closed
//!   surface), falling back to the solid-angle sum on the rare rows that pass within rounding
//!   distance of an edge or a vertex, where a crossing count could be wrong.
//! - [`ClosedSurface::tetrahedralize`] meshes the inside: the cubes of a lattice of the given
//!   cell size, each split into the six tetrahedra of Kuhn's triangulation around its main
//!   diagonal (conforming from cube to cube), keeps the tetrahedra whose centroid is inside, then
//!   moves each vertex on the boundary of that mesh onto the closest point of the surface unless
//!   the move would shrink one of its tetrahedra below a tenth of its lattice volume (which also
//!   excludes inverting it). The tetrahedra are all well shaped; the boundary follows the surface
//!   to within a fraction of a cell where the cells resolve it, and features smaller than a cell
//!   are lost.
//! - [`DistanceField`] samples the signed distance to the surface on a lattice (exact near
//!   the surface, by fast sweeping beyond) and interpolates it with its gradient and Hessian:
//!   the collider of a triangle-mesh obstacle.
//!
//! ```
//! use anim_core::surface::ClosedSurface;
//!
//! // The unit cube [0, 1]^3, twelve outward triangles.
//! let p = vec![
//!     [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0],
//!     [0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 1.0, 1.0], [0.0, 1.0, 1.0],
//! ];
//! let t = vec![
//!     [0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
//!     [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7],
//! ];
//! let cube = ClosedSurface::new(p, t)?;
//! assert!((cube.volume() - 1.0).abs() < 1e-12);
//! assert!(cube.contains([0.5, 0.5, 0.5]) && !cube.contains([1.5, 0.5, 0.5]));
//! let (nodes, tets) = cube.tetrahedralize(0.25)?;
//! assert_eq!(tets.len(), 6 * 4 * 4 * 4);
//! # let _ = nodes;
//! # Ok::<(), anim_core::surface::SurfaceError>(())
//! ```

use std::collections::HashMap;
use std::f64::consts::PI;

use crate::geometry::closest_point_on_triangle;

use crate::par::prelude::*;
use glam::DVec3;

mod distance;
#[cfg(test)]
mod distance_tests;
mod lattice;
#[cfg(test)]
mod tests;
mod tetrahedralize;

pub use distance::{DistanceField, FieldSample};

/// A tetrahedral mesh: the vertex positions and the tetrahedra (four vertex indices each,
/// positively oriented).
pub type Tetrahedra = (Vec<[f64; 3]>, Vec<[usize; 4]>);

/// Why a triangle surface is not a usable closed surface, or why it cannot be meshed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SurfaceError {
    /// No triangle.
    #[error("the surface has no triangle")]
    Empty,
    /// A position holds NaN or an infinity.
    #[error("vertex {vertex} has a non-finite position {position:?}")]
    NonFinite {
        /// The vertex (0-based).
        vertex: usize,
        /// Its position.
        position: [f64; 3],
    },
    /// A triangle names a vertex that does not exist.
    #[error("triangle {triangle} names vertex {index}, but there are {vertices} vertices")]
    Index {
        /// The triangle (0-based).
        triangle: usize,
        /// The index it holds.
        index: usize,
        /// The number of vertices.
        vertices: usize,
    },
    /// A triangle with a repeated vertex or (nearly) collinear corners.
    #[error("triangle {triangle} (vertices {vertices:?}) has zero area")]
    Degenerate {
        /// The triangle (0-based).
        triangle: usize,
        /// Its vertices.
        vertices: [usize; 3],
    },
    /// An edge used by one triangle only: the surface has a hole.
    #[error(
        "the surface is not closed: edge ({}, {}) of triangle {triangle} has no neighbour",
        edge[0],
        edge[1]
    )]
    Open {
        /// The edge's vertices.
        edge: [usize; 2],
        /// The triangle that uses it.
        triangle: usize,
    },
    /// An edge used by more than two triangles.
    #[error("the surface is not manifold: edge ({}, {}) is shared by {count} triangles", edge[0], edge[1])]
    NonManifold {
        /// The edge's vertices.
        edge: [usize; 2],
        /// How many triangles share it.
        count: usize,
    },
    /// Two triangles run along their shared edge in the same direction: one of them is flipped.
    #[error(
        "triangles {} and {} are inconsistently oriented: both run along edge ({}, {}) the same way",
        triangles[0],
        triangles[1],
        edge[0],
        edge[1]
    )]
    Inconsistent {
        /// The edge, as both triangles run along it.
        edge: [usize; 2],
        /// The two triangles.
        triangles: [usize; 2],
    },
    /// A surface too large for its volume to be computed in `f64` (the product of its extents
    /// overflows).
    #[error(
        "the surface spans {} x {} x {} m, too large to measure its volume: scale it down",
        extent[0],
        extent[1],
        extent[2]
    )]
    TooLarge {
        /// The extents of its bounding box (m).
        extent: [f64; 3],
    },
    /// A closed surface enclosing no volume (a sheet folded onto itself).
    #[error("the surface encloses no volume")]
    ZeroVolume,
    /// A cell size or spacing that is not positive and finite, or too fine for the surface.
    #[error("{0}")]
    Resolution(String),
}

/// A closed, manifold, consistently oriented triangle surface (see the [module](self)).
#[derive(Debug, Clone)]
pub struct ClosedSurface {
    positions: Vec<DVec3>,
    triangles: Vec<[usize; 3]>,
    lo: DVec3,
    hi: DVec3,
    /// `+1` if the triangles face outward, `-1` if inward.
    orientation: f64,
    volume: f64,
}

impl ClosedSurface {
    /// Checks the surface (see the [module](self)).
    ///
    /// # Errors
    /// [`SurfaceError`] naming the vertex, triangle or edge at fault.
    pub fn new(positions: Vec<[f64; 3]>, triangles: Vec<[usize; 3]>) -> Result<Self, SurfaceError> {
        if triangles.is_empty() {
            return Err(SurfaceError::Empty);
        }
        if let Some((vertex, &position)) =
            positions.iter().enumerate().find(|(_, p)| !p.iter().all(|x| x.is_finite()))
        {
            return Err(SurfaceError::NonFinite { vertex, position });
        }
        let n = positions.len();
        for (triangle, t) in triangles.iter().enumerate() {
            if let Some(&index) = t.iter().find(|&&i| i >= n) {
                return Err(SurfaceError::Index { triangle, index, vertices: n });
            }
        }
        let positions: Vec<DVec3> = positions.iter().map(|p| DVec3::from_array(*p)).collect();
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for t in &triangles {
            for &i in t {
                lo = lo.min(positions[i]);
                hi = hi.max(positions[i]);
            }
        }
        let extent = hi - lo;
        let scale = extent.length_squared();
        if !scale.is_finite() || !(extent.x * extent.y * extent.z).is_finite() {
            return Err(SurfaceError::TooLarge { extent: extent.to_array() });
        }
        for (triangle, &t) in triangles.iter().enumerate() {
            let [a, b, c] = t.map(|i| positions[i]);
            let area2 = (b - a).cross(c - a).length();
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || area2 <= 1e-14 * scale {
                return Err(SurfaceError::Degenerate { triangle, vertices: t });
            }
        }
        check_edges(&triangles)?;
        let signed: f64 = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i] - lo);
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        if !signed.is_finite() {
            return Err(SurfaceError::TooLarge { extent: extent.to_array() });
        }
        if signed.abs() <= 1e-12 * extent.x * extent.y * extent.z {
            return Err(SurfaceError::ZeroVolume);
        }
        Ok(ClosedSurface { positions, triangles, lo, hi, orientation: signed.signum(), volume: signed.abs() })
    }

    /// The vertex positions.
    #[must_use]
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// The triangles.
    #[must_use]
    pub fn triangles(&self) -> &[[usize; 3]] {
        &self.triangles
    }

    /// The corners of the axis-aligned box around the surface's triangles.
    #[must_use]
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        (self.lo.to_array(), self.hi.to_array())
    }

    /// The enclosed volume, positive.
    #[must_use]
    pub fn volume(&self) -> f64 {
        self.volume
    }

    /// The generalized winding number at `p`: 1 inside and 0 outside, whichever way the
    /// triangles face (on the surface itself, either).
    #[must_use]
    pub fn winding_number(&self, p: [f64; 3]) -> f64 {
        let p = DVec3::from_array(p);
        let total: f64 = self.triangles.iter().map(|t| solid_angle(t.map(|i| self.positions[i] - p))).sum();
        self.orientation * total / (4.0 * PI)
    }

    /// Whether `p` is inside: its [winding number](Self::winding_number) exceeds 1/2 (a point on
    /// the surface may count as either).
    #[must_use]
    pub fn contains(&self, p: [f64; 3]) -> bool {
        let q = DVec3::from_array(p);
        if q.cmplt(self.lo).any() || q.cmpgt(self.hi).any() {
            return false;
        }
        self.winding_number(p) > 0.5
    }

    /// Whether each point of the lattice `origin + (i, j, k) spacing`, `i < counts[0]`,
    /// `j < counts[1]`, `k < counts[2]`, is inside, with `i` running fastest.
    ///
    /// # Errors
    /// [`SurfaceError::Resolution`] for a spacing that is not positive and finite, a non-finite
    /// origin or a lattice of more than 2^27 points.
    pub fn inside_lattice(
        &self,
        origin: [f64; 3],
        spacing: f64,
        counts: [usize; 3],
    ) -> Result<Vec<bool>, SurfaceError> {
        lattice::check(origin, spacing, counts)?;
        let rows = lattice::Rows::new(self, origin[1], origin[2], spacing, [counts[1], counts[2]]);
        let mut inside = vec![false; counts.iter().product()];
        let xs: Vec<f64> = (0..counts[0]).map(|i| origin[0] + i as f64 * spacing).collect();
        // Rows are independent: z-slices in parallel, the same answers on any thread count.
        inside.par_chunks_mut(counts[0] * counts[1]).enumerate().for_each(|(k, slice)| {
            for (j, row) in slice.chunks_mut(counts[0]).enumerate() {
                rows.classify(self, j, k, &xs, row);
            }
        });
        Ok(inside)
    }

    /// The points of a lattice of this spacing that lie inside: the cell centres of a grid of
    /// cubes of side `spacing` laid from the lower corner of the [bounds](Self::bounds), in
    /// x-fastest order.
    ///
    /// # Errors
    /// As [`inside_lattice`](Self::inside_lattice).
    pub fn sample_inside(&self, spacing: f64) -> Result<Vec<[f64; 3]>, SurfaceError> {
        lattice::check(self.lo.to_array(), spacing, [1, 1, 1])?;
        let extent = self.hi - self.lo;
        let counts = [0, 1, 2].map(|a| ((extent[a] / spacing).ceil() as usize).max(1));
        let origin = (self.lo + DVec3::splat(0.5 * spacing)).to_array();
        let inside = self.inside_lattice(origin, spacing, counts)?;
        let mut points = Vec::new();
        for (c, _) in inside.iter().enumerate().filter(|(_, i)| **i) {
            let (i, j, k) = (c % counts[0], (c / counts[0]) % counts[1], c / (counts[0] * counts[1]));
            points.push([0, 1, 2].map(|a| origin[a] + [i, j, k][a] as f64 * spacing));
        }
        Ok(points)
    }

    /// A tetrahedral mesh of the inside with edges of about `cell` (see the [module](self)):
    /// the vertices and the positively oriented tetrahedra.
    ///
    /// # Errors
    /// [`SurfaceError::Resolution`] for a cell that is not positive and finite, that exceeds
    /// the surface's size so that no tetrahedron is inside, or that would make more than
    /// 2^21 lattice cubes.
    pub fn tetrahedralize(&self, cell: f64) -> Result<Tetrahedra, SurfaceError> {
        tetrahedralize::mesh(self, cell)
    }

    /// The closest point of the surface to `p`.
    #[must_use]
    pub fn closest_point(&self, p: DVec3) -> DVec3 {
        let mut best = (f64::INFINITY, p);
        for t in &self.triangles {
            let (q, _) = closest_point_on_triangle(p, t.map(|i| self.positions[i]));
            let d = (q - p).length_squared();
            if d < best.0 {
                best = (d, q);
            }
        }
        best.1
    }
}

/// The axis-aligned box with corners `lo` and `hi` as a closed surface: its eight corners,
/// numbered by the bits `(x, y, z)` of their index (corner `k` takes `hi` on axis `a` where bit
/// `a` of `k` is set), and twelve outward triangles, two per face.
///
/// ```
/// let (p, t) = anim_core::surface::cuboid([0.0, 0.0, 0.0], [2.0, 1.0, 0.5]);
/// assert_eq!((p[5], t.len()), ([2.0, 0.0, 0.5], 12));
/// let s = anim_core::surface::ClosedSurface::new(p, t)?;
/// assert!((s.volume() - 1.0).abs() < 1e-15 && s.contains([1.0, 0.5, 0.25]));
/// # Ok::<(), anim_core::surface::SurfaceError>(())
/// ```
#[must_use]
pub fn cuboid(lo: [f64; 3], hi: [f64; 3]) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let corners =
        (0..8).map(|k| std::array::from_fn(|a| if (k >> a) & 1 == 1 { hi[a] } else { lo[a] })).collect();
    // Each face as a quad counter-clockwise from outside, split along its first diagonal.
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let triangles = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
    (corners, triangles)
}

/// A unit-radius icosphere around the origin: the icosahedron subdivided `subdivisions` times
/// (20 * 4^s triangles), outward-oriented, closed: the midpoint of each edge is pushed out onto
/// the sphere, shared by the edge's two triangles.
///
/// ```
/// let (p, t) = anim_core::surface::icosphere(2);
/// assert_eq!((p.len(), t.len()), (162, 320));
/// let s = anim_core::surface::ClosedSurface::new(p, t)?;
/// assert!(s.volume() > 0.95 * 4.0 / 3.0 * std::f64::consts::PI);
/// # Ok::<(), anim_core::surface::SurfaceError>(())
/// ```
#[must_use]
pub fn icosphere(subdivisions: usize) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut pos: Vec<DVec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|&p| DVec3::from_array(p).normalize())
    .collect();
    let mut tris: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut mid: HashMap<(usize, usize), usize> = HashMap::new();
        let mut next = Vec::with_capacity(4 * tris.len());
        let mut midpoint = |a: usize, b: usize, pos: &mut Vec<DVec3>| {
            let k = if a < b { (a, b) } else { (b, a) };
            *mid.entry(k).or_insert_with(|| {
                pos.push(((pos[a] + pos[b]) * 0.5).normalize());
                pos.len() - 1
            })
        };
        for [a, b, c] in tris {
            let ab = midpoint(a, b, &mut pos);
            let bc = midpoint(b, c, &mut pos);
            let ca = midpoint(c, a, &mut pos);
            next.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    (pos.iter().map(|p| p.to_array()).collect(), tris)
}

/// Every undirected edge used twice, in opposite directions.
fn check_edges(triangles: &[[usize; 3]]) -> Result<(), SurfaceError> {
    // Undirected edge -> (count, first directed use, its triangle).
    let mut edges: HashMap<(usize, usize), (usize, [usize; 2], usize)> =
        HashMap::with_capacity(triangles.len() * 2);
    for (triangle, t) in triangles.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            let entry = edges.entry((a.min(b), a.max(b))).or_insert((0, [a, b], triangle));
            entry.0 += 1;
            if entry.0 == 2 && entry.1 == [a, b] {
                return Err(SurfaceError::Inconsistent { edge: [a, b], triangles: [entry.2, triangle] });
            }
        }
    }
    let mut bad: Vec<_> = edges.into_iter().filter(|(_, (count, _, _))| *count != 2).collect();
    bad.sort_unstable_by_key(|(_, (_, _, triangle))| *triangle);
    match bad.first() {
        None => Ok(()),
        Some(&(_, (1, edge, triangle))) => Err(SurfaceError::Open { edge, triangle }),
        Some(&(_, (count, edge, _))) => Err(SurfaceError::NonManifold { edge, count }),
    }
}

/// The signed solid angle of the triangle `a, b, c` (relative to the viewpoint), Van Oosterom
/// and Strackee's formula.
fn solid_angle([a, b, c]: [DVec3; 3]) -> f64 {
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let numerator = a.dot(b.cross(c));
    let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    2.0 * numerator.atan2(denominator)
}
