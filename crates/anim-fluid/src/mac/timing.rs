//! Timing comparison kept out of the normal test run (`cargo test --release -p anim-fluid --lib
//! -- --ignored --nocapture mgpcg_against`); `cargo xtask bench --peers` runs the same.

use super::*;
use std::time::Instant;

/// Times the pressure solve alone on the 2D box with a sphere: (seconds, residual, iterations).
fn projection(n: usize, method: PressureMethod, tol: f64, cap: usize) -> (f64, f64, usize) {
    let (mut f, mut s) = MacFluid::new([n, n, 1], 2, 1.0 / n as f64, MacParams::default()).unwrap();
    f.set_solid(|p| (p[0] - 0.6).powi(2) + (p[1] - 0.45).powi(2) < 0.04).unwrap();
    f.set_velocity(&mut s, |p| {
        [(3.0 * p[1]).sin() + (5.0 * p[0] * p[2]).cos(), (2.0 * p[0]).cos() * p[1], 0.0]
    });
    let mut rhs = vec![0.0; n * n];
    f.net_outflow(&s, &mut rhs);
    rhs.iter_mut().for_each(|x| *x = -*x);
    let mut solver = PressureSolver::new(f.pressure_operator().clone(), method, tol, cap).unwrap();
    let mut x = vec![0.0; n * n];
    let t = Instant::now();
    let info = solver.solve(&rhs, &mut x);
    (t.elapsed().as_secs_f64(), info.residual, info.iterations)
}

#[test]
#[ignore = "timing, run by hand"]
fn mgpcg_against_gauss_seidel_n512() {
    let n = 512;
    let (gs_t, gs_r, gs_it) = projection(n, PressureMethod::RedBlackGaussSeidel, 0.0, 20);
    let (mg_t, mg_r, mg_it) = projection(n, PressureMethod::Mgpcg, gs_r, 1000);
    println!("rb-gs 20 sweeps: {gs_it} its, residual {gs_r:.3e}, {gs_t:.4} s");
    println!(
        "mgpcg to that residual: {mg_it} its, residual {mg_r:.3e}, {mg_t:.4} s; ratio {:.2}",
        gs_t / mg_t
    );
    for tol in [1e-2, 1e-4] {
        let (mg_t, mg_r, mg_it) = projection(n, PressureMethod::Mgpcg, tol, 1000);
        let (gs_t, gs_r, gs_it) = projection(n, PressureMethod::RedBlackGaussSeidel, tol, 4000);
        println!("mgpcg {tol:e}: {mg_it} its, residual {mg_r:.3e}, {mg_t:.4} s");
        println!(
            "rb-gs {tol:e} (cap 4000): {gs_it} its, residual {gs_r:.3e}, {gs_t:.3} s; ratio {:.1}",
            gs_t / mg_t
        );
    }
}
