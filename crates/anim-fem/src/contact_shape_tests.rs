//! Box and capsule obstacles: the penalty's gradient and Gauss-Newton Hessian against finite
//! differences of its energy, and a cube coming to rest on a box's top face with either
//! integrator.

use crate::boundary::{Obstacle, obstacle_distance, penalty};
use crate::generate::box_mesh;
use crate::material::{Material, MaterialModel};
use crate::model::{EARTH_GRAVITY, FemModel};
use crate::sim::{FemParams, FemSimulation, TimeIntegrator};
use anim_core::integrate::State;
use anim_core::solver::Solver;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const K: f64 = 1e5;

fn energy(o: &Obstacle, x: [f64; 3]) -> f64 {
    penalty(o, K, x).map_or(0.0, |(e, _, _)| e)
}

fn gradient(o: &Obstacle, x: [f64; 3]) -> [f64; 3] {
    penalty(o, K, x).map_or([0.0; 3], |(_, g, _)| g)
}

/// Checks the gradient against central differences of the energy and the Hessian against
/// central differences of the gradient minus the curvature term `k phi dn/dx` that the
/// Gauss-Newton Hessian `k n n^T` leaves out (`curvature(x)` gives `dn/dx`, row-major).
fn check_derivatives(o: &Obstacle, x: [f64; 3], curvature: impl Fn([f64; 3]) -> [f64; 9]) {
    let (phi, n) = obstacle_distance(o, x);
    assert!(phi < -1e-3, "{o:?}: {x:?} is not inside (phi {phi})");
    let (_, g, h) = penalty(o, K, x).expect("inside");
    // The force -g pushes out along the outward normal with magnitude k |phi|.
    for c in 0..3 {
        assert!((-g[c] - K * -phi * n[c]).abs() < 1e-12 * K, "{o:?} {x:?}");
    }
    let step = 1e-6;
    let dn = curvature(x);
    for c in 0..3 {
        let (mut xp, mut xm) = (x, x);
        xp[c] += step;
        xm[c] -= step;
        let fd = (energy(o, xp) - energy(o, xm)) / (2.0 * step);
        assert!((fd - g[c]).abs() < 1e-6 * K * phi.abs(), "{o:?} {x:?} gradient {c}: {fd} vs {}", g[c]);
        let (gp, gm) = (gradient(o, xp), gradient(o, xm));
        for r in 0..3 {
            let exact = (gp[r] - gm[r]) / (2.0 * step);
            let gauss_newton = exact - K * phi * dn[3 * r + c];
            assert!(
                (gauss_newton - h[3 * r + c]).abs() < 1e-5 * K,
                "{o:?} {x:?} Hessian ({r},{c}): {gauss_newton} vs {}",
                h[3 * r + c]
            );
        }
    }
}

/// `dn/dx` of the normal `n = d / |d|` of a point at offset `d` from its closest axis point,
/// with the axis direction `a` (zero for a sphere's centre): `(I - a a^T - n n^T) / |d|`.
fn radial_curvature(d: [f64; 3], a: [f64; 3]) -> [f64; 9] {
    let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    std::array::from_fn(|i| {
        let (row, col) = (i / 3, i % 3);
        let identity = if row == col { 1.0 } else { 0.0 };
        (identity - a[row] * a[col] - d[row] * d[col] / (r * r)) / r
    })
}

#[test]
fn box_penalty_derivatives_match_finite_differences() {
    let o = Obstacle::Box { center: [0.3, -0.2, 0.5], half_extents: [0.4, 0.3, 0.2] };
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut tried = 0;
    while tried < 40 {
        let x: [f64; 3] = std::array::from_fn(|c| {
            let Obstacle::Box { center, half_extents } = o else { unreachable!() };
            center[c] + rng.random_range(-0.98..0.98) * half_extents[c]
        });
        // Away from the planes where the nearest face changes (the box's medial surface).
        let Obstacle::Box { center, half_extents } = o else { unreachable!() };
        let mut depth: Vec<f64> = (0..3).map(|c| half_extents[c] - (x[c] - center[c]).abs()).collect();
        depth.sort_by(f64::total_cmp);
        if depth[1] - depth[0] < 1e-3 || depth[0] < 2e-3 {
            continue;
        }
        tried += 1;
        // Inside a box phi is linear: no curvature term.
        check_derivatives(&o, x, |_| [0.0; 9]);
    }
}

#[test]
fn capsule_and_sphere_penalty_derivatives_match_finite_differences() {
    let (a, b, radius) = ([0.1, 0.2, 0.3], [0.9, -0.4, 0.5], 0.25);
    let capsule = Obstacle::Capsule { a, b, radius };
    let axis = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let len = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let unit = axis.map(|c| c / len);
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    for trial in 0..40 {
        // Along the axis (t in (0.05, 0.95)) or beyond an end (a spherical cap), at a depth
        // between 0.1 and 0.9 of the radius.
        let t: f64 =
            if trial % 4 == 3 { rng.random_range(-0.2..-0.05) } else { rng.random_range(0.05..0.95) };
        let dir: [f64; 3] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
        let along = dir[0] * unit[0] + dir[1] * unit[1] + dir[2] * unit[2];
        let mut perp = [0, 1, 2].map(|c| dir[c] - along * unit[c]);
        if t < 0.0 {
            // In the cap: any direction away from the end, inside the cap's half-ball.
            perp = [0, 1, 2].map(|c| perp[c] + t * len * unit[c]);
        }
        let l = (perp[0] * perp[0] + perp[1] * perp[1] + perp[2] * perp[2]).sqrt();
        let depth: f64 = rng.random_range(0.1..0.9) * radius;
        let foot = [0, 1, 2].map(|c| a[c] + t.max(0.0) * axis[c]);
        let d = perp.map(|c| c / l * depth);
        let x = [0, 1, 2].map(|c| foot[c] + d[c]);
        let cap = t < 0.0;
        check_derivatives(&capsule, x, |_| radial_curvature(d, if cap { [0.0; 3] } else { unit }));
        let sphere = Obstacle::Sphere { center: foot, radius };
        check_derivatives(&sphere, x, |_| radial_curvature(d, [0.0; 3]));
    }
}

/// A 0.2 m cube of 48 tetrahedra (8 kg, E = 1 MPa) dropped from 1 cm onto the top face (z = 0.5)
/// of a box obstacle, with the ground under the box.
fn cube_over_box(integrator: TimeIntegrator) -> (FemSimulation, State) {
    let mesh = box_mesh([-0.1, -0.1, 0.51], [0.2; 3], [2, 2, 2]).expect("mesh");
    let material = Material::new(MaterialModel::StableNeoHookean, 1e6, 0.3, 1000.0).expect("material");
    let mut model = FemModel::new(mesh, material).expect("model").with_gravity(EARTH_GRAVITY);
    model.add_obstacle(Obstacle::ground(0.0), K).expect("ground");
    let table = Obstacle::Box { center: [0.1, 0.0, 0.25], half_extents: [0.5, 0.4, 0.25] };
    model.add_obstacle(table, K).expect("box");
    // Stiffness damping settles the implicit run; the explicit step takes none (it would
    // shrink its stable step).
    let gamma = if integrator == TimeIntegrator::BackwardEuler { 0.01 } else { 0.0 };
    let params = FemParams::new(integrator).with_rayleigh(gamma);
    let sim = FemSimulation::new(model, params).expect("sim");
    let state = sim.rest_state();
    (sim, state)
}

/// Backward Euler: the cube comes to rest on the box; its lowest layer (the 9 vertices of the
/// bottom face) sinks into the top face by `m g / (k 9)` on average (the penalty forces carry
/// the weight), no vertex is deeper than 3 times that, and it has stopped.
#[test]
fn a_cube_comes_to_rest_on_a_box_top_face() {
    let (mut sim, mut state) = cube_over_box(TimeIntegrator::BackwardEuler);
    for _ in 0..300 {
        sim.step(&mut state, 0.01).expect("step");
    }
    let mass: f64 = sim.model().lumped_mass().iter().sum();
    let bottom: Vec<usize> =
        (0..state.x.len() / 3).filter(|&i| sim.model().mesh().positions[i][2] < 0.52).collect();
    assert_eq!(bottom.len(), 9);
    let sink = mass * 9.81 / (K * bottom.len() as f64);
    let depths: Vec<f64> = bottom.iter().map(|&i| 0.5 - state.x[3 * i + 2]).collect();
    let mean = depths.iter().sum::<f64>() / depths.len() as f64;
    assert!((mean - sink).abs() < 1e-3 * sink, "mean depth {mean:e}, m g / (k n) = {sink:e}");
    assert!(depths.iter().all(|&d| d > 0.0 && d < 3.0 * sink), "{depths:?} vs {sink:e}");
    let speed = state.v.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(speed < 1e-5, "still moving at {speed:e} m/s");
}

/// Symplectic Euler: the projection puts the landing vertices back on the top face; the cube
/// never goes through it.
#[test]
fn an_explicit_cube_lands_on_a_box_without_passing_through() {
    let (mut sim, mut state) = cube_over_box(TimeIntegrator::SymplecticEuler);
    let mut lowest = f64::INFINITY;
    for _ in 0..1500 {
        sim.step(&mut state, 2e-4).expect("step");
        lowest = state.x.chunks(3).map(|p| p[2]).fold(lowest, f64::min);
    }
    assert!(lowest > 0.5 - 1e-9 && lowest < 0.5 + 1e-6, "lowest z {lowest}");
}
