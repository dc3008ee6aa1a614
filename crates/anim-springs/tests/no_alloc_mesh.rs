//! A `springs` scene file with a mesh obstacle steps without allocating once its first step is
//! done: a cloth of more particles than the parallel threshold falls onto a closed OBJ ball
//! (`obstacle_meshes`), backward Euler with sparse Cholesky and symplectic Euler, on a rayon
//! pool of 2 threads (`anim_core::alloc_count::step_allocations`). Counted by a wrapping global
//! allocator, so this file is its own test binary.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use anim_core::alloc_count::{CountingAllocator, step_allocations};
use anim_core::scene::BuildContext;
use anim_core::surface::icosphere;

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

#[test]
fn steps_with_a_mesh_obstacle_do_not_allocate() {
    let dir = std::env::temp_dir().join(format!("anim-springs-no-alloc-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (p, t) = icosphere(3);
    let mut ball = String::new();
    for v in &p {
        ball += &format!("v {} {} {}\n", v[0], v[1], v[2]);
    }
    for f in &t {
        ball += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    std::fs::write(dir.join("ball.obj"), ball).unwrap();
    // A 1 m cloth of 48 x 48 vertices.
    let n = 48;
    assert!(n * n > anim_springs::network::PARALLEL_THRESHOLD);
    let mut cloth = String::new();
    for iy in 0..n {
        for ix in 0..n {
            cloth += &format!("v {} {} 0\n", ix as f64 / (n - 1) as f64, iy as f64 / (n - 1) as f64);
        }
    }
    for iy in 0..n - 1 {
        for ix in 0..n - 1 {
            let a = iy * n + ix + 1;
            cloth += &format!("f {} {} {}\nf {} {} {}\n", a, a + 1, a + n + 1, a, a + n + 1, a + n);
        }
    }
    std::fs::write(dir.join("cloth.obj"), cloth).unwrap();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    for (integrator, dt) in [("backward-euler", 0.005), ("symplectic-euler", 1e-4)] {
        let params = serde_json::json!({
            "bodies": [{
                "mesh": "cloth.obj",
                "material": { "density": 0.2, "stiffness": 100.0, "bending": 0.5 },
                "translate": [-0.5, -0.5, 0.301],
            }],
            "obstacle_meshes": [{ "mesh": "ball.obj", "scale": 0.3, "cell": 0.02 }],
            "contact": { "stiffness": 1e3, "thickness": 0.004 },
            "integrator": integrator,
        });
        let blocks = pool.install(|| {
            let mut scene = (anim_springs::KIND.build)(&params, &BuildContext { base: Some(&dir) }).unwrap();
            for _ in 0..3 {
                scene.step(dt).unwrap();
            }
            step_allocations(&ALLOC, scene.as_mut(), dt).unwrap()
        });
        assert_eq!(blocks.last(), Some(&0), "{integrator}: allocations per block of four steps {blocks:?}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
