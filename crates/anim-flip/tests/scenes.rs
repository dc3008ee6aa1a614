//! The scenes of `anim_flip::scenes` against independent references: the linear sloshing
//! frequency of a rectangular tank, the tank-frame body force against the tank's motion, and
//! the seeded geometry of the dam breaks and the drop.

use anim_flip::scenes;
use anim_flip::{FlipError, FlipParams, FlipSimulation, Particles, TankMotion};
use std::f64::consts::PI;

/// Times where `ys` crosses its mean, by linear interpolation between samples.
fn mean_crossings(ts: &[f64], ys: &[f64]) -> Vec<f64> {
    let mean = ys.iter().sum::<f64>() / ys.len() as f64;
    let mut out = Vec::new();
    for i in 1..ys.len() {
        let (a, b) = (ys[i - 1] - mean, ys[i] - mean);
        if (a > 0.0) != (b > 0.0) {
            out.push(ts[i - 1] + (ts[i] - ts[i - 1]) * a / (a - b));
        }
    }
    out
}

/// The period from successive crossings (two per period).
fn period_of(crossings: &[f64]) -> f64 {
    assert!(crossings.len() >= 3, "too few crossings: {crossings:?}");
    2.0 * (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64
}

/// The first sloshing mode of water `d = 0.25 m` deep in a tank `L = 31/32 m` long (64 cells per
/// metre) has the linear period `T = 2 pi / omega`, `omega^2 = g k tanh(k d)`, `k = pi / L`
/// (1.361 s here; the deep-water `omega^2 = g k` would give 1.11 s). The water starts at rest
/// with its surface tilted by the first mode, `eta = eta_0 cos(k x)`, `eta_0 = 0.15 d` (each
/// lattice column stretched to its height), and the period is measured over three periods from the
/// mean crossings of (a) the surface height at the left wall minus that at the right wall (the
/// highest particle within a cell of each wall) and (b) the horizontal centre of mass of the
/// water, which moves with the odd modes only.
///
/// Measured: (a) +3.2%, (b) +3.3% over three periods (over the first 2.25 periods the same
/// run gives +5.2% and +4.5%: the crossings of a short window scatter by about a point). The
/// error comes from the free surface as the projection sees it, at cell granularity (pressure
/// zero at the centre of the first air cell): it is +3.0% to +3.9% at 48 cells with APIC or FLIP
/// 0.97, CFL 1 or 0.25, grid or particle advection, and does not shrink from 48 to 64 cells. The
/// tolerance, 6%, leaves 2.7 points of margin and still refuses the deep-water period (-18%). A
/// tilt of 2% of the depth is below the cell size (0.3 cells at 32 per metre): the labels do not
/// see it and the measured surface sank back without oscillating, so the tilt is 15%, where the
/// weakly nonlinear correction of a standing wave's frequency (Tadjbakhsh & Keller 1960) is a
/// few tenths of a percent.
#[test]
fn sloshing_period_matches_linear_theory() {
    let (n, depth) = (64, 0.25);
    let (mut sim, _) = scenes::sloshing_tank::<2>(n, depth, 0.0, 0.0, FlipParams::default()).unwrap();
    let (lo, hi) = sim.fluid_box();
    let length = hi[0] - lo[0];
    let h = 1.0 / n as f64;
    let k = PI / length;
    let eta0 = 0.15 * depth;
    let mut p = Particles::new();
    let spacing = h / 2.0;
    let rows = (depth / spacing).round() as usize;
    let cols = (length / spacing).round() as usize;
    for i in 0..cols {
        let x = lo[0] + (i as f64 + 0.5) * spacing;
        let height = depth + eta0 * (k * (x - lo[0])).cos();
        for j in 0..rows {
            p.push([x, lo[1] + (j as f64 + 0.5) * height / rows as f64], [0.0; 2]);
        }
    }
    let period = 2.0 * PI / (9.81 * k * (k * depth).tanh()).sqrt();
    let top = |p: &Particles<2>, a: f64, b: f64| {
        p.x.iter().filter(|x| x[0] >= a && x[0] < b).map(|x| x[1]).fold(f64::MIN, f64::max)
    };
    let wall = |p: &Particles<2>| top(p, lo[0], lo[0] + h) - top(p, hi[0] - h, hi[0]);
    let com = |p: &Particles<2>| p.x.iter().map(|x| x[0]).sum::<f64>() / p.len() as f64;
    let samples = 40;
    let dt = period / samples as f64;
    let (mut ts, mut walls, mut coms) = (vec![0.0], vec![wall(&p)], vec![com(&p)]);
    for s in 0..3 * samples {
        sim.advance(&mut p, dt).unwrap();
        ts.push((s + 1) as f64 * dt);
        walls.push(wall(&p));
        coms.push(com(&p));
    }
    assert!((walls[0] - 2.0 * eta0).abs() < 0.1 * eta0, "seeded tilt {}", walls[0]);
    let by_wall = period_of(&mean_crossings(&ts, &walls));
    let by_com = period_of(&mean_crossings(&ts, &coms));
    for (what, measured) in [("wall height", by_wall), ("centre of mass", by_com)] {
        let rel = measured / period - 1.0;
        eprintln!("sloshing period by {what}: {measured:.4} s, linear theory {period:.4} s ({rel:+.4})");
        assert!(rel.abs() < 0.06, "{what}: period {measured} s against {period} s ({rel:+.4})");
    }
}

/// A blob of water away from the walls, no gravity, in a tank accelerating at a constant `a`:
/// in the tank's frame the fluid feels `-a`, a uniform field that the projection leaves alone
/// (it has no divergence), so every particle's velocity after `T` is `-a T` to rounding. With an
/// oscillating tank the velocity gained is minus the tank's velocity change,
/// `-A omega (cos(omega T) - 1)`.
#[test]
fn tank_frame_force_is_minus_the_tank_acceleration() {
    let h = 1.0 / 32.0;
    let blob = |tank: TankMotion| {
        let mut params = FlipParams::<2>::default();
        params.gravity = [0.0; 2];
        params.tank_motion = Some(tank);
        let sim = FlipSimulation::<2>::new([32, 32], h, params).unwrap();
        let mut p = Particles::new();
        scenes::fill_box(&mut p, h, 2, [0.35, 0.4], [0.65, 0.6], |_| [0.0; 2]);
        (sim, p)
    };
    let a = 1.5;
    let (mut sim, mut p) = blob(TankMotion::accelerating(0, a));
    let t_end = 0.2;
    for _ in 0..10 {
        sim.advance(&mut p, t_end / 10.0).unwrap();
    }
    let com_v = |p: &Particles<2>| {
        let m = p.linear_momentum();
        [m[0] / p.len() as f64, m[1] / p.len() as f64]
    };
    let v = com_v(&p);
    assert!((v[0] + a * t_end).abs() < 1e-9 && v[1].abs() < 1e-9, "{v:?} against {}", -a * t_end);
    assert!(p.v.iter().all(|u| (u[0] + a * t_end).abs() < 1e-9), "not uniform");
    let (amp, f) = (0.02, 1.5);
    let tank = TankMotion::oscillation(0, amp, f);
    let (mut sim, mut p) = blob(tank);
    let t_end = 0.25;
    for _ in 0..7 {
        sim.advance(&mut p, t_end / 7.0).unwrap();
    }
    let w = 2.0 * PI * f;
    let expected = -amp * w * ((w * t_end).cos() - 1.0);
    let v = com_v(&p);
    assert!((v[0] - expected).abs() < 1e-9 * expected.abs().max(1.0), "{v:?} against {expected}");
    // The closed forms agree with each other: the velocity change is the integral of the
    // acceleration (midpoint rule on a fine partition).
    let m = 1000;
    let integral: f64 =
        (0..m).map(|i| tank.acceleration_at((i as f64 + 0.5) * t_end / m as f64)).sum::<f64>() * t_end
            / m as f64;
    assert!((integral - tank.velocity_change(0.0, t_end)).abs() < 1e-6, "{integral}");
    assert!((tank.velocity(t_end) - tank.velocity(0.0) - tank.velocity_change(0.0, t_end)).abs() < 1e-12);
}

/// The seeded scenes hold the volumes their geometry says (particle volume `h^D / 2^D`), and a
/// few steps keep every particle inside the fluid box.
#[test]
fn seeded_volumes_and_particles_stay_in_the_tank() {
    // The benchmark block: n/4 x n/2 x n/2 cells at 8 particles per cell, n^3 / 2 particles, on
    // the lattice at (k + 1/2) h / 2 from the fluid box corner.
    for n in [8, 16, 32] {
        let h = 1.0 / n as f64;
        let (sim, p) = scenes::benchmark_dam_break_3d(n, FlipParams::default()).unwrap();
        assert_eq!(p.len(), n * n * n / 2);
        let (lo, _) = sim.fluid_box();
        let hi = [lo[0] + 0.25, lo[1] + 0.5, lo[2] + 0.5];
        for a in 0..3 {
            let min = p.x.iter().map(|x| x[a]).fold(f64::INFINITY, f64::min);
            let max = p.x.iter().map(|x| x[a]).fold(f64::NEG_INFINITY, f64::max);
            assert!((min - (lo[a] + h / 4.0)).abs() < 1e-12 && (max - (hi[a] - h / 4.0)).abs() < 1e-12);
        }
    }
    let n = 16;
    let h = 1.0 / n as f64;
    let (mut sim, mut p, x0) = scenes::dam_break_3d(n, 0.25, FlipParams::default()).unwrap();
    assert_eq!(x0, h);
    assert!((p.len() as f64 * h.powi(3) / 8.0 - 0.25 * 0.5 * 0.25).abs() < 1e-12);
    for _ in 0..3 {
        sim.advance(&mut p, 0.02).unwrap();
    }
    let (lo, hi) = sim.fluid_box();
    assert!(p.x.iter().all(|x| (0..3).all(|a| x[a] >= lo[a] && x[a] <= hi[a])));
    // Tank 2a wide inside: the column fills half of it.
    assert!((hi[2] - lo[2] - 0.5).abs() < h);
    // The drop: pool plus disk, to the lattice's resolution (one particle spacing of perimeter).
    let n = 64;
    let h = 1.0 / n as f64;
    let (_, p) = scenes::drop_into_pool::<2>(n, FlipParams::default()).unwrap();
    let area = p.len() as f64 * h * h / 4.0;
    let exact = (1.0 - 2.0 * h) * scenes::POOL_DEPTH + PI * scenes::DROP_RADIUS.powi(2);
    assert!((area - exact).abs() < 2.0 * PI * scenes::DROP_RADIUS * h / 2.0, "{area} against {exact}");
    let (mut sim, mut p) = scenes::drop_into_pool::<3>(10, FlipParams::default()).unwrap();
    for _ in 0..3 {
        sim.advance(&mut p, 0.03).unwrap();
    }
    let (lo, hi) = sim.fluid_box();
    assert!(p.x.iter().all(|x| (0..3).all(|a| x[a] >= lo[a] && x[a] <= hi[a])));
    let (mut sim, mut p) = scenes::sloshing_tank::<3>(12, 0.25, 0.02, 1.0, FlipParams::default()).unwrap();
    for _ in 0..3 {
        sim.advance(&mut p, 0.03).unwrap();
    }
    assert!(p.max_speed() > 0.0 && p.max_speed().is_finite());
}

#[test]
fn bad_scene_and_tank_parameters_are_named() {
    let name = |r: Result<(), FlipError>| match r {
        Err(FlipError::BadParameter { name, .. }) => name,
        other => panic!("expected a bad parameter, got {other:?}"),
    };
    let tank = |t: TankMotion| {
        let mut params = FlipParams::<2>::default();
        params.tank_motion = Some(t);
        FlipSimulation::<2>::new([8, 8], 0.125, params).map(|_| ())
    };
    assert_eq!(name(tank(TankMotion::oscillation(2, 0.1, 1.0))), "tank_motion.axis");
    assert_eq!(name(tank(TankMotion::oscillation(0, -0.1, 1.0))), "tank_motion.amplitude");
    assert_eq!(name(tank(TankMotion::oscillation(0, 0.1, f64::NAN))), "tank_motion.frequency");
    assert_eq!(name(tank(TankMotion::accelerating(0, f64::INFINITY))), "tank_motion.acceleration");
    assert_eq!(name(tank(TankMotion::oscillation(0, 1e300, 1e300))), "tank_motion");
    let p = FlipParams::<2>::default;
    assert_eq!(name(scenes::sloshing_tank::<2>(16, -0.2, 0.01, 1.0, p()).map(|_| ())), "depth");
    assert_eq!(name(scenes::sloshing_tank::<2>(16, 2.0, 0.01, 1.0, p()).map(|_| ())), "depth");
    assert_eq!(
        name(scenes::sloshing_tank::<2>(16, 0.2, -0.01, 1.0, p()).map(|_| ())),
        "tank_motion.amplitude"
    );
    assert_eq!(
        name(scenes::sloshing_tank::<2>(16, 0.2, 0.01, f64::NAN, p()).map(|_| ())),
        "tank_motion.frequency"
    );
    let p3 = FlipParams::<3>::default;
    assert_eq!(name(scenes::dam_break_3d(16, 0.0, p3()).map(|_| ())), "a");
    assert_eq!(name(scenes::dam_break_3d(16, 0.6, p3()).map(|_| ())), "a");
    assert_eq!(name(scenes::benchmark_dam_break_3d(4, p3()).map(|_| ())), "n");
    assert_eq!(name(scenes::benchmark_dam_break_3d(18, p3()).map(|_| ())), "n");
    assert_eq!(name(scenes::drop_into_pool::<2>(2, p()).map(|_| ())), "cells[0]");
    assert_eq!(name(scenes::drop_into_pool::<2>(0, p()).map(|_| ())), "h");
    // Scene files without the field still parse (tank at rest).
    let mut value = serde_json::to_value(FlipParams::<2>::default()).unwrap();
    value.as_object_mut().unwrap().remove("tank_motion");
    let back: FlipParams<2> = serde_json::from_value(value).unwrap();
    assert_eq!(back.tank_motion, None);
    let partial: TankMotion =
        serde_json::from_str(r#"{ "axis": 0, "amplitude": 0.1, "frequency": 2.0 }"#).unwrap();
    assert_eq!(partial, TankMotion::oscillation(0, 0.1, 2.0));
}

/// The presets build with the names they are listed under, and an unknown name is `None`.
#[test]
fn presets_build_by_name() {
    for name in scenes::NAMES {
        let scene = scenes::by_name(name, Some(8), None).unwrap().unwrap();
        assert_eq!(scene.name(), name);
        assert_eq!(scene.dim(), if name.ends_with("3d") { 3 } else { 2 });
    }
    assert!(scenes::by_name("dam-break", None, None).is_none());
    let scenes::FlipScene::Two(s) = scenes::by_name("sloshing-tank", Some(16), None).unwrap().unwrap() else {
        panic!("sloshing is 2D");
    };
    let (lo, hi) = s.sim.fluid_box();
    let tank = s.sim.params().tank_motion.unwrap();
    let f = scenes::sloshing_frequency(hi[0] - lo[0], scenes::SLOSHING_DEPTH, 9.81);
    assert!((tank.frequency - f).abs() < 1e-12 && tank.amplitude == scenes::SLOSHING_AMPLITUDE);
}
