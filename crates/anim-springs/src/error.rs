//! What can be wrong with a builder's input: [`BuildError`], one variant per kind of problem, each
//! naming the element (particle, spring, triangle, edge or OBJ line) and the offending value.
//!
//! It sits below the builders, the network and the OBJ reader, which all report it: the builders
//! for their shapes and for [`NetworkBuilder::build`](crate::NetworkBuilder::build), the network
//! when gravity is reset
//! ([`SpringNetwork::set_gravity`](crate::SpringNetwork::set_gravity)), the reader for a
//! malformed line ([`TriangleMesh::from_obj`](crate::TriangleMesh::from_obj)).

/// A builder input that cannot make a valid network. Every variant names the element.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BuildError {
    /// The network has no particles.
    #[error("the network has no particles")]
    NoParticles,
    /// More particles or springs than the compact indices hold.
    #[error("{count} {what} exceed the maximum of {max}")]
    TooLarge {
        /// "particles" or "springs".
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
    #[error("pin {pin}: particle {index} does not exist (the network has {particles} particles)")]
    PinIndex {
        /// Position in the list of pins.
        pin: usize,
        /// The index given.
        index: usize,
        /// Number of particles.
        particles: usize,
    },
    /// A spring names a particle that does not exist.
    #[error("spring {spring}: particle {index} does not exist (the network has {particles} particles)")]
    SpringIndex {
        /// Spring index.
        spring: usize,
        /// The index given.
        index: usize,
        /// Number of particles.
        particles: usize,
    },
    /// A spring joins a particle to itself.
    #[error("spring {spring} joins particle {particle} to itself")]
    SelfSpring {
        /// Spring index.
        spring: usize,
        /// The particle.
        particle: usize,
    },
    /// A spring's stiffness is not a positive finite number.
    #[error("spring {spring}: stiffness must be positive and finite, got {stiffness}")]
    BadStiffness {
        /// Spring index.
        spring: usize,
        /// The stiffness given.
        stiffness: f64,
    },
    /// A spring's damping is negative or not finite.
    #[error("spring {spring}: damping must be non-negative and finite, got {damping}")]
    BadDamping {
        /// Spring index.
        spring: usize,
        /// The damping given.
        damping: f64,
    },
    /// A spring's rest length is negative or not finite.
    #[error("spring {spring}: rest length must be non-negative and finite, got {rest_length}")]
    BadRestLength {
        /// Spring index.
        spring: usize,
        /// The rest length given.
        rest_length: f64,
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
    /// An edge is shared by more than two triangles: bending across it is undefined.
    #[error("edge ({a}, {b}) is shared by {triangles} triangles; bending springs need a manifold mesh")]
    NonManifoldEdge {
        /// First vertex.
        a: usize,
        /// Second vertex.
        b: usize,
        /// Number of triangles sharing it.
        triangles: usize,
    },
    /// Two triangles have the same three vertices.
    #[error("triangle ({a}, {b}, {c}) appears twice")]
    DuplicateTriangle {
        /// First vertex of the shared edge.
        a: usize,
        /// Second vertex of the shared edge.
        b: usize,
        /// The vertex opposite the edge in both.
        c: usize,
    },
    /// With mass by area, a vertex that belongs to no triangle would get no mass.
    #[error("vertex {vertex} belongs to no triangle, so mass by area gives it no mass")]
    IsolatedVertex {
        /// Vertex index.
        vertex: usize,
    },
    /// A shape parameter is out of range.
    #[error("{shape}: {name} {requirement}, got {value}")]
    BadParameter {
        /// Which builder ("chain", "cloth", "lattice", "mesh").
        shape: &'static str,
        /// The parameter.
        name: &'static str,
        /// What it must satisfy.
        requirement: &'static str,
        /// The value given.
        value: String,
    },
    /// A collider's parameters are invalid.
    #[error("collider {collider}: {reason}")]
    BadCollider {
        /// Collider index.
        collider: usize,
        /// What is wrong.
        reason: String,
    },
    /// Gravity has a NaN or infinite component.
    #[error("gravity {gravity:?} is not finite")]
    NonFiniteGravity {
        /// The vector given.
        gravity: [f64; 3],
    },
    /// A Wavefront OBJ file could not be read.
    #[error("OBJ line {line}: {message}")]
    Obj {
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
}
