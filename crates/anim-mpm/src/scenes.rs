//! Ready-to-run scenes for the command line, the benches and the peer comparisons. All scenes
//! live in the unit box `[0, 1]^D`, y up.
//!
//! | scene | D | what | materials |
//! | --- | --- | --- | --- |
//! | `three-materials` | 2 | the classic jelly, snow and water blocks falling into a box | fixed corotated, snow (default parameters), fluid |
//! | `dam-break-2d` | 2 | the dam break of the report's study against Martin & Moyce (1952): a 0.2 x 0.4 m column in a 1 m tank with no-slip walls ([`dam_break_2d`], [`SurgeFront`]) | fluid (`K` = 2.5 MPa) |
//! | `dam-break-3d` | 3 | a water column collapsing along a box | fluid |
//! | `snowball` | 3 | a snowball thrown against a wall, flattening and sliding down | snow (default parameters), box collider with friction |
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
use crate::{Boundary, Collider, Kernel, MpmError, MpmParams, MpmSimulation, Particles, Shape, Transfer};
use anim_core::solver::{Solver, StepReport};
use serde::{Deserialize, Serialize};

/// The built-in scene names.
pub const NAMES: [&str; 6] =
    ["three-materials", "dam-break-2d", "dam-break-3d", "snowball", "benchmark-2d", "benchmark-3d"];

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

    /// Rebuilds the simulation with another transfer and kernel (the particles, materials and
    /// every other parameter kept), before the first step.
    ///
    /// # Errors
    /// [`MpmError::BadParameter`] once the scene has stepped.
    pub fn set_method(&mut self, transfer: Transfer, kernel: Kernel) -> Result<(), MpmError> {
        fn rebuild<const D: usize>(
            s: &mut Scene<D>,
            transfer: Transfer,
            kernel: Kernel,
        ) -> Result<(), MpmError> {
            if s.sim.steps() > 0 {
                return Err(MpmError::BadParameter {
                    name: "transfer",
                    reason: "the method can only be changed before the first step".into(),
                });
            }
            let mut params = s.sim.params().clone();
            params.transfer = transfer;
            params.kernel = kernel;
            s.sim = MpmSimulation::new(params, s.sim.materials().to_vec())?;
            Ok(())
        }
        match self {
            MpmScene::Two(s) => rebuild(s, transfer, kernel),
            MpmScene::Three(s) => rebuild(s, transfer, kernel),
        }
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
    let n = resolution.or_else(|| resolution_default(name))?;
    if let Err(e) = check_resolution(name, n) {
        return Some(Err(e));
    }
    Some(match name {
        "three-materials" => three_materials(n).map(MpmScene::Two),
        "dam-break-2d" => dam_break_2d(n, 2, Transfer::Mls, Kernel::Quadratic).map(MpmScene::Two),
        "dam-break-3d" => dam_break_3d(n).map(MpmScene::Three),
        "snowball" => snowball(n).map(MpmScene::Three),
        "benchmark-2d" => benchmark_2d(n).map(MpmScene::Two),
        "benchmark-3d" => benchmark_3d(n).map(MpmScene::Three),
        _ => return None,
    })
}

/// The grid cells per axis of a scene when none is given; `None` for an unknown name.
#[must_use]
pub fn resolution_default(name: &str) -> Option<usize> {
    Some(match name {
        "three-materials" | "benchmark-2d" => 128,
        "dam-break-2d" => 64,
        "dam-break-3d" => 48,
        "snowball" | "benchmark-3d" => 64,
        _ => return None,
    })
}

/// The dimension of a scene, 2 or 3; `None` for an unknown name.
#[must_use]
pub fn dim(name: &str) -> Option<usize> {
    match name {
        "three-materials" | "dam-break-2d" | "benchmark-2d" => Some(2),
        _ if NAMES.contains(&name) => Some(3),
        _ => None,
    }
}

/// Refuses a resolution past what the grid's `u32` block keys address
/// ([`max_resolution`](crate::max_resolution)) before the particles are laid out (their number
/// grows as the resolution to the power of the dimension). The memory a resolution takes is
/// the `mpm` kind's to check ([`crate::memory`]).
fn check_resolution(name: &str, n: usize) -> Result<(), MpmError> {
    let Some(dim) = dim(name) else { return Ok(()) };
    let max = crate::sim::max_resolution(dim);
    if n > max {
        return Err(MpmError::BadParameter {
            name: "resolution",
            reason: format!("{n} must lie in [8, {max}] in {dim}D"),
        });
    }
    Ok(())
}

/// [`by_name`] with the particles per cell and axis of the scenes that take it (`dam-break-2d`;
/// `None`: 2); the other scenes place their own particles and refuse a count.
#[must_use]
pub fn by_name_with(
    name: &str,
    resolution: Option<usize>,
    per_cell: Option<usize>,
) -> Option<Result<MpmScene, MpmError>> {
    match (name, per_cell) {
        (_, None) => by_name(name, resolution),
        ("dam-break-2d", Some(k)) => {
            let n = resolution.unwrap_or(64);
            Some(
                check_resolution(name, n)
                    .and_then(|()| dam_break_2d(n, k, Transfer::Mls, Kernel::Quadratic).map(MpmScene::Two)),
            )
        }
        (_, Some(_)) if NAMES.contains(&name) => Some(Err(MpmError::BadParameter {
            name: "particles per cell",
            reason: format!("{name} places its own particles; only dam-break-2d takes a count"),
        })),
        _ => None,
    }
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
    let point = |flat: usize| {
        let mut r = flat;
        let mut x = [0.0f64; D];
        for a in 0..D {
            x[a] = lo[a] + (r % counts[a]) as f64 * s + 0.5 * s;
            r /= counts[a];
        }
        x
    };
    // Room for exactly the points kept: pushed one by one, the arrays would grow up to twice
    // what they hold.
    reserve(particles, (0..total).filter(|&flat| inside(&point(flat))).count());
    let mut added = 0;
    for flat in 0..total {
        let x = point(flat);
        if inside(&x) {
            particles.push(x.map(|c| c as f32), velocity, (density * vol) as f32, vol as f32, material)?;
            added += 1;
        }
    }
    Ok(added)
}

/// Room for `additional` more particles in each of `particles`' arrays.
pub(crate) fn reserve<const D: usize>(particles: &mut Particles<D>, additional: usize) {
    let p = particles;
    p.x.reserve_exact(D * additional);
    p.v.reserve_exact(D * additional);
    p.c.reserve_exact(D * D * additional);
    p.f.reserve_exact(D * D * additional);
    for scalars in [&mut p.plastic, &mut p.mass, &mut p.volume] {
        scalars.reserve_exact(additional);
    }
    p.material.reserve_exact(additional);
    p.id.reserve_exact(additional);
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

/// The 2D dam break of the report's study (Martin & Moyce 1952): a water column
/// [`DAM_BREAK_COLUMN`] wide and twice as high, against the left wall of a 1 m tank with no-slip
/// walls, collapses along the floor. `n` cells per axis, `per_cell x per_cell` particles per cell,
/// the given transfer and kernel; step [`dam_break_2d_dt`], duration up to Martin & Moyce's last
/// time `T = 3.33` ([`dam_break_duration`]). [`SurgeFront`] measures the surge front against
/// [`MARTIN_MOYCE`].
///
/// # Errors
/// [`MpmError`] for a resolution below 8, or `per_cell` outside `1..=8`.
pub fn dam_break_2d(
    n: usize,
    per_cell: usize,
    transfer: Transfer,
    kernel: Kernel,
) -> Result<Scene<2>, MpmError> {
    if !(1..=8).contains(&per_cell) {
        return Err(MpmError::BadParameter {
            name: "particles per cell",
            reason: format!("{per_cell} per axis is outside 1..=8"),
        });
    }
    let mut params = MpmParams::with_resolution(n);
    params.transfer = transfer;
    params.kernel = kernel;
    // No-slip walls, as the experiment's tank (a frictionless floor lets a thin film run ahead
    // of the measured front).
    params.wall = Boundary::Sticky;
    let h = params.h();
    let a = DAM_BREAK_COLUMN;
    let x0 = dam_break_wall(&params);
    // c = sqrt(K / rho) = 50 m/s, ten times the largest flow speed sqrt(2 g 2a) = 2.8 m/s.
    let fluid = Material::Fluid(Fluid { bulk: 2.5e6, gamma: 1.0, density: 1000.0 });
    let sim = MpmSimulation::<2>::new(params, vec![fluid])?;
    let mut p = Particles::<2>::new();
    fill(&mut p, h, per_cell, [x0, x0], [x0 + a, x0 + 2.0 * a], 0, 1000.0, [0.0; 2], |_| true)?;
    Ok(Scene {
        name: "dam-break-2d",
        description: "the 2D dam break of Martin & Moyce (1952): a 0.2 x 0.4 m water column collapsing",
        sim,
        state: p,
        dt: dam_break_2d_dt(n),
        duration: dam_break_duration(),
    })
}

/// Width `a` of the dam-break column (m); its height is `2a`.
pub const DAM_BREAK_COLUMN: f64 = 0.2;

/// Gravity of the dam break (m/s^2), for its time scale.
const DAM_BREAK_GRAVITY: f64 = 9.81;

/// Simulated time of Martin & Moyce's last tabulated front, `T = 3.33` (s).
#[must_use]
pub fn dam_break_duration() -> f64 {
    MARTIN_MOYCE[MARTIN_MOYCE.len() - 1].0 / dam_break_time_scale()
}

/// The dam break's step at `n` cells per axis: half a cell per sound crossing (`c = 50` m/s).
#[must_use]
pub fn dam_break_2d_dt(n: usize) -> f64 {
    0.5 * MpmParams::with_resolution(n).h() / 50.0
}

/// The dam break's dimensionless time scale `sqrt(2 g / a)`: `T = t sqrt(2 g / a)`.
#[must_use]
pub fn dam_break_time_scale() -> f64 {
    (2.0 * DAM_BREAK_GRAVITY / DAM_BREAK_COLUMN).sqrt()
}

/// Where the dam-break column starts: the inner face of the left wall (`wall_nodes` cells).
fn dam_break_wall(params: &MpmParams) -> f64 {
    params.wall_nodes as f64 * params.h()
}

/// Martin & Moyce (1952), tables 2 and 6, `a` = 2.25 in, `n^2 = 2`: the surge front
/// `Z = x / a` at `T = t sqrt(2 g / a)`, as `(T, Z)`.
pub const MARTIN_MOYCE: [(f64, f64); 15] = [
    (0.41, 1.11),
    (0.84, 1.22),
    (1.19, 1.44),
    (1.43, 1.67),
    (1.63, 1.89),
    (1.83, 2.11),
    (1.98, 2.33),
    (2.20, 2.56),
    (2.32, 2.78),
    (2.51, 3.00),
    (2.65, 3.22),
    (2.83, 3.44),
    (2.98, 3.67),
    (3.11, 3.89),
    (3.33, 4.11),
];

/// The dam break's surge front `Z = (max x - x_wall) / a` of `particles` in a simulation with
/// `params` (the dam break is 2D; the front of particles in `D` dimensions is along x).
#[must_use]
pub fn surge_front<const D: usize>(params: &MpmParams, particles: &Particles<D>) -> f64 {
    let right = particles.x.chunks_exact(D).map(|c| f64::from(c[0])).fold(f64::MIN, f64::max);
    (right - dam_break_wall(params)) / DAM_BREAK_COLUMN
}

/// The study's error of fronts `z` against the first `z.len()` entries of [`MARTIN_MOYCE`]:
/// `(max, rms)` of `|Z - Z_MM| / Z_MM`.
#[must_use]
pub fn surge_front_errors(z: &[f64]) -> (f64, f64) {
    let mut max: f64 = 0.0;
    let mut sq = 0.0;
    for (zi, (_, zr)) in z.iter().zip(MARTIN_MOYCE.iter()) {
        let e = (zi - zr).abs() / zr;
        max = max.max(e);
        sq += e * e;
    }
    (max, (sq / z.len().max(1) as f64).sqrt())
}

/// The surge front of a dam-break run sampled at [`MARTIN_MOYCE`]'s times as the run passes
/// them: each is interpolated linearly between the fronts after the steps around it (exact when
/// a step ends on it). No allocation per step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurgeFront {
    /// The last observation `(T, Z)`.
    last: (f64, f64),
    /// The fronts at the table's times passed so far.
    z: Vec<f64>,
}

impl SurgeFront {
    /// Starts at the run's initial particles (`T = 0`).
    #[must_use]
    pub fn new<const D: usize>(params: &MpmParams, particles: &Particles<D>) -> Self {
        Self { last: (0.0, surge_front(params, particles)), z: Vec::with_capacity(MARTIN_MOYCE.len()) }
    }

    /// Checks a tracker read from a checkpoint (at most one front per time of the table, every
    /// value finite) and gives it the capacity of the whole table, so that observing does not
    /// allocate.
    ///
    /// # Errors
    /// What is wrong with it.
    pub(crate) fn checked(mut self) -> Result<Self, String> {
        if self.z.len() > MARTIN_MOYCE.len() {
            return Err(format!("{} fronts; the table has {} times", self.z.len(), MARTIN_MOYCE.len()));
        }
        if let Some(bad) = [self.last.0, self.last.1].iter().chain(&self.z).find(|v| !v.is_finite()) {
            return Err(format!("holds the non-finite value {bad}"));
        }
        self.z.reserve_exact(MARTIN_MOYCE.len() - self.z.len());
        Ok(self)
    }

    /// Records the front after a step ending at simulated time `time` (s).
    pub fn observe<const D: usize>(&mut self, time: f64, params: &MpmParams, particles: &Particles<D>) {
        let now = (time * dam_break_time_scale(), surge_front(params, particles));
        while let Some(&(t, _)) = MARTIN_MOYCE.get(self.z.len()) {
            if now.0 < t - 1e-9 {
                break;
            }
            let (t0, z0) = self.last;
            let z = if now.0 > t0 {
                z0 + (now.1 - z0) * ((t - t0) / (now.0 - t0)).clamp(0.0, 1.0)
            } else {
                now.1
            };
            self.z.push(z);
        }
        self.last = now;
    }

    /// The fronts at the table's times passed so far.
    #[must_use]
    pub fn fronts(&self) -> &[f64] {
        &self.z
    }

    /// [`surge_front_errors`] over the times passed so far (`None` before the first).
    #[must_use]
    pub fn errors(&self) -> Option<(f64, f64)> {
        (!self.z.is_empty()).then(|| surge_front_errors(&self.z))
    }
}

/// A snowball (radius 0.1, 6 m/s) thrown against a wall (separating contact, Coulomb friction
/// 0.5): it flattens against the wall (from 0.2 m to 0.1 m thick along x), rebounds at about
/// 0.5 m/s, falls to the floor and slides back along it.
///
/// # Errors
/// [`MpmError`] for a resolution below 8.
pub fn snowball(n: usize) -> Result<Scene<3>, MpmError> {
    let mut params = MpmParams::with_resolution(n);
    params.colliders.push(Collider::fixed(
        Shape::Box { center: [0.85, 0.5, 0.5], half_extents: [0.05, 0.45, 0.45] },
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

#[cfg(test)]
mod dam_break_tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;

    #[test]
    fn the_front_error_is_the_relative_distance_to_martin_and_moyce() {
        let exact: Vec<f64> = MARTIN_MOYCE.iter().map(|(_, z)| *z).collect();
        assert_eq!(surge_front_errors(&exact), (0.0, 0.0));
        // 10 % ahead at every time: max and rms are 0.1.
        let ahead: Vec<f64> = exact.iter().map(|z| z * 1.1).collect();
        let (max, rms) = surge_front_errors(&ahead);
        assert!((max - 0.1).abs() < 1e-12 && (rms - 0.1).abs() < 1e-12, "{max} {rms}");
        // One point 30 % behind among four exact ones: rms sqrt(0.09 / 5), over the first five.
        let mut one = exact[..5].to_vec();
        one[2] *= 0.7;
        let (max, rms) = surge_front_errors(&one);
        assert!((max - 0.3).abs() < 1e-12 && (rms - (0.09f64 / 5.0).sqrt()).abs() < 1e-12, "{max} {rms}");
    }

    #[test]
    fn the_tracker_samples_a_linear_front_exactly_at_the_tables_times() {
        // One particle whose front runs as Z = 1 + 2 T, observed at steps that miss the table's
        // times: linear interpolation recovers Z at each exactly (to f32 positions).
        let params = MpmParams::with_resolution(32);
        let wall = 3.0 / 32.0;
        let scale = dam_break_time_scale();
        let z_at = |t: f64| 1.0 + 2.0 * t * scale;
        let mut p = Particles::<2>::new();
        p.push([(wall + DAM_BREAK_COLUMN * z_at(0.0)) as f32, 0.5], [0.0; 2], 1.0, 1.0, 0).unwrap();
        let mut front = SurgeFront::new(&params, &p);
        assert_eq!(front.errors(), None);
        let dt = 0.0037;
        let mut t = 0.0;
        while t < dam_break_duration() + dt {
            t += dt;
            p.x[0] = (wall + DAM_BREAK_COLUMN * z_at(t)) as f32;
            front.observe(t, &params, &p);
            let passed = MARTIN_MOYCE.iter().filter(|(tt, _)| *tt <= t * scale).count();
            assert_eq!(front.fronts().len(), passed, "t = {t}");
        }
        assert_eq!(front.fronts().len(), MARTIN_MOYCE.len());
        for (z, (tt, _)) in front.fronts().iter().zip(MARTIN_MOYCE) {
            assert!((z - (1.0 + 2.0 * tt)).abs() < 1e-5, "T = {tt}: {z}");
        }
    }

    #[test]
    fn the_dam_break_fills_the_column_and_takes_its_method() {
        let s = dam_break_2d(32, 3, Transfer::Apic, Kernel::Cubic).unwrap();
        // floor(0.2 / (h / 3)) x floor(0.4 / (h / 3)) = 19 x 38 particles at h = 1/32.
        assert_eq!(s.state.len(), 19 * 38);
        assert_eq!((s.sim.params().transfer, s.sim.params().kernel), (Transfer::Apic, Kernel::Cubic));
        assert_eq!(s.dt, 0.5 / 32.0 / 50.0);
        assert!(dam_break_2d(32, 0, Transfer::Mls, Kernel::Quadratic).is_err());
        assert!(dam_break_2d(32, 9, Transfer::Mls, Kernel::Quadratic).is_err());
        // A count is refused by the presets that place their own particles.
        assert!(matches!(by_name_with("three-materials", Some(16), Some(2)), Some(Err(_))));
        assert!(by_name_with("no-such-scene", None, Some(2)).is_none());
        let mut scene = by_name_with("dam-break-2d", Some(16), Some(1)).unwrap().unwrap();
        assert_eq!(scene.len(), 3 * 6);
        scene.set_method(Transfer::Apic, Kernel::Quadratic).unwrap();
        scene.step().unwrap();
        assert!(scene.set_method(Transfer::Mls, Kernel::Quadratic).is_err(), "after a step");
    }
}
