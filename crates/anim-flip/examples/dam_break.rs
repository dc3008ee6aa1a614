//! The 2D dam break against Martin & Moyce (1952), by resolution, transfer and wall condition:
//! `cargo run --release -p anim-flip --example dam_break -- [cells,...] [transfer,...] [walls,...]`
//! (defaults `80`, `flip`, `no-slip,free-slip`; transfers `pic`, `flip` (FLIP 0.97), `apic`;
//! walls `no-slip`, `free-slip`).
//!
//! A water column `a x 2a` (`a = 0.2 m`) collapses along the floor of a 1 m tank. The surge front
//! `Z = (x_front - x0) / a` (the rightmost particle) is compared with the experiment's readings at
//! `T = t sqrt(2 g / a)` (Martin & Moyce's tables 2 and 6, as anim-mpm's dam
//! break holds them; the readings advance in steps of a quarter inch, 0.11 in `Z`). Printed per
//! run: the front at each reading, the largest and rms relative error, the same with the time
//! origin shifted by the `dT` in `[0, 0.6]` that minimises the largest error (the experiment's
//! gate takes time to open), the density-estimated volume change and the wall time.

use anim_flip::{FlipParams, Particles, Transfer, scenes};
use anim_mpm::scenes::{MARTIN_MOYCE, surge_front_errors as errors};

/// The front at `t`, linear between recorded steps (`Z(0)` before the start).
fn front_at(history: &[(f64, f64)], t: f64) -> f64 {
    let i = history.partition_point(|(ti, _)| *ti < t).clamp(1, history.len() - 1);
    let ((t0, z0), (t1, z1)) = (history[i - 1], history[i]);
    if t <= t0 { z0 } else { z0 + (z1 - z0) * (t - t0) / (t1 - t0) }
}

fn list(arg: Option<&String>, default: &str) -> Vec<String> {
    arg.map_or(default, String::as_str).split(',').map(|s| s.trim().to_owned()).collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let cells = list(args.get(1), "80").iter().map(|s| s.parse::<usize>()).collect::<Result<Vec<_>, _>>()?;
    let transfers = list(args.get(2), "flip")
        .iter()
        .map(|s| match s.as_str() {
            "pic" => Ok(Transfer::Pic),
            "flip" => Ok(Transfer::Flip(0.97)),
            "apic" => Ok(Transfer::Apic),
            _ => Err(format!("unknown transfer {s:?} (pic, flip, apic)")),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let walls = list(args.get(3), "no-slip,free-slip")
        .iter()
        .map(|s| match s.as_str() {
            "no-slip" => Ok(true),
            "free-slip" => Ok(false),
            _ => Err(format!("unknown walls {s:?} (no-slip, free-slip)")),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let a: f64 = 0.2;
    let time_scale = (2.0 * 9.81 / a).sqrt();
    let t_end = (MARTIN_MOYCE[MARTIN_MOYCE.len() - 1].0 + 0.1) / time_scale;
    println!("T     {}", MARTIN_MOYCE.map(|(t, _)| format!("{t:5.2}")).join(" "));
    println!("M&M   {}", MARTIN_MOYCE.map(|(_, z)| format!("{z:5.2}")).join(" "));
    for &n in &cells {
        for &transfer in &transfers {
            for &no_slip in &walls {
                let mut params = FlipParams::<2>::default();
                params.transfer = transfer;
                params.no_slip = no_slip;
                let (mut sim, mut p, x0) = scenes::dam_break(n, a, params)?;
                let front = |p: &Particles<2>| (p.x.iter().map(|x| x[0]).fold(f64::MIN, f64::max) - x0) / a;
                let v0 = sim.volume_estimate(&p, 4.0);
                let mut history = vec![(0.0, front(&p))];
                let start = std::time::Instant::now();
                while sim.time() < t_end - 1e-12 {
                    sim.advance(&mut p, 2e-3_f64.min(t_end - sim.time()))?;
                    history.push((sim.time() * time_scale, front(&p)));
                }
                let seconds = start.elapsed().as_secs_f64();
                let z: Vec<f64> = MARTIN_MOYCE.iter().map(|(t, _)| front_at(&history, *t)).collect();
                let (max, rms) = errors(&z);
                let (shift, shifted) = (0..=60)
                    .map(|k| {
                        let dt = f64::from(k) * 0.01;
                        let z: Vec<f64> =
                            MARTIN_MOYCE.iter().map(|(t, _)| front_at(&history, t - dt)).collect();
                        (dt, errors(&z))
                    })
                    .min_by(|a, b| a.1.0.total_cmp(&b.1.0))
                    .unwrap_or((0.0, (f64::NAN, f64::NAN)));
                let dv = (sim.volume_estimate(&p, 4.0) - v0) / v0;
                println!(
                    "\n{n} cells/m, {}, {}: {seconds:.1} s, volume change {:+.2}%",
                    transfer.name(),
                    if no_slip { "no-slip" } else { "free-slip" },
                    100.0 * dv
                );
                println!("Z     {}", z.iter().map(|v| format!("{v:5.2}")).collect::<Vec<_>>().join(" "));
                println!(
                    "error max {:.1}%, rms {:.1}%; time origin shifted by dT = {shift:.2}: max {:.1}%, rms {:.1}%",
                    100.0 * max,
                    100.0 * rms,
                    100.0 * shifted.0,
                    100.0 * shifted.1
                );
            }
        }
    }
    Ok(())
}
