//! Soak cases (`cargo xtask stability --long`): one hard case per crate that steps in time, run
//! for `10^5` steps or ten minutes, with its bound checked on a fixed stride. anim-material has no
//! time stepping of its own (its models run inside the FEM and MPM soaks); anim-io has none.

use crate::registry::fmt_num;
use crate::registry::{Budget, Soak, SoakCase, drive, finish, rejected};

/// Registers the soak cases, in crate order.
pub fn register(r: &mut crate::registry::Registry) {
    r.soak.extend([
        SoakCase {
            crate_name: "anim-fluid",
            name: "vortex in a box at CFL 10, semi-Lagrangian, 64x64 MAC",
            bound: "kinetic energy never above its initial value; density within [0, 1]",
            run: fluid_cfl10,
        },
        SoakCase {
            crate_name: "anim-skin",
            name: "twisted cylinder, DQS, clip looped 500 times",
            bound: "every pose identical to its first cycle, bit for bit; volume within 2% of rest",
            run: skin_loop,
        },
    ]);
}

/// Energy-stride shared by the cases.
const STRIDE: u64 = 10;

/// Whether `e` is above `e0` beyond rounding.
fn exceeds(e: f64, e0: f64) -> bool {
    !(e <= e0 + 1e-9 * e0.abs().max(1e-12))
}

/// The error text of a bound broken at step `k`.
fn above(k: u64, e: f64, e0: f64) -> String {
    format!("step {k}: energy {e} J above its initial value {e0} J")
}

fn fluid_cfl10(budget: Budget) -> Soak {
    use anim_fluid::advection::Advection;
    use anim_fluid::mac::{MacFluid, MacParams, MacState};
    use std::f64::consts::PI;
    let (n, speed) = (64, 1.0);
    let params = MacParams { advection: Advection::Linear, ..MacParams::default() };
    let (mut f, mut s) = match MacFluid::new([n, n, 1], 2, 1.0 / n as f64, params) {
        Ok(x) => x,
        Err(e) => return rejected(budget, e),
    };
    f.set_velocity(&mut s, |p| [speed * (PI * p[1]).sin(), -speed * (PI * p[0]).sin(), 0.0]);
    for c in 0..s.density.len() {
        let (i, j) = (c % n, c / n);
        s.density[c] = if (i / 8 + j / 8) % 2 == 0 { 1.0 } else { 0.0 };
    }
    let kinetic = |s: &MacState| 0.5 * s.vel.iter().flatten().map(|u| u * u).sum::<f64>() / (n * n) as f64;
    let dt = 10.0 / n as f64 / speed;
    let e0 = kinetic(&s);
    let mut last = e0;
    let clock = match drive(budget, dt, |k| {
        f.advance(&mut s, dt).map_err(|e| e.to_string())?;
        if k.is_multiple_of(STRIDE) {
            last = kinetic(&s);
            let (lo, hi) = s.density.iter().fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
            if exceeds(last, e0) || lo < -1e-12 || hi > 1.0 + 1e-12 {
                return Err(format!(
                    "step {k}: kinetic energy {last} (initial {e0}), density in [{lo}, {hi}]"
                ));
            }
        }
        Ok(())
    }) {
        Ok(c) => c,
        Err(s) => return s,
    };
    let d = format!(
        "kinetic energy per unit area {} -> {}, checked every {STRIDE} steps",
        fmt_num(e0),
        fmt_num(last)
    );
    finish(&clock, dt, true, d)
}

fn skin_loop(budget: Budget) -> Soak {
    use anim_skin::SkinningMethod;
    use anim_skin::scenes::{twisted_cylinder, volume};
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
            worst = worst.max((volume(&scene.character, &data) / rest - 1.0).abs());
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
