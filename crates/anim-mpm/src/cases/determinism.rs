//! Determinism across thread counts: the three-materials scene on 1, 2 and 4 threads, bit for bit.

use super::CRATE;
use crate::Particles;
use crate::scenes;
use anim_core::cases::{Check, Ctx, Judge};
use anim_core::solver::Solver;

pub(super) fn determinism(ctx: &Ctx) -> Vec<Check> {
    let steps = if ctx.quick { 20 } else { 100 };
    let run = |threads: usize| -> Option<Particles<2>> {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().ok()?;
        pool.install(|| {
            let mut scene = scenes::three_materials(64).ok()?;
            for _ in 0..steps {
                scene.sim.step(&mut scene.state, scene.dt).ok()?;
            }
            Some(scene.state)
        })
    };
    let one = run(1);
    let mut checks = vec![];
    for threads in [2, 4] {
        let other = run(threads);
        let differing = match (&one, &other) {
            (Some(a), Some(b)) if a.len() == b.len() => {
                a.x.iter()
                    .zip(&b.x)
                    .chain(a.v.iter().zip(&b.v))
                    .chain(a.f.iter().zip(&b.f))
                    .filter(|(p, q)| p.to_bits() != q.to_bits())
                    .count() as f64
            }
            _ => f64::NAN,
        };
        checks.push(Check {
            crate_name: CRATE,
            case: format!("three-materials 64^2, {steps} steps, 1 vs {threads} threads"),
            metric: "floats differing in x, v, F".into(),
            measured: differing,
            reference: 0.0,
            tolerance: 0.0,
            judge: Judge::AtMost,
            source: "ordered block scatter, no float atomics",
        });
    }
    checks
}
