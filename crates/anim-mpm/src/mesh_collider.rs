//! Triangle-mesh obstacles (3D): a closed surface turned into a level-set collider, as in
//! grid-based MPM codes.
//!
//! **Build.** The signed distance `phi` to the surface (negative inside) is sampled once on the
//! grid nodes `x_i = i h` of the box around the surface's bounds widened by [`MARGIN`] cells on
//! every side and clipped to the domain's nodes `[0, n]`, and stored dense in `f32` for that
//! box only. The sign is the surface's inside test at the node (anim-core's
//! [`ClosedSurface::inside_lattice`]); the magnitude is the distance to the closest point of
//! the triangles within [`BAND`] cells of the node, and `BAND` cells where no triangle is that
//! close (the table is a narrow-band distance, clamped beyond). The closest points are searched
//! triangle by triangle over the nodes of the triangle's box widened by the band only, so the
//! build costs one inside classification of the box (anim-core's row crossings) plus, per
//! triangle, one closest-point evaluation per node of its widened box: about
//! `T (e / h + 2 BAND + 1)^3` evaluations for `T` triangles of extent `e` (a 12-triangle cube
//! filling a quarter of a 64-cell domain: about 12 x 25^3 = 190 000; a mesh of 100 000 small
//! triangles: about 100 000 x 9^3 = 7.3e7), run in parallel over z-slices of
//! the box. A box of more than [`MAX_NODES`] nodes (64 MB of table) is refused.
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

use std::fmt;
use std::sync::Arc;

use anim_core::geometry::closest_point_on_triangle;
use anim_core::glam::DVec3;
use anim_core::surface::ClosedSurface;
use rayon::prelude::*;

use crate::{Boundary, MpmParams, Vector};

/// The most grid nodes the table of one mesh obstacle may hold: `2^24` (64 MB of `f32`).
pub const MAX_NODES: usize = 1 << 24;

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
#[derive(Clone)]
pub struct MeshCollider {
    /// First node index of the box per axis.
    lo: [usize; 3],
    /// Nodes of the box per axis.
    counts: [usize; 3],
    /// Signed distance (m) per node of the box, x fastest.
    phi: Arc<[f32]>,
    /// Boundary condition on the surface.
    pub(crate) boundary: Boundary,
}

impl fmt::Debug for MeshCollider {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("MeshCollider")
            .field("lo", &self.lo)
            .field("counts", &self.counts)
            .field("boundary", &self.boundary)
            .finish_non_exhaustive()
    }
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
        let total = total as usize;
        let origin = lo.map(|i| i as f64 * h);
        let inside = surface.inside_lattice(origin, h, counts).map_err(|e| e.to_string())?;
        let distance = distances(surface, lo, counts, h);
        let phi: Vec<f32> =
            distance.iter().zip(&inside).map(|(&d, &i)| if i { -d as f32 } else { d as f32 }).collect();
        debug_assert_eq!(phi.len(), total);
        if !phi.iter().any(|&p| p <= 0.0) {
            return Err(format!(
                "has no grid node inside it at resolution {n} (cells {h} m): it would have no effect"
            ));
        }
        Ok(Self { lo, counts, phi: phi.into(), boundary })
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
        self.phi[(l[2] * self.counts[1] + l[1]) * self.counts[0] + l[0]]
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

    /// The trilinear interpolation of the table at `x` (m) with grid spacing `h`; `None`
    /// outside the box.
    #[must_use]
    pub fn interpolate(&self, x: [f64; 3], h: f64) -> Option<f64> {
        let mut base = [0usize; 3];
        let mut t = [0.0; 3];
        for a in 0..3 {
            let s = x[a] / h - self.lo[a] as f64;
            if !(0.0..=(self.counts[a] - 1) as f64).contains(&s) {
                return None;
            }
            let b = (s.floor() as usize).min(self.counts[a].saturating_sub(2));
            base[a] = b;
            t[a] = s - b as f64;
        }
        let mut sum = 0.0;
        for c in 0..8 {
            let mut l = base;
            let mut w = 1.0;
            for a in 0..3 {
                let up = c >> a & 1 == 1;
                if up && self.counts[a] > 1 {
                    l[a] += 1;
                }
                w *= if up { t[a] } else { 1.0 - t[a] };
            }
            sum += w * f64::from(self.at(l));
        }
        Some(sum)
    }
}

/// The distance from each node of the box to the closest triangle of `surface` within
/// [`BAND`] cells, `BAND` cells where none is that close; in parallel over z-slices (each node
/// takes the minimum over its triangles, the same whatever the order).
fn distances(surface: &ClosedSurface, lo: [usize; 3], counts: [usize; 3], h: f64) -> Vec<f64> {
    let band = BAND as f64 * h;
    let positions = surface.positions();
    let triangles: Vec<([DVec3; 3], [f64; 3], [f64; 3])> = surface
        .triangles()
        .iter()
        .map(|t| {
            let p = t.map(|i| positions[i]);
            let (mut a, mut b) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
            a -= DVec3::splat(band);
            b += DVec3::splat(band);
            (p, a.to_array(), b.to_array())
        })
        .collect();
    // The local node range `[first, last]` of axis `a` within `[from, to]` m, or `None`.
    let range = |a: usize, from: f64, to: f64| -> Option<(usize, usize)> {
        let first = ((from / h).ceil() - lo[a] as f64).max(0.0);
        let last = ((to / h).floor() - lo[a] as f64).min((counts[a] - 1) as f64);
        (first <= last).then_some((first as usize, last as usize))
    };
    let slice = counts[0] * counts[1];
    let mut out = vec![band; slice * counts[2]];
    out.par_chunks_mut(slice).enumerate().for_each(|(k, d)| {
        let z = (lo[2] + k) as f64 * h;
        for (tri, tlo, thi) in &triangles {
            if z < tlo[2] || z > thi[2] {
                continue;
            }
            let (Some((i0, i1)), Some((j0, j1))) = (range(0, tlo[0], thi[0]), range(1, tlo[1], thi[1]))
            else {
                continue;
            };
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let p = DVec3::new((lo[0] + i) as f64 * h, (lo[1] + j) as f64 * h, z);
                    let q = closest_point_on_triangle(p, *tri).0;
                    let e = &mut d[j * counts[0] + i];
                    *e = e.min((q - p).length());
                }
            }
        }
    });
    out
}
