//! Mesh colliders against their analytic shapes: particles resting on a mesh sphere sit where
//! they sit on the analytic sphere within the bound of the polyhedron's sagitta and the field's
//! interpolation error, and particles dropping, bouncing and sliding on a mesh box's top face
//! follow the analytic box's particles to the field's rounding.

use crate::{
    Collider, EARTH_GRAVITY, MeshCollider, Method, PbdBuilder, PbdParams, PbdSimulation, Shape, SolverKind,
};
use anim_core::glam::DVec3;
use anim_core::integrate::State;
use anim_core::surface::{ClosedSurface, DistanceField, icosphere};

/// A closed surface from `(positions, triangles)` scaled by `scale` and moved by `shift`.
fn placed(mesh: (Vec<[f64; 3]>, Vec<[usize; 3]>), scale: f64, shift: DVec3) -> ClosedSurface {
    let (p, t) = mesh;
    let p = p.iter().map(|x| (DVec3::from_array(*x) * scale + shift).to_array()).collect();
    ClosedSurface::new(p, t).expect("closed")
}

/// The unit cube `[0, 1]^3` as twelve outward triangles.
fn unit_cube() -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    anim_core::surface::cuboid([0.0; 3], [1.0; 3])
}

/// Directions from the sphere's centre at which particles rest: the poles, the equator and
/// skew directions that meet the icosphere's faces, edges and vertices anywhere.
fn directions() -> Vec<DVec3> {
    [
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
        [1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [1.0, 2.0, 3.0],
        [-2.0, 1.0, 0.5],
        [0.3, -0.7, -0.2],
        [-0.4, -0.4, 0.9],
        [0.9, 0.1, -0.6],
        [-0.25, 0.8, -0.55],
    ]
    .iter()
    .map(|d| DVec3::from_array(*d).normalize())
    .collect()
}

/// Particles of mass 0.1 kg at `start`, with gravity or without, against `collider` or `mesh`,
/// started at rest, with XPBD's 5 iterations of 4 substeps.
fn particles(
    start: &[DVec3],
    gravity: bool,
    collider: Option<Collider>,
    mesh: Option<MeshCollider>,
) -> (PbdSimulation, State) {
    let mut b = PbdBuilder::new();
    if gravity {
        b.gravity(EARTH_GRAVITY);
    }
    for p in start {
        b.particle(p.to_array(), 0.1);
    }
    // A far ground plane first, so that the mesh collider is contact collider 1 and its
    // coefficients are looked up past the shapes'.
    b.collider(Collider::ground(-10.0));
    if let Some(c) = collider {
        b.collider(c);
    }
    if let Some(m) = mesh {
        b.mesh_collider(m);
    }
    let model = b.build().expect("builds");
    let state = model.rest_state();
    let params = PbdParams::new(Method::Xpbd, SolverKind::GaussSeidel, 5, 4);
    (PbdSimulation::new(model, params).expect("params"), state)
}

/// Runs particles of mass 0.1 kg at `start` with constant forces `force` (no gravity) against
/// `collider` or `mesh` for 1 s (60 steps of 4 substeps, 5 XPBD iterations); the end positions.
fn rest(
    start: &[DVec3],
    force: &[DVec3],
    collider: Option<Collider>,
    mesh: Option<MeshCollider>,
) -> Vec<DVec3> {
    let (mut sim, mut state) = particles(start, false, collider, mesh);
    for (i, f) in force.iter().enumerate() {
        sim.set_external_force(i, (*f * 0.1).to_array());
    }
    sim.run(&mut state, 1.0 / 60.0, 60).expect("runs");
    state.x.chunks_exact(3).map(|p| DVec3::new(p[0], p[1], p[2])).collect()
}

/// Particles pressed against a sphere of radius `R` by a force of 1 m/s^2 towards its centre,
/// starting at rest on the analytic sphere plus the thickness `t`: on the analytic sphere they
/// stay there (a closed form: `c + (R + t) r`), and on an icosphere of 5120 triangles sampled
/// at spacing `h` they rest where the field reads `t`, which is bounded from both sides:
///
/// - the polyhedron lies inside the sphere and outside its inscribed sphere of radius `r_min`
///   (the smallest distance from the centre to a face's plane, measured on the mesh), so the
///   exact distance to it at radius `rho` lies in `[rho - R, rho - r_min]`, and `R - r_min` is
///   its sagitta;
/// - both distance functions are convex (the body is), so the trilinear interpolant of the
///   nodes lies above them, and above the sphere's distance by at most
///   `sum_a h^2 / 8 max |d_aa| <= 3 h^2 / (8 rho_min)`, `rho_min = R - sqrt(3) h` the smallest
///   radius in a cell at the surface (every node of such a cell is within the field's exact
///   band of 3 cells for `t <= 1.2 h`); `f32` storage adds at most `2^-24` of the values;
/// - the projection moves along the unit normal by `t - phi(p)` where Newton would divide by
///   `|grad phi|`: under the load `a h^2` per substep the particle settles up to
///   `a h^2 (|grad phi| - 1)` off, and `|grad phi| <= sqrt(3)` (each component is a mean of
///   difference quotients of a 1-Lipschitz function).
///
/// So the resting radius lies in `[R + t - (R - r_min) - 3 h^2 / (8 rho_min) - a h^2, R + t +
/// a h^2]`. Sideways, a particle moves only while a contact pushes it along a normal that is
/// not radial: at the impact, by at most its speed times the substep, `sqrt(2 a fall) h`, plus
/// `a h^2`; friction (`mu = 1`) holds it afterwards.
#[test]
fn particles_rest_on_a_mesh_sphere_where_they_rest_on_the_analytic_sphere() {
    let (r, t, a) = (0.3, 0.01, 1.0);
    let centre = DVec3::new(0.05, -0.02, 0.4);
    let sub = 1.0 / 240.0;
    let surface = placed(icosphere(4), r, centre);
    let r_min = surface
        .triangles()
        .iter()
        .map(|tri| {
            let [p0, p1, p2] = tri.map(|i| surface.positions()[i] - centre);
            p0.dot((p1 - p0).cross(p2 - p0).normalize()).abs()
        })
        .fold(f64::INFINITY, f64::min);
    let sagitta = r - r_min;
    assert!(sagitta > 1e-4 && sagitta < 1e-3, "sagitta {sagitta}");
    let dirs = directions();
    let start: Vec<DVec3> = dirs.iter().map(|d| centre + (r + t) * *d).collect();
    let force: Vec<DVec3> = dirs.iter().map(|d| -a * *d).collect();
    let sphere = Collider::sphere(centre.to_array(), r).with_thickness(t).with_friction(1.0, 1.0);
    let exact = rest(&start, &force, Some(sphere), None);
    for (x, s) in exact.iter().zip(&start) {
        assert!((*x - *s).length() < 1e-9, "analytic sphere: {x} instead of {s}");
    }
    for h in [0.01, 0.02] {
        let field = DistanceField::around(&surface, h, 0.05).expect("field");
        let mesh = MeshCollider::new(field).with_thickness(t).with_friction(1.0, 1.0);
        let on_mesh = rest(&start, &force, None, Some(mesh));
        let interpolation = 3.0 * h * h / (8.0 * (r - 3f64.sqrt() * h)) + 2f64.powi(-24) * 3.0 * h;
        let load = a * sub * sub;
        let (lo, hi) = (r + t - sagitta - interpolation - load, r + t + load);
        let fall = sagitta + interpolation + load;
        let sideways = (2.0 * a * fall).sqrt() * sub + load;
        let mut worst = 0.0f64;
        for ((x, d), e) in on_mesh.iter().zip(&dirs).zip(&exact) {
            let radial = (*x - centre).dot(*d);
            let lateral = (*x - centre - radial * *d).length();
            assert!(
                radial >= lo && radial <= hi,
                "h = {h}, direction {d}: radius {radial} not in [{lo}, {hi}]"
            );
            assert!(
                lateral <= sideways,
                "h = {h}, direction {d}: moved {lateral} sideways (bound {sideways})"
            );
            worst = worst.max((*x - *e).length());
        }
        // The bound is not vacuous: the mesh sphere is measurably smaller than the sphere.
        assert!(worst > 0.1 * sagitta && worst < hi - lo + sideways, "h = {h}: {worst}");
    }
}

/// Particles thrown onto a box's top face bounce (restitution 0.5) and stop at their first
/// impact (static friction 0.4; kinetic friction 0.05 alone would let them slide on) exactly as
/// on the analytic box: the field of a flat face is linear, which the trilinear interpolation
/// reproduces, so only the `f32` rounding of the nodes (`2^-24` of values below 0.1 m)
/// separates the two, while a wrong restitution or friction would not.
#[test]
fn particles_on_a_mesh_box_move_as_on_the_analytic_box() {
    let (half, t) = (0.2, 0.01);
    let cube = placed(unit_cube(), 2.0 * half, DVec3::splat(-half));
    let field = DistanceField::around(&cube, 0.02, 0.05).expect("field");
    let start: Vec<DVec3> = [[-0.1, 0.0, 0.35], [-0.05, -0.04, 0.3], [-0.12, 0.03, 0.26]]
        .iter()
        .map(|p| DVec3::from_array(*p))
        .collect();
    let run = |collider: Option<Collider>, mesh: Option<MeshCollider>| {
        let (mut sim, mut state) = particles(&start, true, collider, mesh);
        // Not at rest: a bounce from rest would return to the contact height exactly at a
        // substep's end (both speeds multiples of g h), where the two runs' 1e-10 apart
        // decide differently whether to touch.
        for i in 0..start.len() {
            state.v[3 * i..3 * i + 3].copy_from_slice(&[0.3, 0.1, -0.37]);
        }
        let mut path = Vec::new();
        for _ in 0..90 {
            sim.run(&mut state, 1.0 / 60.0, 1).expect("runs");
            path.push(state.x.clone());
        }
        path
    };
    let shape = Shape::Box { center: [0.0; 3], half_extents: [half; 3] };
    let contact = |c: Collider| c.with_thickness(t).with_friction(0.4, 0.05).with_restitution(0.5);
    let exact = run(Some(contact(Collider::new(shape))), None);
    let mesh = MeshCollider::new(field).with_thickness(t).with_friction(0.4, 0.05).with_restitution(0.5);
    let on_mesh = run(None, Some(mesh));
    let mut bounced = false;
    for (step, (e, m)) in exact.iter().zip(&on_mesh).enumerate() {
        for (a, b) in e.iter().zip(m) {
            assert!((a - b).abs() < 1e-8, "step {step}: {e:?} against {m:?}");
        }
        bounced |= step > 0 && e[2] > exact[step - 1][2];
    }
    let (last, before) = (&exact[89], &exact[88]);
    // They bounced and came to rest on the top face at the thickness, at least 5 cm from its
    // edges (where the field rounds the box).
    assert!(bounced);
    for i in 0..start.len() {
        assert!((last[3 * i + 2] - (half + t)).abs() < 1e-9, "{last:?}");
        assert!(last[3 * i].abs() < half - 0.05 && last[3 * i + 1].abs() < half - 0.05, "{last:?}");
        assert!((last[3 * i] - before[3 * i]).abs() < 1e-12, "{last:?} after {before:?}");
    }
}

/// A mesh collider's bad contact parameters are refused naming it.
#[test]
fn bad_mesh_collider_parameters_are_refused_by_index() {
    let cube = placed(unit_cube(), 1.0, DVec3::ZERO);
    let field = DistanceField::around(&cube, 0.1, 0.1).expect("field");
    for (m, words) in [
        (MeshCollider::new(field.clone()).with_thickness(-1.0), "thickness"),
        (MeshCollider::new(field.clone()).with_friction(f64::NAN, 0.0), "friction"),
        (MeshCollider::new(field.clone()).with_restitution(1.5), "restitution"),
        (MeshCollider::new(field.clone()).on_body(0), "body 0 does not exist"),
    ] {
        let mut b = PbdBuilder::new();
        b.particle([0.0, 0.0, 2.0], 1.0);
        b.mesh_collider(MeshCollider::new(field.clone()));
        b.mesh_collider(m);
        let msg = b.build().expect_err("refused").to_string();
        assert!(msg.starts_with("mesh collider 1: ") && msg.contains(words), "{msg}");
    }
}

/// A plate of 1 m x 1 m x 1 cm, its top face at `z = 0`, sampled every 5 mm over a margin of
/// 5 cm: two layers of nodes inside it.
pub(crate) fn thin_plate() -> DistanceField {
    let (p, t) = anim_core::surface::cuboid([-0.5, -0.5, -0.01], [0.5, 0.5, 0.0]);
    let plate = ClosedSurface::new(p, t).expect("closed");
    DistanceField::around(&plate, 0.005, 0.05).expect("field")
}

/// The march finds where a path first comes within reach of the thin plate: on the near side
/// for a path through the plate from either side, at the start for a start within reach,
/// nowhere for a path that stays clear of it (beside it, above it, or outside the lattice), and
/// within the lattice for a path that starts outside it. The plate's top face is flat, so the
/// field there is exact and the point found lies within the march's stopping distance above
/// `z = reach` (`TOUCH` spacings), whatever the speed.
#[test]
fn the_march_finds_the_near_side_of_a_thin_plate() {
    use super::sweep::{TOUCH, first_touch};
    let field = thin_plate();
    let reach = 0.002;
    let stop = TOUCH * field.spacing();
    let on_segment = |a: DVec3, b: DVec3, y: DVec3| {
        let s = (y - a).dot(b - a) / (b - a).length_squared();
        (a + s * (b - a) - y).length() < 1e-9
    };
    for (a, b) in [
        ([0.1, 0.2, 0.3], [0.1, 0.2, -0.3]),
        ([0.1, 0.2, 0.05], [0.05, 0.15, -0.02]),
        ([0.0, 0.0, 0.01], [0.0, 0.0, -0.02]),
        // Starting outside the lattice, 100 m up (10 km/s over a substep of 1/100 s).
        ([0.0, 0.0, 100.0], [0.0, 0.0, -0.5]),
    ] {
        let (a, b) = (DVec3::from_array(a), DVec3::from_array(b));
        let y = first_touch(&field, a, b, reach).expect("touches");
        assert!(y.z >= reach && y.z <= reach + stop + 1e-7, "{a} -> {b}: {y}");
        assert!(on_segment(a, b, y), "{y} off the segment");
    }
    // A grazing path (13 degrees) closes a sixth of its gap per step: the steps run out short of
    // the plate, at a point still above it whose closest point is on the top face (the contact's
    // plane is the face's all the same).
    let (a, b) = (DVec3::new(0.1, 0.2, 0.05), DVec3::new(-0.2, 0.1, -0.02));
    let y = first_touch(&field, a, b, reach).expect("touches");
    let s = field.sample(y).expect("in the field");
    assert!(y.z > reach + stop && y.z < 0.02 && on_segment(a, b, y), "{y}");
    assert!((s.distance - y.z).abs() < 1e-7 && (s.normal() - DVec3::Z).length() < 1e-6, "{s:?}");
    // From below, through the bottom face at z = -0.01: stopped below it.
    let y =
        first_touch(&field, DVec3::new(0.0, 0.0, -0.2), DVec3::new(0.0, 0.0, 0.3), reach).expect("touches");
    assert!(y.z <= -0.01 - reach && y.z >= -0.01 - reach - stop - 1e-7, "{y}");
    // Starting within reach: the start.
    let a = DVec3::new(0.2, 0.0, 0.001);
    assert_eq!(first_touch(&field, a, DVec3::new(0.2, 0.0, -0.5), reach), Some(a));
    // Clear of it: beside the plate, above it, outside the lattice altogether.
    for (a, b) in [
        ([0.6, 0.0, 0.2], [0.6, 0.0, -0.2]),
        ([0.0, 0.0, 0.2], [0.1, 0.0, 0.01]),
        ([2.0, 0.0, 0.2], [2.0, 1.0, -0.2]),
    ] {
        let (a, b) = (DVec3::from_array(a), DVec3::from_array(b));
        assert_eq!(first_touch(&field, a, b, reach), None, "{a} -> {b}");
    }
}

/// Particles thrown at a 1 cm plate at 20 to 50 m/s, each substep moving them 8 to 21 cm, from
/// distances that put the end of the substep in which they reach it at every depth of the
/// plate and below it, head on and at 45 and 80 degrees: none is ever below the top face
/// (plus the thickness) while over the plate, and those thrown head on stop on it, at the
/// thickness (no restitution). Against the analytic box of the same plate, where a particle's
/// contact comes from its predicted position alone, most go through (the closest point of a
/// position past the middle of the plate is on its bottom face).
#[test]
fn particles_thrown_at_a_thin_mesh_plate_stop_on_its_near_side() {
    let t = 0.002;
    let field = thin_plate();
    let starts = 16;
    // The positions after each of 12 steps of 1/60 s (4 substeps).
    let run = |collider: Option<Collider>, mesh: Option<MeshCollider>, speed: f64, angle: f64| {
        let dir = DVec3::new(angle.sin(), 0.0, -angle.cos());
        let start: Vec<DVec3> = (0..starts)
            .map(|k| {
                let target = DVec3::new(if angle > 0.0 { -0.3 } else { 0.0 }, 0.02 * k as f64 - 0.15, 0.0);
                target - (0.3 / angle.cos() + (k as f64 / starts as f64) * speed / 240.0) * dir
            })
            .collect();
        let (mut sim, mut state) = particles(&start, true, collider, mesh);
        for v in state.v.chunks_mut(3) {
            v.copy_from_slice(&(speed * dir).to_array());
        }
        (0..12)
            .map(|_| {
                sim.run(&mut state, 1.0 / 60.0, 1).expect("runs");
                state.x.chunks_exact(3).map(|p| DVec3::new(p[0], p[1], p[2])).collect::<Vec<_>>()
            })
            .collect::<Vec<_>>()
    };
    let over = |x: &DVec3| x.x.abs() < 0.5 && x.y.abs() < 0.5;
    let mut through_box = 0;
    for speed in [20.0, 35.0, 50.0] {
        for angle in [0.0, 45f64.to_radians(), 80f64.to_radians()] {
            let mesh = MeshCollider::new(field.clone()).with_thickness(t).with_friction(1.0, 1.0);
            let path = run(None, Some(mesh), speed, angle);
            for (step, xs) in path.iter().enumerate() {
                for x in xs.iter().filter(|x| over(x)) {
                    assert!(x.z > t - 1e-6, "{speed} m/s at {angle} rad, step {step}: a particle at {x}");
                }
            }
            if angle == 0.0 {
                for x in &path[11] {
                    assert!((x.z - t).abs() < 1e-6 && over(x), "{speed} m/s head on: ended at {x}");
                }
            }
            let plate = Collider::cuboid([0.0, 0.0, -0.005], [0.5, 0.5, 0.005])
                .with_thickness(t)
                .with_friction(1.0, 1.0);
            let path = run(Some(plate), None, speed, angle);
            through_box +=
                (0..starts).filter(|&i| path.iter().any(|xs| over(&xs[i]) && xs[i].z < -0.01)).count();
        }
    }
    assert!(through_box > 9 * starts / 2, "{through_box} of {} through the analytic box", 9 * starts);
}
