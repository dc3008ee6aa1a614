//! The body contacts: the grid finds exactly the contacts of an all-pairs search (near the origin
//! and far from it, triangles of sizes 10x apart), a particle just inside a closed body ends
//! `thickness` outside it, one deeper than the search reach stays inside, and friction between
//! two soft bodies stops a sliding cube where Coulomb's law does.

use super::super::scratch::Data;
use super::*;
use crate::{BodyContact, PbdBuilder, PbdParams, PbdSimulation, TetMeshParams, shapes};
use anim_core::integrate::State;
use anim_core::solver::Solver;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The contacts of an all-pairs search: every particle against every triangle of every other
/// body, with the grid's reach test (boxes relative to their lowest corner) and contact.
fn brute_force(model: &PbdModel, x: &[DVec3], p: &[DVec3], margin: f64) -> Vec<PairContact> {
    let motion = |i: usize| (p[i] - x[i]).length();
    let surface: Vec<([u32; 3], usize)> = model
        .contact_bodies
        .iter()
        .enumerate()
        .flat_map(|(b, body)| body.triangles.iter().map(move |t| (t.map(|i| i as u32), b)))
        .collect();
    let mut boxes: Vec<(DVec3, DVec3, f64)> = surface
        .iter()
        .map(|&(t, _)| {
            let c = t.map(|i| p[i as usize]);
            let moved = t.iter().map(|&i| motion(i as usize)).fold(0.0, f64::max);
            (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]), moved)
        })
        .collect();
    let origin = boxes.iter().fold(DVec3::INFINITY, |o, b| o.min(b.0));
    for b in &mut boxes {
        (b.0, b.1) = (b.0 - origin, b.1 - origin);
    }
    let thickness = model.body_contact.thickness;
    let mut out = Vec::new();
    for (own, body) in model.contact_bodies.iter().enumerate() {
        for i in body.particles.0..body.particles.1 {
            let near = thickness + margin + motion(i);
            for (other, to) in model.contact_bodies.iter().enumerate() {
                if other == own {
                    continue;
                }
                let mut best: Option<((f64, f64), [u32; 3])> = None;
                for (&(t, from), b) in surface.iter().zip(&boxes) {
                    if from != other {
                        continue;
                    }
                    if let Some(found) =
                        reach_distance(p, &model.inv_mass, i, p[i] - origin, near, t, b, to.closed)
                        && best.is_none_or(|(d, _)| beats(found, d, tie(near)))
                    {
                        best = Some((found, t));
                    }
                }
                if let Some((_, t)) = best
                    && let Some(c) = pair_contact(x, p, i, t, to.closed)
                {
                    out.push(c);
                }
            }
        }
    }
    out
}

/// The grid's contacts at start positions `x` and predicted positions `p`.
fn grid(model: &PbdModel, x: &[DVec3], p: &[DVec3], margin: f64) -> Vec<PairContact> {
    let mut d = Data::new(model);
    d.x.copy_from_slice(x);
    d.p.copy_from_slice(p);
    generate_body_contacts(model, &mut d, margin);
    d.bodies.contacts.clone()
}

/// Adds a contact body of `positions` (mass 1 each) with surface `triangles` (local indices).
fn add_body(b: &mut PbdBuilder, positions: &[[f64; 3]], triangles: &[[usize; 3]], closed: bool) -> usize {
    let first = b.num_particles();
    for &p in positions {
        b.particle(p, 1.0);
    }
    let tris: Vec<[usize; 3]> = triangles.iter().map(|t| t.map(|i| first + i)).collect();
    b.contact_body(first..first + positions.len(), &tris, closed)
}

/// A closed box of `n^3` cells of side `h` from `origin`: its particles and outward surface.
fn closed_box(n: usize, origin: [f64; 3], h: f64) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let (p, t) = shapes::tet_box([n; 3], origin, h);
    let s = shapes::tet_surface(&p, &t);
    (p, s)
}

/// A square grid of `n x n` particles `h` apart, rotated by `angles` (about x, then y, then z)
/// about the origin and moved to `center`: positions and triangles.
fn tilted_grid(n: usize, h: f64, angles: [f64; 3], center: [f64; 3]) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let r =
        anim_core::glam::DQuat::from_euler(anim_core::glam::EulerRot::ZYX, angles[2], angles[1], angles[0]);
    let half = h * (n - 1) as f64 / 2.0;
    let mut p = Vec::new();
    for iy in 0..n {
        for ix in 0..n {
            let q =
                r * DVec3::new(ix as f64 * h - half, iy as f64 * h - half, 0.0) + DVec3::from_array(center);
            p.push(q.to_array());
        }
    }
    let mut t = Vec::new();
    for iy in 0..n - 1 {
        for ix in 0..n - 1 {
            let a = iy * n + ix;
            t.push([a, a + 1, a + n + 1]);
            t.push([a, a + n + 1, a + n]);
        }
    }
    (p, t)
}

/// Compares the grid with the all-pairs search at `x`, `p` and at `x + shift`, `p + shift` for
/// shifts of 3e13 m (where a box's rounding used to spread it over a third cell) and 1e14 m
/// (past the old grid's range); returns the numbers of contacts. Far from the origin the
/// positions are rounded to millimetres, so the contacts differ from those near it.
fn compare(model: &PbdModel, x: &[DVec3], p: &[DVec3], case: &str) -> Vec<usize> {
    let margin = 0.005;
    let mut counts = Vec::new();
    for shift in [0.0, 3e13, 1e14] {
        let xs: Vec<DVec3> = x.iter().map(|&v| v + shift).collect();
        let ps: Vec<DVec3> = p.iter().map(|&v| v + shift).collect();
        let expected = brute_force(model, &xs, &ps, margin);
        assert_eq!(grid(model, &xs, &ps, margin), expected, "{case}, shifted by {shift:e} m");
        counts.push(expected.len());
    }
    counts
}

/// A tilted 41 x 41 cloth of 5 cm cells through a closed box of 5 cm cells, and a small pinned
/// cloth beside them; with `coarse`, also a closed box of 0.5 m cells (10x the others).
fn bodies(coarse: bool) -> PbdModel {
    let mut b = PbdBuilder::new();
    let (cloth, cloth_tris) = tilted_grid(41, 0.05, [0.6, 0.5, 0.3], [0.0, 0.0, 0.0]);
    add_body(&mut b, &cloth, &cloth_tris, false);
    let (cube, cube_tris) = closed_box(4, [-0.1, -0.1, -0.1], 0.05);
    add_body(&mut b, &cube, &cube_tris, true);
    let (patch, patch_tris) = tilted_grid(5, 0.02, [0.0, 0.0, 0.0], [-0.3, 0.2, 0.004]);
    let first = b.num_particles();
    add_body(&mut b, &patch, &patch_tris, false);
    for i in first..first + 5 {
        b.pin(i);
    }
    if coarse {
        let (coarse, coarse_tris) = closed_box(2, [0.3, -0.5, -0.5], 0.5);
        add_body(&mut b, &coarse, &coarse_tris, true);
    }
    b.body_contact(BodyContact { thickness: 0.005, ..BodyContact::default() });
    b.build().expect("builds")
}

/// Two bodies of `n^3` separate triangles each, `(0, 0, 0)`, `(h, h, 0)`, `(0, h, h)` with
/// `h = 5 cm` on a lattice 13 cm apart: every triangle's box is a cube, so its box grown by
/// the search radius is about one grid cell and spans two cells on every axis (the table's
/// bound) nearly always. The second body is the first moved 8 mm along the triangles' normal,
/// so that each of its particles touches a triangle of the first.
/// With `lone`, a third body: one small triangle at the origin.
fn soup(n: usize, lone: bool) -> PbdModel {
    let h = 0.05;
    let normal = DVec3::new(1.0, -1.0, 1.0).normalize();
    let mut b = PbdBuilder::new();
    for offset in [DVec3::ZERO, 0.008 * normal] {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for k in 0..n * n * n {
            let corner = 0.13 * DVec3::new((k % n) as f64, (k / n % n) as f64, (k / n / n) as f64) + offset;
            triangles.push([0, 1, 2].map(|j| positions.len() + j));
            for v in [[0.0, 0.0, 0.0], [h, h, 0.0], [0.0, h, h]] {
                positions.push((corner + DVec3::from_array(v)).to_array());
            }
        }
        add_body(&mut b, &positions, &triangles, false);
    }
    if lone {
        add_body(&mut b, &[[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.0, 0.01, 0.0]], &[[0, 1, 2]], false);
    }
    b.body_contact(BodyContact { thickness: 0.005, ..BodyContact::default() });
    b.build().expect("builds")
}

/// At rest the grown boxes of the soup's triangles and of the cloth's are about one grid cell;
/// with random motions of up to 1 and 5 cm the cells grow, and with the coarse box most
/// triangles are much smaller than a cell.
#[test]
fn the_grid_finds_the_contacts_of_an_all_pairs_search_near_and_far_from_the_origin() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for (name, model) in [("soup", soup(10, false)), ("cloth", bodies(false)), ("coarse", bodies(true))] {
        let x: Vec<DVec3> = model.positions.iter().map(|&p| DVec3::from_array(p)).collect();
        let counts = compare(&model, &x, &x, &format!("{name}, at rest"));
        assert!(counts.iter().all(|&n| n > 10), "{name}, at rest: {counts:?} contacts");
        for jitter in [0.01, 0.05] {
            let p: Vec<DVec3> = x
                .iter()
                .map(|&v| v + DVec3::from_array([(); 3].map(|()| rng.random_range(-jitter..jitter))))
                .collect();
            let case = format!("{name}, motions of {jitter} m");
            let counts = compare(&model, &x, &p, &case);
            assert!(counts.iter().all(|&n| n > 50), "{case}: {counts:?} contacts");
        }
    }
}

/// A scene 3e13 m across: the soup there and a triangle at the origin. The grid's cells are
/// counted from the triangle, so rounding spreads the soup's boxes over a third cell and the
/// table grows; every contact is still found.
#[test]
fn the_grid_of_a_scene_as_wide_as_3e13_m_grows_its_table_and_finds_every_contact() {
    let model = soup(10, true);
    let lone = model.contact_bodies[2].particles.0;
    let x: Vec<DVec3> = model
        .positions
        .iter()
        .enumerate()
        .map(|(i, &p)| DVec3::from_array(p) + if i < lone { 3e13 } else { 0.0 })
        .collect();
    let expected = brute_force(&model, &x, &x, 0.005);
    let mut d = Data::new(&model);
    let table = d.bodies.entries.len();
    d.x.copy_from_slice(&x);
    d.p.copy_from_slice(&x);
    generate_body_contacts(&model, &mut d, 0.005);
    assert!(d.bodies.entries.len() > table, "the table stayed at {table} entries");
    assert_eq!(d.bodies.contacts, expected);
    assert!(expected.len() > 1000, "{} contacts", expected.len());
}

/// A model of a pinned closed box (the cube from -0.1 to 0.1) and one free particle at `z`
/// above its centre, with thickness `thickness`; no gravity.
fn particle_and_box(z: f64, thickness: f64) -> (PbdSimulation, State) {
    let mut b = PbdBuilder::new();
    b.gravity([0.0; 3]);
    let (cube, tris) = closed_box(2, [-0.1, -0.1, -0.1], 0.1);
    add_body(&mut b, &cube, &tris, true);
    for i in 0..cube.len() {
        b.pin(i);
    }
    add_body(&mut b, &[[0.01, 0.02, z]], &[], false);
    b.body_contact(BodyContact { thickness, ..BodyContact::default() });
    let model = b.build().expect("builds");
    let state = model.rest_state();
    let sim = PbdSimulation::new(model, PbdParams::default()).expect("valid");
    (sim, state)
}

/// A particle 4 mm inside a closed body's top face comes out to `thickness` above it in one
/// step; one 5 cm inside, deeper than the search reach (`thickness + margin` at rest), gets no
/// contact and stays where it is.
#[test]
fn a_particle_just_inside_a_closed_body_ends_thickness_outside_and_a_deep_one_stays() {
    let thickness = 0.01;
    let (mut sim, mut state) = particle_and_box(0.1 - 0.004, thickness);
    let last = state.x.len() - 1;
    sim.step(&mut state, 1.0 / 60.0).expect("step");
    assert!((state.x[last] - (0.1 + thickness)).abs() < 1e-12, "z {}", state.x[last]);
    let (mut sim, mut state) = particle_and_box(0.1 - 0.05, thickness);
    sim.step(&mut state, 1.0 / 60.0).expect("step");
    assert_eq!(state.x[last], 0.1 - 0.05);
}

/// A soft cube (0.1 m, rigid) sliding at 1 m/s on a pinned soft slab (1 m, of `cells^3` cells),
/// under `gravity`, `thickness` above it, with friction `mu` between them: how far its centre
/// went in `seconds`, and its mean x velocity then. With one cell the slab's vertices are its
/// corners, out of the cube's way; with ten, the cube passes over vertices level with its
/// bottom face, beside its edges.
fn slide_on(cells: usize, gravity: [f64; 3], mu: f64, seconds: f64) -> (f64, f64) {
    let thickness = 0.005;
    let mut b = PbdBuilder::new();
    b.gravity(gravity);
    let (slab, slab_tets) = shapes::tet_box([cells; 3], [-0.5, -0.5, -1.0], 1.0 / cells as f64);
    let params = TetMeshParams {
        mass: crate::MeshMass::Density(1000.0),
        stretch: Some(crate::ConstraintParams::rigid()),
        volume: Some(crate::ConstraintParams::rigid()),
    };
    let r = b.tet_mesh(&slab, &slab_tets, &params).expect("slab");
    let surface: Vec<[usize; 3]> = shapes::tet_surface(&slab, &slab_tets);
    b.contact_body(r.clone(), &surface, true);
    for i in r.clone() {
        b.pin(i);
    }
    let (cube, cube_tets) = shapes::tet_box([2, 2, 2], [-0.3, -0.05, thickness], 0.05);
    let c = b.tet_mesh(&cube, &cube_tets, &params).expect("cube");
    let surface: Vec<[usize; 3]> =
        shapes::tet_surface(&cube, &cube_tets).iter().map(|t| t.map(|i| c.start + i)).collect();
    b.contact_body(c.clone(), &surface, true);
    b.body_contact(BodyContact { thickness, static_friction: mu, kinetic_friction: mu });
    let model = b.build().expect("builds");
    let mut state = model.rest_state();
    for i in c.clone() {
        state.v[3 * i] = 1.0;
    }
    let mut sim = PbdSimulation::new(model, PbdParams { substeps: 8, iterations: 2, ..PbdParams::default() })
        .expect("valid");
    let mean_x = |s: &State| c.clone().map(|i| s.x[3 * i]).sum::<f64>() / c.len() as f64;
    let start = mean_x(&state);
    let dt = 1.0 / 60.0;
    for _ in 0..(seconds / dt).round() as usize {
        sim.step(&mut state, dt).expect("step");
    }
    let vx = c.clone().map(|i| state.v[3 * i]).sum::<f64>() / c.len() as f64;
    (mean_x(&state) - start, vx)
}

/// [`slide_on`] the slab of one cell under gravity.
fn slide(mu: f64, seconds: f64) -> (f64, f64) {
    slide_on(1, crate::EARTH_GRAVITY, mu, seconds)
}

/// Without friction the cube keeps its speed; with friction `mu` it decelerates at `mu g` and
/// stops after `v^2 / (2 mu g)` (Coulomb: 0.204 m for `mu = 0.25`, 0.102 m for 0.5), within 5%
/// (the contact starts a substep late; a substep is 2 mm of sliding).
#[test]
fn friction_between_bodies_stops_a_sliding_cube_where_coulomb_does() {
    let (dx, vx) = slide(0.0, 0.5);
    assert!((vx - 1.0).abs() < 1e-3, "frictionless: vx {vx}");
    assert!((dx - 0.5).abs() < 1e-3, "frictionless: slid {dx}");
    for mu in [0.25, 0.5] {
        let (dx, vx) = slide(mu, 0.5);
        let coulomb = 1.0 / (2.0 * mu * 9.81);
        assert!(vx.abs() < 1e-3, "mu {mu}: still moving at {vx}");
        assert!((dx - coulomb).abs() < 0.05 * coulomb, "mu {mu}: slid {dx}, Coulomb {coulomb}");
    }
}

/// Without friction the cube slides over a slab of 10 cm cells as over one of a single cell:
/// its bottom particles pass within `thickness` of the slab's vertices beside the cube's edges,
/// and the slab's vertices pass as close to the cube's bottom edges, where a side face is as
/// close as the bottom one. It keeps its speed within 1e-3 in 0.5 s, with gravity and without.
#[test]
fn a_frictionless_cube_slides_over_the_vertices_of_a_fine_slab_without_catching() {
    for gravity in [[0.0; 3], crate::EARTH_GRAVITY] {
        let (dx, vx) = slide_on(10, gravity, 0.0, 0.5);
        assert!((vx - 1.0).abs() < 1e-3, "gravity {gravity:?}: vx {vx}");
        assert!((dx - 0.5).abs() < 1e-3, "gravity {gravity:?}: slid {dx}");
    }
}
