//! What can be wrong with the input of a particle-model builder, in the terms every such builder
//! shares: [`InputError`] names the element (particle, pin, triangle, edge, vertex or collider
//! index, or the builder and parameter) and the offending value.
//!
//! The mass-spring and position-based builders (`anim-springs`, `anim-pbd`) both wrap it in their
//! own `BuildError`, next to the variants only their model has (springs, constraints, bodies).
//! [`check_triangle`] is the index and repeated-vertex check both run on each triangle of a mesh.

/// A builder input that names an element that is wrong: a particle, pin, triangle, edge, vertex
/// or collider, a builder parameter, or gravity. Every variant names the element and the value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum InputError {
    /// No particles were given.
    #[error("there are no particles")]
    NoParticles,
    /// More particles (or springs, constraints) than the compact indices hold.
    #[error("{count} {what} exceed the maximum of {max}")]
    TooLarge {
        /// "particles", "springs" or "constraints".
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
    #[error("pin {pin}: particle {index} does not exist (there are {particles} particles)")]
    PinIndex {
        /// Position in the list of pins.
        pin: usize,
        /// The index given.
        index: usize,
        /// Number of particles.
        particles: usize,
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
    #[error("edge ({a}, {b}) is shared by {triangles} triangles; bending needs a manifold mesh")]
    NonManifoldEdge {
        /// First vertex.
        a: usize,
        /// Second vertex.
        b: usize,
        /// Number of triangles sharing it.
        triangles: usize,
    },
    /// With mass by area or volume density, a vertex that belongs to no element would get no mass.
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
    /// A builder parameter is out of range.
    #[error("{shape}: {name} {requirement}, got {value}")]
    BadParameter {
        /// Which builder ("chain", "cloth", "lattice", "mesh", "tet mesh", "wind", ...).
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

/// Triangle `triangle` of a mesh with `vertices` vertices: every index names a vertex
/// ([`InputError::TriangleIndex`] otherwise) and no vertex repeats
/// ([`InputError::DegenerateTriangle`] with reason "repeated vertex" otherwise).
///
/// # Errors
/// The first of the two problems found, naming the triangle.
pub fn check_triangle(triangle: usize, tri: [usize; 3], vertices: usize) -> Result<(), InputError> {
    if let Some(&index) = tri.iter().find(|&&i| i >= vertices) {
        return Err(InputError::TriangleIndex { triangle, index, vertices });
    }
    let [a, b, c] = tri;
    if a == b || b == c || a == c {
        return Err(InputError::DegenerateTriangle { triangle, vertices: tri, reason: "repeated vertex" });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_checks_name_the_triangle() {
        assert_eq!(check_triangle(0, [0, 1, 2], 3), Ok(()));
        assert_eq!(
            check_triangle(4, [0, 5, 2], 3),
            Err(InputError::TriangleIndex { triangle: 4, index: 5, vertices: 3 })
        );
        let e = check_triangle(2, [1, 0, 1], 3).unwrap_err();
        assert_eq!(e.to_string(), "triangle 2 [1, 0, 1] is degenerate: repeated vertex");
    }

    #[test]
    fn messages_name_the_element_and_value() {
        let e = InputError::BadMass { particle: 3, mass: -1.0 };
        assert_eq!(e.to_string(), "particle 3: mass must be positive and finite, got -1");
        let e = InputError::PinIndex { pin: 1, index: 9, particles: 4 };
        assert_eq!(e.to_string(), "pin 1: particle 9 does not exist (there are 4 particles)");
    }
}
