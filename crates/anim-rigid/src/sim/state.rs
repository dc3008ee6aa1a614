//! The integrated state of a tree: time, configuration `q` on its manifold (unit quaternions
//! for spherical and free joints) and joint-frame velocity `v`.

/// The integrated state of a tree: time, configuration `q` (length `nq`, unit quaternions for
/// spherical and free joints) and velocity `v` (length `nv`, joint-frame velocities).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct RigidState {
    /// Simulated time (s).
    pub t: f64,
    /// Configuration.
    pub q: Vec<f64>,
    /// Velocity.
    pub v: Vec<f64>,
}

impl RigidState {
    /// The state `(q, v)` at time 0.
    #[must_use]
    pub fn new(q: Vec<f64>, v: Vec<f64>) -> Self {
        Self { t: 0.0, q, v }
    }
}
