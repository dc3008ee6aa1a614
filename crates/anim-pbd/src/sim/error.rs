//! What a step or a setting can get wrong: [`PbdError`]. A step that fails leaves the caller's
//! state and the simulation's memory as they were (see the `check` module for the guard).

/// A failed step or bad settings. The state is unchanged when a step returns one.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PbdError {
    /// A checkpointed memory that does not belong to this simulation.
    #[error("checkpoint does not fit this simulation: {0}")]
    Checkpoint(String),
    /// A solver setting is out of range.
    #[error("{name} {requirement}, got {value}")]
    BadParameter {
        /// The setting.
        name: &'static str,
        /// What it must satisfy.
        requirement: &'static str,
        /// The value given.
        value: String,
    },
    /// The time step is not positive and finite.
    #[error("time step must be positive and finite, got {dt}")]
    BadTimeStep {
        /// The value given.
        dt: f64,
    },
    /// A position or velocity became NaN or infinite. The step was undone.
    #[error(
        "anim-pbd: step {step}: non-finite {field} of particle {particle}{} (value {value}); last finite {field} of particle {particle}: {last_finite:?}; {}; the step was undone",
        match component { Some(c) => format!(", component {}", ["x", "y", "z"][(*c).min(2)]), None => String::new() },
        match constraint { Some((c, kind)) => format!("constraint {c} ({kind}) produced it"), None => "no constraint involved (external force or input)".to_string() }
    )]
    NonFinite {
        /// Step index (0-based count of completed steps).
        step: u64,
        /// "position" or "velocity".
        field: &'static str,
        /// First offending particle.
        particle: usize,
        /// Its first offending component (0, 1, 2 for `x`, `y`, `z`); `None` when a constraint's
        /// update was not finite and was skipped, leaving the particle finite.
        component: Option<usize>,
        /// The offending value (NaN when the update was skipped, see `component`).
        value: f64,
        /// The particle's position or velocity (as `field` says) before the step.
        last_finite: [f64; 3],
        /// The first constraint whose update was not finite (or else the first constraint at that
        /// particle), with its kind.
        constraint: Option<(usize, &'static str)>,
    },
    /// A distance constraint stretched beyond the bound: the run is diverging. The step was undone.
    #[error(
        "diverged at step {step}: constraint {constraint} (distance, particles {i} and {j}) stretched to {ratio:.3e} times its rest length (bound {bound}); the step was undone"
    )]
    Diverged {
        /// Step index.
        step: u64,
        /// Constraint index.
        constraint: usize,
        /// Its first particle.
        i: usize,
        /// Its second particle.
        j: usize,
        /// `|x_i - x_j| / l` after the step.
        ratio: f64,
        /// The bound.
        bound: f64,
    },
}
