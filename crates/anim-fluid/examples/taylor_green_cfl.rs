//! Taylor-Green decay error against the CFL number, the resolution, the advection scheme and the
//! splitting:
//! `cargo run --release -p anim-fluid --example taylor_green_cfl -- [N,...] [CFL,...] [scheme,...] [nu] [splitting,...]`
//! (defaults `64,128,256`, `0.25,0.5,1,2,4`, every scheme, `nu = 0.01`, both splittings:
//! `advect-project,reflection`).
//!
//! The vortex `u = sin(pi x) cos(pi y)`, `v = -cos(pi x) sin(pi y)` in the unit box with
//! free-slip walls is a steady solution of the Euler equations (its advection term is a
//! gradient) that viscosity damps as `exp(-2 nu pi^2 t)`. The amplitude is the projection of
//! the computed `u` on the mode after `t = 1`, with `dt = CFL h` (the peak speed is 1). One
//! JSON object per run: the relative amplitude error, and the numerical viscosity that error
//! corresponds to, `nu_num = -ln(A / A_exact) / (2 pi^2 t)`.

use anim_fluid::advection::{Advection, Splitting};
use std::f64::consts::PI;

fn list<T: std::str::FromStr>(arg: Option<&String>, default: &str) -> Result<Vec<T>, String> {
    arg.map_or(default, String::as_str)
        .split(',')
        .map(|s| s.trim().parse::<T>().map_err(|_| format!("cannot parse {s:?}")))
        .collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let sizes: Vec<usize> = list(args.get(1), "64,128,256")?;
    let cfls: Vec<f64> = list(args.get(2), "0.25,0.5,1,2,4")?;
    let names: Vec<String> = list(args.get(3), "sl-linear,sl-monotone-cubic,bfecc,maccormack")?;
    let nu: f64 = args.get(4).map_or(Ok(0.01), |s| s.parse())?;
    let splits: Vec<String> = list(args.get(5), "advect-project,reflection")?;
    let splittings: Vec<Splitting> = splits
        .iter()
        .map(|n| {
            Splitting::ALL
                .into_iter()
                .find(|s| s.name() == n)
                .ok_or_else(|| format!("unknown splitting {n:?}"))
        })
        .collect::<Result<_, _>>()?;
    let schemes: Vec<Advection> = names
        .iter()
        .map(|n| {
            Advection::ALL.into_iter().find(|s| s.name() == n).ok_or_else(|| format!("unknown scheme {n:?}"))
        })
        .collect::<Result<_, _>>()?;
    let t_end = 1.0;
    for &n in &sizes {
        for &cfl in &cfls {
            for (&advection, &splitting) in
                schemes.iter().flat_map(|a| splittings.iter().map(move |s| (a, s)))
            {
                let start = std::time::Instant::now();
                let r = anim_fluid::scenes::taylor_green_decay(n, advection, splitting, nu, t_end, cfl)?;
                let secs = start.elapsed().as_secs_f64();
                let (a, exact, steps) = (r.amplitude, r.exact, r.steps);
                let nu_num = -(a / exact).ln() / (2.0 * PI * PI * t_end);
                println!(
                    "{{\"n\":{n},\"cfl\":{cfl},\"scheme\":\"{}\",\"splitting\":\"{}\",\"steps\":{steps},\"amplitude\":{a:.6},\"exact\":{exact:.6},\"rel_err\":{:.5},\"nu_num\":{nu_num:.3e},\"seconds\":{secs:.1}}}",
                    advection.name(),
                    splitting.name(),
                    (a / exact - 1.0).abs()
                );
            }
        }
    }
    Ok(())
}
