//! Triangle-mesh obstacles (3D): a closed surface turned into a level-set collider, as in
//! grid-based MPM codes.
//!
//! **Build.** The signed distance `phi` to the surface (negative inside) is sampled once on the
//! grid nodes `x_i = i h` of the box around the surface's bounds widened by [`MARGIN`] cells on
//! every side and clipped to the domain's nodes `[0, n]`, and stored dense in `f32` for that
//! box only: anim-core's narrow-band [`DistanceField`] with a band of [`BAND`] cells (the sign
//! is the surface's inside test at the node, the magnitude the distance to the closest triangle
//! within the band, `BAND` cells where none is that close). The build costs one inside
//! classification of the box plus, per triangle, one closest-point evaluation per node of its
//! box widened by the band: about `T (e / h + 2 BAND + 1)^3` evaluations for `T` triangles of
//! extent `e` (a 12-triangle cube filling a quarter of a 64-cell domain: about 12 x 25^3 =
//! 190 000; a mesh of 100 000 small triangles: about 100 000 x 9^3 = 7.3e7), run in parallel
//! over z-slices of the box. A box of more than [`MAX_NODES`] nodes (64 MB of table) is refused.
//!
//! **Grid update.** A grid node inside the box whose table value is `<= 0` (inside, or on the
//! surface) gets the scene's [`Boundary`] condition with the outward normal the normalised
//! central difference of the table at the node (one-sided at the box's faces). Where that
//! difference vanishes (the node and its six neighbours all at least `BAND` cells inside, where
//! the table is clamped) the node is stopped (the obstacle is fixed). Nodes outside the box are outside the obstacle. A step
//! thus pays a table lookup per grid node in the box (seven for the nodes inside); nothing is
//! allocated and the result does not depend on the thread count.
//!
//! **Particles.** A particle is inside the obstacle (and refused when a scene starts so) when
//! the trilinear interpolation of the table at its position is negative.

use anim_core::surface::{ClosedSurface, DistanceField};

use crate::{Boundary, MpmParams, Vector};

/// The most grid nodes the table of one mesh obstacle may hold: `2^24` (64 MB of `f32`).
pub const MAX_NODES: usize = DistanceField::MAX_NODES;

/// Cells the table's box reaches beyond the surface's bounds on every side.
pub const MARGIN: usize = 4;

/// Cells within which the table holds the exact distance to the surface (clamped beyond).
pub const BAND: usize = 4;

/// A fixed obstacle from a closed OBJ surface (`obstacle_meshes = [{ mesh, scale, rotate,
/// translate }]` in a scene file of bodies, 3D; anim-core's spelling), with the scene's
/// `boundary` condition.
pub use anim_core::scene::ObstacleMesh;

/// A fixed obstacle of a closed surface as the grid sees it: its signed distance table on the
/// nodes of a box (see the [module](self)) and its boundary condition. Cloning shares the table.
#[derive(Clone, Debug)]
pub struct MeshCollider {
    /// First node index of the box per axis.
    lo: [usize; 3],
    /// Nodes of the box per axis.
    counts: [usize; 3],
    /// Signed distance (m) on the nodes of the box (with the placed surface it samples).
    phi: DistanceField,
    /// Boundary condition on the surface.
    pub(crate) boundary: Boundary,
}

impl MeshCollider {
    /// Samples the signed distance of `surface` (placed already, in the domain's metres) on the
    /// grid nodes of `params` around it.
    ///
    /// # Errors
    /// A box of nodes more than [`MAX_NODES`] (the numbers in the message), a surface outside
    /// the domain or with no grid node inside it, a boundary friction that is negative or not
    /// finite.
    pub fn new(surface: &ClosedSurface, params: &MpmParams, boundary: Boundary) -> Result<Self, String> {
        boundary.validate("boundary").map_err(|e| e.to_string())?;
        let n = params.resolution;
        let h = params.h();
        let (blo, bhi) = surface.bounds();
        let round = |v: [f64; 3]| v.map(|x| (x * 1e6).round() / 1e6);
        if (0..3).any(|a| bhi[a] < 0.0 || blo[a] > params.size) {
            return Err(format!(
                "lies outside the domain: its bounds are {:?} to {:?} m, the domain [0, {}] m on every axis",
                round(blo),
                round(bhi),
                params.size
            ));
        }
        let margin = MARGIN as f64;
        let lo: [usize; 3] =
            std::array::from_fn(|a| ((blo[a] / h).floor() - margin).clamp(0.0, n as f64) as usize);
        let hi: [usize; 3] =
            std::array::from_fn(|a| ((bhi[a] / h).ceil() + margin).clamp(0.0, n as f64) as usize);
        let counts: [usize; 3] = std::array::from_fn(|a| hi[a] - lo[a] + 1);
        let total = counts.iter().map(|&c| c as u128).product::<u128>();
        if total > MAX_NODES as u128 {
            return Err(format!(
                "its box of {} x {} x {} grid nodes (the mesh's bounds {:?} to {:?} m widened by {MARGIN} \
                 cells, at resolution {n}) holds {total} nodes, more than the {MAX_NODES} (2^24) a mesh \
                 obstacle may sample; lower the resolution or make the mesh smaller",
                counts[0],
                counts[1],
                counts[2],
                round(blo),
                round(bhi),
            ));
        }
        let origin = lo.map(|i| i as f64 * h);
        let phi = DistanceField::narrow_band(surface, origin, h, counts, BAND).map_err(|e| e.to_string())?;
        let any_inside = (0..counts[2])
            .any(|k| (0..counts[1]).any(|j| (0..counts[0]).any(|i| phi.node([i, j, k]) <= 0.0)));
        if !any_inside {
            return Err(format!(
                "has no grid node inside it at resolution {n} (cells {h} m): it would have no effect"
            ));
        }
        Ok(Self { lo, counts, phi, boundary })
    }

    /// The surface the table samples, placed in the domain.
    #[must_use]
    pub fn surface(&self) -> &ClosedSurface {
        self.phi.surface()
    }

    /// The first node index and the node counts of the table's box, per axis.
    #[must_use]
    pub fn node_box(&self) -> ([usize; 3], [usize; 3]) {
        (self.lo, self.counts)
    }

    /// The table's index of node `idx` (its first `D` components; the others 0), if in the box.
    #[inline]
    fn index<const D: usize>(&self, idx: &[usize; D]) -> Option<[usize; 3]> {
        let mut local = [0usize; 3];
        for a in 0..3 {
            let i = if a < D { idx[a] } else { 0 };
            let l = i.checked_sub(self.lo[a])?;
            if l >= self.counts[a] {
                return None;
            }
            local[a] = l;
        }
        Some(local)
    }

    #[inline]
    fn at(&self, l: [usize; 3]) -> f32 {
        self.phi.node(l)
    }

    /// The signed distance (m) at grid node `idx`, `None` outside the box.
    #[must_use]
    pub fn distance(&self, idx: [usize; 3]) -> Option<f32> {
        self.index(&idx).map(|l| self.at(l))
    }

    /// Whether the node block `[origin, origin + width)` per axis overlaps the box.
    #[inline]
    pub(crate) fn overlaps<const D: usize>(&self, origin: &[usize; D], width: usize) -> bool {
        (0..D).all(|a| origin[a] + width > self.lo[a] && origin[a] < self.lo[a] + self.counts[a])
    }

    /// At grid node `idx`: `None` when it is outside the obstacle (outside the box or
    /// `phi > 0`); else the outward unit normal, the normalised central difference of the table
    /// (one-sided at the box's faces), or zero where that difference vanishes.
    #[inline]
    pub(crate) fn contact<const D: usize>(&self, idx: &[usize; D]) -> Option<Vector<D>> {
        let l = self.index(idx)?;
        if self.at(l) > 0.0 {
            return None;
        }
        let mut g = Vector::<D>::zeros();
        for a in 0..D {
            let (mut lo, mut hi) = (l, l);
            lo[a] = l[a].saturating_sub(1);
            hi[a] = (l[a] + 1).min(self.counts[a] - 1);
            if hi[a] > lo[a] {
                g[a] = (self.at(hi) - self.at(lo)) / (hi[a] - lo[a]) as f32;
            }
        }
        let len = g.norm();
        Some(if len > 0.0 && len.is_finite() { g / len } else { Vector::<D>::zeros() })
    }

    /// The outward normal the grid update uses at grid node `idx`: the normalised central
    /// difference of the table, one-sided at the box's faces (`None` outside the obstacle; zero
    /// where the difference vanishes and the node is stopped).
    #[must_use]
    pub fn normal(&self, idx: [usize; 3]) -> Option<[f32; 3]> {
        self.contact::<3>(&idx).map(|n| [n[0], n[1], n[2]])
    }

    /// The trilinear interpolation of the table at `x` (m); `None` outside the box.
    #[must_use]
    pub fn interpolate(&self, x: [f64; 3]) -> Option<f64> {
        self.phi.sample(anim_core::glam::DVec3::from_array(x)).map(|s| s.distance)
    }
}
