//! Cost of the particle-grid transfers and the split of a substep, on the 3D dam break of
//! `anim_flip::scenes::benchmark_dam_break_3d` (8 particles per cell, APIC, quadratic kernel,
//! MGPCG):
//!
//! ```text
//! cargo run --release -p anim-flip --example transfer_cost -- transfers [n] [rounds]
//! cargo run --release -p anim-flip --example transfer_cost -- step [n] [frames]
//! ```
//!
//! `transfers` (default `n = 64`, 131 072 particles, 7 rounds): the time per particle and
//! substep of P2G + G2P (`StepTimes::transfer`) beside that of a whole step of anim-mpm's 3D
//! fluid (`anim_mpm::scenes::benchmark_3d` at 80^3, 128 000 particles, APIC, quadratic: P2G,
//! grid update and G2P, so an upper bound on its transfers), timed alternately in one process;
//! printed per round and as the median and range of the ratio ours / anim-mpm.
//!
//! `step` (default `n = 128`, 1 048 576 particles, 3 frames): after 0.1 s of warm-up, frames of
//! 0.01 s timed with the substep split (transfers, pressure projection, advection, other); the
//! median frame is printed per substep.
//!
//! Both run on rayon's global pool (`RAYON_NUM_THREADS` sets its size).

use anim_flip::{FlipParams, FlipSimulation, Particles, scenes};
use anim_mpm::{Kernel, MpmSimulation, Transfer};
use std::time::Instant;

type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// Simulated warm-up before timing, s (the block has started to fall).
const WARMUP: f64 = 0.1;
/// One timed frame, s.
const FRAME: f64 = 0.01;

fn dam_break(n: usize) -> Res<(FlipSimulation<3>, Particles<3>)> {
    let (mut sim, mut p) = scenes::benchmark_dam_break_3d(n, FlipParams::default())?;
    let mut t = 0.0;
    while t < WARMUP - 1e-12 {
        sim.advance(&mut p, FRAME)?;
        t += FRAME;
    }
    sim.set_timing(true);
    Ok((sim, p))
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn transfers(n: usize, rounds: usize) -> Res<()> {
    let (mut sim, mut p) = dam_break(n)?;
    let scene = anim_mpm::scenes::benchmark_3d(80)?;
    let mut params = scene.sim.params().clone();
    params.transfer = Transfer::Apic;
    params.kernel = Kernel::Quadratic;
    let mut mpm = MpmSimulation::<3>::new(params, scene.sim.materials().to_vec())?;
    let mut state = scene.state.clone();
    for _ in 0..20 {
        mpm.advance(&mut state, scene.dt)?;
    }
    println!(
        "threads {}: anim-flip {} particles on {n}^3, anim-mpm {} particles on 80^3",
        rayon::current_num_threads(),
        p.len(),
        state.len()
    );
    println!("round  flip P2G+G2P us/particle/substep  mpm step us/particle  ratio");
    let mut ratios = vec![];
    let (mut ours_all, mut theirs_all) = (vec![], vec![]);
    for round in 0..rounds {
        let info = sim.advance(&mut p, FRAME)?;
        let ours = info.times.transfer / (info.substeps * p.len()) as f64 * 1e6;
        let steps = 10;
        let t0 = Instant::now();
        for _ in 0..steps {
            mpm.advance(&mut state, scene.dt)?;
        }
        let theirs = t0.elapsed().as_secs_f64() / (steps * state.len()) as f64 * 1e6;
        println!("{round:5}  {ours:34.3}  {theirs:20.3}  {:5.2}", ours / theirs);
        ratios.push(ours / theirs);
        ours_all.push(ours);
        theirs_all.push(theirs);
    }
    let (lo, hi) = ratios.iter().fold((f64::MAX, 0.0f64), |(l, h), r| (l.min(*r), h.max(*r)));
    println!(
        "median: flip {:.3} us, mpm {:.3} us, ratio {:.2} (range {lo:.2}-{hi:.2})",
        median(&mut ours_all),
        median(&mut theirs_all),
        median(&mut ratios)
    );
    Ok(())
}

fn step(n: usize, frames: usize) -> Res<()> {
    let (mut sim, mut p) = dam_break(n)?;
    let mut rows = vec![];
    for _ in 0..frames {
        let t0 = Instant::now();
        let info = sim.advance(&mut p, FRAME)?;
        let wall = t0.elapsed().as_secs_f64();
        rows.push((wall / info.substeps as f64, info));
    }
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (per, info) = rows[rows.len() / 2];
    let s = info.substeps as f64;
    let t = info.times;
    let total = t.total();
    let pct = |x: f64| 100.0 * x / total;
    println!(
        "threads {}: {} particles on {n}^3, median of {frames} frames of {FRAME} s: {} substeps, {per:.3} s per substep",
        rayon::current_num_threads(),
        p.len(),
        info.substeps
    );
    println!(
        "per substep: transfers {:.3} s ({:.0}%), pressure {:.3} s ({:.0}%, {} iterations), advection {:.3} s ({:.0}%), other {:.3} s ({:.0}%)",
        t.transfer / s,
        pct(t.transfer),
        t.projection / s,
        pct(t.projection),
        info.pressure_iterations,
        t.advection / s,
        pct(t.advection),
        t.other / s,
        pct(t.other)
    );
    println!("transfers per particle and substep: {:.3} us", t.transfer / s / p.len() as f64 * 1e6);
    Ok(())
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().collect();
    let num = |i: usize, default: usize| -> Res<usize> {
        Ok(args.get(i).map(|s| s.parse::<usize>()).transpose()?.unwrap_or(default))
    };
    match args.get(1).map(String::as_str) {
        Some("transfers") | None => transfers(num(2, 64)?, num(3, 7)?),
        Some("step") => step(num(2, 128)?, num(3, 3)?),
        Some(other) => {
            Err(format!("unknown mode `{other}`: `transfers [n] [rounds]` or `step [n] [frames]`").into())
        }
    }
}
