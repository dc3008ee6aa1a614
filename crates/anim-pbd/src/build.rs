//! Building models: particles and constraints by hand, or whole shapes (a chain, a cloth grid,
//! any triangle mesh, any tetrahedral mesh, a closed balloon), all checked before a
//! [`PbdModel`] exists.
//!
//! Every input is validated by [`PbdBuilder::build`] (or by the shape method, for the shape's own
//! parameters), and a problem is a [`BuildError`] naming the element: the particle, constraint,
//! triangle, tetrahedron or collider index and the offending value. Nothing here panics on user
//! data.
//!
//! ```
//! use anim_pbd::{Chain, ConstraintParams, PbdBuilder};
//!
//! let mut b = PbdBuilder::new();
//! b.gravity([0.0, 0.0, -9.81]);
//! let rope = b.chain(&Chain {
//!     count: 11,
//!     start: [0.0, 0.0, 1.0],
//!     end: [1.0, 0.0, 1.0],
//!     mass: 0.01,
//!     stretch: ConstraintParams::with_compliance(1e-6),
//! })?;
//! b.pin(rope.start);
//! let model = b.build()?;
//! assert_eq!((model.num_particles(), model.num_constraints()), (11, 10));
//! # Ok::<(), anim_pbd::BuildError>(())
//! ```

use crate::collide::{Collider, KinematicBody};
use crate::constraint::{
    AttachTarget, Constraint, ConstraintFunction, ConstraintParams, IsometricBending, dihedral,
    isometric_weights, tet_volume,
};
use crate::model::{Particle, PbdModel, VolumeMesh, Wind};
use anim_core::glam::DVec3;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::ops::Range;

/// A builder input that cannot make a valid model. Every variant names the element.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BuildError {
    /// The model has no particles.
    #[error("the model has no particles")]
    NoParticles,
    /// More particles or constraints than 32-bit indices hold.
    #[error("{count} {what} exceed the maximum of {max}")]
    TooLarge {
        /// "particles" or "constraints".
        what: &'static str,
        /// How many were given.
        count: usize,
        /// The maximum.
        max: usize,
    },
    /// A particle's mass is not a positive finite number.
    #[error("particle {particle}: mass must be positive and finite, got {mass}")]
    BadMass {
        /// Particle index.
        particle: usize,
        /// The mass given.
        mass: f64,
    },
    /// A particle's position has a NaN or infinite coordinate.
    #[error("particle {particle}: position {position:?} is not finite")]
    NonFinitePosition {
        /// Particle index.
        particle: usize,
        /// The position given.
        position: [f64; 3],
    },
    /// A pin names a particle that does not exist.
    #[error("pin {pin}: particle {index} does not exist (the model has {particles} particles)")]
    PinIndex {
        /// Position in the list of pins.
        pin: usize,
        /// The index given.
        index: usize,
        /// Number of particles.
        particles: usize,
    },
    /// A constraint names a particle that does not exist.
    #[error(
        "constraint {constraint} ({kind}): particle {index} does not exist (the model has {particles} particles)"
    )]
    ConstraintIndex {
        /// Constraint index.
        constraint: usize,
        /// Its function's name.
        kind: &'static str,
        /// The index given.
        index: usize,
        /// Number of particles.
        particles: usize,
    },
    /// A constraint names the same particle twice.
    #[error("constraint {constraint} ({kind}) names particle {particle} twice")]
    RepeatedIndex {
        /// Constraint index.
        constraint: usize,
        /// Its function's name.
        kind: &'static str,
        /// The repeated particle.
        particle: usize,
    },
    /// A PBD stiffness outside `[0, 1]`.
    #[error("constraint {constraint} ({kind}): stiffness k must lie in [0, 1], got {value}")]
    BadStiffness {
        /// Constraint index.
        constraint: usize,
        /// Its function's name.
        kind: &'static str,
        /// The value given.
        value: f64,
    },
    /// A negative or non-finite XPBD compliance.
    #[error(
        "constraint {constraint} ({kind}): compliance alpha must be non-negative and finite, got {value}"
    )]
    BadCompliance {
        /// Constraint index.
        constraint: usize,
        /// Its function's name.
        kind: &'static str,
        /// The value given.
        value: f64,
    },
    /// A negative or non-finite XPBD damping.
    #[error("constraint {constraint} ({kind}): damping beta must be non-negative and finite, got {value}")]
    BadDamping {
        /// Constraint index.
        constraint: usize,
        /// Its function's name.
        kind: &'static str,
        /// The value given.
        value: f64,
    },
    /// A rest value (length, angle, volume, distance, pressure) that is negative or not finite.
    #[error("constraint {constraint} ({kind}): {name} must be {requirement}, got {value}")]
    BadRestValue {
        /// Constraint index.
        constraint: usize,
        /// Its function's name.
        kind: &'static str,
        /// Which value.
        name: &'static str,
        /// What it must satisfy.
        requirement: &'static str,
        /// The value given.
        value: f64,
    },
    /// The rest shape of a constraint is degenerate: its gradient is undefined there.
    #[error(
        "constraint {constraint} ({kind}) on particles {particles:?} has a degenerate rest shape: {reason}"
    )]
    DegenerateRest {
        /// Constraint index.
        constraint: usize,
        /// Its function's name.
        kind: &'static str,
        /// Its particles.
        particles: Vec<usize>,
        /// What is wrong.
        reason: &'static str,
    },
    /// An attachment names a kinematic body that does not exist.
    #[error(
        "constraint {constraint} (attachment): body {body} does not exist (the model has {bodies} kinematic bodies)"
    )]
    BodyIndex {
        /// Constraint index.
        constraint: usize,
        /// The body given.
        body: usize,
        /// Number of bodies.
        bodies: usize,
    },
    /// A triangle names a vertex that does not exist.
    #[error("triangle {triangle}: vertex {index} does not exist (there are {vertices} vertices)")]
    TriangleIndex {
        /// Triangle index.
        triangle: usize,
        /// The index given.
        index: usize,
        /// Number of vertices.
        vertices: usize,
    },
    /// A triangle repeats a vertex or has (numerically) zero area.
    #[error("triangle {triangle} {vertices:?} is degenerate: {reason}")]
    DegenerateTriangle {
        /// Triangle index.
        triangle: usize,
        /// Its vertices.
        vertices: [usize; 3],
        /// What is wrong.
        reason: &'static str,
    },
    /// An edge is shared by more than two triangles.
    #[error("edge ({a}, {b}) is shared by {triangles} triangles; bending needs a manifold mesh")]
    NonManifoldEdge {
        /// First vertex.
        a: usize,
        /// Second vertex.
        b: usize,
        /// Number of triangles sharing it.
        triangles: usize,
    },
    /// A mesh for a global volume constraint is not closed and consistently oriented, or its
    /// volume is not positive.
    #[error("volume mesh: {reason}")]
    BadVolumeMesh {
        /// What is wrong.
        reason: String,
    },
    /// A tetrahedron names a vertex that does not exist.
    #[error("tetrahedron {tet}: vertex {index} does not exist (there are {vertices} vertices)")]
    TetIndex {
        /// Tetrahedron index.
        tet: usize,
        /// The index given.
        index: usize,
        /// Number of vertices.
        vertices: usize,
    },
    /// A tetrahedron repeats a vertex or has (numerically) zero volume.
    #[error("tetrahedron {tet} {vertices:?} is degenerate: {reason} (signed volume {volume:e})")]
    DegenerateTet {
        /// Tetrahedron index.
        tet: usize,
        /// Its vertices.
        vertices: [usize; 4],
        /// Its signed volume.
        volume: f64,
        /// What is wrong.
        reason: &'static str,
    },
    /// With mass by area or volume, a vertex that belongs to no element would get no mass.
    #[error("vertex {vertex} belongs to no {element}, so mass by density gives it no mass")]
    IsolatedVertex {
        /// Vertex index.
        vertex: usize,
        /// "triangle" or "tetrahedron".
        element: &'static str,
    },
    /// A collider's parameters are invalid.
    #[error("collider {collider}: {reason}")]
    BadCollider {
        /// Collider index.
        collider: usize,
        /// What is wrong.
        reason: String,
    },
    /// A kinematic body's pose or motion is not finite.
    #[error("kinematic body {body}: {reason}")]
    BadBody {
        /// Body index.
        body: usize,
        /// What is wrong.
        reason: String,
    },
    /// A shape parameter is out of range.
    #[error("{shape}: {name} {requirement}, got {value}")]
    BadParameter {
        /// Which builder ("chain", "cloth", "mesh", "tet mesh", "wind").
        shape: &'static str,
        /// The parameter.
        name: &'static str,
        /// What it must satisfy.
        requirement: &'static str,
        /// The value given.
        value: String,
    },
    /// Gravity has a NaN or infinite component.
    #[error("gravity {gravity:?} is not finite")]
    NonFiniteGravity {
        /// The vector given.
        gravity: [f64; 3],
    },
}

/// A straight chain (rope) of `count` particles from `start` to `end`, joined by `count - 1`
/// distance constraints at their rest length.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Chain {
    /// Number of particles (>= 2).
    pub count: usize,
    /// First particle.
    pub start: [f64; 3],
    /// Last particle (distinct from `start`).
    pub end: [f64; 3],
    /// Mass of each particle (kg).
    pub mass: f64,
    /// The distance constraints.
    pub stretch: ConstraintParams,
}

/// Which bending constraint a cloth or mesh gets across each interior edge.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
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
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
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

/// How mesh vertices get their mass.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MeshMass {
    /// Every vertex has this mass (kg).
    PerVertex(f64),
    /// Density per area (kg/m^2, triangle meshes) or per volume (kg/m^3, tet meshes), lumped:
    /// each element gives its vertices equal shares of its mass.
    Density(f64),
}

/// Constraints made from a triangle mesh.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshParams {
    /// Vertex masses.
    pub mass: MeshMass,
    /// A distance constraint on every unique edge.
    pub stretch: ConstraintParams,
    /// Bending across interior edges (the mesh must then be manifold).
    pub bending: Bending,
}

/// Constraints made from a tetrahedral mesh.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TetMeshParams {
    /// Vertex masses.
    pub mass: MeshMass,
    /// A distance constraint on every unique tetrahedron edge, if any.
    pub stretch: Option<ConstraintParams>,
    /// A volume constraint per tetrahedron, if any.
    pub volume: Option<ConstraintParams>,
}

#[derive(Debug, Clone)]
enum Pending {
    Distance { i: usize, j: usize, rest: Option<f64> },
    Dihedral([usize; 4]),
    Isometric([usize; 4]),
    Tet([usize; 4]),
    Volume { mesh: usize, pressure: f64 },
    Attach { particle: usize, target: AttachTarget, distance: f64 },
}

/// Collects particles, constraints, pins, bodies, colliders, gravity and wind, then checks them
/// all in [`build`](Self::build). Gravity is zero until set.
#[derive(Debug, Clone, Default)]
pub struct PbdBuilder {
    positions: Vec<[f64; 3]>,
    masses: Vec<f64>,
    pins: Vec<usize>,
    pending: Vec<(Pending, ConstraintParams)>,
    volume_meshes: Vec<(Vec<[usize; 3]>, usize)>,
    colliders: Vec<Collider>,
    bodies: Vec<KinematicBody>,
    gravity: [f64; 3],
    wind: Option<Wind>,
    triangles: Vec<[usize; 3]>,
    edges: Vec<[usize; 2]>,
    tets: Vec<[usize; 4]>,
}

/// Standard gravity pointing down the z axis (m/s^2): the scenes' convention is z up.
pub const EARTH_GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

fn bad(
    shape: &'static str,
    name: &'static str,
    requirement: &'static str,
    value: impl ToString,
) -> BuildError {
    BuildError::BadParameter { shape, name, requirement, value: value.to_string() }
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

fn check_mass(shape: &'static str, m: MeshMass) -> Result<(), BuildError> {
    match m {
        MeshMass::PerVertex(v) => check_positive(shape, "mass per vertex", v),
        MeshMass::Density(v) => check_positive(shape, "density", v),
    }
}

/// Sorted vertex pair.
fn key(a: usize, b: usize) -> (usize, usize) {
    if a < b { (a, b) } else { (b, a) }
}

impl PbdBuilder {
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

    /// Number of constraints added so far (the index the next one gets).
    #[must_use]
    pub fn num_constraints(&self) -> usize {
        self.pending.len()
    }

    /// Sets gravity (m/s^2), e.g. [`EARTH_GRAVITY`].
    pub fn gravity(&mut self, g: [f64; 3]) -> &mut Self {
        self.gravity = g;
        self
    }

    /// Sets a wind acting on the model's triangles.
    pub fn wind(&mut self, wind: Wind) -> &mut Self {
        self.wind = Some(wind);
        self
    }

    /// Adds a particle and returns its index.
    pub fn particle(&mut self, position: [f64; 3], mass: f64) -> usize {
        self.positions.push(position);
        self.masses.push(mass);
        self.positions.len() - 1
    }

    /// Pins particle `p` (inverse mass 0).
    pub fn pin(&mut self, p: usize) -> &mut Self {
        self.pins.push(p);
        self
    }

    /// Adds a kinematic body and returns its index.
    pub fn body(&mut self, body: KinematicBody) -> usize {
        self.bodies.push(body);
        self.bodies.len() - 1
    }

    /// Adds a collider and returns its index.
    pub fn collider(&mut self, c: Collider) -> usize {
        self.colliders.push(c);
        self.colliders.len() - 1
    }

    /// Records a triangle for rendering and wind (it adds no constraint).
    pub fn triangle(&mut self, t: [usize; 3]) -> &mut Self {
        self.triangles.push(t);
        self
    }

    /// Records a line segment for rendering (it adds no constraint).
    pub fn edge(&mut self, e: [usize; 2]) -> &mut Self {
        self.edges.push(e);
        self
    }

    fn push(&mut self, c: Pending, params: ConstraintParams) -> usize {
        self.pending.push((c, params));
        self.pending.len() - 1
    }

    /// A distance constraint whose rest length is the particles' current distance; returns the
    /// constraint index.
    pub fn distance(&mut self, i: usize, j: usize, params: ConstraintParams) -> usize {
        self.push(Pending::Distance { i, j, rest: None }, params)
    }

    /// A distance constraint with an explicit rest length (0 joins the particles).
    pub fn distance_with_rest(&mut self, i: usize, j: usize, rest: f64, params: ConstraintParams) -> usize {
        self.push(Pending::Distance { i, j, rest: Some(rest) }, params)
    }

    /// A dihedral bending constraint on `[p0, p1, p2, p3]` (edge `p2, p3`; `p0`, `p1` opposite),
    /// rest angle from the current positions.
    pub fn dihedral(&mut self, particles: [usize; 4], params: ConstraintParams) -> usize {
        self.push(Pending::Dihedral(particles), params)
    }

    /// An isometric bending constraint on `[p0, p1, p2, p3]` (edge `p2, p3`), weights from the
    /// current positions.
    pub fn isometric_bending(&mut self, particles: [usize; 4], params: ConstraintParams) -> usize {
        self.push(Pending::Isometric(particles), params)
    }

    /// A tetrahedral volume constraint, rest volume from the current positions.
    pub fn tet_volume(&mut self, particles: [usize; 4], params: ConstraintParams) -> usize {
        self.push(Pending::Tet(particles), params)
    }

    /// A global volume constraint on the closed, outward-oriented triangle mesh `triangles`
    /// (particle indices), keeping `pressure` times its current volume.
    pub fn global_volume(
        &mut self,
        triangles: &[[usize; 3]],
        pressure: f64,
        params: ConstraintParams,
    ) -> usize {
        let c = self.pending.len();
        self.volume_meshes.push((triangles.to_vec(), c));
        let mesh = self.volume_meshes.len() - 1;
        self.push(Pending::Volume { mesh, pressure }, params)
    }

    /// Attaches particle `p` to a target (within `distance`, 0 to pin it there).
    pub fn attach(
        &mut self,
        p: usize,
        target: AttachTarget,
        distance: f64,
        params: ConstraintParams,
    ) -> usize {
        self.push(Pending::Attach { particle: p, target, distance }, params)
    }

    /// A chain; returns the range of its particles.
    ///
    /// # Errors
    /// [`BuildError::BadParameter`] for fewer than 2 particles, coincident ends or non-finite input.
    pub fn chain(&mut self, c: &Chain) -> Result<Range<usize>, BuildError> {
        if c.count < 2 {
            return Err(bad("chain", "count", "must be at least 2", c.count));
        }
        let a = check_vec("chain", "start", c.start)?;
        let b = check_vec("chain", "end", c.end)?;
        if a == b {
            return Err(bad("chain", "end", "must differ from start", format!("{:?}", c.end)));
        }
        let first = self.positions.len();
        for k in 0..c.count {
            let s = k as f64 / (c.count - 1) as f64;
            self.particle(a.lerp(b, s).to_array(), c.mass);
        }
        for k in first..first + c.count - 1 {
            self.distance(k, k + 1, c.stretch);
            self.edge([k, k + 1]);
        }
        Ok(first..first + c.count)
    }

    /// A cloth grid; returns where its particles are.
    ///
    /// # Errors
    /// [`BuildError::BadParameter`] for fewer than 2 particles along a side, parallel `u` and `v`,
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
    /// [`BuildError::TriangleIndex`], [`BuildError::DegenerateTriangle`],
    /// [`BuildError::NonManifoldEdge`] (with bending), [`BuildError::IsolatedVertex`] (mass by
    /// density), [`BuildError::BadParameter`].
    pub fn triangle_mesh(
        &mut self,
        positions: &[[f64; 3]],
        triangles: &[[usize; 3]],
        params: &MeshParams,
    ) -> Result<Range<usize>, BuildError> {
        check_mass("mesh", params.mass)?;
        let nv = positions.len();
        let pos: Vec<DVec3> = positions.iter().map(|&p| DVec3::from_array(p)).collect();
        let mut area = vec![0.0; nv];
        for (t, tri) in triangles.iter().enumerate() {
            for &i in tri {
                if i >= nv {
                    return Err(BuildError::TriangleIndex { triangle: t, index: i, vertices: nv });
                }
            }
            let [a, b, c] = *tri;
            if a == b || b == c || a == c {
                return Err(BuildError::DegenerateTriangle {
                    triangle: t,
                    vertices: *tri,
                    reason: "repeated vertex",
                });
            }
            let (e1, e2) = (pos[b] - pos[a], pos[c] - pos[a]);
            let twice = e1.cross(e2).length();
            if !(twice > 1e-12 * e1.length_squared().max(e2.length_squared())) {
                return Err(BuildError::DegenerateTriangle {
                    triangle: t,
                    vertices: *tri,
                    reason: "zero area",
                });
            }
            for &i in tri {
                area[i] += twice / 6.0;
            }
        }
        let masses: Vec<f64> = match params.mass {
            MeshMass::PerVertex(m) => vec![m; nv],
            MeshMass::Density(rho) => {
                if let Some(v) = area.iter().position(|&a| a == 0.0) {
                    return Err(BuildError::IsolatedVertex { vertex: v, element: "triangle" });
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
        let first = self.positions.len();
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
                    return Err(BuildError::NonManifoldEdge { a, b, triangles: used.len() });
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

    /// A tetrahedral mesh from any positions and tetrahedra: distance constraints on the unique
    /// edges and a volume constraint per tetrahedron, as `params` asks; the boundary faces are
    /// recorded (outward) for rendering, the tetrahedra for output. Returns the range of its
    /// particles.
    ///
    /// # Errors
    /// [`BuildError::TetIndex`], [`BuildError::DegenerateTet`] (repeated vertex or
    /// `|V| <= 1e-12 l^3` with `l` the longest edge), [`BuildError::IsolatedVertex`] (mass by
    /// density), [`BuildError::BadParameter`].
    pub fn tet_mesh(
        &mut self,
        positions: &[[f64; 3]],
        tets: &[[usize; 4]],
        params: &TetMeshParams,
    ) -> Result<Range<usize>, BuildError> {
        check_mass("tet mesh", params.mass)?;
        let nv = positions.len();
        let pos: Vec<DVec3> = positions.iter().map(|&p| DVec3::from_array(p)).collect();
        let mut vol = vec![0.0; nv];
        for (t, tet) in tets.iter().enumerate() {
            for &i in tet {
                if i >= nv {
                    return Err(BuildError::TetIndex { tet: t, index: i, vertices: nv });
                }
            }
            let p = tet.map(|i| pos[i]);
            let v = tet_volume(p).0;
            for a in 0..4 {
                for b in a + 1..4 {
                    if tet[a] == tet[b] {
                        return Err(BuildError::DegenerateTet {
                            tet: t,
                            vertices: *tet,
                            volume: v,
                            reason: "repeated vertex",
                        });
                    }
                }
            }
            let mut l2 = 0.0f64;
            for a in 0..4 {
                for b in a + 1..4 {
                    l2 = l2.max((p[a] - p[b]).length_squared());
                }
            }
            if !(v.abs() > 1e-12 * l2 * l2.sqrt()) {
                return Err(BuildError::DegenerateTet {
                    tet: t,
                    vertices: *tet,
                    volume: v,
                    reason: "zero volume",
                });
            }
            for &i in tet {
                vol[i] += v.abs() / 4.0;
            }
        }
        let masses: Vec<f64> = match params.mass {
            MeshMass::PerVertex(m) => vec![m; nv],
            MeshMass::Density(rho) => {
                if let Some(v) = vol.iter().position(|&a| a == 0.0) {
                    return Err(BuildError::IsolatedVertex { vertex: v, element: "tetrahedron" });
                }
                vol.iter().map(|a| rho * a).collect()
            }
        };
        let first = self.positions.len();
        for (p, m) in positions.iter().zip(&masses) {
            self.particle(*p, *m);
        }
        if let Some(stretch) = params.stretch {
            let mut seen = std::collections::HashSet::new();
            for tet in tets {
                for a in 0..4 {
                    for b in a + 1..4 {
                        if seen.insert(key(tet[a], tet[b])) {
                            self.distance(first + tet[a], first + tet[b], stretch);
                        }
                    }
                }
            }
        }
        if let Some(volume) = params.volume {
            for tet in tets {
                self.tet_volume(tet.map(|i| first + i), volume);
            }
        }
        for f in crate::shapes::tet_surface(positions, tets) {
            self.triangles.push(f.map(|i| first + i));
        }
        for t in tets {
            self.tets.push(t.map(|i| first + i));
        }
        Ok(first..first + nv)
    }

    /// Checks everything and builds the model.
    ///
    /// # Errors
    /// The first problem found, as a [`BuildError`] naming the element.
    pub fn build(&self) -> Result<PbdModel, BuildError> {
        let n = self.positions.len();
        if n == 0 {
            return Err(BuildError::NoParticles);
        }
        if n >= u32::MAX as usize {
            return Err(BuildError::TooLarge { what: "particles", count: n, max: u32::MAX as usize - 1 });
        }
        if self.pending.len() >= u32::MAX as usize {
            return Err(BuildError::TooLarge {
                what: "constraints",
                count: self.pending.len(),
                max: u32::MAX as usize - 1,
            });
        }
        if !self.gravity.iter().all(|g| g.is_finite()) {
            return Err(BuildError::NonFiniteGravity { gravity: self.gravity });
        }
        let mut particles = Vec::with_capacity(n);
        for (i, (&m, p)) in self.masses.iter().zip(&self.positions).enumerate() {
            if !(m > 0.0 && m.is_finite()) {
                return Err(BuildError::BadMass { particle: i, mass: m });
            }
            if !p.iter().all(|c| c.is_finite()) {
                return Err(BuildError::NonFinitePosition { particle: i, position: *p });
            }
            particles.push(Particle { mass: m, pinned: false });
        }
        for (k, &p) in self.pins.iter().enumerate() {
            if p >= n {
                return Err(BuildError::PinIndex { pin: k, index: p, particles: n });
            }
            particles[p].pinned = true;
        }
        let inv_mass: Vec<f64> =
            particles.iter().map(|p| if p.pinned { 0.0 } else { 1.0 / p.mass }).collect();
        for (b, body) in self.bodies.iter().enumerate() {
            let pose = body.pose;
            let ok = pose.position.is_finite()
                && pose.rotation.is_finite()
                && (pose.rotation.length() - 1.0).abs() < 1e-6
                && match body.motion {
                    crate::collide::BodyMotion::Fixed => true,
                    crate::collide::BodyMotion::Constant { velocity, angular_velocity } => {
                        velocity.iter().chain(&angular_velocity).all(|v| v.is_finite())
                    }
                    crate::collide::BodyMotion::Oscillate { amplitude, frequency } => {
                        amplitude.iter().all(|v| v.is_finite()) && frequency.is_finite()
                    }
                };
            if !ok {
                return Err(BuildError::BadBody {
                    body: b,
                    reason: "pose must be finite with a unit quaternion, motion finite".into(),
                });
            }
        }
        let colliders = self
            .colliders
            .iter()
            .enumerate()
            .map(|(k, c)| {
                c.validate(self.bodies.len())
                    .map_err(|reason| BuildError::BadCollider { collider: k, reason })
            })
            .collect::<Result<Vec<_>, _>>()?;
        if let Some(w) = self.wind
            && !(w.velocity.iter().all(|v| v.is_finite())
                && w.drag >= 0.0
                && w.drag.is_finite()
                && w.gust.is_finite())
        {
            return Err(bad(
                "wind",
                "velocity, drag, gust",
                "must be finite with drag >= 0",
                format!("{w:?}"),
            ));
        }
        for (t, tri) in self.triangles.iter().enumerate() {
            if let Some(&i) = tri.iter().find(|&&i| i >= n) {
                return Err(BuildError::TriangleIndex { triangle: t, index: i, vertices: n });
            }
        }
        for e in &self.edges {
            if let Some(&i) = e.iter().find(|&&i| i >= n) {
                return Err(bad("edge", "vertex", "must be a particle index", i));
            }
        }
        let pos: Vec<DVec3> = self.positions.iter().map(|&p| DVec3::from_array(p)).collect();
        let mut volume_meshes = Vec::with_capacity(self.volume_meshes.len());
        for (tris, c) in &self.volume_meshes {
            volume_meshes.push(volume_mesh(tris, &pos, *c)?);
        }
        let mut constraints = Vec::with_capacity(self.pending.len());
        for (j, (p, params)) in self.pending.iter().enumerate() {
            constraints.push(self.constraint(j, p, params, &pos, &volume_meshes)?);
        }
        // Incidence: constraints per particle, in increasing constraint order.
        let mut count = vec![0usize; n + 1];
        let parts = |c: &Constraint| -> Vec<usize> {
            match &c.function {
                ConstraintFunction::GlobalVolume { mesh, .. } => volume_meshes[*mesh].vertices.clone(),
                _ => c.particles().to_vec(),
            }
        };
        let all_parts: Vec<Vec<usize>> = constraints.iter().map(parts).collect();
        for ps in &all_parts {
            for &p in ps {
                count[p + 1] += 1;
            }
        }
        for p in 0..n {
            count[p + 1] += count[p];
        }
        let inc_ptr = count.clone();
        let mut fill = count;
        let mut inc = vec![(0u32, 0u32); inc_ptr[n]];
        for (j, ps) in all_parts.iter().enumerate() {
            for (slot, &p) in ps.iter().enumerate() {
                inc[fill[p]] = (j as u32, slot as u32);
                fill[p] += 1;
            }
        }
        let mut tcount = vec![0usize; n + 1];
        for t in &self.triangles {
            for &p in t {
                tcount[p + 1] += 1;
            }
        }
        for p in 0..n {
            tcount[p + 1] += tcount[p];
        }
        let tri_ptr = tcount.clone();
        let mut tfill = tcount;
        let mut tri_inc = vec![0u32; tri_ptr[n]];
        for (k, t) in self.triangles.iter().enumerate() {
            for &p in t {
                tri_inc[tfill[p]] = k as u32;
                tfill[p] += 1;
            }
        }
        Ok(PbdModel {
            particles,
            inv_mass,
            positions: self.positions.clone(),
            constraints,
            volume_meshes,
            colliders,
            bodies: self.bodies.clone(),
            gravity: DVec3::from_array(self.gravity),
            wind: self.wind,
            triangles: self.triangles.clone(),
            edges: self.edges.clone(),
            tets: self.tets.clone(),
            inc_ptr,
            inc,
            tri_ptr,
            tri_inc,
        })
    }

    fn constraint(
        &self,
        j: usize,
        p: &Pending,
        params: &ConstraintParams,
        pos: &[DVec3],
        meshes: &[VolumeMesh],
    ) -> Result<Constraint, BuildError> {
        let n = pos.len();
        let kind = match p {
            Pending::Distance { .. } => "distance",
            Pending::Dihedral(_) => "dihedral bending",
            Pending::Isometric(_) => "isometric bending",
            Pending::Tet(_) => "tetrahedral volume",
            Pending::Volume { .. } => "global volume",
            Pending::Attach { .. } => "attachment",
        };
        if !(0.0..=1.0).contains(&params.stiffness) {
            return Err(BuildError::BadStiffness { constraint: j, kind, value: params.stiffness });
        }
        if !(params.compliance >= 0.0 && params.compliance.is_finite()) {
            return Err(BuildError::BadCompliance { constraint: j, kind, value: params.compliance });
        }
        if !(params.damping >= 0.0 && params.damping.is_finite()) {
            return Err(BuildError::BadDamping { constraint: j, kind, value: params.damping });
        }
        let indices: Vec<usize> = match p {
            Pending::Distance { i, j, .. } => vec![*i, *j],
            Pending::Dihedral(s) | Pending::Isometric(s) | Pending::Tet(s) => s.to_vec(),
            Pending::Volume { .. } => vec![],
            Pending::Attach { particle, .. } => vec![*particle],
        };
        for (a, &i) in indices.iter().enumerate() {
            if i >= n {
                return Err(BuildError::ConstraintIndex { constraint: j, kind, index: i, particles: n });
            }
            if indices[..a].contains(&i) {
                return Err(BuildError::RepeatedIndex { constraint: j, kind, particle: i });
            }
        }
        let degenerate =
            |reason| BuildError::DegenerateRest { constraint: j, kind, particles: indices.clone(), reason };
        let function = match p {
            Pending::Distance { i, j: k, rest } => {
                let l = rest.unwrap_or_else(|| (pos[*i] - pos[*k]).length());
                if !(l >= 0.0 && l.is_finite()) {
                    return Err(BuildError::BadRestValue {
                        constraint: j,
                        kind,
                        name: "rest length",
                        requirement: "non-negative and finite",
                        value: l,
                    });
                }
                ConstraintFunction::Distance { particles: [*i, *k], rest_length: l }
            }
            Pending::Dihedral(s) => {
                let (theta, _) =
                    dihedral(s.map(|i| pos[i])).ok_or_else(|| degenerate("a triangle has zero area"))?;
                ConstraintFunction::DihedralBending { particles: *s, rest_angle: theta }
            }
            Pending::Isometric(s) => {
                let (weights, rest) = isometric_weights(s.map(|i| pos[i].to_array()))
                    .ok_or_else(|| degenerate("a triangle has zero area"))?;
                ConstraintFunction::IsometricBending(IsometricBending { particles: *s, weights, rest })
            }
            Pending::Tet(s) => {
                let p4 = s.map(|i| pos[i]);
                let v = tet_volume(p4).0;
                let mut l2 = 0.0f64;
                for a in 0..4 {
                    for b in a + 1..4 {
                        l2 = l2.max((p4[a] - p4[b]).length_squared());
                    }
                }
                if !(v.abs() > 1e-12 * l2 * l2.sqrt()) {
                    return Err(degenerate("zero volume"));
                }
                ConstraintFunction::TetVolume { particles: *s, rest_volume: v }
            }
            Pending::Volume { mesh, pressure } => {
                if !(*pressure > 0.0 && pressure.is_finite()) {
                    return Err(BuildError::BadRestValue {
                        constraint: j,
                        kind,
                        name: "pressure",
                        requirement: "positive and finite",
                        value: *pressure,
                    });
                }
                let m = &meshes[*mesh];
                let x: Vec<f64> = pos.iter().flat_map(|p| p.to_array()).collect();
                ConstraintFunction::GlobalVolume {
                    mesh: *mesh,
                    rest_volume: m.volume(&x),
                    pressure: *pressure,
                }
            }
            Pending::Attach { particle, target, distance } => {
                if !(*distance >= 0.0 && distance.is_finite()) {
                    return Err(BuildError::BadRestValue {
                        constraint: j,
                        kind,
                        name: "distance",
                        requirement: "non-negative and finite",
                        value: *distance,
                    });
                }
                match target {
                    AttachTarget::Point(t) if !t.iter().all(|c| c.is_finite()) => {
                        return Err(BuildError::BadRestValue {
                            constraint: j,
                            kind,
                            name: "target",
                            requirement: "finite",
                            value: f64::NAN,
                        });
                    }
                    AttachTarget::Body { body, local } => {
                        if *body >= self.bodies.len() {
                            return Err(BuildError::BodyIndex {
                                constraint: j,
                                body: *body,
                                bodies: self.bodies.len(),
                            });
                        }
                        if !local.iter().all(|c| c.is_finite()) {
                            return Err(BuildError::BadRestValue {
                                constraint: j,
                                kind,
                                name: "local point",
                                requirement: "finite",
                                value: f64::NAN,
                            });
                        }
                    }
                    AttachTarget::Point(_) => {}
                }
                ConstraintFunction::Attachment { particle: *particle, target: *target, distance: *distance }
            }
        };
        Ok(Constraint { function, params: *params })
    }
}

/// Validates a closed mesh and converts it to local indices.
fn volume_mesh(tris: &[[usize; 3]], pos: &[DVec3], constraint: usize) -> Result<VolumeMesh, BuildError> {
    let n = pos.len();
    let fail =
        |reason: String| BuildError::BadVolumeMesh { reason: format!("constraint {constraint}: {reason}") };
    if tris.len() < 4 {
        return Err(fail(format!("a closed mesh needs at least 4 triangles, got {}", tris.len())));
    }
    let mut directed: HashMap<(usize, usize), usize> = HashMap::new();
    for (t, tri) in tris.iter().enumerate() {
        if let Some(&i) = tri.iter().find(|&&i| i >= n) {
            return Err(fail(format!("triangle {t} names particle {i}, which does not exist")));
        }
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
            return Err(fail(format!("triangle {t} {tri:?} repeats a vertex")));
        }
        for k in 0..3 {
            let e = (tri[k], tri[(k + 1) % 3]);
            if directed.insert(e, t).is_some() {
                return Err(fail(format!(
                    "directed edge {e:?} appears twice (triangle {t}): the mesh is not consistently oriented or not manifold"
                )));
            }
        }
    }
    for (&(a, b), &t) in &directed {
        if !directed.contains_key(&(b, a)) {
            return Err(fail(format!(
                "edge ({a}, {b}) of triangle {t} has no opposite: the mesh is not closed"
            )));
        }
    }
    let mut vertices: Vec<usize> = tris.iter().flatten().copied().collect();
    vertices.sort_unstable();
    vertices.dedup();
    let local: HashMap<usize, u32> = vertices.iter().enumerate().map(|(k, &v)| (v, k as u32)).collect();
    let triangles = tris.iter().map(|t| t.map(|i| local[&i])).collect();
    let m = VolumeMesh { vertices, triangles };
    let x: Vec<f64> = pos.iter().flat_map(|p| p.to_array()).collect();
    let v = m.volume(&x);
    if !(v > 0.0) {
        return Err(fail(format!(
            "enclosed volume {v:e} is not positive (are the normals pointing inward?)"
        )));
    }
    Ok(m)
}
