//! [`Checkpoint`]: versioned save and restore of everything a step reads.

use crate::solver::Solver;
use serde::de::DeserializeOwned;

/// Save and restore of everything the next step of a solver reads, so that a run restored from
/// a checkpoint continues bit for bit like one that never stopped.
///
/// What is saved is the state passed to [`Solver::step`] *and* the solver's memory: whatever it
/// carries from one step to the next beyond its model (an integrator's previous positions, a
/// kept factorisation's warm start, the last pressure as an initial guess, step counters). The
/// model itself (topology, rest shape, parameters) is not saved: a checkpoint is restored into a
/// solver built from the same scene.
///
/// **Time.** Every solver reports its simulated time through [`Checkpoint::time`], the one way
/// the workspace reads it, and [`DynScene::save`](super::DynScene::save) writes it beside the
/// saved value; where the time is kept (in the state, as `State::t`, or in the simulation, for
/// particle methods whose grid is rebuilt every step) is the solver's business.
///
/// **Invariants** every implementation keeps:
/// - `restore(save())` into a solver built from the same scene continues bit for bit (floats
///   are written so that they read back exactly; the workspace's `serde_json` keeps
///   `float_roundtrip`);
/// - a `restore` that fails leaves the solver and the state exactly as they were: it checks
///   everything (sizes, kinds, finiteness) before it commits.
pub trait Checkpoint: Solver {
    /// Layout version of what [`Checkpoint::save`] writes. Raise it when the layout changes: a
    /// checkpoint of another version is refused with [`CheckpointError::Version`].
    const VERSION: u32;

    /// Simulated time of `state`, in seconds.
    fn time(&self, state: &Self::State) -> f64;

    /// Everything the next step reads, beyond the model.
    fn save(&self, state: &Self::State) -> serde_json::Value;

    /// Restores what [`Checkpoint::save`] of a solver built from the same scene wrote.
    ///
    /// # Errors
    /// A [`CheckpointError`] naming the field and the cause when `saved` belongs to another
    /// scene (other sizes, another method) or is damaged; `self` and `state` are then unchanged.
    fn restore(&mut self, state: &mut Self::State, saved: &serde_json::Value) -> Result<(), CheckpointError>;

    /// Sets one value of `state` so that the next step overflows to a non-finite value, and
    /// says which; `None` when the scene integrates nothing that could (a pose that is a
    /// function of time). The workspace's conformance suite uses it to check that a step which
    /// meets a non-finite value fails and leaves the state and the checkpoint memory unchanged.
    fn provoke_overflow(&mut self, state: &mut Self::State) -> Option<String> {
        let _ = state;
        None
    }
}

/// A checkpoint that cannot be restored.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CheckpointError {
    /// Written by another layout version.
    #[error("a checkpoint of layout version {found}; this build reads version {expected}")]
    Version {
        /// The checkpoint's version.
        found: u64,
        /// The version this build writes and reads.
        expected: u32,
    },
    /// A field is missing.
    #[error("the checkpoint has no `{field}`")]
    Missing {
        /// The field's name (dotted for nested fields).
        field: String,
    },
    /// A field is present but not valid for this scene (wrong type, size, or value).
    #[error("`{field}`: {message}")]
    Invalid {
        /// The field's name (dotted for nested fields).
        field: String,
        /// What is wrong with it.
        message: String,
    },
}

impl CheckpointError {
    /// An [`CheckpointError::Invalid`] of `field`.
    #[must_use]
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self::Invalid { field: field.into(), message: message.into() }
    }
}

/// Field `key` of a saved value, deserialised.
///
/// # Errors
/// [`CheckpointError::Missing`] when there is no such field; [`CheckpointError::Invalid`] when
/// it does not deserialise as `T`.
pub fn saved_field<T: DeserializeOwned>(saved: &serde_json::Value, key: &str) -> Result<T, CheckpointError> {
    let value = saved.get(key).ok_or_else(|| CheckpointError::Missing { field: key.to_string() })?;
    T::deserialize(value).map_err(|e| CheckpointError::invalid(key, e.to_string()))
}

/// The [`State`](crate::integrate::State) saved under `key`, checked against the sizes of
/// `current` (the state of the scene it is restored into) and for finite values.
///
/// # Errors
/// [`CheckpointError`] when the field is missing, is not a state, holds another number of
/// degrees of freedom than `current`, or a value that is not finite.
pub fn saved_state(
    saved: &serde_json::Value,
    key: &str,
    current: &crate::integrate::State,
) -> Result<crate::integrate::State, CheckpointError> {
    let state: crate::integrate::State = saved_field(saved, key)?;
    if state.x.len() != current.x.len() || state.v.len() != current.v.len() {
        return Err(CheckpointError::invalid(
            key,
            format!(
                "{} positions and {} velocities; this scene has {} and {}",
                state.x.len(),
                state.v.len(),
                current.x.len(),
                current.v.len()
            ),
        ));
    }
    if let Some(bad) = state.x.iter().chain(&state.v).chain([&state.t]).find(|v| !v.is_finite()) {
        return Err(CheckpointError::invalid(key, format!("holds the non-finite value {bad}")));
    }
    Ok(state)
}

/// The checkpoint of a solver whose step reads a [`State`](crate::integrate::State) and the
/// solver's own memory (step counts, warm starts): `{"state": state, "simulation": memory}`.
#[must_use]
pub fn save_state_and_memory(
    state: &crate::integrate::State,
    memory: serde_json::Value,
) -> serde_json::Value {
    serde_json::json!({ "state": state, "simulation": memory })
}

/// Restores what [`save_state_and_memory`] saved: the state is read and checked against
/// `state` first ([`saved_state`]), then `restore_memory` takes the memory (whole or not at all),
/// and only then is `state` replaced, so a refused checkpoint changes nothing.
///
/// # Errors
/// [`CheckpointError`] naming `state` or `simulation` when either is missing or refused.
pub fn restore_state_and_memory<E: std::fmt::Display>(
    saved: &serde_json::Value,
    state: &mut crate::integrate::State,
    restore_memory: impl FnOnce(&serde_json::Value) -> Result<(), E>,
) -> Result<(), CheckpointError> {
    let restored = saved_state(saved, "state", state)?;
    let memory =
        saved.get("simulation").ok_or_else(|| CheckpointError::Missing { field: "simulation".into() })?;
    restore_memory(memory).map_err(|e| CheckpointError::invalid("simulation", e.to_string()))?;
    *state = restored;
    Ok(())
}
