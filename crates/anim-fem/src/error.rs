//! The crate's error type: bad input (meshes, parameters, boundary conditions) and numerical
//! failure (divergence, a failed Newton or linear solve), each naming the element, vertex or
//! step concerned.

use anim_core::linalg::SolveError;
use anim_material::MaterialError;

/// Which state array held a non-finite value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StateField {
    /// Vertex positions.
    Position,
    /// Vertex velocities.
    Velocity,
}

impl std::fmt::Display for StateField {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            StateField::Position => "position",
            StateField::Velocity => "velocity",
        })
    }
}

/// The name of axis `c` (`x`, `y`, `z`).
fn axis(c: usize) -> &'static str {
    ["x", "y", "z"].get(c).copied().unwrap_or("?")
}

/// Everything that can go wrong building or stepping a finite element body.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FemError {
    /// A checkpointed memory that does not belong to this simulation.
    #[error("checkpoint does not fit this simulation: {0}")]
    Checkpoint(String),
    /// The mesh has no elements.
    #[error("the mesh has no elements")]
    EmptyMesh,
    /// An element names a vertex that does not exist.
    #[error("element {element} references vertex {vertex}, but the mesh has {vertices} vertices")]
    VertexOutOfRange {
        /// Element index.
        element: usize,
        /// The bad vertex index.
        vertex: usize,
        /// Number of vertices.
        vertices: usize,
    },
    /// An element uses the same vertex twice.
    #[error("element {element} uses vertex {vertex} twice")]
    RepeatedVertex {
        /// Element index.
        element: usize,
        /// The repeated vertex.
        vertex: usize,
    },
    /// A rest vertex has a NaN or infinite coordinate.
    #[error("rest vertex {vertex} has a non-finite coordinate")]
    NonFiniteVertex {
        /// Vertex index.
        vertex: usize,
    },
    /// A rest element has (almost) zero volume: `|det Dm| <= 1e-12 * (longest edge)^3`.
    #[error(
        "element {element} is degenerate in the rest configuration (6 x volume {volume6:e}, longest edge {edge:e})"
    )]
    DegenerateElement {
        /// Element index.
        element: usize,
        /// Six times its signed rest volume.
        volume6: f64,
        /// Its longest rest edge.
        edge: f64,
    },
    /// A rest element is inverted: `(X1 - X0) x (X2 - X0) . (X3 - X0) < 0`.
    #[error(
        "element {element} is inverted in the rest configuration (6 x signed volume {volume6:e}); swap two of its vertices"
    )]
    InvertedElement {
        /// Element index.
        element: usize,
        /// Six times its signed rest volume.
        volume6: f64,
    },
    /// A 10-node element whose edge node is not at the midpoint of its edge (only straight-edged,
    /// affine 10-node elements are supported).
    #[error(
        "10-node element {element}: edge node {node} lies {offset:e} from the midpoint of its edge (edge length {edge:e}); only straight-edged elements are supported"
    )]
    CurvedElement {
        /// Element index.
        element: usize,
        /// The edge node's index in the mesh.
        node: usize,
        /// Its distance from the edge midpoint.
        offset: f64,
        /// The edge's length.
        edge: f64,
    },
    /// Materials per element that do not fit the mesh: none, a list of indices of the wrong
    /// length, or an index past the materials.
    #[error("element materials: {0}")]
    MaterialIndex(String),
    /// Bad material parameters (Young's modulus, Poisson's ratio).
    #[error("material: {0}")]
    Material(#[from] MaterialError),
    /// An obstacle's shape is invalid (fails [`Shape::check`](anim_core::geometry::Shape::check)).
    #[error("obstacle {obstacle}: {reason}")]
    BadObstacle {
        /// Index of the obstacle in the order added.
        obstacle: usize,
        /// What is wrong, naming the shape.
        reason: String,
    },
    /// A scalar parameter out of its range.
    #[error("parameter `{name}` = {value}: {reason}")]
    BadParameter {
        /// Field name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
    /// A boundary condition or load names a vertex that does not exist.
    #[error("{what} names vertex {vertex}, but the mesh has {vertices} vertices")]
    BoundaryVertexOutOfRange {
        /// Which input ("pinned vertex", "kinematic group 2", "nodal force").
        what: String,
        /// The bad vertex index.
        vertex: usize,
        /// Number of vertices.
        vertices: usize,
    },
    /// The state does not match the mesh.
    #[error("state has {found} {what} coordinates, the mesh needs {expected}")]
    StateSize {
        /// "position" or "velocity".
        what: &'static str,
        /// Length found.
        found: usize,
        /// Length expected (3 x vertices).
        expected: usize,
    },
    /// A mesh file could not be read or converted.
    #[error("mesh input: {0}")]
    MeshInput(String),
    /// The step produced a NaN or infinity; the step was undone.
    #[error(
        "anim-fem: step {step}: non-finite {field} of vertex {vertex}, component {} (value {value}); last finite {field} of vertex {vertex}: {last_finite:?}",
        axis(*component)
    )]
    NonFiniteState {
        /// Completed steps before the failing one.
        step: u64,
        /// Which array.
        field: StateField,
        /// First offending vertex.
        vertex: usize,
        /// Its first offending component (0, 1, 2 for `x`, `y`, `z`).
        component: usize,
        /// The offending value.
        value: f64,
        /// The vertex's position or velocity (as `field` says) before the step.
        last_finite: [f64; 3],
    },
    /// An element's energy or stress is not finite (an element inverted beyond what its material
    /// model defines, e.g. `det F <= 0` for Neo-Hookean, or a NaN deformation).
    #[error(
        "anim-fem: step {step}: element {element} has non-finite energy or stress (det F = {det_f}); the state is the one before the step"
    )]
    NonFiniteElement {
        /// Completed steps before the failing one.
        step: u64,
        /// First offending element.
        element: usize,
        /// `det F` of that element.
        det_f: f64,
    },
    /// Newton's method hit its iteration cap.
    #[error(
        "Newton did not converge at step {step}: {iterations} iterations, last update {update:e} (tolerance {tolerance:e})"
    )]
    NewtonNotConverged {
        /// Completed steps before the failing one.
        step: u64,
        /// Iterations performed.
        iterations: usize,
        /// Infinity norm of the last Newton update.
        update: f64,
        /// The tolerance it had to reach.
        tolerance: f64,
    },
    /// The backtracking line search found no decrease of the incremental potential.
    #[error(
        "line search failed at step {step}, Newton iteration {iteration}: no decrease after {halvings} halvings"
    )]
    LineSearch {
        /// Completed steps before the failing one.
        step: u64,
        /// Newton iteration.
        iteration: usize,
        /// Step halvings tried.
        halvings: usize,
    },
    /// The linear solve inside Newton failed.
    #[error("linear solve failed at step {step}, Newton iteration {iteration}: {source}")]
    LinearSolve {
        /// Completed steps before the failing one.
        step: u64,
        /// Newton iteration.
        iteration: usize,
        /// The solver's error.
        source: SolveError,
    },
}

#[cfg(feature = "files")]
impl From<anim_io::IoError> for FemError {
    fn from(e: anim_io::IoError) -> Self {
        FemError::MeshInput(e.to_string())
    }
}
