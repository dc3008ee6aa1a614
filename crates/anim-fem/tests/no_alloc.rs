//! The architecture invariant "no solver allocates inside `step`" for FEM: after the first step,
//! symplectic Euler and backward Euler steps (every linear solver) of linear and 10-node bodies
//! (lumped and consistent mass, Rayleigh damping, kinematic nodes, a shape obstacle and a mesh
//! obstacle with friction, both touched by the body) on a rayon pool
//! of 2 threads perform no heap allocation. Counted by a wrapping global allocator, so this file is its own
//! test binary.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use anim_core::alloc_count::CountingAllocator;
use anim_core::surface::{ClosedSurface, DistanceField};
use anim_fem::boundary::{Motion, Obstacle};
use anim_fem::generate::box_mesh;
use anim_fem::material::{Material, MaterialModel};
use anim_fem::model::{EARTH_GRAVITY, ElementOrder, FemModel, MassKind};
use anim_fem::sim::{FemParams, FemSimulation, LinearSolverChoice, TimeIntegrator};

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

#[test]
fn steps_do_not_allocate() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
    let mesh = box_mesh([0.0, -0.05, 0.02], [0.6, 0.1, 0.1], [6, 1, 1]).unwrap();
    let material = Material::new(MaterialModel::StableNeoHookean, 1e5, 0.3, 1000.0).unwrap();
    // A block under the middle of the beam, its top 5 mm above the beam's bottom (z = 0.02).
    let (lo, hi) = ([0.15, -0.1, -0.1], [0.45, 0.1, 0.025]);
    let (corners, faces) = anim_core::surface::cuboid(lo, hi);
    let block = ClosedSurface::new(corners, faces).unwrap();
    let field = DistanceField::around(&block, 0.02, 0.05).unwrap();
    let explicit = FemParams::new(TimeIntegrator::SymplecticEuler);
    let implicit =
        LinearSolverChoice::ALL.map(|s| FemParams::new(TimeIntegrator::BackwardEuler).with_linear_solver(s));
    for order in [ElementOrder::Linear, ElementOrder::Quadratic] {
        for (mass, params) in [MassKind::Lumped, MassKind::Consistent]
            .into_iter()
            .flat_map(|m| std::iter::once(explicit).chain(implicit).map(move |p| (m, p)))
        {
            let mut model = FemModel::with_order(mesh.clone(), material, order)
                .unwrap()
                .with_mass(mass)
                .with_gravity(EARTH_GRAVITY);
            let left = model.vertices_where(|p| p[0] < 1e-9);
            let right = model.vertices_where(|p| p[0] > 0.6 - 1e-9);
            model.pin_vertices(&left).unwrap();
            model.add_kinematic(&right, Motion::Translate { velocity: [0.0, 0.0, -0.1] }).unwrap();
            model.add_obstacle(Obstacle::ground(0.0), 1e5).unwrap();
            model.add_mesh_obstacle(field.clone(), 1e5, 0.3).unwrap();
            let touching = model.mesh().positions.iter().filter(|p| {
                field.sample(anim_core::glam::DVec3::from_array(**p)).is_some_and(|s| s.distance < 0.0)
            });
            assert!(touching.count() >= 4, "the beam's bottom is inside the block");
            let mut sim = FemSimulation::new(model, params.with_rayleigh(1e-4)).unwrap();
            let mut state = sim.rest_state();
            // The counter sees every thread of the process, including the pool's own bookkeeping
            // (work-stealing deques free old buffers through epoch-based reclamation, which can
            // allocate on a loaded machine). A step that allocates does so in every block; three
            // blocks are run and one must be clean.
            let blocks: Vec<usize> = pool.install(|| {
                sim.advance(&mut state, 1e-5).expect("first step");
                let mut blocks = Vec::with_capacity(3);
                for _ in 0..3 {
                    let counted = ALLOC.count(|| {
                        for _ in 0..20 {
                            sim.advance(&mut state, 1e-5).expect("step");
                        }
                    });
                    blocks.push(counted);
                    if blocks.last() == Some(&0) {
                        break;
                    }
                }
                blocks
            });
            assert_eq!(
                blocks.last(),
                Some(&0),
                "{order:?} {mass:?} {:?} {:?}: allocations per block of 20 steps {blocks:?}",
                params.integrator,
                params.linear_solver
            );
        }
    }
}
