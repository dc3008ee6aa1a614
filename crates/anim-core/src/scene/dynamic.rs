//! [`DynScene`]: a scene behind a `Box<dyn DynScene>`, and the blanket implementation for every
//! solver that is a [`Checkpoint`] and a [`View`].

use super::checkpoint::{Checkpoint, CheckpointError, saved_field};
use super::view::{Context, Frame, View};
use crate::solver::{Solver, StepReport};

/// The error of a dynamic step: the solver's own error, boxed. Its message is the solver's: it
/// begins with the crate's name and names the step's failure (a non-finite value with its
/// element, a solve that did not converge). [`StepError::get`] gives the solver's error back.
#[derive(Debug)]
pub struct StepError(Box<dyn std::error::Error + Send + Sync>);

impl StepError {
    /// Wraps a solver's error.
    pub fn new(error: impl std::error::Error + Send + Sync + 'static) -> Self {
        Self(Box::new(error))
    }

    /// The solver's error, if it is an `E`.
    #[must_use]
    pub fn get<E: std::error::Error + 'static>(&self) -> Option<&E> {
        self.0.downcast_ref::<E>()
    }
}

impl std::fmt::Display for StepError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for StepError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.0.source()
    }
}

/// A scene the run loop steps, checkpoints and draws without knowing its crate: object safe,
/// implemented for every [`Simulated`] solver that is a [`Checkpoint`] and a [`View`].
///
/// The invariants of the three traits carry over: a failed step or restore leaves the scene
/// unchanged; `restore(save())` continues bit for bit; results do not depend on the number of
/// rayon threads.
pub trait DynScene: Send {
    /// Advances the scene by `dt` seconds.
    ///
    /// # Errors
    /// The solver's error; the scene is unchanged.
    fn step(&mut self, dt: f64) -> Result<StepReport, StepError>;

    /// Simulated time (s).
    fn time(&self) -> f64;

    /// `{"version": V, "time": t, "saved": ...}`: the solver's [`Checkpoint::save`] with its
    /// layout version and the simulated time.
    fn save(&self) -> serde_json::Value;

    /// Restores what [`DynScene::save`] of a scene built from the same parameters wrote.
    ///
    /// # Errors
    /// [`CheckpointError`] for another version, another scene or a damaged value; the scene is
    /// unchanged.
    fn restore(&mut self, saved: &serde_json::Value) -> Result<(), CheckpointError>;

    /// The method in a few words ([`View::method`]).
    fn method(&self) -> String;

    /// The static context ([`View::context`]).
    fn context(&self) -> Context;

    /// The current frame ([`View::frame`]).
    fn frame(&self, out: &mut Frame);

    /// The error against the scene's reference, where it has one ([`View::reference_error`]).
    fn reference_error(&self) -> Option<f64>;

    /// Provokes a non-finite value at the next step ([`Checkpoint::provoke_overflow`]).
    fn provoke_overflow(&mut self) -> Option<String>;
}

/// A solver paired with its state: the form in which every solver is a [`DynScene`].
#[derive(Debug, Clone)]
pub struct Simulated<S: Solver> {
    /// The solver: model, data and memory.
    pub solver: S,
    /// The integrated state.
    pub state: S::State,
}

impl<S: Solver> Simulated<S> {
    /// `solver` with its initial `state`.
    pub fn new(solver: S, state: S::State) -> Self {
        Self { solver, state }
    }

    /// Boxed as a [`DynScene`].
    #[must_use]
    pub fn boxed(self) -> Box<dyn DynScene>
    where
        Self: DynScene + 'static,
    {
        Box::new(self)
    }
}

impl<S> DynScene for Simulated<S>
where
    S: Solver + Checkpoint + View + Send,
    S::State: Send,
{
    fn step(&mut self, dt: f64) -> Result<StepReport, StepError> {
        self.solver.step(&mut self.state, dt).map_err(StepError::new)
    }

    fn time(&self) -> f64 {
        self.solver.time(&self.state)
    }

    fn save(&self) -> serde_json::Value {
        serde_json::json!({
            "version": S::VERSION,
            "time": self.solver.time(&self.state),
            "saved": self.solver.save(&self.state),
        })
    }

    fn restore(&mut self, saved: &serde_json::Value) -> Result<(), CheckpointError> {
        let version: u64 = saved_field(saved, "version")?;
        if version != u64::from(S::VERSION) {
            return Err(CheckpointError::Version { found: version, expected: S::VERSION });
        }
        let inner = saved.get("saved").ok_or_else(|| CheckpointError::Missing { field: "saved".into() })?;
        self.solver.restore(&mut self.state, inner)
    }

    fn method(&self) -> String {
        self.solver.method()
    }

    fn context(&self) -> Context {
        self.solver.context(&self.state)
    }

    fn frame(&self, out: &mut Frame) {
        self.solver.frame(&self.state, out);
    }

    fn reference_error(&self) -> Option<f64> {
        self.solver.reference_error(&self.state)
    }

    fn provoke_overflow(&mut self) -> Option<String> {
        self.solver.provoke_overflow(&mut self.state)
    }
}
