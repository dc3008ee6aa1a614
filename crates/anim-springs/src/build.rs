//! Building networks: particles and springs by hand, or whole shapes (chain, cloth grid, 3-D
//! lattice, any triangle mesh), all checked before a [`SpringNetwork`] exists.
//!
//! Every builder input is validated by [`NetworkBuilder::build`] (or by the shape method, for the
//! shape's own parameters), and a problem is a [`BuildError`] naming the element: the particle,
//! spring, triangle or edge index and the offending value. Nothing here panics on user data.
//!
//! ```
//! use anim_springs::{Chain, NetworkBuilder, SpringParams};
//!
//! let mut b = NetworkBuilder::new();
//! b.gravity([0.0, 0.0, -9.81]);
//! let rope = b.chain(&Chain {
//!     count: 10,
//!     start: [0.0, 0.0, 1.0],
//!     end: [0.9, 0.0, 1.0],
//!     mass: 0.01,
//!     spring: SpringParams { stiffness: 100.0, damping: 0.01 },
//! })?;
//! b.pin(rope.start);
//! let net = b.build()?;
//! assert_eq!((net.num_particles(), net.num_springs()), (10, 9));
//! # Ok::<(), anim_springs::BuildError>(())
//! ```

use crate::contact::{Collider, MeshCollider};
use crate::error::{BuildError, InputError};
use crate::network::{Particle, Spring, SpringKind, SpringModel, SpringNetwork};
use anim_core::glam::DVec3;
use anim_core::input::{check_particles, check_triangle, check_triangle_indices};
use std::ops::Range;

/// Stiffness and damping of a family of springs.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct SpringParams {
    /// Stiffness `k` (N/m, > 0).
    pub stiffness: f64,
    /// Damping along the spring `c` (N s/m, >= 0).
    pub damping: f64,
}

impl SpringParams {
    /// Stiffness `k` and damping `c`.
    #[must_use]
    pub fn new(stiffness: f64, damping: f64) -> Self {
        Self { stiffness, damping }
    }
}

/// A straight chain (rope) of `count` particles from `start` to `end`, joined by `count - 1`
/// structural springs at their rest length.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Chain {
    /// Number of particles (>= 2).
    pub count: usize,
    /// First particle.
    pub start: [f64; 3],
    /// Last particle (distinct from `start`).
    pub end: [f64; 3],
    /// Mass of each particle (kg).
    pub mass: f64,
    /// The springs.
    pub spring: SpringParams,
}

/// A rectangular cloth of `nx x ny` particles spanning `origin + s u + t v`, `s, t` in `[0, 1]`.
///
/// Particle `(ix, iy)` has index `first + iy nx + ix`. Springs: structural between grid
/// neighbours, shear across both diagonals of each quad, bending between particles two apart
/// along each grid line (Provot 1995). Two triangles per quad are recorded for rendering.
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
    /// Total mass (kg), shared equally by the particles.
    pub mass: f64,
    /// Structural springs.
    pub structural: SpringParams,
    /// Shear springs, if any.
    pub shear: Option<SpringParams>,
    /// Bending springs, if any.
    pub bending: Option<SpringParams>,
}

/// A box-shaped 3-D lattice of `n[0] x n[1] x n[2]` particles with spacing `spacing` (a jelly
/// cube). Particle `(a, b, c)` has index `first + (c n[1] + b) n[0] + a`. Springs along the axes
/// (structural), and optionally across every face diagonal and every cell's four body diagonals
/// (shear). The box's surface is recorded as triangles for rendering.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Lattice {
    /// Particles along x, y, z (each >= 2).
    pub n: [usize; 3],
    /// Position of particle `(0, 0, 0)`.
    pub origin: [f64; 3],
    /// Distance between neighbours (> 0).
    pub spacing: f64,
    /// Total mass (kg), shared equally.
    pub mass: f64,
    /// Axis-aligned springs.
    pub edge: SpringParams,
    /// Springs across the diagonals of each cell face, if any.
    pub face_diagonal: Option<SpringParams>,
    /// Springs across the four body diagonals of each cell, if any.
    pub body_diagonal: Option<SpringParams>,
}

/// How a triangle mesh's vertices get their mass.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case", deny_unknown_fields))]
pub enum MeshMass {
    /// Every vertex has this mass (kg).
    PerVertex(f64),
    /// Surface density (kg/m^2): each vertex gets a third of its triangles' area (lumped mass).
    AreaDensity(f64),
}

/// Springs made from a triangle mesh: one structural spring per unique edge, and optionally one
/// bending spring across each interior edge (between the two vertices opposite it).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct MeshSprings {
    /// Vertex masses.
    pub mass: MeshMass,
    /// Edge springs.
    pub edge: SpringParams,
    /// Bending springs across interior edges, if any (the mesh must then be manifold).
    pub bending: Option<SpringParams>,
}

#[derive(Debug, Clone, Copy)]
struct PendingSpring {
    i: usize,
    j: usize,
    rest_length: Option<f64>,
    params: SpringParams,
    kind: SpringKind,
}

/// Collects particles, springs, pins, triangles, gravity and colliders, then checks them all in
/// [`build`](Self::build). Gravity is zero until set.
#[derive(Debug, Clone, Default)]
pub struct NetworkBuilder {
    positions: Vec<[f64; 3]>,
    masses: Vec<f64>,
    pins: Vec<usize>,
    springs: Vec<PendingSpring>,
    triangles: Vec<[usize; 3]>,
    gravity: [f64; 3],
    colliders: Vec<Collider>,
    mesh_colliders: Vec<MeshCollider>,
}

/// Standard gravity pointing down the z axis (m/s^2): the scenes' convention is z up.
pub const EARTH_GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

fn bad(
    shape: &'static str,
    name: &'static str,
    requirement: &'static str,
    value: impl ToString,
) -> BuildError {
    BuildError::Input(InputError::BadParameter { shape, name, requirement, value: value.to_string() })
}

fn check_vec(shape: &'static str, name: &'static str, v: [f64; 3]) -> Result<DVec3, BuildError> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(DVec3::from_array(v))
    } else {
        Err(bad(shape, name, "must be finite", format!("{v:?}")))
    }
}

fn check_positive(shape: &'static str, name: &'static str, v: f64) -> Result<(), BuildError> {
    if v > 0.0 && v.is_finite() { Ok(()) } else { Err(bad(shape, name, "must be positive and finite", v)) }
}

impl NetworkBuilder {
    /// An empty builder without gravity.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of particles added so far.
    #[must_use]
    pub fn num_particles(&self) -> usize {
        self.positions.len()
    }

    /// Sets gravity (m/s^2), e.g. [`EARTH_GRAVITY`].
    pub fn gravity(&mut self, g: [f64; 3]) -> &mut Self {
        self.gravity = g;
        self
    }

    /// Adds a particle and returns its index.
    pub fn particle(&mut self, position: [f64; 3], mass: f64) -> usize {
        self.positions.push(position);
        self.masses.push(mass);
        self.positions.len() - 1
    }

    /// Pins particle `p` (it will not respond to forces).
    pub fn pin(&mut self, p: usize) -> &mut Self {
        self.pins.push(p);
        self
    }

    /// Adds a spring whose rest length is the distance between the particles' positions.
    pub fn spring(&mut self, i: usize, j: usize, params: SpringParams) -> &mut Self {
        self.springs.push(PendingSpring { i, j, rest_length: None, params, kind: SpringKind::Custom });
        self
    }

    /// Adds a spring with an explicit rest length (0 gives a zero-length spring).
    pub fn spring_with_rest_length(
        &mut self,
        i: usize,
        j: usize,
        rest_length: f64,
        params: SpringParams,
    ) -> &mut Self {
        self.springs.push(PendingSpring {
            i,
            j,
            rest_length: Some(rest_length),
            params,
            kind: SpringKind::Custom,
        });
        self
    }

    fn add(&mut self, i: usize, j: usize, params: SpringParams, kind: SpringKind) {
        self.springs.push(PendingSpring { i, j, rest_length: None, params, kind });
    }

    /// Records a triangle for rendering (it adds no springs).
    pub fn triangle(&mut self, t: [usize; 3]) -> &mut Self {
        self.triangles.push(t);
        self
    }

    /// Adds a collider.
    pub fn collider(&mut self, c: Collider) -> &mut Self {
        self.colliders.push(c);
        self
    }

    /// Adds a collider bounded by a closed triangle mesh ([`MeshCollider`]).
    pub fn mesh_collider(&mut self, c: MeshCollider) -> &mut Self {
        self.mesh_colliders.push(c);
        self
    }

    /// Adds a [`Chain`]; returns the range of its particle indices.
    ///
    /// # Errors
    /// [`InputError::BadParameter`] for `count < 2`, coincident or non-finite ends; masses and
    /// springs are checked by [`build`](Self::build).
    pub fn chain(&mut self, c: &Chain) -> Result<Range<usize>, BuildError> {
        const S: &str = "chain";
        if c.count < 2 {
            return Err(bad(S, "count", "must be at least 2", c.count));
        }
        let a = check_vec(S, "start", c.start)?;
        let b = check_vec(S, "end", c.end)?;
        if !((b - a).length() > 0.0) {
            return Err(bad(S, "end", "must differ from start", format!("{:?}", c.end)));
        }
        let first = self.num_particles();
        for k in 0..c.count {
            let s = k as f64 / (c.count - 1) as f64;
            self.particle((a + s * (b - a)).to_array(), c.mass);
        }
        for k in 0..c.count - 1 {
            self.add(first + k, first + k + 1, c.spring, SpringKind::Structural);
        }
        Ok(first..first + c.count)
    }

    /// Adds a [`Cloth`] grid; returns the range of its particle indices.
    ///
    /// # Errors
    /// [`InputError::BadParameter`] for fewer than 2 particles along a side, non-finite or
    /// parallel edge vectors, or a non-positive total mass.
    pub fn cloth(&mut self, c: &Cloth) -> Result<Range<usize>, BuildError> {
        const S: &str = "cloth";
        if c.nx < 2 {
            return Err(bad(S, "nx", "must be at least 2", c.nx));
        }
        if c.ny < 2 {
            return Err(bad(S, "ny", "must be at least 2", c.ny));
        }
        let o = check_vec(S, "origin", c.origin)?;
        let u = check_vec(S, "u", c.u)?;
        let v = check_vec(S, "v", c.v)?;
        let area = u.cross(v).length();
        if !(area > 1e-12 * u.length_squared().max(v.length_squared())) || !area.is_finite() {
            return Err(bad(S, "v", "must be non-zero and not parallel to u", format!("{:?}", c.v)));
        }
        check_positive(S, "mass", c.mass)?;
        let (nx, ny) = (c.nx, c.ny);
        let first = self.num_particles();
        let m = c.mass / (nx * ny) as f64;
        for iy in 0..ny {
            for ix in 0..nx {
                let p = o + (ix as f64 / (nx - 1) as f64) * u + (iy as f64 / (ny - 1) as f64) * v;
                self.particle(p.to_array(), m);
            }
        }
        let id = |ix: usize, iy: usize| first + iy * nx + ix;
        for iy in 0..ny {
            for ix in 0..nx {
                if ix + 1 < nx {
                    self.add(id(ix, iy), id(ix + 1, iy), c.structural, SpringKind::Structural);
                }
                if iy + 1 < ny {
                    self.add(id(ix, iy), id(ix, iy + 1), c.structural, SpringKind::Structural);
                }
            }
        }
        if let Some(sh) = c.shear {
            for iy in 0..ny - 1 {
                for ix in 0..nx - 1 {
                    self.add(id(ix, iy), id(ix + 1, iy + 1), sh, SpringKind::Shear);
                    self.add(id(ix + 1, iy), id(ix, iy + 1), sh, SpringKind::Shear);
                }
            }
        }
        if let Some(be) = c.bending {
            for iy in 0..ny {
                for ix in 0..nx {
                    if ix + 2 < nx {
                        self.add(id(ix, iy), id(ix + 2, iy), be, SpringKind::Bending);
                    }
                    if iy + 2 < ny {
                        self.add(id(ix, iy), id(ix, iy + 2), be, SpringKind::Bending);
                    }
                }
            }
        }
        for iy in 0..ny - 1 {
            for ix in 0..nx - 1 {
                let (a, b, cc, d) = (id(ix, iy), id(ix + 1, iy), id(ix, iy + 1), id(ix + 1, iy + 1));
                self.triangles.push([a, b, d]);
                self.triangles.push([a, d, cc]);
            }
        }
        Ok(first..first + nx * ny)
    }

    /// Adds a [`Lattice`]; returns the range of its particle indices.
    ///
    /// # Errors
    /// [`InputError::BadParameter`] for fewer than 2 particles along an axis, a non-positive
    /// spacing or mass, or a non-finite origin.
    pub fn lattice(&mut self, l: &Lattice) -> Result<Range<usize>, BuildError> {
        const S: &str = "lattice";
        for (axis, &n) in ["n[0]", "n[1]", "n[2]"].iter().zip(&l.n) {
            if n < 2 {
                return Err(bad(S, axis, "must be at least 2", n));
            }
        }
        let o = check_vec(S, "origin", l.origin)?;
        check_positive(S, "spacing", l.spacing)?;
        check_positive(S, "mass", l.mass)?;
        let [nx, ny, nz] = l.n;
        let first = self.num_particles();
        let m = l.mass / (nx * ny * nz) as f64;
        for c in 0..nz {
            for b in 0..ny {
                for a in 0..nx {
                    let p = o + l.spacing * DVec3::new(a as f64, b as f64, c as f64);
                    self.particle(p.to_array(), m);
                }
            }
        }
        let id = |a: usize, b: usize, c: usize| first + (c * ny + b) * nx + a;
        for c in 0..nz {
            for b in 0..ny {
                for a in 0..nx {
                    if a + 1 < nx {
                        self.add(id(a, b, c), id(a + 1, b, c), l.edge, SpringKind::Structural);
                    }
                    if b + 1 < ny {
                        self.add(id(a, b, c), id(a, b + 1, c), l.edge, SpringKind::Structural);
                    }
                    if c + 1 < nz {
                        self.add(id(a, b, c), id(a, b, c + 1), l.edge, SpringKind::Structural);
                    }
                }
            }
        }
        if let Some(fd) = l.face_diagonal {
            for c in 0..nz {
                for b in 0..ny {
                    for a in 0..nx {
                        if a + 1 < nx && b + 1 < ny {
                            self.add(id(a, b, c), id(a + 1, b + 1, c), fd, SpringKind::Shear);
                            self.add(id(a + 1, b, c), id(a, b + 1, c), fd, SpringKind::Shear);
                        }
                        if a + 1 < nx && c + 1 < nz {
                            self.add(id(a, b, c), id(a + 1, b, c + 1), fd, SpringKind::Shear);
                            self.add(id(a + 1, b, c), id(a, b, c + 1), fd, SpringKind::Shear);
                        }
                        if b + 1 < ny && c + 1 < nz {
                            self.add(id(a, b, c), id(a, b + 1, c + 1), fd, SpringKind::Shear);
                            self.add(id(a, b + 1, c), id(a, b, c + 1), fd, SpringKind::Shear);
                        }
                    }
                }
            }
        }
        if let Some(bd) = l.body_diagonal {
            for c in 0..nz - 1 {
                for b in 0..ny - 1 {
                    for a in 0..nx - 1 {
                        self.add(id(a, b, c), id(a + 1, b + 1, c + 1), bd, SpringKind::Shear);
                        self.add(id(a + 1, b, c), id(a, b + 1, c + 1), bd, SpringKind::Shear);
                        self.add(id(a, b + 1, c), id(a + 1, b, c + 1), bd, SpringKind::Shear);
                        self.add(id(a, b, c + 1), id(a + 1, b + 1, c), bd, SpringKind::Shear);
                    }
                }
            }
        }
        // Surface triangles, counter-clockwise seen from outside.
        let mut quad = |p00: usize, p10: usize, p11: usize, p01: usize| {
            self.triangles.push([p00, p10, p11]);
            self.triangles.push([p00, p11, p01]);
        };
        for b in 0..ny - 1 {
            for a in 0..nx - 1 {
                quad(id(a, b, 0), id(a, b + 1, 0), id(a + 1, b + 1, 0), id(a + 1, b, 0));
                let c = nz - 1;
                quad(id(a, b, c), id(a + 1, b, c), id(a + 1, b + 1, c), id(a, b + 1, c));
            }
        }
        for c in 0..nz - 1 {
            for a in 0..nx - 1 {
                quad(id(a, 0, c), id(a + 1, 0, c), id(a + 1, 0, c + 1), id(a, 0, c + 1));
                let b = ny - 1;
                quad(id(a, b, c), id(a, b, c + 1), id(a + 1, b, c + 1), id(a + 1, b, c));
            }
        }
        for c in 0..nz - 1 {
            for b in 0..ny - 1 {
                quad(id(0, b, c), id(0, b, c + 1), id(0, b + 1, c + 1), id(0, b + 1, c));
                let a = nx - 1;
                quad(id(a, b, c), id(a, b + 1, c), id(a, b + 1, c + 1), id(a, b, c + 1));
            }
        }
        Ok(first..first + nx * ny * nz)
    }

    /// Adds a triangle mesh (vertex positions and triangles indexing them): one structural
    /// spring per unique edge, optionally one bending spring across each interior edge, the
    /// triangles recorded for rendering. Returns the range of the new particle indices.
    ///
    /// Edges are visited in sorted `(min, max)` vertex order, so the spring order does not
    /// depend on the triangle order.
    ///
    /// # Errors
    /// [`InputError::TriangleIndex`], [`InputError::DegenerateTriangle`] (repeated vertex or zero
    /// area), [`InputError::NonManifoldEdge`] (with bending springs), [`InputError::IsolatedVertex`]
    /// (mass by area), [`InputError::NonFinitePosition`], [`InputError::BadParameter`] (no
    /// triangles, non-positive mass or density).
    pub fn mesh(
        &mut self,
        positions: &[[f64; 3]],
        triangles: &[[usize; 3]],
        params: &MeshSprings,
    ) -> Result<Range<usize>, BuildError> {
        const S: &str = "mesh";
        if triangles.is_empty() {
            return Err(bad(S, "triangles", "must not be empty", 0));
        }
        let first = self.num_particles();
        for (k, p) in positions.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(BuildError::Input(InputError::NonFinitePosition {
                    particle: first + k,
                    position: *p,
                }));
            }
        }
        let nv = positions.len();
        let mut area_of = vec![0.0; nv];
        for (t, tri) in triangles.iter().enumerate() {
            check_triangle(t, *tri, nv)?;
            let [a, b, c] = *tri;
            let (pa, pb, pc) =
                (DVec3::from(positions[a]), DVec3::from(positions[b]), DVec3::from(positions[c]));
            let area = 0.5 * (pb - pa).cross(pc - pa).length();
            let longest =
                (pb - pa).length_squared().max((pc - pb).length_squared()).max((pa - pc).length_squared());
            if !(area > 1e-12 * longest) {
                return Err(BuildError::Input(InputError::DegenerateTriangle {
                    triangle: t,
                    vertices: *tri,
                    reason: "zero area",
                }));
            }
            for &v in tri {
                area_of[v] += area / 3.0;
            }
        }
        let masses: Vec<f64> = match params.mass {
            MeshMass::PerVertex(m) => {
                check_positive(S, "mass per vertex", m)?;
                vec![m; nv]
            }
            MeshMass::AreaDensity(rho) => {
                check_positive(S, "area density", rho)?;
                if let Some(vertex) = area_of.iter().position(|a| *a == 0.0) {
                    return Err(BuildError::Input(InputError::IsolatedVertex {
                        vertex,
                        element: "triangle",
                    }));
                }
                area_of.iter().map(|a| rho * a).collect()
            }
        };
        // Unique edges with the vertex opposite them in each triangle, sorted.
        let mut edges: Vec<(usize, usize, usize)> = Vec::with_capacity(3 * triangles.len());
        for &[a, b, c] in triangles {
            for (p, q, opp) in [(a, b, c), (b, c, a), (c, a, b)] {
                edges.push((p.min(q), p.max(q), opp));
            }
        }
        edges.sort_unstable();
        for (k, &p) in positions.iter().enumerate() {
            self.particle(p, masses[k]);
        }
        self.triangles.extend(triangles.iter().map(|t| [first + t[0], first + t[1], first + t[2]]));
        let mut bending = Vec::new();
        let mut k = 0;
        while k < edges.len() {
            let (a, b, _) = edges[k];
            let mut end = k + 1;
            while end < edges.len() && edges[end].0 == a && edges[end].1 == b {
                end += 1;
            }
            self.add(first + a, first + b, params.edge, SpringKind::Structural);
            if let Some(be) = params.bending {
                match end - k {
                    1 => {}
                    2 => {
                        let (c, d) = (edges[k].2, edges[k + 1].2);
                        if c == d {
                            return Err(BuildError::DuplicateTriangle { a, b, c });
                        }
                        bending.push((first + c.min(d), first + c.max(d), be));
                    }
                    many => {
                        return Err(BuildError::Input(InputError::NonManifoldEdge { a, b, triangles: many }));
                    }
                }
            }
            k = end;
        }
        for (c, d, be) in bending {
            self.add(c, d, be, SpringKind::Bending);
        }
        Ok(first..first + nv)
    }

    /// Checks everything and builds the network.
    ///
    /// # Errors
    /// The first problem found, as a [`BuildError`] naming the element.
    pub fn build(&self) -> Result<SpringNetwork, BuildError> {
        let n = self.positions.len();
        if n == 0 {
            return Err(BuildError::Input(InputError::NoParticles));
        }
        if n > crate::network::MAX_PARTICLES {
            return Err(BuildError::Input(InputError::TooLarge {
                what: "particles",
                count: n,
                max: crate::network::MAX_PARTICLES,
            }));
        }
        if self.springs.len() > crate::network::MAX_SPRINGS {
            return Err(BuildError::Input(InputError::TooLarge {
                what: "springs",
                count: self.springs.len(),
                max: crate::network::MAX_SPRINGS,
            }));
        }
        let pinned = check_particles(&self.positions, &self.masses, &self.pins, self.gravity)?;
        let particles: Vec<Particle> =
            self.masses.iter().zip(pinned).map(|(&mass, pinned)| Particle { mass, pinned }).collect();
        let mut springs = Vec::with_capacity(self.springs.len());
        for (spring, s) in self.springs.iter().enumerate() {
            for index in [s.i, s.j] {
                if index >= n {
                    return Err(BuildError::SpringIndex { spring, index, particles: n });
                }
            }
            if s.i == s.j {
                return Err(BuildError::SelfSpring { spring, particle: s.i });
            }
            let SpringParams { stiffness, damping } = s.params;
            if !(stiffness > 0.0 && stiffness.is_finite()) {
                return Err(BuildError::BadStiffness { spring, stiffness });
            }
            if !(damping >= 0.0 && damping.is_finite()) {
                return Err(BuildError::BadDamping { spring, damping });
            }
            let rest_length = s.rest_length.unwrap_or_else(|| {
                (DVec3::from_array(self.positions[s.i]) - DVec3::from_array(self.positions[s.j])).length()
            });
            if !(rest_length >= 0.0 && rest_length.is_finite()) {
                return Err(BuildError::BadRestLength { spring, rest_length });
            }
            springs.push(Spring { i: s.i, j: s.j, rest_length, stiffness, damping, kind: s.kind });
        }
        for (triangle, t) in self.triangles.iter().enumerate() {
            check_triangle_indices(triangle, *t, n)?;
        }
        let mut colliders = Vec::with_capacity(self.colliders.len());
        for (collider, c) in self.colliders.iter().enumerate() {
            c.check().map_err(|reason| BuildError::Input(InputError::BadCollider { collider, reason }))?;
            colliders.push(c.normalized());
        }
        for (collider, c) in self.mesh_colliders.iter().enumerate() {
            c.check().map_err(|reason| BuildError::BadMeshCollider { collider, reason })?;
        }
        let model = SpringModel::new(
            particles,
            self.positions.clone(),
            springs,
            self.triangles.clone(),
            DVec3::from_array(self.gravity),
            colliders,
            self.mesh_colliders.clone(),
        );
        Ok(SpringNetwork::from_model(model))
    }
}
