//! A mesh obstacle against its analytic shape: particles pressed onto a sphere of radius 0.3 m
//! and onto an icosphere of the same radius (5 subdivisions, 20,480 triangles) sampled as a
//! signed distance field of spacing `cell`, for several cells. Prints, per cell: the largest
//! distance between a particle's resting position on the mesh and on the sphere (and the
//! polyhedron's sagitta, the part of it no cell removes), the time to build the field, and the
//! time of a step of the drape scene (a 32 x 32 cloth falling onto the sphere) with the analytic
//! sphere and with the mesh sphere. Times are medians of 5 runs on one thread.
//!
//! ```sh
//! cargo run --release -p anim-pbd --example mesh_sphere
//! ```

use anim_core::glam::DVec3;
use anim_core::surface::{ClosedSurface, DistanceField, icosphere};
use anim_pbd::{
    Bending, Cloth, Collider, ConstraintParams, EARTH_GRAVITY, MeshCollider, Method, PbdBuilder, PbdParams,
    PbdSimulation, SolverKind,
};
use std::time::Instant;

const R: f64 = 0.3;
const THICKNESS: f64 = 0.005;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Particles at rest on the sphere plus the thickness along `dirs`, pressed towards the centre
/// by 1 m/s^2 for 1 s; their end positions.
fn press(
    dirs: &[DVec3],
    collider: Option<Collider>,
    mesh: Option<MeshCollider>,
) -> Result<Vec<DVec3>, Error> {
    let mut b = PbdBuilder::new();
    for d in dirs {
        b.particle((*d * (R + THICKNESS)).to_array(), 0.1);
    }
    if let Some(c) = collider {
        b.collider(c);
    }
    if let Some(m) = mesh {
        b.mesh_collider(m);
    }
    let model = b.build()?;
    let mut state = model.rest_state();
    let mut sim = PbdSimulation::new(model, PbdParams::new(Method::Xpbd, SolverKind::GaussSeidel, 5, 4))?;
    for (i, d) in dirs.iter().enumerate() {
        sim.set_external_force(i, (-0.1 * *d).to_array());
    }
    sim.run(&mut state, 1.0 / 60.0, 60)?;
    Ok(state.x.chunks_exact(3).map(|p| DVec3::new(p[0], p[1], p[2])).collect())
}

/// The seconds per step of a 32 x 32 cloth falling onto the sphere at the origin (2 s of 1/60 s
/// steps, XPBD, coloured Gauss-Seidel, 5 iterations x 4 substeps).
fn drape(collider: Option<Collider>, mesh: Option<MeshCollider>) -> Result<f64, Error> {
    let n = 32;
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    b.cloth(&Cloth {
        nx: n,
        ny: n,
        origin: [-0.5, -0.5, 0.6],
        u: [1.0, 0.0, 0.0],
        v: [0.0, 1.0, 0.0],
        particle_mass: 0.3 / (n * n) as f64,
        stretch: ConstraintParams::rigid(),
        bending: Bending::Isometric(ConstraintParams::with_compliance(20.0)),
    })?;
    if let Some(c) = collider {
        b.collider(c);
    }
    if let Some(m) = mesh {
        b.mesh_collider(m);
    }
    let model = b.build()?;
    let mut state = model.rest_state();
    let mut sim =
        PbdSimulation::new(model, PbdParams::new(Method::Xpbd, SolverKind::ColoredGaussSeidel, 5, 4))?;
    let steps = 120;
    let start = Instant::now();
    sim.run(&mut state, 1.0 / 60.0, steps)?;
    Ok(start.elapsed().as_secs_f64() / steps as f64)
}

type Error = Box<dyn std::error::Error + Send + Sync>;

fn main() -> Result<(), Error> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    pool.install(run)
}

fn run() -> Result<(), Error> {
    let (p, t) = icosphere(5);
    let p = p.iter().map(|x| x.map(|c| R * c)).collect();
    let ball = ClosedSurface::new(p, t)?;
    let r_min = ball
        .triangles()
        .iter()
        .map(|tri| {
            let [a, b, c] = tri.map(|i| ball.positions()[i]);
            a.dot((b - a).cross(c - a).normalize()).abs()
        })
        .fold(f64::INFINITY, f64::min);
    // Directions spread over the sphere (a Fibonacci lattice of 50 points).
    let dirs: Vec<DVec3> = (0..50)
        .map(|k| {
            let z = 1.0 - (2 * k + 1) as f64 / 50.0;
            let phi = k as f64 * std::f64::consts::PI * (3.0 - 5f64.sqrt());
            let s = (1.0 - z * z).sqrt();
            DVec3::new(s * phi.cos(), s * phi.sin(), z)
        })
        .collect();
    let sphere = Collider::sphere([0.0; 3], R).with_thickness(THICKNESS).with_friction(1.0, 1.0);
    let exact = press(&dirs, Some(sphere), None)?;
    let analytic_step = median((0..5).map(|_| drape(Some(sphere), None)).collect::<Result<_, _>>()?);
    println!(
        "sphere R = {R} m, icosphere(5): {} triangles, sagitta R - r_min = {:.2e} m; thickness {THICKNESS} m",
        ball.triangles().len(),
        R - r_min
    );
    println!("drape step with the analytic sphere: {:.2} ms", 1e3 * analytic_step);
    println!();
    println!(
        "| cell (m) | nodes | max error vs analytic (m) | field build (ms) | step, analytic sphere (ms) | step, mesh sphere (ms) |"
    );
    println!("| --- | --- | --- | --- | --- | --- |");
    for cell in [0.04, 0.02, 0.01, 0.005] {
        let mut builds = Vec::new();
        let mut field = None;
        for _ in 0..5 {
            let start = Instant::now();
            let f = DistanceField::around(&ball, cell, THICKNESS + 0.005 + 2.0 * cell)?;
            builds.push(start.elapsed().as_secs_f64());
            field = Some(f);
        }
        let field = field.ok_or("no field")?;
        let nodes: usize = field.counts().iter().product();
        let mesh = MeshCollider::new(field).with_thickness(THICKNESS).with_friction(1.0, 1.0);
        let on_mesh = press(&dirs, None, Some(mesh.clone()))?;
        let error = on_mesh.iter().zip(&exact).map(|(a, b)| (*a - *b).length()).fold(0.0, f64::max);
        let analytic = median((0..5).map(|_| drape(Some(sphere), None)).collect::<Result<_, _>>()?);
        let step = median((0..5).map(|_| drape(None, Some(mesh.clone()))).collect::<Result<_, _>>()?);
        println!(
            "| {cell} | {nodes} | {error:.2e} | {:.1} | {:.2} | {:.2} |",
            1e3 * median(builds),
            1e3 * analytic,
            1e3 * step
        );
    }
    Ok(())
}
