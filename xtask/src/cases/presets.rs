//! The scene contracts, checked on every registered preset through anim-core's `DynScene`
//! alone, so that a newly registered preset gets them
//! without any edit here:
//!
//! - **determinism**: the same steps on rayon pools of 1, 2 and 4 threads end in the same
//!   checkpoint and the same frame, bit for bit;
//! - **no allocation per step**: after [`STEPS`] steps (buffers sized, a particle fluid's active
//!   cells grown), the next block of four steps makes no heap allocation (counted by the
//!   process's counting allocator, on every thread; up to three blocks, as
//!   `anim_core::alloc_count::step_allocations` counts);
//! - **checkpoint**: a scene restored from the JSON text of a checkpoint continues bit for bit
//!   like the one that never stopped;
//! - **non-finite guard**: a step that meets a provoked overflow fails and leaves the checkpoint
//!   exactly as it was (skipped, with a note, for scenes that integrate nothing: a pose that is a
//!   function of time).
//!
//! Quick mode runs each preset's `quick_params` (a coarser version of the same scene).

use crate::registry::{Check, ConformanceCase, Ctx, Judge, Registry, across_threads, differing_bits};
use anim_core::scene::{BuildContext, DynScene, Frame, Preset, SceneKind};
use std::sync::OnceLock;

/// Steps taken before the contracts are checked.
const STEPS: usize = 3;
const SOURCE: &str = "the scene contracts of anim-core";

/// The 2-thread pool the allocations are counted in, built once and every thread started: a
/// pool built or dropped while allocations are counted would count its threads' start or end.
fn pool() -> Result<&'static rayon::ThreadPool, String> {
    static POOL: OnceLock<Result<rayon::ThreadPool, String>> = OnceLock::new();
    POOL.get_or_init(|| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().map_err(|e| e.to_string())?;
        pool.broadcast(|_| ());
        Ok(pool)
    })
    .as_ref()
    .map_err(Clone::clone)
}

pub fn register(r: &mut Registry) {
    for (kind, preset) in anim::presets() {
        // A case per preset: the name names it, so `--filter NAME` selects one preset.
        let name: &'static str = Box::leak(format!("scene contracts: {}", preset.name).into_boxed_str());
        r.conformance.push(ConformanceCase {
            crate_name: kind.crate_name,
            name,
            run: Box::new(move |ctx| contracts(kind, &preset, ctx)),
        });
    }
}

/// Every number of a checkpoint, in document order, then every value of the frame.
pub(crate) fn fingerprint(scene: &dyn DynScene, frame: &mut Frame) -> Vec<f64> {
    fn walk(v: &serde_json::Value, out: &mut Vec<f64>) {
        match v {
            serde_json::Value::Number(n) => out.push(n.as_f64().unwrap_or(f64::NAN)),
            serde_json::Value::Array(a) => a.iter().for_each(|x| walk(x, out)),
            serde_json::Value::Object(o) => o.values().for_each(|x| walk(x, out)),
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk(&scene.save(), &mut out);
    scene.frame(frame);
    out.push(frame.time);
    out.extend_from_slice(&frame.points);
    for f in &frame.fields {
        out.extend_from_slice(&f.values);
    }
    out
}

fn check(kind: &SceneKind, case: String, metric: &str, measured: f64) -> Check {
    Check {
        crate_name: kind.crate_name,
        case,
        metric: metric.into(),
        measured,
        reference: 0.0,
        tolerance: 0.0,
        judge: Judge::AtMost,
        source: SOURCE,
    }
}

fn contracts(kind: &'static SceneKind, preset: &Preset, ctx: &Ctx) -> Vec<Check> {
    scene_contracts(kind, preset.name, preset.params_for(ctx.quick), &BuildContext::default(), preset.run.dt)
}

/// The contracts of the scene `kind` builds from `params` (file names relative to `context`),
/// stepped by `dt`; `name` names it in the checks.
pub(crate) fn scene_contracts(
    kind: &'static SceneKind,
    name: &str,
    params: &serde_json::Value,
    context: &BuildContext<'_>,
    dt: f64,
) -> Vec<Check> {
    let build = || (kind.build)(params, context).map_err(|e| e.to_string());
    let run = |steps: usize| -> Result<Vec<f64>, String> {
        let mut scene = build()?;
        for _ in 0..steps {
            scene.step(dt).map_err(|e| e.to_string())?;
        }
        Ok(fingerprint(scene.as_ref(), &mut Frame::default()))
    };
    let failed =
        |what: &str, e: String| vec![check(kind, format!("{name}: {what} failed: {e}"), "error", f64::NAN)];
    let mut out = Vec::new();

    // Determinism across thread counts.
    out.extend(across_threads(kind.crate_name, &format!("{name}: checkpoint and frame"), || run(STEPS + 2)));

    // No allocation once the buffers are sized. The steps run inside a pool, as a worker: a
    // parallel call made from a thread outside every pool goes through rayon's global injector,
    // whose queue allocates a block every few dozen calls (rayon's cost, not the solver's; a
    // run loop that wants none steps inside `ThreadPool::install`).
    let pool = match pool() {
        Ok(p) => p,
        Err(e) => return failed("the 2-thread pool", e),
    };
    let measured = pool.install(|| -> Result<(Box<dyn DynScene>, usize), String> {
        let mut scene = build()?;
        for _ in 0..STEPS {
            scene.step(dt).map_err(|e| e.to_string())?;
        }
        let blocks = anim_core::alloc_count::step_allocations(&crate::ALLOC, scene.as_mut(), dt)?;
        Ok((scene, blocks.last().copied().unwrap_or(usize::MAX)))
    });
    let mut scene = match measured {
        Ok((scene, allocations)) => {
            out.push(check(
                kind,
                format!("{name}: a block of 4 steps after step {STEPS}, 2 threads"),
                "heap allocations",
                allocations as f64,
            ));
            scene
        }
        Err(e) => return failed("the steps counted for allocations", e),
    };

    // Checkpoint, then resume: the same bits as the run that never stopped.
    let saved = scene.save().to_string();
    let uninterrupted = (|| -> Result<Vec<f64>, String> {
        for _ in 0..2 {
            scene.step(dt).map_err(|e| e.to_string())?;
        }
        Ok(fingerprint(scene.as_ref(), &mut Frame::default()))
    })();
    let resumed = (|| -> Result<Vec<f64>, String> {
        let mut fresh = build()?;
        let value: serde_json::Value = serde_json::from_str(&saved).map_err(|e| e.to_string())?;
        fresh.restore(&value).map_err(|e| e.to_string())?;
        for _ in 0..2 {
            fresh.step(dt).map_err(|e| e.to_string())?;
        }
        Ok(fingerprint(fresh.as_ref(), &mut Frame::default()))
    })();
    let measured = match (&uninterrupted, &resumed) {
        (Ok(a), Ok(b)) => differing_bits(a, b) as f64,
        _ => f64::NAN,
    };
    out.push(check(
        kind,
        format!("{name}: resumed from a checkpoint, 2 more steps"),
        "values whose bits differ from the uninterrupted run",
        measured,
    ));

    // A provoked overflow fails the step and leaves the checkpoint as it was.
    let before = scene.save();
    if let Some(what) = scene.provoke_overflow() {
        // Compared as text: `-0.0` and `0.0` are equal numbers but not the same bits.
        let poisoned = scene.save().to_string();
        let failed_step = scene.step(dt);
        let after: String = scene.save().to_string();
        let unchanged = after == poisoned;
        let measured = match failed_step {
            Err(e) if e.to_string().contains("non-finite") && unchanged => 0.0,
            Err(_) if unchanged => 1.0,
            _ => 2.0,
        };
        out.push(check(
            kind,
            format!("{name}: a step after {what}"),
            "0: refused as non-finite, checkpoint unchanged (1: other error, 2: no error or changed)",
            measured,
        ));
        // The scene's own values again, for nothing else to meet the poison.
        if scene.restore(&before).is_err() {
            return failed("restore after the overflow", String::new());
        }
    } else {
        eprintln!("  note: {name} integrates nothing that can overflow; its non-finite check is skipped");
    }
    out
}
