//! Mesh colliders: the exact Jacobians (the curvature term from the field's Hessian) against
//! finite differences, a particle resting on a mesh sphere and on a mesh box where it rests on
//! the analytic shapes, and thread-count determinism of a cloth over a mesh.

use super::tests::{finite_differences, jacobians, max_abs};
use super::*;
use crate::{EARTH_GRAVITY, NetworkBuilder, SpringNetwork, scenes};
use anim_core::integrate::{IntegratorKind, NewtonParams, SecondOrderSystem, State, study::advance};
use anim_core::linalg::LinearSolverKind;
use anim_core::surface::{ClosedSurface, DistanceField, icosphere};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const RADIUS: f64 = 0.5;

/// An icosphere of `subdivisions` scaled to `RADIUS` about the origin, and its sagitta (`RADIUS`
/// minus the least distance from the centre to a face's plane).
fn mesh_ball(subdivisions: usize) -> (ClosedSurface, f64) {
    let (p, t) = icosphere(subdivisions);
    let p: Vec<[f64; 3]> = p.iter().map(|v| v.map(|c| RADIUS * c)).collect();
    let nearest = t
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|i| DVec3::from_array(p[i]));
            (b - a).cross(c - a).normalize().dot(a).abs()
        })
        .fold(f64::INFINITY, f64::min);
    (ClosedSurface::new(p, t).expect("closed"), RADIUS - nearest)
}

/// The box `[lo, hi]` as a closed surface of 12 outward triangles.
fn mesh_box(lo: [f64; 3], hi: [f64; 3]) -> ClosedSurface {
    let (p, t) = anim_core::surface::cuboid(lo, hi);
    ClosedSurface::new(p, t).expect("closed")
}

/// The unit direction of the centroid of the face of `surface` whose centroid is highest.
fn top_face(surface: &ClosedSurface) -> DVec3 {
    let p = surface.positions();
    surface
        .triangles()
        .iter()
        .map(|t| (p[t[0]] + p[t[1]] + p[t[2]]).normalize())
        .max_by(|a, b| a.z.total_cmp(&b.z))
        .expect("faces")
}

/// The exact Jacobians of a mesh collider (the normal stiffness with `|grad phi|`, the friction
/// coupling, and the curvature term `e(p) (dg/dn) (I - n n^T) H / |grad phi|`) match central
/// differences of the force, away from the lattice's cell faces (where the trilinear field's
/// gradient has a kink) and the smoothing zone's end, within the field's exact band (deeper, the
/// swept field's gradient can nearly vanish and the normal turn sharply); without the curvature
/// term they would not
/// (checked: the term is a sizeable part of `K` at some samples). The definite Jacobian is
/// symmetric and negative semi-definite.
#[test]
fn mesh_jacobians_match_central_finite_differences() {
    let (ball, _) = mesh_ball(4);
    let h = 0.02;
    let mut rng = ChaCha8Rng::seed_from_u64(0x6d657368);
    let mut curved = 0;
    for thickness in [0.0, 0.03] {
        let field = DistanceField::around(&ball, h, thickness + 0.05).expect("field");
        let c = MeshCollider::new(field.clone(), 40.0)
            .with_damping(0.3)
            .with_friction(0.7)
            .with_smoothing(0.01)
            .with_thickness(thickness);
        let mut checked = 0;
        while checked < 200 {
            let dir = DVec3::from_array(std::array::from_fn(|_| rng.random_range(-1.0..1.0)));
            if dir.length() < 0.1 {
                continue;
            }
            // Within the field's exact band (three cells of the surface), where it is a distance.
            let x = dir.normalize() * (RADIUS + thickness - rng.random_range(0.0..thickness + 2.0 * h));
            let cell = (x - field.origin()) / h;
            let near_face = cell.to_array().iter().any(|s| (s - s.round()).abs() < 1e-4);
            let Some((p, _, _)) = c.probe(x) else { continue };
            if near_face || p < 1e-4 || (p - c.smoothing).abs() < 1e-4 {
                continue;
            }
            let v = DVec3::from_array(std::array::from_fn(|_| rng.random_range(-1.0..1.0)));
            let (k, d) = jacobians(&c, x, v, true);
            let (k_fd, d_fd) = (finite_differences(&c, x, v, true), finite_differences(&c, x, v, false));
            let scale = max_abs(k_fd).max(1e-3);
            assert!(max_abs(k - k_fd) < 1e-5 * scale, "K at {x} (t {thickness}):\n{k}\nvs\n{k_fd}");
            assert!(max_abs(d - d_fd) < 1e-5 * max_abs(d_fd).max(1e-3), "D at {x}");
            // The curvature term's share of K.
            let Some((_, _, Bend::Field { hessian, .. })) = c.probe(x) else { panic!("a field's bend") };
            if max_abs(hessian) * Law::elastic(&c.law(), p).0 > 1e-2 * scale {
                curved += 1;
            }
            // Definite: symmetric, negative semi-definite.
            let (kd, _) = jacobians(&c, x, v, false);
            assert!(max_abs(kd - kd.transpose()) < 1e-12 * max_abs(kd).max(1.0));
            let w = DVec3::from_array(std::array::from_fn(|_| rng.random_range(-1.0..1.0)));
            assert!(w.dot(kd * w) <= 1e-12 * max_abs(kd).max(1.0));
            checked += 1;
        }
    }
    assert!(curved > 20, "the curvature term mattered at {curved} samples");
}

/// A particle held sideways by four stiff horizontal springs from pinned anchors rests over the
/// centre of the icosphere's face nearest the top (5120 triangles, sampled every 1 cm) and on the
/// analytic sphere. The field's distance is within the sagitta (the faces lie inside the sphere
/// by up to that) plus the interpolation error (`h^2 / 8` times the curvature `1 / R`) of the
/// sphere's, and a particle held on a vertical line meets a surface lower by `d` along a normal
/// `n` a height `d / n_z` lower: the particles end apart by at most that, with or without a
/// thickness, and by more than a micrometre (a face's centre is where the faces lie deepest).
#[cfg_attr(not(feature = "faer"), ignore = "sparse Cholesky needs the `faer` feature")]
#[test]
fn a_particle_rests_on_a_mesh_sphere_where_it_rests_on_the_sphere() {
    let (ball, sagitta) = mesh_ball(4);
    let h = 0.01;
    let field = DistanceField::around(&ball, h, 0.05).expect("field");
    for thickness in [0.0, 0.01] {
        let like = Collider {
            shape: Shape::Sphere { center: [0.0; 3], radius: RADIUS },
            stiffness: 1e4,
            damping: 0.5,
            friction: 1.0,
            smoothing: 1e-3,
            thickness,
        };
        let top = top_face(&ball);
        let (x, y) = ((RADIUS * top).x, (RADIUS * top).y);
        let z = ((RADIUS + thickness).powi(2) - x * x - y * y).sqrt();
        let settle = |mesh: bool| {
            let mut b = NetworkBuilder::new();
            b.gravity(EARTH_GRAVITY);
            let p = b.particle([x, y, z + 0.002], 0.01);
            for anchor in [[x + 0.1, y, z], [x - 0.1, y, z], [x, y + 0.1, z], [x, y - 0.1, z]] {
                let a = b.particle(anchor, 0.01);
                b.pin(a);
                b.spring(p, a, crate::SpringParams::new(1e4, 0.0));
            }
            if mesh {
                b.mesh_collider(MeshCollider::like(field.clone(), &like));
            } else {
                b.collider(like);
            }
            let mut net = b.build().expect("builds");
            let mut state = net.rest_state();
            let mut integ = IntegratorKind::BackwardEuler.build_with::<SpringNetwork>(
                net.dof(),
                NewtonParams::with_tolerance(1e-12),
                LinearSolverKind::Cholesky,
            );
            advance(integ.as_mut(), &mut net, &mut state, 0.005, 400).expect("steps");
            DVec3::from_slice(&state.x[..3])
        };
        let (analytic, meshed) = (settle(false), settle(true));
        // Within the smoothing zone: k_c p^2 / (2 delta) = m g.
        let depth = (2.0 * 1e-3 * 0.01 * 9.81 / 1e4_f64).sqrt();
        assert!(depth < 1e-3);
        assert!((analytic.z - (z - depth)).abs() < 1e-5, "{analytic}");
        let bound = (sagitta + h * h / (8.0 * RADIUS)) / top.z;
        let apart = analytic.distance(meshed);
        assert!(apart <= bound, "thickness {thickness}: {apart} apart, bound {bound} (sagitta {sagitta})");
        assert!(apart > 1e-6, "over a face's centre: {apart}");
    }
}

/// On a flat face the field is exact (the distance to a plane is linear, and so is its trilinear
/// interpolation; the nodes hold it in `f32`): a particle on a mesh box's top face rests at the
/// penalty depth below `top + thickness`, as on the analytic box, to the `f32` rounding of the
/// node values (`2^-24` of their size, at most the thickness plus two cells).
#[cfg_attr(not(feature = "faer"), ignore = "sparse Cholesky needs the `faer` feature")]
#[test]
fn a_particle_rests_on_a_mesh_box_where_it_rests_on_the_box() {
    let h = 0.02;
    for thickness in [0.0, 0.01] {
        let field = DistanceField::around(&mesh_box([-0.5, -0.5, 0.0], [0.5, 0.5, 0.5]), h, thickness + 0.05)
            .expect("field");
        let mut b = NetworkBuilder::new();
        b.gravity(EARTH_GRAVITY);
        b.particle([0.1, 0.2, 0.55], 0.2);
        b.mesh_collider(
            MeshCollider::new(field, 1000.0)
                .with_damping(0.5)
                .with_friction(1.0)
                .with_smoothing(1e-3)
                .with_thickness(thickness),
        );
        let mut net = b.build().expect("builds");
        let mut state = net.rest_state();
        let mut integ = IntegratorKind::BackwardEuler.build_with::<SpringNetwork>(
            3,
            NewtonParams::with_tolerance(1e-12),
            LinearSolverKind::Cholesky,
        );
        advance(integ.as_mut(), &mut net, &mut state, 0.005, 2000).expect("steps");
        let depth = 0.2 * 9.81 / 1000.0 + 0.5e-3;
        let z = 0.5 + thickness - depth;
        let rounding = (thickness + 2.0 * h) / f64::from(1u32 << 24);
        assert!((state.x[2] - z).abs() < 1e-9 + rounding, "z = {}, expected {z}", state.x[2]);
        assert!((state.x[0] - 0.1).abs() < 1e-12 && (state.x[1] - 0.2).abs() < 1e-12);
    }
}

/// A mesh collider with a parameter out of range is refused naming it, by the builder and when
/// added to a built network (numbered after the mesh colliders already there).
#[test]
fn a_bad_mesh_collider_is_named() {
    let field = DistanceField::around(&mesh_box([0.0; 3], [1.0; 3]), 0.1, 0.0).expect("field");
    let mut b = NetworkBuilder::new();
    b.particle([0.0, 0.0, 2.0], 1.0);
    b.mesh_collider(MeshCollider::new(field.clone(), 0.0));
    let err = b.build().unwrap_err();
    assert!(matches!(err, crate::BuildError::BadMeshCollider { collider: 0, .. }), "{err:?}");
    assert!(err.to_string().starts_with("mesh collider 0: stiffness"), "{err}");
    let mut b = NetworkBuilder::new();
    b.particle([0.0, 0.0, 2.0], 1.0);
    b.mesh_collider(MeshCollider::new(field.clone(), 1.0));
    let mut net = b.build().expect("builds");
    for bad in [
        MeshCollider::new(field.clone(), 1.0).with_damping(-1.0),
        MeshCollider::new(field.clone(), 1.0).with_friction(f64::NAN),
        MeshCollider::new(field.clone(), 1.0).with_smoothing(-1.0),
        MeshCollider::new(field.clone(), 1.0).with_thickness(f64::INFINITY),
    ] {
        let err = net.add_mesh_colliders(vec![MeshCollider::new(field.clone(), 1.0), bad]).unwrap_err();
        assert!(matches!(err, crate::BuildError::BadMeshCollider { collider: 2, .. }), "{err:?}");
    }
    assert_eq!(net.model().mesh_colliders().len(), 1);
}

/// A cloth of more particles than the parallel threshold falls onto a mesh sphere: the same bits
/// on 1, 2 and 4 threads, explicit and implicit.
#[cfg_attr(not(feature = "faer"), ignore = "sparse Cholesky needs the `faer` feature")]
#[test]
fn a_cloth_on_a_mesh_is_bitwise_identical_for_any_thread_count() {
    let (ball, _) = mesh_ball(3);
    let field = DistanceField::around(&ball, 0.03, 0.05).expect("field");
    let run = |threads: usize, kind: IntegratorKind, linear: LinearSolverKind, steps: usize, dt: f64| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        pool.install(|| {
            // The hanging cloth: a 1 m square at z = 1 from the origin, pinned at two corners.
            let scene = scenes::hanging_cloth(Some(48)).expect("scene");
            let mut net = scene.network;
            let mut state: State = scene.state;
            net.add_mesh_colliders(vec![
                MeshCollider::new(field.clone(), 500.0).with_damping(0.2).with_friction(0.5),
            ])
            .expect("collider");
            // The cloth moved over the ball, its middle 1 mm above the top.
            for p in state.x.chunks_mut(3) {
                p[0] -= 0.5;
                p[1] -= 0.5;
                p[2] -= 1.0 - RADIUS - 0.001;
            }
            assert!(net.num_particles() > crate::network::PARALLEL_THRESHOLD);
            let mut integ = kind.build_with::<SpringNetwork>(net.dof(), scenes::animation_newton(), linear);
            advance(integ.as_mut(), &mut net, &mut state, dt, steps).expect("steps");
            let e = net.energy(state.t, &state.x, &state.v).expect("energy");
            state.x.iter().chain(&state.v).chain([&e]).map(|v| v.to_bits()).collect::<Vec<u64>>()
        })
    };
    for (kind, linear, steps, dt) in [
        (IntegratorKind::SymplecticEuler, LinearSolverKind::Cg, 200, 1e-4),
        (IntegratorKind::BackwardEuler, LinearSolverKind::Cholesky, 5, 0.01),
    ] {
        let one = run(1, kind, linear, steps, dt);
        for threads in [2, 4] {
            assert!(
                run(threads, kind, linear, steps, dt) == one,
                "{}: {threads} threads differ",
                kind.label()
            );
        }
    }
}

/// The elastic force of a mesh collider is the exact negative gradient of the penalty energy the
/// network counts, also where the field's gradient is not of unit length: on a coarse field
/// (spacing 0.1 m over a ball of radius 0.5 m) between its nodes, where the trilinear gradient
/// is shorter or longer than 1, and beyond its exact band, where the swept distance is only
/// first-order. Central differences of the energy (no velocity, so no damping or friction) give
/// the force to the differences' error at every sample whose `|grad phi|` is more than 1% off
/// 1, away from the cell faces where the interpolant's gradient has a kink; a force `e(p) n`
/// without the factor `|grad phi|` would be off by that 1% or more.
#[test]
fn mesh_force_is_minus_the_gradient_of_its_energy() {
    let (ball, _) = mesh_ball(3);
    let h = 0.1;
    let thickness = 0.45;
    let field = DistanceField::around(&ball, h, thickness + 0.1).expect("field");
    let c = MeshCollider::new(field.clone(), 40.0).with_smoothing(0.02).with_thickness(thickness);
    let mut rng = ChaCha8Rng::seed_from_u64(0x656e6572);
    let (mut checked, mut off_band, mut short, mut long) = (0, 0, 0, 0);
    while checked < 300 {
        let x = DVec3::from_array(std::array::from_fn(|_| rng.random_range(-0.9..0.9)));
        let cell = (x - field.origin()) / h;
        if cell.to_array().iter().any(|s| (s - s.round()).abs() < 1e-3) {
            continue;
        }
        let Some((p, _, Bend::Field { slope, .. })) = c.probe(x) else { continue };
        if (slope - 1.0).abs() < 0.01 || p < 1e-3 || (p - c.smoothing).abs() < 1e-3 {
            continue;
        }
        let step = 1e-6;
        let de = DVec3::AXES.map(|e| (c.energy(x + step * e) - c.energy(x - step * e)) / (2.0 * step));
        let minus_grad = -DVec3::new(de[0], de[1], de[2]);
        let f = c.force(x, DVec3::ZERO);
        assert!(
            (f - minus_grad).length() < 1e-6 * f.length().max(1e-3),
            "at {x} (|grad phi| = {slope}): force {f}, -dE/dx {minus_grad}"
        );
        let s = field.sample(x).expect("in the field");
        if s.distance.abs() > 3.0 * h {
            off_band += 1;
        }
        if slope < 1.0 {
            short += 1;
        } else {
            long += 1;
        }
        checked += 1;
    }
    // Both kinds of slope, and points beyond the exact band, were among the samples.
    assert!(
        off_band > 20 && short > 20 && long > 20,
        "{off_band} beyond the band, {short} short, {long} long"
    );
}
