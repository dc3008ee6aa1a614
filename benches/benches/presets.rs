//! Criterion benches of one `DynScene::step` of every registered preset (`anim::presets()`), so
//! that a newly registered preset gets its bench with no edit here: each preset built once from
//! its quick parameters (its full ones where it has none), named `presets/NAME`. A preset that
//! ends (its divergence guard fires, or its nominal duration `run.steps()` is reached) is
//! restored from its initial checkpoint; the restore is not timed.

use anim_core::scene::{BuildContext, DynScene};
use criterion::{Criterion, criterion_group, criterion_main};
use std::time::{Duration, Instant};

/// A preset's scene, stepped from its initial checkpoint for at most `duration` steps at a time.
struct Looped {
    scene: Box<dyn DynScene>,
    start: serde_json::Value,
    dt: f64,
    duration: usize,
    since_start: usize,
    name: &'static str,
}

impl Looped {
    fn restart(&mut self) {
        self.scene
            .restore(&self.start)
            .unwrap_or_else(|e| panic!("{}: restore of the initial checkpoint: {e}", self.name));
        self.since_start = 0;
    }

    /// One step and its wall time; a restart before it (the duration reached, or the step failed
    /// after steps from the start) is not counted.
    fn step(&mut self) -> Duration {
        if self.since_start >= self.duration {
            self.restart();
        }
        let t = Instant::now();
        let mut result = self.scene.step(self.dt).map(drop);
        let mut elapsed = t.elapsed();
        if result.is_err() && self.since_start > 0 {
            self.restart();
            let t = Instant::now();
            result = self.scene.step(self.dt).map(drop);
            elapsed = t.elapsed();
        }
        result.unwrap_or_else(|e| panic!("{}: step {}: {e}", self.name, self.since_start + 1));
        self.since_start += 1;
        elapsed
    }
}

fn steps(c: &mut Criterion) {
    let mut g = c.benchmark_group("presets");
    g.sample_size(10);
    g.warm_up_time(Duration::from_millis(500));
    g.measurement_time(Duration::from_secs(2));
    for (kind, preset) in anim::presets() {
        let params = preset.quick_params.as_ref().unwrap_or(&preset.params);
        let scene = (kind.build)(params, &BuildContext::default())
            .unwrap_or_else(|e| panic!("{}: build: {e}", preset.name));
        let start = scene.save();
        let mut looped = Looped {
            scene,
            start,
            dt: preset.run.dt,
            duration: preset.run.steps().max(1),
            since_start: 0,
            name: preset.name,
        };
        g.bench_function(preset.name, |b| {
            b.iter_custom(|iterations| (0..iterations).map(|_| looped.step()).sum());
        });
    }
    g.finish();
}

criterion_group!(benches, steps);
criterion_main!(benches);
