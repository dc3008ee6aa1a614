//! What can be wrong with the input of a particle-model builder, in the terms every such builder
//! shares: [`InputError`] names the element (particle, pin, triangle, edge, vertex or collider
//! index, or the builder and parameter) and the offending value.
//!
//! The mass-spring and position-based builders (`anim-springs`, `anim-pbd`) both wrap it in their
//! own `BuildError`, next to the variants only their model has (springs, constraints, bodies).
//! [`check_triangle`] is the index and repeated-vertex check both run on each triangle of a mesh,
//! [`check_triangle_indices`] its index half for the triangles they record as given, and
//! [`check_particles`] the gravity, particle and pin check both `build` methods start with.

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

/// The particles of a particle-model builder: `gravity` finite
/// ([`InputError::NonFiniteGravity`]), then for each particle in order a finite position
/// ([`InputError::NonFinitePosition`]) and a positive finite mass ([`InputError::BadMass`]),
/// then every pin naming a particle ([`InputError::PinIndex`]). `positions` and `masses` are
/// paired index by index. Returns whether each particle is pinned.
///
/// # Errors
/// The first problem found, naming the particle or pin.
pub fn check_particles(
    positions: &[[f64; 3]],
    masses: &[f64],
    pins: &[usize],
    gravity: [f64; 3],
) -> Result<Vec<bool>, InputError> {
    if !gravity.iter().all(|g| g.is_finite()) {
        return Err(InputError::NonFiniteGravity { gravity });
    }
    for (particle, (&position, &mass)) in positions.iter().zip(masses).enumerate() {
        if !position.iter().all(|c| c.is_finite()) {
            return Err(InputError::NonFinitePosition { particle, position });
        }
        if !(mass > 0.0 && mass.is_finite()) {
            return Err(InputError::BadMass { particle, mass });
        }
    }
    let particles = positions.len().min(masses.len());
    let mut pinned = vec![false; particles];
    for (pin, &index) in pins.iter().enumerate() {
        match pinned.get_mut(index) {
            Some(p) => *p = true,
            None => return Err(InputError::PinIndex { pin, index, particles }),
        }
    }
    Ok(pinned)
}

/// The index half of [`check_triangle`]: every index of triangle `triangle` names one of
/// `vertices` vertices ([`InputError::TriangleIndex`] with the first that does not otherwise).
/// For triangles recorded as they are (for rendering or wind), where a repeated vertex is allowed.
///
/// # Errors
/// The first index out of range, naming the triangle.
pub fn check_triangle_indices(triangle: usize, tri: [usize; 3], vertices: usize) -> Result<(), InputError> {
    match tri.iter().find(|&&i| i >= vertices) {
        Some(&index) => Err(InputError::TriangleIndex { triangle, index, vertices }),
        None => Ok(()),
    }
}

/// Triangle `triangle` of a mesh with `vertices` vertices: every index names a vertex
/// ([`InputError::TriangleIndex`] otherwise) and no vertex repeats
/// ([`InputError::DegenerateTriangle`] with reason "repeated vertex" otherwise).
///
/// # Errors
/// The first of the two problems found, naming the triangle.
pub fn check_triangle(triangle: usize, tri: [usize; 3], vertices: usize) -> Result<(), InputError> {
    check_triangle_indices(triangle, tri, vertices)?;
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
        assert_eq!(check_triangle_indices(2, [1, 0, 1], 3), Ok(()));
        assert_eq!(
            check_triangle_indices(4, [7, 5, 2], 3),
            Err(InputError::TriangleIndex { triangle: 4, index: 7, vertices: 3 })
        );
    }

    #[test]
    fn particle_checks_name_the_particle_or_pin() {
        let x = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let m = [1.0, 2.0, 3.0];
        let g = [0.0, 0.0, -9.81];
        assert_eq!(check_particles(&x, &m, &[2, 0, 2], g), Ok(vec![true, false, true]));
        assert_eq!(check_particles(&x, &m, &[], g), Ok(vec![false; 3]));
        let e = check_particles(&x, &m, &[], [0.0, f64::NAN, 0.0]).unwrap_err();
        assert!(matches!(e, InputError::NonFiniteGravity { .. }), "{e}");
        let mut bad = x;
        bad[1][2] = f64::INFINITY;
        assert_eq!(
            check_particles(&bad, &m, &[], g),
            Err(InputError::NonFinitePosition { particle: 1, position: bad[1] })
        );
        for mass in [0.0, -1.0, f64::INFINITY] {
            assert_eq!(
                check_particles(&x, &[1.0, 1.0, mass], &[], g),
                Err(InputError::BadMass { particle: 2, mass })
            );
        }
        assert!(matches!(
            check_particles(&x, &[1.0, f64::NAN, 1.0], &[], g),
            Err(InputError::BadMass { particle: 1, .. })
        ));
        assert_eq!(
            check_particles(&x, &m, &[0, 3], g),
            Err(InputError::PinIndex { pin: 1, index: 3, particles: 3 })
        );
    }

    #[test]
    fn messages_name_the_element_and_value() {
        let e = InputError::BadMass { particle: 3, mass: -1.0 };
        assert_eq!(e.to_string(), "particle 3: mass must be positive and finite, got -1");
        let e = InputError::PinIndex { pin: 1, index: 9, particles: 4 };
        assert_eq!(e.to_string(), "pin 1: particle 9 does not exist (there are 4 particles)");
    }
}
