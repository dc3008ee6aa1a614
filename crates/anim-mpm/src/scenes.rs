//! Ready-to-run scenes for the command line, the benches and the peer comparisons. All scenes
//! live in the unit box `[0, 1]^D`, y up.
//!
//! | scene | D | what | materials |
//! | --- | --- | --- | --- |
//! | `three-materials` | 2 | the classic jelly, snow and water blocks falling into a box | fixed corotated, snow (seed defaults), fluid |
//! | `dam-break-3d` | 3 | a water column collapsing along a box | fluid |
//! | `snowball` | 3 | a snowball thrown against a wall, flattening and sliding down | snow (seed defaults), box collider with friction |
//! | `benchmark-2d` | 2 | the `mpm88` fluid scene of the peer benchmark (8192 particles at 128^2) | fluid |
//! | `benchmark-3d` | 3 | the `mpm3d` fluid scene of the peer benchmark (65536 particles at 64^3) | fluid |
//!
//! ```
//! use anim_mpm::scenes;
//!
//! let mut scene = scenes::by_name("three-materials", Some(32)).expect("a known scene")?;
//! let report = scene.step()?;
//! assert!(report.time > 0.0);
//! assert_eq!(scene.positions().len(), scene.material_ids().len());
//! # Ok::<(), anim_mpm::MpmError>(())
//! ```

use crate::material::{Elastic, ElasticModel, Fluid, Material, Snow};
use crate::{Boundary, Collider, MpmError, MpmParams, MpmSimulation, Particles, Shape};
use anim_core::solver::{Solver, StepReport};

/// The built-in scene names.
pub const NAMES: [&str; 5] = ["three-materials", "dam-break-3d", "snowball", "benchmark-2d", "benchmark-3d"];

/// A scene in `D` dimensions: the simulation, its particles and how to step it.
#[derive(Debug, Clone)]
pub struct Scene<const D: usize> {
    /// Short name.
    pub name: &'static str,
    /// One-line description.
    pub description: &'static str,
    /// The simulation.
    pub sim: MpmSimulation<D>,
    /// The particles.
    pub state: Particles<D>,
    /// Time step of one [`Solver::step`] (substeps are added when the CFL limits need them).
    pub dt: f64,
    /// Suggested simulated duration.
    pub duration: f64,
}

/// A scene of either dimension, with what a runner needs.
#[derive(Debug, Clone)]
pub enum MpmScene {
    /// A 2D scene.
    Two(Scene<2>),
    /// A 3D scene.
    Three(Scene<3>),
}

impl MpmScene {
    /// The scene's name.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            MpmScene::Two(s) => s.name,
            MpmScene::Three(s) => s.name,
        }
    }

    /// One-line description.
    #[must_use]
    pub fn description(&self) -> &'static str {
        match self {
            MpmScene::Two(s) => s.description,
            MpmScene::Three(s) => s.description,
        }
    }

    /// 2 or 3.
    #[must_use]
    pub fn dim(&self) -> usize {
        match self {
            MpmScene::Two(_) => 2,
            MpmScene::Three(_) => 3,
        }
    }

    /// Time step of [`step`](Self::step).
    #[must_use]
    pub fn dt(&self) -> f64 {
        match self {
            MpmScene::Two(s) => s.dt,
            MpmScene::Three(s) => s.dt,
        }
    }

    /// Suggested simulated duration.
    #[must_use]
    pub fn duration(&self) -> f64 {
        match self {
            MpmScene::Two(s) => s.duration,
            MpmScene::Three(s) => s.duration,
        }
    }

    /// Steps of `dt` covering the duration.
    #[must_use]
    pub fn steps(&self) -> usize {
        (self.duration() / self.dt()).round().max(1.0) as usize
    }

    /// Simulated time.
    #[must_use]
    pub fn time(&self) -> f64 {
        match self {
            MpmScene::Two(s) => s.sim.time(),
            MpmScene::Three(s) => s.sim.time(),
        }
    }

    /// Number of particles.
    #[must_use]
    pub fn len(&self) -> usize {
        match self {
            MpmScene::Two(s) => s.state.len(),
            MpmScene::Three(s) => s.state.len(),
        }
    }

    /// Whether the scene has no particles.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Advances by [`dt`](Self::dt).
    ///
    /// # Errors
    /// The simulation's [`MpmError`] (divergence, CFL substep limit).
    pub fn step(&mut self) -> Result<StepReport, MpmError> {
        match self {
            MpmScene::Two(s) => s.sim.step(&mut s.state, s.dt),
            MpmScene::Three(s) => s.sim.step(&mut s.state, s.dt),
        }
    }

    /// Particle positions as 3-vectors (z = 0 in 2D), in the current (sorted) order.
    #[must_use]
    pub fn positions(&self) -> Vec<[f32; 3]> {
        match self {
            MpmScene::Two(s) => s.state.x.chunks_exact(2).map(|p| [p[0], p[1], 0.0]).collect(),
            MpmScene::Three(s) => s.state.x.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect(),
        }
    }

    /// Per-particle material index (for colouring), in the same order as
    /// [`positions`](Self::positions).
    #[must_use]
    pub fn material_ids(&self) -> &[u16] {
        match self {
            MpmScene::Two(s) => &s.state.material,
            MpmScene::Three(s) => &s.state.material,
        }
    }

    /// Per-particle speed (a scalar for colouring).
    #[must_use]
    pub fn speeds(&self) -> Vec<f32> {
        fn speeds<const D: usize>(v: &[f32]) -> Vec<f32> {
            v.chunks_exact(D).map(|c| c.iter().map(|x| x * x).sum::<f32>().sqrt()).collect()
        }
        match self {
            MpmScene::Two(s) => speeds::<2>(&s.state.v),
            MpmScene::Three(s) => speeds::<3>(&s.state.v),
        }
    }
}

/// Builds a scene by name (see [`NAMES`]); `None` for an unknown name. `resolution` is the grid
/// cells per axis (`None`: the scene's default).
#[must_use]
pub fn by_name(name: &str, resolution: Option<usize>) -> Option<Result<MpmScene, MpmError>> {
    Some(match name {
        "three-materials" => three_materials(resolution.unwrap_or(128)).map(MpmScene::Two),
        "dam-break-3d" => dam_break_3d(resolution.unwrap_or(48)).map(MpmScene::Three),
        "snowball" => snowball(resolution.unwrap_or(64)).map(MpmScene::Three),
        "benchmark-2d" => benchmark_2d(resolution.unwrap_or(128)).map(MpmScene::Two),
        "benchmark-3d" => benchmark_3d(resolution.unwrap_or(64)).map(MpmScene::Three),
        _ => return None,
    })
}

/// A small deterministic generator (SplitMix64) for jittered and random sampling.
#[derive(Debug, Clone)]
pub struct SplitMix(u64);

impl SplitMix {
    /// Seeded generator.
    #[must_use]
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// Uniform in `[0, 1)`.
    pub fn next_f32(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Adds particles on a lattice of `per_cell` particles per cell and axis over the box
/// `[lo, hi]` for which `inside` holds, with mass from `density` and rest volume
/// `(h / per_cell)^D`; returns how many were added.
///
/// # Errors
/// [`MpmError::BadParticle`] (non-finite input).
pub fn fill<const D: usize>(
    particles: &mut Particles<D>,
    h: f64,
    per_cell: usize,
    lo: [f64; D],
    hi: [f64; D],
    material: u16,
    density: f64,
    velocity: [f32; D],
    inside: impl Fn(&[f64; D]) -> bool,
) -> Result<usize, MpmError> {
    let s = h / per_cell as f64;
    let vol = s.powi(D as i32);
    let counts: [usize; D] = std::array::from_fn(|a| ((hi[a] - lo[a]) / s).floor().max(0.0) as usize);
    let total: usize = counts.iter().product();
    let mut added = 0;
    for flat in 0..total {
        let mut r = flat;
        let mut x = [0.0f64; D];
        for a in 0..D {
            x[a] = lo[a] + (r % counts[a]) as f64 * s + 0.5 * s;
            r /= counts[a];
        }
        if inside(&x) {
            particles.push(x.map(|c| c as f32), velocity, (density * vol) as f32, vol as f32, material)?;
            added += 1;
        }
    }
    Ok(added)
}

/// The classic 2D scene: jelly, snow and water blocks fall into a box and interact.
///
/// # Errors
/// [`MpmError`] for a resolution below 8.
pub fn three_materials(n: usize) -> Result<Scene<2>, MpmError> {
    let params = MpmParams::with_resolution(n);
    let h = params.h();
    let materials = vec![
        Material::Elastic(Elastic {
            model: ElasticModel::FixedCorotated,
            young: 2e4,
            poisson: 0.3,
            density: 1000.0,
        }),
        Material::Snow(Snow::default()),
        Material::Fluid(Fluid { bulk: 1e5, gamma: 1.0, density: 1000.0 }),
    ];
    let mut p = Particles::<2>::new();
    let all = |_: &[f64; 2]| true;
    fill(&mut p, h, 2, [0.1, 0.45], [0.3, 0.65], 0, 1000.0, [0.0; 2], all)?;
    fill(&mut p, h, 2, [0.4, 0.6], [0.6, 0.8], 1, 400.0, [0.0, -1.0], all)?;
    fill(&mut p, h, 2, [0.65, 0.1], [0.9, 0.45], 2, 1000.0, [0.0; 2], all)?;
    Ok(Scene {
        name: "three-materials",
        description: "jelly, snow and water blocks falling into a box (MLS-MPM, 2D)",
        sim: MpmSimulation::new(params, materials)?,
        state: p,
        dt: 5e-4,
        duration: 3.0,
    })
}

/// A 3D dam break: a water column `0.3 x 0.6` (depth 0.4) collapses along the box.
///
/// # Errors
/// [`MpmError`] for a resolution below 8.
pub fn dam_break_3d(n: usize) -> Result<Scene<3>, MpmError> {
    let params = MpmParams::with_resolution(n);
    let h = params.h();
    let (lo, _) = params.particle_range();
    let lo = lo + h;
    let mut p = Particles::<3>::new();
    fill(&mut p, h, 2, [lo, lo, 0.3], [lo + 0.3, lo + 0.6, 0.7], 0, 1000.0, [0.0; 3], |_| true)?;
    Ok(Scene {
        name: "dam-break-3d",
        description: "a water column collapsing along a box (MLS-MPM, 3D)",
        sim: MpmSimulation::new(
            params,
            vec![Material::Fluid(Fluid { bulk: 1e5, gamma: 1.0, density: 1000.0 })],
        )?,
        state: p,
        dt: 1e-3,
        duration: 2.0,
    })
}

/// A snowball (radius 0.1, 6 m/s) thrown against a wall (separating contact, Coulomb friction
/// 0.5): it flattens, partly sticks by friction and slides down.
///
/// # Errors
/// [`MpmError`] for a resolution below 8.
pub fn snowball(n: usize) -> Result<Scene<3>, MpmError> {
    let mut params = MpmParams::with_resolution(n);
    params.colliders.push(Collider::fixed(
        Shape::Box { center: [0.85, 0.5, 0.5], half: [0.05, 0.45, 0.45] },
        Boundary::Separate { friction: 0.5 },
    ));
    params.wall = Boundary::Separate { friction: 0.3 };
    let h = params.h();
    let mut p = Particles::<3>::new();
    let c = [0.35, 0.55, 0.5];
    fill(&mut p, h, 2, [0.25, 0.45, 0.4], [0.45, 0.65, 0.6], 0, 400.0, [6.0, 1.0, 0.0], |x| {
        (x[0] - c[0]).powi(2) + (x[1] - c[1]).powi(2) + (x[2] - c[2]).powi(2) <= 0.01
    })?;
    Ok(Scene {
        name: "snowball",
        description: "a snowball thrown against a wall (MLS-MPM, snow, 3D)",
        sim: MpmSimulation::new(params, vec![Material::Snow(Snow::default())])?,
        state: p,
        dt: 5e-4,
        duration: 1.0,
    })
}

/// Parameters of the `mpm88` / `mpm3d` fluid benchmark (Taichi's examples): `n` cells per
/// axis, `dt`, `E = 400` (`tau = E (J - 1) I`), unit density, particle volume `(h/2)^2` in both
/// dimensions (as the examples have it), gravity 9.8, walls 3 nodes thick, particles uniformly
/// random in a box.
pub mod benchmark {
    /// Particles of the 2D scene at `n` cells: `n^2 / 2` (8192 at 128).
    #[must_use]
    pub fn particles_2d(n: usize) -> usize {
        n * n / 2
    }
    /// Time step of the 2D scene: `2e-4 * 128 / n`.
    #[must_use]
    pub fn dt_2d(n: usize) -> f64 {
        2e-4 * 128.0 / n as f64
    }
    /// Particles of the 3D scene at `n` cells: `n^3 / 4`.
    #[must_use]
    pub fn particles_3d(n: usize) -> usize {
        n * n * n / 4
    }
    /// Time step of the 3D scene: `4e-4 * 32 / n`.
    #[must_use]
    pub fn dt_3d(n: usize) -> f64 {
        4e-4 * 32.0 / n as f64
    }
}

fn benchmark_scene<const D: usize>(
    n: usize,
    count: usize,
    dt: f64,
    lo: f32,
    side: f32,
    name: &'static str,
    description: &'static str,
) -> Result<Scene<D>, MpmError> {
    let mut params = MpmParams::with_resolution(n);
    params.gravity = [0.0, -9.8, 0.0];
    params.wall = Boundary::SeparateFrictionless;
    params.wall_nodes = 3;
    // The peer runs fixed steps: do the same (no CFL substeps) and let the scene stay stable.
    params.wave_cfl = f64::INFINITY;
    params.cfl = f64::INFINITY;
    let h = params.h() as f32;
    let vol = (0.5 * h) * (0.5 * h);
    let mut p = Particles::<D>::new();
    let mut rng = SplitMix::new(20_240_601);
    for _ in 0..count {
        let x: [f32; D] = std::array::from_fn(|_| lo + side * rng.next_f32());
        p.push(x, [0.0; D], vol, vol, 0)?;
    }
    Ok(Scene {
        name,
        description,
        sim: MpmSimulation::new(
            params,
            vec![Material::Fluid(Fluid { bulk: 400.0, gamma: 1.0, density: 1.0 })],
        )?,
        state: p,
        dt,
        duration: 2000.0 * dt,
    })
}

/// Taichi's `mpm88`: `8192 (n/128)^2` fluid particles in `[0.2, 0.6]^2`, `n^2` cells.
///
/// # Errors
/// [`MpmError`] for a resolution below 8.
pub fn benchmark_2d(n: usize) -> Result<Scene<2>, MpmError> {
    benchmark_scene(
        n,
        benchmark::particles_2d(n),
        benchmark::dt_2d(n),
        0.2,
        0.4,
        "benchmark-2d",
        "mpm88 fluid (peer benchmark, 2D)",
    )
}

/// Taichi's `mpm3d`: `n^3 / 4` fluid particles in `[0.15, 0.55]^3`, `n^3` cells.
///
/// # Errors
/// [`MpmError`] for a resolution below 8.
pub fn benchmark_3d(n: usize) -> Result<Scene<3>, MpmError> {
    benchmark_scene(
        n,
        benchmark::particles_3d(n),
        benchmark::dt_3d(n),
        0.15,
        0.4,
        "benchmark-3d",
        "mpm3d fluid (peer benchmark, 3D)",
    )
}
