//! Reference runs kept out of the normal test run (`cargo test --release -p anim-fluid --lib --
//! --ignored --nocapture reference_`); the xtask conformance cases judge the same quantities.

use super::*;
use std::time::Instant;

fn ghia(file: &str) -> Vec<(f64, f64)> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata").join(file);
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .filter_map(|l| {
            let (a, b) = l.split_once(',')?;
            Some((a.parse().ok()?, b.parse().ok()?))
        })
        .filter(|&(c, _)| c > 0.0 && c < 1.0)
        .collect()
}

#[test]
#[ignore = "long, run by hand"]
fn reference_cavity_against_ghia() {
    let (tu, tv) = (ghia("ghia_re100_u.csv"), ghia("ghia_re100_v.csv"));
    let runs = std::env::var("CAVITY_RUNS").unwrap_or_else(|_| "32:all,64:all,128:maccormack".into());
    for run in runs.split(',') {
        let (n, which) = run.split_once(':').unwrap();
        let n: usize = n.parse().unwrap();
        for scheme in Advection::ALL {
            if which != "all" && which != scheme.name() {
                continue;
            }
            let t0 = Instant::now();
            let mut scene = lid_driven_cavity(n, 100.0, scheme).unwrap();
            let dt = scene.dt;
            let FluidSim::Mac(f, s) = &mut scene.sim else { unreachable!() };
            let mut prev = s.vel[0].clone();
            let every = (0.5 / dt).round() as usize;
            let (mut t, mut k) = (0.0, 0);
            while t < 30.0 {
                f.advance(s, dt).unwrap();
                t += dt;
                k += 1;
                if k % every == 0 {
                    let ch = s.vel[0].iter().zip(&prev).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
                        / (every as f64 * dt);
                    prev.copy_from_slice(&s.vel[0]);
                    if ch < 1e-4 {
                        break;
                    }
                }
            }
            let eu = tu
                .iter()
                .map(|&(y, u)| (f.velocity_at_point(s, [0.5, y, 0.0])[0] - u).abs())
                .fold(0.0, f64::max);
            let ev = tv
                .iter()
                .map(|&(x, v)| (f.velocity_at_point(s, [x, 0.5, 0.0])[1] - v).abs())
                .fold(0.0, f64::max);
            println!(
                "cavity N = {n} {}: max err u {eu:.4}, v {ev:.4}; steady at t = {t:.1}; {:.1} s",
                scheme.name(),
                t0.elapsed().as_secs_f64()
            );
        }
    }
}

#[test]
#[ignore = "long, run by hand"]
fn reference_taylor_green_n128() {
    for scheme in Advection::ALL {
        let t0 = Instant::now();
        let (a, exact) = super::tests::taylor_green(128, scheme, 0.01, 1.0);
        println!(
            "taylor-green N = 128 {}: A = {a:.5}, exact {exact:.5}, rel err {:.4}; {:.1} s",
            scheme.name(),
            (a / exact - 1.0).abs(),
            t0.elapsed().as_secs_f64()
        );
    }
}
