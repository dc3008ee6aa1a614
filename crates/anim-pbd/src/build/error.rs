//! What can be wrong with a builder's input: [`BuildError`], one variant per kind of problem,
//! each naming the element (particle, pin, constraint, triangle, edge, tetrahedron, collider or
//! body index) and the offending value. Every builder method and
//! [`PbdBuilder::build`](crate::PbdBuilder::build) report it; nothing in the builders panics on
//! user data.

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
