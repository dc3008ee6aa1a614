//! Determinism across thread counts: each crate's main scene run on rayon pools of 1, 2 and 4
//! threads must end in the same state, bit for bit. The metric is the number of state values
//! whose bits differ from the 1-thread run (must be 0).

use crate::registry::{Check, ConformanceCase, Ctx, Registry, across_threads};
use anim_core::integrate::systems::LinearChain;
use anim_core::integrate::{IntegratorKind, State, study::advance};
use anim_core::solver::Solver;

pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: "anim-skin",
        name: "determinism: twisted cylinder (LBS and DQS) on 1, 2, 4 threads",
        run: Box::new(skin_cylinder),
    });
    r.conformance.push(ConformanceCase {
        crate_name: "anim-flip",
        name: "determinism: 2D dam break (APIC) on 1, 2, 4 threads",
        run: Box::new(flip_dam_break),
    });
}

fn flat(state: &State) -> Vec<f64> {
    state.x.iter().chain(&state.v).copied().collect()
}

fn skin_cylinder(ctx: &Ctx) -> Vec<Check> {
    // 96 segments around: about 11,000 vertices, several parallel chunks.
    let segments = if ctx.quick { 96 } else { 192 };
    across_threads("anim-skin", &format!("twisted cylinder, {segments} segments"), || {
        let scene = anim_skin::scenes::twisted_cylinder(Some(segments)).map_err(|e| e.to_string())?;
        let mut data = scene.data();
        let mut out = Vec::new();
        for method in [anim_skin::SkinningMethod::Lbs, anim_skin::SkinningMethod::Dqs] {
            for t in [0.5, 1.3, 2.0] {
                scene.pose(&mut data, t, method).map_err(|e| e.to_string())?;
                for m in &data.skinned {
                    out.extend(m.x.iter().chain(&m.y).chain(&m.z));
                }
            }
        }
        Ok(out)
    })
}

fn flip_dam_break(ctx: &Ctx) -> Vec<Check> {
    let (n, steps) = if ctx.quick { (48, 10) } else { (96, 40) };
    across_threads("anim-flip", &format!("dam break, {n} cells/m"), || {
        let mut params = anim_flip::FlipParams::<2>::default();
        params.transfer = anim_flip::Transfer::Apic;
        let (mut sim, mut p, _) = anim_flip::scenes::dam_break(n, 0.2, params).map_err(|e| e.to_string())?;
        for _ in 0..steps {
            sim.advance(&mut p, 0.01).map_err(|e| e.to_string())?;
        }
        Ok(p.x.iter().flatten().chain(p.v.iter().flatten()).copied().collect())
    })
}
