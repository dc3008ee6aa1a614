//! Cloth and any triangle mesh: a distance constraint on every unique edge (in order of first
//! appearance) and, across every interior edge, a bending constraint of the kind [`Bending`]
//! chooses: the dihedral angle (Müller et al. 2007) or isometric quadratic bending (Bergou et al.
//! 2006), the right one for inextensible cloth. A [`Cloth`] is a grid triangulated along one
//! diagonal per quad. Vertex masses are given per vertex or lumped from a density per area, each
//! triangle giving a third of its mass to each corner. The triangles are recorded for rendering
//! and wind.

use super::builder::{MeshMass, PbdBuilder, bad, check_mass, check_positive, check_vec, key};
use super::error::{BuildError, InputError};
use crate::constraint::ConstraintParams;
use anim_core::glam::DVec3;
use anim_core::input::check_triangle;
use std::collections::HashMap;
use std::ops::Range;

/// Which bending constraint a cloth or mesh gets across each interior edge.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum Bending {
    /// No bending resistance.
    None,
    /// Dihedral angle constraints (Müller et al. 2007).
    Dihedral(ConstraintParams),
    /// Isometric quadratic bending (Bergou et al. 2006).
    Isometric(ConstraintParams),
}

/// A rectangular cloth of `nx x ny` particles spanning `origin + s u + t v`, `s, t` in `[0, 1]`,
/// triangulated with the diagonal from `(ix, iy)` to `(ix + 1, iy + 1)` in every quad.
///
/// Particle `(ix, iy)` has index `first + iy nx + ix`. A distance constraint on every triangle
/// edge and a bending constraint across every interior edge: for 100 x 100 particles, 29,601
/// distance and 29,205 bending constraints.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Cloth {
    /// Particles along `u` (>= 2).
    pub nx: usize,
    /// Particles along `v` (>= 2).
    pub ny: usize,
    /// Corner `(0, 0)`.
    pub origin: [f64; 3],
    /// Edge vector from corner `(0, 0)` to corner `(nx - 1, 0)`.
    pub u: [f64; 3],
    /// Edge vector from corner `(0, 0)` to corner `(0, ny - 1)` (not parallel to `u`).
    pub v: [f64; 3],
    /// Mass of each particle (kg).
    pub particle_mass: f64,
    /// Distance constraints on the triangle edges.
    pub stretch: ConstraintParams,
    /// Bending constraints across interior edges.
    pub bending: Bending,
}

/// The particles a cloth occupies: index of `(ix, iy)` is `start + iy * nx + ix`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ClothHandle {
    /// First particle.
    pub start: usize,
    /// Particles along `u`.
    pub nx: usize,
    /// Particles along `v`.
    pub ny: usize,
}

impl ClothHandle {
    /// Index of particle `(ix, iy)`.
    #[must_use]
    pub fn at(&self, ix: usize, iy: usize) -> usize {
        self.start + iy * self.nx + ix
    }
}

/// Constraints made from a triangle mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct MeshParams {
    /// Vertex masses.
    pub mass: MeshMass,
    /// A distance constraint on every unique edge.
    pub stretch: ConstraintParams,
    /// Bending across interior edges (the mesh must then be manifold).
    pub bending: Bending,
}

impl PbdBuilder {
    /// A cloth grid; returns where its particles are.
    ///
    /// # Errors
    /// [`InputError::BadParameter`] for fewer than 2 particles along a side, parallel `u` and `v`,
    /// or non-finite input.
    pub fn cloth(&mut self, c: &Cloth) -> Result<ClothHandle, BuildError> {
        if c.nx < 2 || c.ny < 2 {
            return Err(bad("cloth", "nx, ny", "must both be at least 2", format!("{} x {}", c.nx, c.ny)));
        }
        let o = check_vec("cloth", "origin", c.origin)?;
        let u = check_vec("cloth", "u", c.u)?;
        let v = check_vec("cloth", "v", c.v)?;
        if !(u.cross(v).length() > 1e-12 * u.length() * v.length()) {
            return Err(bad("cloth", "u, v", "must not be parallel", format!("{:?}, {:?}", c.u, c.v)));
        }
        check_positive("cloth", "particle_mass", c.particle_mass)?;
        let mut positions = Vec::with_capacity(c.nx * c.ny);
        for iy in 0..c.ny {
            for ix in 0..c.nx {
                let p = o + u * (ix as f64 / (c.nx - 1) as f64) + v * (iy as f64 / (c.ny - 1) as f64);
                positions.push(p.to_array());
            }
        }
        let mut tris = Vec::with_capacity(2 * (c.nx - 1) * (c.ny - 1));
        for iy in 0..c.ny - 1 {
            for ix in 0..c.nx - 1 {
                let a = iy * c.nx + ix;
                let (b, d, e) = (a + 1, a + c.nx, a + c.nx + 1);
                tris.push([a, b, e]);
                tris.push([a, e, d]);
            }
        }
        let params =
            MeshParams { mass: MeshMass::PerVertex(c.particle_mass), stretch: c.stretch, bending: c.bending };
        let r = self.triangle_mesh(&positions, &tris, &params)?;
        Ok(ClothHandle { start: r.start, nx: c.nx, ny: c.ny })
    }

    /// A triangle mesh: a distance constraint per unique edge (in order of first appearance) and
    /// a bending constraint across every interior edge; the triangles are recorded for rendering
    /// and wind. Returns the range of its particles.
    ///
    /// # Errors
    /// [`InputError::NonFinitePosition`], [`InputError::TriangleIndex`],
    /// [`InputError::DegenerateTriangle`], [`InputError::NonManifoldEdge`] (with bending),
    /// [`InputError::IsolatedVertex`] (mass by density), [`InputError::BadParameter`].
    pub fn triangle_mesh(
        &mut self,
        positions: &[[f64; 3]],
        triangles: &[[usize; 3]],
        params: &MeshParams,
    ) -> Result<Range<usize>, BuildError> {
        check_mass("mesh", params.mass)?;
        // Positions first: a non-finite vertex would otherwise show as a zero-area triangle.
        let first = self.positions.len();
        for (k, p) in positions.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(BuildError::Input(InputError::NonFinitePosition {
                    particle: first + k,
                    position: *p,
                }));
            }
        }
        let nv = positions.len();
        let pos: Vec<DVec3> = positions.iter().map(|&p| DVec3::from_array(p)).collect();
        let mut area = vec![0.0; nv];
        for (t, tri) in triangles.iter().enumerate() {
            check_triangle(t, *tri, nv)?;
            let [a, b, c] = *tri;
            let (e1, e2) = (pos[b] - pos[a], pos[c] - pos[a]);
            let twice = e1.cross(e2).length();
            if !(twice > 1e-12 * e1.length_squared().max(e2.length_squared())) {
                return Err(BuildError::Input(InputError::DegenerateTriangle {
                    triangle: t,
                    vertices: *tri,
                    reason: "zero area",
                }));
            }
            for &i in tri {
                area[i] += twice / 6.0;
            }
        }
        let masses: Vec<f64> = match params.mass {
            MeshMass::PerVertex(m) => vec![m; nv],
            MeshMass::Density(rho) => {
                if let Some(v) = area.iter().position(|&a| a == 0.0) {
                    return Err(BuildError::Input(InputError::IsolatedVertex {
                        vertex: v,
                        element: "triangle",
                    }));
                }
                area.iter().map(|a| rho * a).collect()
            }
        };
        // Edges in order of first appearance, with the triangles (and opposite vertices) using them.
        let mut order: Vec<(usize, usize)> = Vec::new();
        // Per undirected edge: (from, to, opposite vertex) in each triangle using it.
        let mut uses: HashMap<(usize, usize), Vec<[usize; 3]>> = HashMap::new();
        for tri in triangles {
            for k in 0..3 {
                let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
                let e = uses.entry(key(a, b)).or_default();
                if e.is_empty() {
                    order.push(key(a, b));
                }
                // (directed a -> b, opposite c)
                e.push([a, b, c]);
            }
        }
        for (p, m) in positions.iter().zip(&masses) {
            self.particle(*p, *m);
        }
        for &(a, b) in &order {
            self.distance(first + a, first + b, params.stretch);
        }
        if params.bending != Bending::None {
            for &(a, b) in &order {
                let used = &uses[&(a, b)];
                if used.len() > 2 {
                    return Err(BuildError::Input(InputError::NonManifoldEdge {
                        a,
                        b,
                        triangles: used.len(),
                    }));
                }
                if used.len() == 2 {
                    // p2 -> p3 is the edge as directed in the first triangle, p0 its opposite vertex.
                    let [p2, p3, p0] = used[0];
                    let p1 = used[1][2];
                    let s = [p0, p1, p2, p3].map(|i| first + i);
                    match params.bending {
                        Bending::Dihedral(c) => self.dihedral(s, c),
                        Bending::Isometric(c) => self.isometric_bending(s, c),
                        Bending::None => 0,
                    };
                }
            }
        }
        for t in triangles {
            self.triangles.push(t.map(|i| first + i));
        }
        Ok(first..first + nv)
    }
}
