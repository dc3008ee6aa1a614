//! What can be wrong with a builder's input: [`BuildError`], the shared [`InputError`] (particle,
//! pin, triangle, edge, vertex, collider, parameter, gravity) or one variant per problem only a
//! position-based model has (constraint, tetrahedron, body, volume mesh), each naming the element
//! and the offending value. Every builder method and
//! [`PbdBuilder::build`](crate::PbdBuilder::build) report it; nothing in the builders panics on
//! user data.

pub use anim_core::input::InputError;

/// A builder input that cannot make a valid model. Every variant names the element.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BuildError {
    /// A problem every particle-model builder can have: a particle, pin, triangle, edge,
    /// vertex or collider, a builder parameter or gravity (see [`InputError`]).
    #[error(transparent)]
    Input(#[from] InputError),
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
    /// A kinematic body's pose or motion is not finite.
    #[error("kinematic body {body}: {reason}")]
    BadBody {
        /// Body index.
        body: usize,
        /// What is wrong.
        reason: String,
    },
    /// A mesh collider's contact parameters are not valid.
    #[error("mesh collider {collider}: {reason}")]
    BadMeshCollider {
        /// Mesh collider index.
        collider: usize,
        /// What is wrong.
        reason: String,
    },
    /// A contact body's particle range or surface is not valid.
    #[error("contact body {body}: {reason}")]
    BadContactBody {
        /// Contact body index.
        body: usize,
        /// What is wrong.
        reason: String,
    },
    /// The contact parameters between bodies are not valid.
    #[error("body contact: {reason}")]
    BadBodyContact {
        /// What is wrong.
        reason: String,
    },
}
