//! What can be wrong with a builder's input: [`BuildError`], the shared [`InputError`] (particle,
//! pin, triangle, edge, vertex, collider, parameter, gravity) or one variant per problem only a
//! network has (a spring, a duplicated triangle, an OBJ line), each naming the element and the
//! offending value.
//!
//! It sits below the builders, the network and the OBJ reader, which all report it: the builders
//! for their shapes and for [`NetworkBuilder::build`](crate::NetworkBuilder::build), the network
//! when gravity is reset
//! ([`SpringNetwork::set_gravity`](crate::SpringNetwork::set_gravity)), the reader for a
//! malformed line ([`TriangleMesh::from_obj`](crate::TriangleMesh::from_obj)).

pub use anim_core::input::InputError;

/// A builder input that cannot make a valid network. Every variant names the element.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BuildError {
    /// A problem every particle-model builder can have: a particle, pin, triangle, edge,
    /// vertex or collider, a builder parameter or gravity (see [`InputError`]).
    #[error(transparent)]
    Input(#[from] InputError),
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
    /// A mesh collider's parameters are invalid.
    #[error("mesh collider {collider}: {reason}")]
    BadMeshCollider {
        /// Mesh collider index, in the order added.
        collider: usize,
        /// What is wrong.
        reason: String,
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
