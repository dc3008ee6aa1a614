//! Criterion benches of one `DynScene::step` of every registered preset (`anim::presets()`), so
//! that a newly registered preset gets its bench with no edit here: each preset built once from
//! its quick parameters (its full ones where it has none), named `presets/NAME`. A preset that
//! ends (its divergence guard fires, or its nominal duration `run.steps()` is reached) is
//! restored from its initial checkpoint; the restore is not timed.

use anim_core::scene::{BuildContext, Looped};
use criterion::{Criterion, criterion_group, criterion_main};
use std::time::Duration;

fn steps(c: &mut Criterion) {
    let mut g = c.benchmark_group("presets");
    g.sample_size(10);
    g.warm_up_time(Duration::from_millis(500));
    g.measurement_time(Duration::from_secs(2));
    // The steps run on a worker of a pool, as `anim run` and the scaling suite step them: a
    // parallel call from a thread outside every pool goes through rayon's global injector, whose
    // queue allocates now and then.
    let pool = rayon::ThreadPoolBuilder::new().build().unwrap_or_else(|e| panic!("thread pool: {e}"));
    for (kind, preset) in anim::presets() {
        let scene = (kind.build)(preset.params_for(true), &BuildContext::default())
            .unwrap_or_else(|e| panic!("{}: build: {e}", preset.name));
        let mut looped = Looped::new(scene, preset.run.dt, preset.run.steps());
        g.bench_function(preset.name, |b| {
            b.iter_custom(|iterations| {
                pool.install(|| {
                    (0..iterations)
                        .map(|_| looped.step().unwrap_or_else(|e| panic!("{}: {e}", preset.name)))
                        .sum()
                })
            });
        });
    }
    g.finish();
}

criterion_group!(benches, steps);
criterion_main!(benches);
