//! The architecture invariant "no solver allocates inside `step`": after the first step, stepping
//! every scene (contacts, wind, a moving body, a global volume) and a cloth falling onto a mesh
//! obstacle (a distance field) with every solver on a rayon pool of 2 threads performs no heap
//! allocation. Counted by a wrapping global allocator, so this file is its own test binary.

use anim_core::alloc_count::CountingAllocator;
use anim_core::solver::Solver;
use anim_core::surface::{ClosedSurface, DistanceField, icosphere};
use anim_pbd::scenes::{self, PbdScene};
use anim_pbd::{
    Bending, BodyMotion, Cloth, Collider, ConstraintParams, EARTH_GRAVITY, KinematicBody, MeshCollider,
    PbdBuilder, PbdSimulation, Pose, SolverKind,
};

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

/// A cloth like the drape's falling onto a mesh sphere (an icosphere of 1280 triangles sampled
/// at 1 cm) on a swaying kinematic body, so that the field is queried in a moving frame too.
fn drape_on_a_mesh() -> Result<PbdScene, Box<dyn std::error::Error>> {
    let mut scene = scenes::cloth_drape(Some(16))?;
    let (p, t) = icosphere(3);
    let p = p.iter().map(|x| x.map(|c| 0.35 * c)).collect();
    let ball = ClosedSurface::new(p, t)?;
    let field = DistanceField::around(&ball, 0.01, 0.05)?;
    let mut b = PbdBuilder::new();
    b.gravity(EARTH_GRAVITY);
    b.cloth(&Cloth {
        nx: 16,
        ny: 16,
        origin: [-0.6, -0.6, 1.2],
        u: [1.2, 0.0, 0.0],
        v: [0.0, 1.2, 0.0],
        particle_mass: 0.3 / 256.0,
        stretch: ConstraintParams::rigid(),
        bending: Bending::Isometric(ConstraintParams::with_compliance(20.0)),
    })?;
    let body = b.body(KinematicBody::new(
        Pose::from_translation([0.05, 0.0, 0.35]),
        BodyMotion::Oscillate { amplitude: [0.0, 0.02, 0.0], frequency: 0.5 },
    ));
    b.collider(Collider::ground(0.0).with_thickness(0.01).with_friction(0.6, 0.4));
    b.mesh_collider(MeshCollider::new(field).with_thickness(0.01).with_friction(0.6, 0.4).on_body(body));
    scene.model = b.build()?;
    scene.state = scene.model.rest_state();
    Ok(scene)
}

const MESH: &str = "cloth drape on a mesh sphere";

#[test]
fn steps_do_not_allocate() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().expect("pool");
    let mut all: Vec<(&str, PbdScene)> = scenes::NAMES
        .iter()
        .map(|name| (*name, scenes::by_name(name, None).expect("known").expect("builds")))
        .collect();
    all.push((MESH, drape_on_a_mesh().expect("builds")));
    for (name, scene) in all {
        for solver in SolverKind::ALL {
            let scene = scene.clone();
            let dt = scene.dt;
            let mut params = scene.params;
            params.solver = solver;
            let mut sim = PbdSimulation::new(scene.model, params).expect("params");
            let mut state = scene.state;
            // The counter sees every thread of the process, including the thread pool's own
            // bookkeeping (its work-stealing deques free old buffers through epoch-based
            // reclamation, which can allocate when the machine is loaded). A step that allocates
            // does so in every block of 20 steps; three blocks are run and one must be clean.
            let blocks: Vec<usize> = pool.install(|| {
                sim.advance(&mut state, dt).expect("first step");
                let mut blocks = Vec::with_capacity(3);
                for _ in 0..3 {
                    let counted = ALLOC.count(|| {
                        for _ in 0..10 {
                            sim.advance(&mut state, dt).expect("step");
                            sim.step(&mut state, dt).expect("step with report");
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
                "{name} / {}: allocations in each block of 20 steps: {blocks:?}",
                solver.label()
            );
            if name == MESH {
                // The cloth lies on the mesh sphere's top (0.7 m), not on the ground.
                let top = state.x.chunks(3).map(|p| p[2]).fold(f64::MIN, f64::max);
                assert!(top > 0.7 && top < 0.75, "{name} / {}: the cloth's top at {top}", solver.label());
            }
        }
    }
}
