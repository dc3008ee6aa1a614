//! The twisted cylinder on 1, 2 and 4 threads (bit for bit), and its clip looped as a soak run
//! (`cargo xtask stability --long`): every cycle identical to the first.

use crate::SkinningMethod;
use crate::scenes::{twisted_cylinder, volume};
use anim_core::cases::{Budget, Check, Ctx, Soak, across_threads, drive, finish, fmt_num, nan_max, rejected};

pub(super) fn skin_cylinder(ctx: &Ctx) -> Vec<Check> {
    // 96 segments around: about 11,000 vertices, several parallel chunks.
    let segments = if ctx.quick { 96 } else { 192 };
    across_threads(super::CRATE, &format!("twisted cylinder, {segments} segments"), || {
        let scene = twisted_cylinder(Some(segments)).map_err(|e| e.to_string())?;
        let mut data = scene.data();
        let mut out = Vec::new();
        for method in [SkinningMethod::Lbs, SkinningMethod::Dqs] {
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

pub(super) fn skin_loop(budget: Budget) -> Soak {
    let scene = match twisted_cylinder(None) {
        Ok(s) => s,
        Err(e) => return rejected(budget, e),
    };
    // 200 frames per loop of the 2 s clip; the first loop is kept and every later frame compared.
    let frames = 200u64;
    let dt = scene.duration / frames as f64;
    let mut data = scene.data();
    let rest = scene.rest_volume();
    let mut first: Vec<Vec<f64>> = Vec::with_capacity(frames as usize);
    let mut worst = 0.0f64;
    let clock = match drive(budget, dt, |k| {
        let frame = (k - 1) % frames;
        let t = frame as f64 * dt;
        scene.pose(&mut data, t, SkinningMethod::Dqs).map_err(|e| e.to_string())?;
        let flat: Vec<f64> =
            data.skinned.iter().flat_map(|m| m.x.iter().chain(&m.y).chain(&m.z).copied()).collect();
        if flat.iter().any(|v| !v.is_finite()) {
            return Err(format!("frame {frame}: non-finite vertex"));
        }
        if k <= frames {
            worst = nan_max(worst, (volume(&scene.character, &data) / rest - 1.0).abs());
            first.push(flat);
        } else if first[frame as usize].iter().zip(&flat).any(|(a, b)| a.to_bits() != b.to_bits()) {
            return Err(format!("step {k}: the pose at t = {t} s differs from its first cycle"));
        }
        Ok(())
    }) {
        Ok(c) => c,
        Err(s) => return s,
    };
    let d = format!(
        "{} loops of {frames} frames; largest volume change {} of rest",
        clock.steps / frames,
        fmt_num(worst)
    );
    finish(&clock, dt, worst < 0.02, d)
}
