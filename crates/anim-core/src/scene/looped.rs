//! A scene stepped for as long as a measurement needs: timing loops and benches run a preset
//! for more steps than it lasts, so it goes back to its initial checkpoint when its nominal
//! duration is reached, or when a step fails after the first.

use super::DynScene;
use std::time::{Duration, Instant};

/// A scene with its initial checkpoint, stepped by `dt`, back to the start every `duration`
/// steps and after a failed step (a step that fails right after a restart is an error). The
/// restores are not part of the measured step time.
pub struct Looped {
    scene: Box<dyn DynScene>,
    start: serde_json::Value,
    dt: f64,
    duration: usize,
    /// Steps since the last (re)start.
    since_start: usize,
    restarts: usize,
    failures: Vec<String>,
}

impl Looped {
    /// `scene` from its current state (its initial checkpoint), stepped by `dt`, restarted after
    /// `duration` steps (at least 1).
    #[must_use]
    pub fn new(scene: Box<dyn DynScene>, dt: f64, duration: usize) -> Self {
        let start = scene.save();
        Self {
            scene,
            start,
            dt,
            duration: duration.max(1),
            since_start: 0,
            restarts: 0,
            failures: Vec::new(),
        }
    }

    fn restart(&mut self) -> Result<(), String> {
        self.scene.restore(&self.start).map_err(|e| format!("restart from the initial checkpoint: {e}"))?;
        self.since_start = 0;
        self.restarts += 1;
        Ok(())
    }

    /// One step and its wall time (a restart before it is not timed).
    ///
    /// # Errors
    /// The step's message when a step fails right after a (re)start, or a restore fails.
    pub fn step(&mut self) -> Result<Duration, String> {
        if self.since_start >= self.duration {
            self.restart()?;
        }
        let t = Instant::now();
        let mut result = self.scene.step(self.dt).map(drop);
        let mut elapsed = t.elapsed();
        if let Err(e) = &result
            && self.since_start > 0
        {
            self.failures.push(format!("step {} failed: {e}", self.since_start + 1));
            self.restart()?;
            let t = Instant::now();
            result = self.scene.step(self.dt).map(drop);
            elapsed = t.elapsed();
        }
        result.map_err(|e| format!("step {}: {e}", self.since_start + 1))?;
        self.since_start += 1;
        Ok(elapsed)
    }

    /// The scene.
    #[must_use]
    pub fn scene(&self) -> &dyn DynScene {
        self.scene.as_ref()
    }

    /// How many times the scene went back to its initial checkpoint (duration reached or a step
    /// failed).
    #[must_use]
    pub fn restarts(&self) -> usize {
        self.restarts
    }

    /// The steps that failed before their preset's duration ended (each followed by a restart):
    /// a divergence inside the nominal run, which a measurement must report.
    #[must_use]
    pub fn failures(&self) -> &[String] {
        &self.failures
    }
}
