//! Tests of the particle fluid against independent references: rest, incompressibility,
//! conservation laws of the transfers, determinism.

use crate::scenes;
use crate::{FlipError, FlipParams, FlipSimulation, Particles, Sampling, Transfer};
use anim_fluid::pressure::CellLabel;

/// Still water stays still: after 1 s the largest particle speed is a small fraction of the
/// gravity-wave speed `sqrt(g H)` (~1.1 m/s here), and the grid divergence stays below the
/// solver's tolerance times the pre-projection divergence.
#[test]
fn still_water_stays_still_2d() {
    for transfer in [Transfer::Apic, Transfer::Flip(0.95), Transfer::Pic] {
        let params = FlipParams::<2> { transfer, ..FlipParams::default() };
        let (mut sim, mut p) = scenes::still_water::<2>(24, params).unwrap();
        let y0: f64 = p.x.iter().map(|x| x[1]).sum::<f64>() / p.len() as f64;
        for _ in 0..50 {
            sim.advance(&mut p, 0.02).unwrap();
        }
        let vmax = p.max_speed();
        assert!(vmax < 0.02, "{transfer:?}: max speed after 1 s {vmax}");
        // Centre of mass does not sink (volume kept).
        let y1: f64 = p.x.iter().map(|x| x[1]).sum::<f64>() / p.len() as f64;
        assert!((y1 - y0).abs() < 0.1 / 24.0, "{transfer:?}: centre of mass moved {}", y1 - y0);
    }
}

#[test]
fn still_water_stays_still_3d() {
    let (mut sim, mut p) = scenes::still_water::<3>(10, FlipParams::default()).unwrap();
    for _ in 0..25 {
        sim.advance(&mut p, 0.04).unwrap();
    }
    assert!(p.max_speed() < 0.03, "max speed {}", p.max_speed());
}

/// After projection the net outflow of every fluid cell is the solver's residual: at most the
/// tolerance times the largest pre-projection outflow (plus rounding).
#[test]
fn divergence_below_solver_tolerance() {
    for tol in [1e-6, 1e-10] {
        let params = FlipParams::<2> { tolerance: tol, ..FlipParams::default() };
        let (mut sim, mut p, _) = scenes::dam_break(32, 0.25, params).unwrap();
        for _ in 0..10 {
            let info = sim.advance(&mut p, 0.01).unwrap();
            assert!(info.max_divergence_before > 1e-3, "nothing to project: {info:?}");
            assert!(
                info.max_divergence <= tol * info.max_divergence_before * 1.0001 + 1e-12,
                "tol {tol}: {info:?}"
            );
        }
    }
    let params = FlipParams::<3> { tolerance: 1e-8, ..FlipParams::default() };
    let mut sim = FlipSimulation::<3>::new([10, 10, 10], 0.1, params).unwrap();
    let mut p = Particles::new();
    scenes::fill_box(&mut p, 0.1, 2, [0.1; 3], [0.5, 0.7, 0.9], |_| [0.0; 3]);
    for _ in 0..3 {
        let info = sim.advance(&mut p, 0.02).unwrap();
        assert!(info.max_divergence <= 1e-8 * info.max_divergence_before * 1.0001 + 1e-12, "{info:?}");
        // Independent check of the labels: every cell holding a particle is fluid.
        assert!(sim.labels().iter().filter(|&&l| l == CellLabel::Fluid).count() > 0);
    }
}

/// A rigidly rotating disk: APIC carries the linear velocity field through P2G and G2P exactly,
/// so the angular momentum is kept to rounding over many round trips; PIC averages it away.
#[test]
fn rotating_disk_angular_momentum() {
    let l = |transfer| {
        let params = FlipParams::<2> { transfer, ..FlipParams::default() };
        let (mut sim, mut p) = scenes::rotating_disk(32, 0.3, 2.0, params).unwrap();
        let l0 = p.angular_momentum([0.5, 0.5])[2];
        for _ in 0..10 {
            sim.transfer_round_trip(&mut p);
        }
        (l0, p.angular_momentum([0.5, 0.5])[2])
    };
    let (l0, apic) = l(Transfer::Apic);
    assert!(l0 > 0.0);
    assert!(((apic - l0) / l0).abs() < 1e-10, "APIC: {l0} -> {apic}");
    let (l0, pic) = l(Transfer::Pic);
    assert!((l0 - pic) / l0 > 0.05, "PIC should lose angular momentum: {l0} -> {pic}");
    // FLIP keeps what the grid does not change: with no forces the change is zero.
    let (l0, flip) = l(Transfer::Flip(1.0));
    assert!(((flip - l0) / l0).abs() < 1e-10, "FLIP: {l0} -> {flip}");
}

/// The same in 3D: a disk rotating about z.
#[test]
fn rotating_disk_angular_momentum_3d() {
    let run = |transfer| {
        let params = FlipParams::<3> { transfer, gravity: [0.0; 3], ..FlipParams::default() };
        let mut sim = FlipSimulation::<3>::new([12; 3], 1.0 / 12.0, params).unwrap();
        let mut all = Particles::new();
        let w = 2.0;
        scenes::fill_box(&mut all, 1.0 / 12.0, 2, [0.25; 3], [0.75; 3], |x| {
            [-w * (x[1] - 0.5), w * (x[0] - 0.5), 0.0]
        });
        let mut p = Particles::new();
        for (x, v) in all.x.iter().zip(&all.v) {
            if (x[0] - 0.5).powi(2) + (x[1] - 0.5).powi(2) < 0.0625 {
                p.push(*x, *v);
                if transfer == Transfer::Apic {
                    *p.c.last_mut().unwrap() = [[0.0, -w, 0.0], [w, 0.0, 0.0], [0.0; 3]];
                }
            }
        }
        let l0 = p.angular_momentum([0.5; 3])[2];
        for _ in 0..5 {
            sim.transfer_round_trip(&mut p);
        }
        (l0, p.angular_momentum([0.5; 3])[2])
    };
    let (l0, apic) = run(Transfer::Apic);
    assert!(((apic - l0) / l0).abs() < 1e-10, "APIC: {l0} -> {apic}");
    let (l0, pic) = run(Transfer::Pic);
    assert!((l0 - pic) / l0 > 0.05, "PIC: {l0} -> {pic}");
}

fn dam_break_bits(threads: usize) -> Vec<u64> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let params = FlipParams::<2> { transfer: Transfer::Flip(0.97), ..FlipParams::default() };
        let (mut sim, mut p, _) = scenes::dam_break(24, 0.3, params).unwrap();
        for _ in 0..5 {
            sim.advance(&mut p, 0.02).unwrap();
        }
        p.x.iter().chain(&p.v).flatten().map(|x| x.to_bits()).collect()
    })
}

#[test]
fn bitwise_identical_on_1_and_2_threads() {
    assert_eq!(dam_break_bits(1), dam_break_bits(2));
    let run3 = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut sim = FlipSimulation::<3>::new([8; 3], 0.125, FlipParams::default()).unwrap();
            let mut p = Particles::new();
            scenes::fill_box(&mut p, 0.125, 2, [0.125; 3], [0.5, 0.75, 0.5], |_| [0.0; 3]);
            for _ in 0..3 {
                sim.advance(&mut p, 0.02).unwrap();
            }
            p.x.iter().chain(&p.v).flatten().map(|x| x.to_bits()).collect::<Vec<_>>()
        })
    };
    assert_eq!(run3(1), run3(2));
}

/// Resuming from a checkpoint (particles + memory) gives the same trajectory.
#[test]
fn checkpoint_resume_is_exact() {
    let params = FlipParams::<2>::default();
    let (mut sim, mut p, _) = scenes::dam_break(20, 0.3, params).unwrap();
    for _ in 0..3 {
        sim.advance(&mut p, 0.02).unwrap();
    }
    let saved = serde_json::to_string(&p).unwrap();
    let memory = sim.memory();
    for _ in 0..3 {
        sim.advance(&mut p, 0.02).unwrap();
    }
    let (mut sim2, _, _) = scenes::dam_break(20, 0.3, params).unwrap();
    sim2.restore_memory(&memory).unwrap();
    let mut p2: Particles<2> = serde_json::from_str(&saved).unwrap();
    for _ in 0..3 {
        sim2.advance(&mut p2, 0.02).unwrap();
    }
    assert_eq!(p, p2);
    assert_eq!(sim.time(), sim2.time());
}

#[test]
fn cfl_substeps_scale_with_dt() {
    let params = FlipParams::<2>::default();
    let (mut sim, mut p, _) = scenes::dam_break(32, 0.3, params).unwrap();
    let info = sim.advance(&mut p, 0.2).unwrap();
    // With speeds up to sqrt(2 g 0.6) ~ 3.4 m/s the CFL-1 substep is at most h / sqrt(g h).
    let bound = (0.2 / (1.0 / 32.0 / (9.81f64 / 32.0).sqrt())).floor() as usize;
    assert!(info.substeps >= bound, "{info:?}, bound {bound}");
    // The particles never leave the fluid box.
    let (lo, hi) = sim.fluid_box();
    assert!(p.x.iter().all(|x| (0..2).all(|a| x[a] >= lo[a] && x[a] <= hi[a])));
}

#[test]
fn rejects_bad_input() {
    let bad = |r: Result<FlipSimulation<2>, FlipError>, name: &str| match r {
        Err(FlipError::BadParameter { name: n, .. }) => assert_eq!(n, name),
        other => panic!("expected a bad {name}, got {other:?}"),
    };
    bad(FlipSimulation::new([16, 16], 0.0, FlipParams::default()), "h");
    bad(FlipSimulation::new([3, 16], 0.1, FlipParams::default()), "cells[0]");
    bad(FlipSimulation::new([16, 16], 0.1, FlipParams { cfl: -1.0, ..FlipParams::default() }), "cfl");
    bad(
        FlipSimulation::new(
            [16, 16],
            0.1,
            FlipParams { transfer: Transfer::Flip(1.5), ..FlipParams::default() },
        ),
        "transfer (FLIP blend)",
    );
    bad(
        FlipSimulation::new([16, 16], 0.1, FlipParams { gravity: [0.0, f64::NAN], ..FlipParams::default() }),
        "gravity",
    );
    let (mut sim, mut p) = scenes::still_water::<2>(16, FlipParams::default()).unwrap();
    assert!(matches!(sim.advance(&mut p, -1.0), Err(FlipError::BadParameter { name: "dt", .. })));
    p.v[7][1] = f64::NAN;
    let before = p.clone();
    match sim.advance(&mut p, 0.01) {
        Err(FlipError::BadParticle { index: 7, field: "v", .. }) => {}
        other => panic!("{other:?}"),
    }
    assert_eq!(format!("{:?}", p), format!("{:?}", before));
    p.v[7][1] = 0.0;
    p.c.pop();
    assert!(matches!(sim.advance(&mut p, 0.01), Err(FlipError::BadParticle { field: "c", .. })));
}

/// Velocities whose grid average overflows reach the particles as NaN: the error names the
/// particle and the value it had, and the particles are restored.
#[test]
fn non_finite_is_detected_and_state_kept() {
    let params = FlipParams::<2> {
        pressure: anim_fluid::pressure::PressureMethod::Jacobi,
        tolerance: 0.0,
        max_iterations: 5,
        ..FlipParams::default()
    };
    let (mut sim, mut p) = scenes::still_water::<2>(16, params).unwrap();
    for v in &mut p.v {
        *v = [1e308, 0.0];
    }
    let before = p.clone();
    let err = sim.advance(&mut p, 0.01).unwrap_err();
    match &err {
        FlipError::NonFinite { step: 0, particle, field, last_finite: Some(v), .. } => {
            let old = match *field {
                "x" => before.x[*particle].to_vec(),
                "v" => before.v[*particle].to_vec(),
                _ => before.c[*particle].iter().flatten().copied().collect(),
            };
            assert!(old.contains(v), "{err}");
        }
        other => panic!("{other}"),
    }
    assert!(err.to_string().contains("anim-flip"));
    assert_eq!(p, before);
}

/// A slab driven into an obstacle: no particle ends in a solid cell. Advected with the kernel's
/// sampling, particles next to the obstacle see part of the velocity behind its faces and enter
/// it, and are pushed out (counted); with linear sampling they see the faces' zero normal
/// velocity and none gets in.
#[test]
fn particles_entering_an_obstacle_are_pushed_out() {
    for (sampling, pushes) in [(Sampling::Kernel, true), (Sampling::Linear, false)] {
        let params =
            FlipParams::<2> { gravity: [0.0; 2], advection_sampling: sampling, ..FlipParams::default() };
        let mut sim = FlipSimulation::<2>::new([16, 16], 1.0 / 16.0, params).unwrap();
        sim.set_solid(|x| (x[0] - 0.6).abs() < 0.1 && (x[1] - 0.5).abs() < 0.1);
        let mut p = Particles::new();
        scenes::fill_box(&mut p, 1.0 / 16.0, 2, [0.2, 0.4], [0.35, 0.6], |_| [3.0, 0.0]);
        let mut pushed = 0;
        for _ in 0..10 {
            pushed += sim.advance(&mut p, 0.02).unwrap().pushed_out;
        }
        assert_eq!(pushed > 0, pushes, "{sampling:?}: {pushed} push-outs");
        let h = 1.0 / 16.0;
        for x in &p.x {
            let c = (x[0] / h) as usize + 16 * (x[1] / h) as usize;
            assert!(!sim.solid()[c], "{sampling:?}: particle in a solid cell at {x:?}");
        }
    }
}

/// The volume correction keeps the density-based volume of a collapsing column; without it the
/// particles compressed at impact stay compressed.
#[test]
fn volume_correction_keeps_volume() {
    let run = |beta: f64| {
        let params = FlipParams::<2> { volume_correction: beta, ..FlipParams::default() };
        let h = 1.0 / 24.0;
        let mut sim = FlipSimulation::<2>::new([24, 24], h, params).unwrap();
        let (lo, _) = sim.fluid_box();
        let mut p = Particles::new();
        scenes::fill_box(&mut p, h, 2, lo, [lo[0] + 0.25, lo[1] + 0.5], |_| [0.0; 2]);
        let v0 = sim.volume_estimate(&p, 4.0);
        assert!((v0 - 0.125).abs() < 1e-9, "seeded volume {v0}");
        for _ in 0..40 {
            sim.advance(&mut p, 0.05).unwrap();
        }
        sim.volume_estimate(&p, 4.0) / v0
    };
    let kept = run(0.5);
    let lost = run(0.0);
    assert!((kept - 1.0).abs() < 0.03, "with correction: {kept}");
    assert!(lost < 0.9, "without correction: {lost}");
}

/// Timing is off by default and then reads no clock (every part zero); on, the four parts are
/// measured, add up to at most the wall time of the calls measured outside, and the trajectory
/// is bitwise the one without timing.
#[test]
fn step_times_measure_the_parts_without_changing_the_run() {
    let params = FlipParams::<2>::default();
    let (mut plain, mut p1, _) = scenes::dam_break(32, 0.3, params).unwrap();
    let (mut timed, mut p2, _) = scenes::dam_break(32, 0.3, params).unwrap();
    assert!(!timed.timing());
    timed.set_timing(true);
    let mut outside = 0.0;
    let mut parts = crate::StepTimes::default();
    // Inside a pool, `advance` runs on the calling worker: the time measured outside is the
    // step's, without the wait for a worker of the global pool that a loaded machine stretches.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    pool.install(|| {
        for _ in 0..5 {
            let info = plain.advance(&mut p1, 0.02).unwrap();
            assert_eq!(info.times, crate::StepTimes::default());
            let start = std::time::Instant::now();
            let info = timed.advance(&mut p2, 0.02).unwrap();
            outside += start.elapsed().as_secs_f64();
            let t = info.times;
            parts.transfer += t.transfer;
            parts.projection += t.projection;
            parts.advection += t.advection;
            parts.other += t.other;
        }
    });
    assert_eq!(p1, p2);
    assert!(parts.transfer > 0.0 && parts.projection > 0.0 && parts.advection > 0.0 && parts.other > 0.0);
    assert!(parts.total() <= outside, "{parts:?} against {outside} s measured outside");
    assert!(parts.total() > 0.5 * outside, "{parts:?} against {outside} s measured outside");
}

/// Fills every face of `grid` with `f(position, axis)`.
fn fill_faces<const D: usize>(grid: &mut crate::mac::MacGrid<D>, f: impl Fn([f64; D], usize) -> f64) {
    let h = grid.h;
    for a in 0..D {
        let fd = grid.face_dims(a);
        for (k, u) in grid.u[a].iter_mut().enumerate() {
            let idx = crate::mac::unflatten(fd, k);
            let x: [f64; D] = std::array::from_fn(|b| (idx[b] as f64 + if b == a { 0.0 } else { 0.5 }) * h);
            *u = f(x, a);
        }
    }
}

/// Multilinear sampling reproduces an affine field `u_a(x) = b_a + sum_c A_ac x_c` anywhere in
/// the grid (2D and 3D), so it is exact at the faces.
#[test]
fn linear_sampling_is_exact_for_affine_fields() {
    fn check<const D: usize>() {
        let n = [7, 6, 5];
        let mut grid = crate::mac::MacGrid::<D>::new(std::array::from_fn(|a| n[a]), 0.1);
        let field = |x: [f64; D], a: usize| {
            0.3 * a as f64 - 1.0 + (0..D).map(|c| (1.0 + a as f64 - 0.7 * c as f64) * x[c]).sum::<f64>()
        };
        fill_faces(&mut grid, field);
        for k in 0..50 {
            // Points inside the box, spread by a fixed sequence.
            let x: [f64; D] = std::array::from_fn(|b| {
                0.1 * (n[b] as f64 - 1.0) * ((k * (b + 3) * 37 % 101) as f64 / 100.0) + 0.05
            });
            let u = crate::transfer::sample_linear(&grid, &x);
            for a in 0..D {
                let want = field(x, a);
                assert!(
                    (u[a] - want).abs() < 1e-12,
                    "D = {D}, point {x:?}, axis {a}: {} against {want}",
                    u[a]
                );
            }
        }
    }
    check::<2>();
    check::<3>();
}

/// With the faces behind the walls mirrored with opposite sign, a B-spline sample at a wall
/// has zero normal velocity whatever the interior field (both kernels). Without the mirror the
/// quadratic kernel gives about an eighth of the interior normal velocity there, and the test
/// fails.
#[test]
fn mirrored_walls_give_zero_normal_velocity_at_the_wall() {
    for kernel in [anim_core::bspline::Kernel::Quadratic, anim_core::bspline::Kernel::Cubic] {
        let border = if kernel == anim_core::bspline::Kernel::Cubic { 2 } else { 1 };
        let n = 12;
        let h = 1.0 / n as f64;
        let mut grid = crate::mac::MacGrid::<2>::new([n, n], h);
        let (lo, hi) = (border as f64 * h, (n - border) as f64 * h);
        // A flow into the left and bottom walls that varies along them; the wall faces hold the
        // walls' zero, as the projection leaves them.
        let on_wall = |s: f64| (s - lo).abs() < 1e-9 || (s - hi).abs() < 1e-9;
        fill_faces(&mut grid, |x, a| {
            if on_wall(x[a]) {
                0.0
            } else if a == 0 {
                -1.0 - x[1]
            } else {
                -2.0 + x[0]
            }
        });
        let sample = |grid: &crate::mac::MacGrid<2>, x: [f64; 2]| crate::transfer::sample(grid, kernel, &x);
        let unmirrored = sample(&grid, [lo, 0.5])[0];
        grid.reflect_walls(border);
        for t in [0.3, 0.45, 0.61] {
            for (x, a) in [([lo, t], 0), ([hi, t], 0), ([t, lo], 1), ([t, hi], 1)] {
                let u = sample(&grid, x)[a];
                assert!(u.abs() < 1e-12, "{kernel:?}: normal velocity {u} at the wall point {x:?}");
            }
        }
        assert!(unmirrored.abs() > 0.05, "{kernel:?}: the field without the mirror gives {unmirrored}");
    }
}
