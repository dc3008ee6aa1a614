//! Scene files: a TOML description of what to simulate and how long.
//!
//! ```toml
//! name = "kepler"
//!
//! [run]
//! dt = 0.01          # seconds per step
//! frames = 300       # frames written
//! steps_per_frame = 5
//!
//! [scene]
//! kind = "kepler-orbit"
//! eccentricity = 0.5
//! integrator = "velocity-verlet"   # or { beta-blend = { beta = 0.5 } }
//! ```
//!
//! Unknown fields are errors (a typo never silently falls back to a default), and every error
//! names the file and the field or line.

use anim_core::integrate::IntegratorKind;
use anim_core::linalg::LinearSolverKind;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A scene file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Scene name, used for the output folder.
    pub name: String,
    /// Time stepping and output.
    pub run: RunParams,
    /// What is simulated.
    pub scene: Scene,
}

/// Time stepping and output parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunParams {
    /// Time step in seconds (> 0).
    pub dt: f64,
    /// Frames to write (>= 1).
    pub frames: usize,
    /// Steps between written frames (>= 1). Default 1.
    #[serde(default = "one")]
    pub steps_per_frame: usize,
}

fn one() -> usize {
    1
}

/// The simulated systems a scene can name. Later crates add variants.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Scene {
    /// A damped harmonic oscillator `m x'' = -k x - c x'` with its exact solution.
    HarmonicOscillator {
        /// Mass (> 0).
        mass: f64,
        /// Stiffness (> 0).
        stiffness: f64,
        /// Damping (>= 0). Default 0.
        #[serde(default)]
        damping: f64,
        /// Initial position.
        x0: f64,
        /// Initial velocity.
        v0: f64,
        /// Integrator.
        integrator: IntegratorKind,
    },
    /// A planet on an ellipse of semi-major axis 1 around a fixed sun (`mu = 1`), with the exact
    /// solution from Kepler's equation.
    KeplerOrbit {
        /// Eccentricity in `[0, 1)`.
        eccentricity: f64,
        /// Integrator.
        integrator: IntegratorKind,
    },
    /// A skinned character posed over time (anim-skin): the built-in twisted cylinder or any
    /// skinned glTF 2.0 file (`.gltf` or `.glb`), by linear blend or dual-quaternion skinning.
    Skinning {
        /// A built-in character (`twisted-cylinder`); exactly one of `preset` and `file`.
        #[serde(default)]
        preset: Option<String>,
        /// A glTF file, relative to the scene file's folder.
        #[serde(default)]
        file: Option<PathBuf>,
        /// `lbs`, `dqs`, or `both` (side by side). Default: both for the cylinder, dqs for files.
        #[serde(default)]
        method: Option<SkinningChoice>,
    },
    /// A rigid-body scene of anim-rigid (`panda-swing`, `pendulum-chain`, `t-handle`).
    Rigid {
        /// The preset's name.
        preset: String,
    },
    /// A position-based-dynamics scene of anim-pbd (`cloth-drape`, `flag`, `rope`, `soft-blob`,
    /// `balloon`, `hanging-cloth`, `benchmark-cloth`) with its own solver settings unless
    /// overridden.
    Pbd {
        /// The preset's name.
        preset: String,
        /// Resolution (the preset's default when absent).
        #[serde(default)]
        resolution: Option<usize>,
        /// `"pbd"` (stiffness) or `"xpbd"` (compliance); the preset's when absent.
        #[serde(default)]
        method: Option<anim_pbd::Method>,
        /// Solver iterations per substep, 1 to [`MAX_PBD_COUNT`] (the preset's when absent).
        #[serde(default)]
        iterations: Option<usize>,
        /// Substeps per step, 1 to [`MAX_PBD_COUNT`] (the preset's when absent).
        #[serde(default)]
        substeps: Option<usize>,
    },
    /// A finite element scene of anim-fem (`cantilever-beam`, `soft-cube-drop`, `twisted-bar`).
    Fem {
        /// The preset's name.
        preset: String,
        /// Cells across the beam or bar, or along the cube's side (the preset's default when
        /// absent).
        #[serde(default)]
        resolution: Option<usize>,
        /// Time integrator (`"backward-euler"` or `"symplectic-euler"`; the preset's when
        /// absent).
        #[serde(default)]
        integrator: Option<anim_fem::sim::TimeIntegrator>,
        /// Linear solver inside Newton (`"cholesky"`, `"ldlt"`, `"jacobi-pcg"`; the preset's when
        /// absent).
        #[serde(default)]
        linear_solver: Option<anim_fem::sim::LinearSolverChoice>,
        /// The element: `"tet4"` (linear tetrahedra, the default) or `"tet10"` (10-node
        /// tetrahedra on the same mesh: no locking in bending, 4 to 7 times the nodes).
        #[serde(default)]
        element: Option<anim_fem::model::ElementOrder>,
    },
    /// A material-point-method scene of anim-mpm (`three-materials` and `dam-break-2d` in 2D,
    /// `dam-break-3d`, `snowball`, `benchmark-2d`, `benchmark-3d`); each step may take CFL
    /// substeps.
    Mpm {
        /// The preset's name.
        preset: String,
        /// Grid cells per axis (the preset's default when absent).
        #[serde(default)]
        resolution: Option<usize>,
        /// Particle-grid transfer: `"mls-mpm"` (the presets' default) or `"apic"`.
        #[serde(default)]
        transfer: Option<MpmTransfer>,
        /// Interpolation kernel: `"quadratic"` (the presets' default) or `"cubic"` B-splines.
        #[serde(default)]
        kernel: Option<MpmKernel>,
        /// Particles per cell and axis, 1 to 8 (`dam-break-2d` only; default 2).
        #[serde(default)]
        particles_per_cell: Option<usize>,
    },
    /// A grid fluid of anim-fluid (`smoke-box-2d`: the seed's stable fluids; `smoke-plume-3d`:
    /// buoyant smoke around a sphere on the 3D MAC grid; `lid-driven-cavity`: the Re = 100
    /// cavity with bands of passive dye on the 2D MAC grid). The run's `dt` is the step (the
    /// seed's solver takes it in `f32`); the density and velocity fields are written as `.vti`
    /// frames and the preview shows the density.
    Fluid {
        /// The preset's name.
        preset: String,
        /// Cells across the domain (the preset's default when absent): 2 to 2048 in 2D, 2 to 128
        /// in 3D.
        #[serde(default)]
        resolution: Option<usize>,
        /// Pressure solver of the MAC presets (`"jacobi"`, `"rb-gauss-seidel"`, `"cg"`,
        /// `"mgpcg"`; the preset's when absent). Setting it or the tolerance lets the solver take
        /// up to 200,000 iterations.
        #[serde(default)]
        pressure_solver: Option<PressureSolver>,
        /// Relative residual `max|b - A p| / max|b|` the pressure solve stops at (MAC presets;
        /// the preset's when absent).
        #[serde(default)]
        pressure_tolerance: Option<f64>,
        /// Advection scheme of the MAC presets (`"sl-linear"`, `"sl-monotone-cubic"`, `"bfecc"`,
        /// `"maccormack"`; the preset's when absent).
        #[serde(default)]
        advection: Option<FluidAdvection>,
        /// How a MAC step splits advection from projection (`"advect-project"`, the seed's
        /// order, or `"reflection"`, advection-reflection; the preset's when absent).
        #[serde(default)]
        splitting: Option<FluidSplitting>,
    },
    /// An incompressible particle fluid of anim-flip (`dam-break-2d`, `dam-break-3d`, `drop-2d`,
    /// `drop-3d`, `sloshing-tank`): particles carry the water, a MAC grid makes it
    /// incompressible; each step takes CFL substeps. Frames are the particles as a point cloud,
    /// z up (anim-flip's y); the sloshing tank's are in the world frame (the tank's motion added).
    Flip {
        /// The preset's name (checked when the file is read).
        #[serde(deserialize_with = "flip_preset")]
        preset: String,
        /// Cells across the 1 m tank (the preset's default when absent): at most 1024 in 2D,
        /// 128 in 3D.
        #[serde(default)]
        resolution: Option<usize>,
        /// Grid-to-particle transfer: `"apic"` (the default), `"pic"`, or `{ flip = 0.97 }` (FLIP
        /// blended with PIC, the blend in `[0, 1]`).
        #[serde(default)]
        transfer: Option<FlipTransfer>,
    },
    /// A mass-spring scene of anim-springs (`hanging-cloth`, `swinging-rope`, `jelly-drop`,
    /// `benchmark-cloth`), with its own integrator and solver unless overridden.
    Springs {
        /// The preset's name.
        preset: String,
        /// Particles per side (the preset's default when absent).
        #[serde(default)]
        resolution: Option<usize>,
        /// Integrator override.
        #[serde(default)]
        integrator: Option<IntegratorKind>,
        /// Linear solver override for implicit integrators.
        #[serde(default)]
        linear_solver: Option<LinearSolverKind>,
    },
}

/// The pressure solver of a MAC [`Scene::Fluid`], by its name in reports
/// ([`PressureMethod::name`](anim_fluid::pressure::PressureMethod::name)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PressureSolver(pub anim_fluid::pressure::PressureMethod);

impl PressureSolver {
    /// The solver named `name`, if any.
    #[must_use]
    pub fn by_name(name: &str) -> Option<Self> {
        anim_fluid::pressure::PressureMethod::ALL.into_iter().find(|m| m.name() == name).map(Self)
    }
}

impl Serialize for PressureSolver {
    fn serialize<Se: serde::Serializer>(&self, s: Se) -> Result<Se::Ok, Se::Error> {
        s.serialize_str(self.0.name())
    }
}

impl<'de> Deserialize<'de> for PressureSolver {
    fn deserialize<De: serde::Deserializer<'de>>(d: De) -> Result<Self, De::Error> {
        let name = String::deserialize(d)?;
        Self::by_name(&name).ok_or_else(|| {
            let names: Vec<&str> =
                anim_fluid::pressure::PressureMethod::ALL.iter().map(|m| m.name()).collect();
            serde::de::Error::custom(format!("{UNKNOWN_PRESSURE}{name}` (one of {})", names.join(", ")))
        })
    }
}

/// The largest iteration or substep count a [`Scene::Pbd`] takes.
pub const MAX_PBD_COUNT: usize = 100_000;

/// The particle-grid transfer of a [`Scene::Mpm`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MpmTransfer {
    /// Affine particle-in-cell with grid forces from the kernel gradients.
    Apic,
    /// Moving least squares MPM: the stress fused into the affine momentum.
    MlsMpm,
}

impl MpmTransfer {
    /// The anim-mpm transfer.
    #[must_use]
    pub fn transfer(self) -> anim_mpm::Transfer {
        match self {
            MpmTransfer::Apic => anim_mpm::Transfer::Apic,
            MpmTransfer::MlsMpm => anim_mpm::Transfer::Mls,
        }
    }

    /// The field's value for `transfer`.
    #[must_use]
    pub fn of(transfer: anim_mpm::Transfer) -> Self {
        match transfer {
            anim_mpm::Transfer::Apic => MpmTransfer::Apic,
            anim_mpm::Transfer::Mls => MpmTransfer::MlsMpm,
        }
    }

    /// The name scene files use.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            MpmTransfer::Apic => "apic",
            MpmTransfer::MlsMpm => "mls-mpm",
        }
    }
}

/// The interpolation kernel of a [`Scene::Mpm`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MpmKernel {
    /// Quadratic B-spline (3 nodes per axis).
    Quadratic,
    /// Cubic B-spline (4 nodes per axis).
    Cubic,
}

impl MpmKernel {
    /// The anim-mpm kernel.
    #[must_use]
    pub fn kernel(self) -> anim_mpm::Kernel {
        match self {
            MpmKernel::Quadratic => anim_mpm::Kernel::Quadratic,
            MpmKernel::Cubic => anim_mpm::Kernel::Cubic,
        }
    }

    /// The field's value for `kernel`.
    #[must_use]
    pub fn of(kernel: anim_mpm::Kernel) -> Self {
        match kernel {
            anim_mpm::Kernel::Quadratic => MpmKernel::Quadratic,
            anim_mpm::Kernel::Cubic => MpmKernel::Cubic,
        }
    }

    /// The name scene files use.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            MpmKernel::Quadratic => "quadratic",
            MpmKernel::Cubic => "cubic",
        }
    }
}

/// The advection scheme of a MAC [`Scene::Fluid`], by its name in reports
/// ([`Advection::name`](anim_fluid::advection::Advection::name)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum FluidAdvection {
    /// Semi-Lagrangian, linear interpolation.
    #[serde(rename = "sl-linear")]
    Linear,
    /// Semi-Lagrangian, monotone cubic interpolation.
    #[serde(rename = "sl-monotone-cubic")]
    MonotoneCubic,
    /// BFECC over linear semi-Lagrangian steps.
    #[serde(rename = "bfecc")]
    Bfecc,
    /// MacCormack over linear semi-Lagrangian steps.
    #[serde(rename = "maccormack")]
    MacCormack,
}

impl FluidAdvection {
    /// The anim-fluid scheme.
    #[must_use]
    pub fn advection(self) -> anim_fluid::advection::Advection {
        use anim_fluid::advection::Advection;
        match self {
            Self::Linear => Advection::Linear,
            Self::MonotoneCubic => Advection::MonotoneCubic,
            Self::Bfecc => Advection::Bfecc,
            Self::MacCormack => Advection::MacCormack,
        }
    }
}

/// The splitting of a MAC [`Scene::Fluid`] step, by its name in reports
/// ([`Splitting::name`](anim_fluid::advection::Splitting::name)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum FluidSplitting {
    /// Advect over `dt`, then project.
    #[serde(rename = "advect-project")]
    AdvectProject,
    /// Advection-reflection.
    #[serde(rename = "reflection")]
    Reflection,
}

impl FluidSplitting {
    /// The anim-fluid splitting.
    #[must_use]
    pub fn splitting(self) -> anim_fluid::advection::Splitting {
        match self {
            Self::AdvectProject => anim_fluid::advection::Splitting::AdvectProject,
            Self::Reflection => anim_fluid::advection::Splitting::Reflection,
        }
    }
}

/// The grid-to-particle transfer of a [`Scene::Flip`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FlipTransfer {
    /// Particle-in-cell (dissipative).
    Pic,
    /// Affine particle-in-cell.
    Apic,
    /// FLIP blended with PIC: 1 is pure FLIP, 0 pure PIC.
    Flip(f64),
}

impl FlipTransfer {
    /// The anim-flip transfer.
    #[must_use]
    pub fn transfer(self) -> anim_flip::Transfer {
        match self {
            FlipTransfer::Pic => anim_flip::Transfer::Pic,
            FlipTransfer::Apic => anim_flip::Transfer::Apic,
            FlipTransfer::Flip(blend) => anim_flip::Transfer::Flip(blend),
        }
    }
}

/// Reads a flip preset's name, refusing unknown ones (so the error carries the file's line).
fn flip_preset<'de, De: serde::Deserializer<'de>>(d: De) -> Result<String, De::Error> {
    let name = String::deserialize(d)?;
    if anim_flip::scenes::NAMES.contains(&name.as_str()) {
        Ok(name)
    } else {
        Err(serde::de::Error::custom(format!(
            "{UNKNOWN_PRESET}{name}` for field `preset` (one of {})",
            anim_flip::scenes::NAMES.join(", ")
        )))
    }
}

/// How [`PressureSolver`]'s error starts, for [`parse`] to find the line.
const UNKNOWN_PRESSURE: &str = "unknown pressure solver `";

/// How [`flip_preset`]'s error starts, for [`parse`] to find the line.
const UNKNOWN_PRESET: &str = "unknown preset `";

/// Which skinning to show.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum SkinningChoice {
    /// Linear blend skinning.
    Lbs,
    /// Dual-quaternion skinning.
    Dqs,
    /// Both, side by side (LBS left, DQS right).
    Both,
}

/// A scene that could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{path}: cannot read scene file: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not valid TOML or does not match the scene format.
    #[error("{path}:{line}:{column}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A value is out of its valid range.
    #[error("{path}: field `{field}`: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// Dotted field path, e.g. `run.dt`.
        field: &'static str,
        /// What is wrong.
        message: String,
    },
}

/// The scenes built into the binary: `(name, description, TOML text)`.
pub const BUILTIN: [(&str, &str, &str); 29] = [
    (
        "cloth",
        "a 32x32 cloth pinned at two corners falls and swings, backward Euler + sparse Cholesky",
        CLOTH,
    ),
    ("rope", "a rope pinned at one end swings down, velocity Verlet", ROPE),
    ("jelly", "a jelly cube dropped on the ground bounces, backward Euler + sparse Cholesky", JELLY),
    ("drape", "XPBD cloth falling onto a sphere and draping over it", DRAPE),
    ("flag", "an XPBD flag on a swaying pole in the wind", FLAG),
    ("blob", "a soft tetrahedral blob (XPBD) falling on the ground", BLOB),
    ("pbd-rope", "a 100-link XPBD rope swinging against obstacles", PBD_ROPE),
    ("pbd-cloth", "the report's 14x14 XPBD cloth pinned at two corners, hanging down for 0.5 s", PBD_CLOTH),
    ("panda", "the Franka Panda swinging under gravity with zero torque (RK4)", PANDA),
    ("chain", "a 32-link pendulum chain (RK4)", CHAIN),
    ("t-handle", "a spinning T-handle flipping about its intermediate axis (free-body midpoint)", T_HANDLE),
    ("twist", "a cylinder twisted 180 degrees: LBS's candy-wrapper collapse beside DQS", TWIST),
    ("beam", "a stable Neo-Hookean FEM beam clamped at one end sags and swings, backward Euler", BEAM),
    ("cube", "a soft FEM cube dropped on the ground, backward Euler with penalty contact", CUBE),
    ("twisted-bar", "an FEM bar twisted by a half turn at one end (large rotation)", TWISTED_BAR),
    ("mpm", "MLS-MPM in 2D: a jelly block, a snow block and water falling together", MPM),
    (
        "dam-break-2d-mpm",
        "MLS-MPM in 2D: Martin & Moyce's dam break (0.2 x 0.4 m column), surge front vs the experiment",
        MPM_DAM_BREAK_2D,
    ),
    ("dam-break", "MLS-MPM in 3D: a water column collapsing in a tank", DAM_BREAK),
    ("snowball", "MLS-MPM in 3D: a snowball hitting a wall and breaking up", SNOWBALL),
    (
        "smoke-box-2d",
        "the seed's stable fluids: smoke rising from a source in a closed 128x128 box",
        SMOKE_BOX,
    ),
    (
        "smoke-plume-3d",
        "hot smoke rising around a sphere, 3D MAC grid, MacCormack + MGPCG, open top",
        SMOKE_PLUME,
    ),
    ("lid-driven-cavity", "the Re = 100 lid-driven cavity (64x64 MAC grid) stirring bands of dye", CAVITY),
    (
        "dam-break-2d",
        "APIC particle fluid in 2D: a 0.25 x 0.5 m water column collapsing in a tank (64 cells/m)",
        FLIP_DAM_BREAK_2D,
    ),
    (
        "dam-break-3d",
        "APIC particle fluid in 3D: a water column collapsing in the corner of a tank",
        FLIP_DAM_BREAK_3D,
    ),
    ("drop-2d", "APIC particle fluid in 2D: a disk of water falling into a pool", FLIP_DROP_2D),
    ("drop-3d", "APIC particle fluid in 3D: a ball of water falling into a pool", FLIP_DROP_3D),
    (
        "sloshing-tank",
        "APIC particle fluid in 2D: water in a tank shaken at its first sloshing frequency",
        FLIP_SLOSHING,
    ),
    ("kepler", "a planet on an e = 0.5 ellipse, velocity Verlet, about 3 orbits", KEPLER),
    ("oscillator", "a lightly damped harmonic oscillator, implicit midpoint", OSCILLATOR),
];

/// The scene run when no scene is named: the most telling one the workspace has.
pub const DEFAULT_SCENE: &str = "cloth";

const CLOTH: &str = r#"name = "cloth"

[run]
dt = 0.01
frames = 120
steps_per_frame = 2

[scene]
kind = "springs"
preset = "hanging-cloth"
resolution = 32
"#;

const ROPE: &str = r#"name = "rope"

[run]
dt = 0.0005
frames = 120
steps_per_frame = 40

[scene]
kind = "springs"
preset = "swinging-rope"
"#;

const JELLY: &str = r#"name = "jelly"

[run]
dt = 0.005
frames = 120
steps_per_frame = 2

[scene]
kind = "springs"
preset = "jelly-drop"
"#;

const DRAPE: &str = r#"name = "drape"

[run]
dt = 0.016666666666666666
frames = 120
steps_per_frame = 1

[scene]
kind = "pbd"
preset = "cloth-drape"
"#;

const FLAG: &str = r#"name = "flag"

[run]
dt = 0.016666666666666666
frames = 120
steps_per_frame = 1

[scene]
kind = "pbd"
preset = "flag"
"#;

const BEAM: &str = r#"name = "beam"

[run]
dt = 0.016666666666666666
frames = 120
steps_per_frame = 1

[scene]
kind = "fem"
preset = "cantilever-beam"
"#;

const CUBE: &str = r#"name = "cube"

[run]
dt = 0.005
frames = 100
steps_per_frame = 2

[scene]
kind = "fem"
preset = "soft-cube-drop"
"#;

const TWISTED_BAR: &str = r#"name = "twisted-bar"

[run]
dt = 0.01
frames = 100
steps_per_frame = 1

[scene]
kind = "fem"
preset = "twisted-bar"
"#;

const MPM: &str = r#"name = "mpm"

[run]
dt = 0.0005
frames = 120
steps_per_frame = 40

[scene]
kind = "mpm"
preset = "three-materials"
"#;

const DAM_BREAK: &str = r#"name = "dam-break"

[run]
dt = 0.001
frames = 100
steps_per_frame = 16

[scene]
kind = "mpm"
preset = "dam-break-3d"
"#;

const SNOWBALL: &str = r#"name = "snowball"

[run]
dt = 0.0005
frames = 100
steps_per_frame = 16

[scene]
kind = "mpm"
preset = "snowball"
"#;

const BLOB: &str = r#"name = "blob"

[run]
dt = 0.016666666666666666
frames = 120
steps_per_frame = 1

[scene]
kind = "pbd"
preset = "soft-blob"
"#;

const PBD_CLOTH: &str = r#"name = "pbd-cloth"

[run]
dt = 0.016666666666666666
frames = 30
steps_per_frame = 1

[scene]
kind = "pbd"
preset = "hanging-cloth"
"#;

const MPM_DAM_BREAK_2D: &str = r#"name = "dam-break-2d-mpm"

[run]
dt = 0.00015625
frames = 35
steps_per_frame = 64

[scene]
kind = "mpm"
preset = "dam-break-2d"
resolution = 64
"#;

const PBD_ROPE: &str = r#"name = "pbd-rope"

[run]
dt = 0.016666666666666666
frames = 120
steps_per_frame = 1

[scene]
kind = "pbd"
preset = "rope"
"#;

const PANDA: &str = r#"name = "panda"

[run]
dt = 0.001
frames = 100
steps_per_frame = 30

[scene]
kind = "rigid"
preset = "panda-swing"
"#;

const CHAIN: &str = r#"name = "chain"

[run]
dt = 0.0005
frames = 100
steps_per_frame = 60

[scene]
kind = "rigid"
preset = "pendulum-chain"
"#;

const T_HANDLE: &str = r#"name = "t-handle"

[run]
dt = 0.001
frames = 120
steps_per_frame = 200

[scene]
kind = "rigid"
preset = "t-handle"
"#;

const TWIST: &str = r#"name = "twist"

[run]
dt = 0.02
frames = 100
steps_per_frame = 1

[scene]
kind = "skinning"
preset = "twisted-cylinder"
method = "both"
"#;

const SMOKE_BOX: &str = r#"name = "smoke-box-2d"

[run]
dt = 0.1
frames = 100
steps_per_frame = 2

[scene]
kind = "fluid"
preset = "smoke-box-2d"
resolution = 128
"#;

const SMOKE_PLUME: &str = r#"name = "smoke-plume-3d"

[run]
dt = 0.046875
frames = 64
steps_per_frame = 1

[scene]
kind = "fluid"
preset = "smoke-plume-3d"
resolution = 32
"#;

const CAVITY: &str = r#"name = "lid-driven-cavity"

[run]
dt = 0.015625
frames = 128
steps_per_frame = 10

[scene]
kind = "fluid"
preset = "lid-driven-cavity"
resolution = 64
"#;

const FLIP_DAM_BREAK_2D: &str = r#"name = "dam-break-2d"

[run]
dt = 0.02
frames = 100
steps_per_frame = 1

[scene]
kind = "flip"
preset = "dam-break-2d"
resolution = 64
"#;

const FLIP_DAM_BREAK_3D: &str = r#"name = "dam-break-3d"

[run]
dt = 0.02
frames = 75
steps_per_frame = 1

[scene]
kind = "flip"
preset = "dam-break-3d"
resolution = 32
"#;

const FLIP_DROP_2D: &str = r#"name = "drop-2d"

[run]
dt = 0.02
frames = 75
steps_per_frame = 1

[scene]
kind = "flip"
preset = "drop-2d"
resolution = 64
"#;

const FLIP_DROP_3D: &str = r#"name = "drop-3d"

[run]
dt = 0.02
frames = 75
steps_per_frame = 1

[scene]
kind = "flip"
preset = "drop-3d"
resolution = 32
"#;

const FLIP_SLOSHING: &str = r#"name = "sloshing-tank"

[run]
dt = 0.02
frames = 250
steps_per_frame = 1

[scene]
kind = "flip"
preset = "sloshing-tank"
resolution = 64
transfer = "apic"
"#;

const KEPLER: &str = r#"name = "kepler"

[run]
dt = 0.005
frames = 400
steps_per_frame = 10

[scene]
kind = "kepler-orbit"
eccentricity = 0.5
integrator = "velocity-verlet"
"#;

const OSCILLATOR: &str = r#"name = "oscillator"

[run]
dt = 0.01
frames = 500
steps_per_frame = 2

[scene]
kind = "harmonic-oscillator"
mass = 1.0
stiffness = 40.0
damping = 0.2
x0 = 1.0
v0 = 0.0
integrator = "implicit-midpoint"
"#;

impl Scene {
    /// Sets the resolution of a preset scene that has one (`pbd`, `fem`, `mpm`, `springs`,
    /// `fluid`, `flip`); the preset checks the value when the scene is built.
    ///
    /// # Errors
    /// A message naming the scene kind when it has no resolution.
    pub fn set_resolution(&mut self, value: usize) -> Result<(), String> {
        match self {
            Scene::Pbd { resolution, .. }
            | Scene::Fem { resolution, .. }
            | Scene::Mpm { resolution, .. }
            | Scene::Springs { resolution, .. }
            | Scene::Fluid { resolution, .. }
            | Scene::Flip { resolution, .. } => {
                *resolution = Some(value);
                Ok(())
            }
            Scene::HarmonicOscillator { .. } => Err("a harmonic-oscillator scene has no resolution".into()),
            Scene::KeplerOrbit { .. } => Err("a kepler-orbit scene has no resolution".into()),
            Scene::Skinning { .. } => Err("a skinning scene has no resolution".into()),
            Scene::Rigid { .. } => Err("a rigid scene has no resolution".into()),
        }
    }
}

impl SceneError {
    /// An out-of-range value found after parsing (e.g. by the crate that builds the scene).
    #[must_use]
    pub fn invalid(path: &Path, field: &'static str, message: String) -> Self {
        SceneError::Invalid { path: path.to_path_buf(), field, message }
    }
}

/// Parses scene text; `path` names the source in errors.
///
/// # Errors
/// [`SceneError::Parse`] with line and column, or [`SceneError::Invalid`] naming the field.
pub fn parse(text: &str, path: &Path) -> Result<SceneFile, SceneError> {
    let scene: SceneFile = toml::from_str(text).map_err(|e| {
        let start = e.span().map_or(0, |s| s.start);
        // Fields of tagged tables are reported at the table's start; point at the field itself.
        let start = unknown_field(e.message())
            .or_else(|| e.message().contains(UNKNOWN_PRESET).then_some("preset"))
            .or_else(|| e.message().contains(UNKNOWN_PRESSURE).then_some("pressure_solver"))
            .and_then(|name| field_offset(text, start, name))
            .unwrap_or(start);
        let (line, column) = line_col(text, start);
        SceneError::Parse { path: path.to_path_buf(), line, column, message: e.message().trim().to_string() }
    })?;
    validate(&scene).map_err(|(field, message)| SceneError::Invalid {
        path: path.to_path_buf(),
        field,
        message,
    })?;
    Ok(scene)
}

/// Loads a scene file from disk.
///
/// # Errors
/// [`SceneError`] naming the file.
pub fn load(path: &Path) -> Result<SceneFile, SceneError> {
    let text = std::fs::read_to_string(path)
        .map_err(|source| SceneError::Io { path: path.to_path_buf(), source })?;
    parse(&text, path)
}

/// Looks up a built-in scene by name.
#[must_use]
pub fn builtin(name: &str) -> Option<&'static str> {
    BUILTIN.iter().find(|(n, _, _)| *n == name).map(|(_, _, text)| *text)
}

/// The name in serde's "unknown field `NAME`" message.
fn unknown_field(message: &str) -> Option<&str> {
    let rest = message.split_once("unknown field `")?.1;
    Some(rest.split_once('`')?.0)
}

/// Byte offset of the first line at or after `from` that assigns `name`.
fn field_offset(text: &str, from: usize, name: &str) -> Option<usize> {
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim_start();
        if offset >= from.saturating_sub(line.len())
            && trimmed.strip_prefix(name).is_some_and(|r| r.trim_start().starts_with('='))
        {
            return Some(offset + (line.len() - trimmed.len()));
        }
        offset += line.len();
    }
    None
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

fn positive(field: &'static str, x: f64) -> Result<(), (&'static str, String)> {
    if x > 0.0 && x.is_finite() {
        Ok(())
    } else {
        Err((field, format!("must be a positive finite number, got {x}")))
    }
}

fn finite(field: &'static str, x: f64) -> Result<(), (&'static str, String)> {
    if x.is_finite() { Ok(()) } else { Err((field, format!("must be finite, got {x}"))) }
}

fn validate(s: &SceneFile) -> Result<(), (&'static str, String)> {
    if s.name.is_empty() || s.name.contains(['/', '\\']) || s.name.starts_with('.') {
        return Err(("name", format!("must be a plain non-empty name (used as a folder), got {:?}", s.name)));
    }
    positive("run.dt", s.run.dt)?;
    if s.run.frames == 0 {
        return Err(("run.frames", "must be at least 1".into()));
    }
    if s.run.steps_per_frame == 0 {
        return Err(("run.steps_per_frame", "must be at least 1".into()));
    }
    let integrator = match &s.scene {
        Scene::HarmonicOscillator { mass, stiffness, damping, x0, v0, integrator } => {
            positive("scene.mass", *mass)?;
            positive("scene.stiffness", *stiffness)?;
            if !(damping.is_finite() && *damping >= 0.0) {
                return Err((
                    "scene.damping",
                    format!("must be a non-negative finite number, got {damping}"),
                ));
            }
            finite("scene.x0", *x0)?;
            finite("scene.v0", *v0)?;
            integrator
        }
        Scene::KeplerOrbit { eccentricity, integrator } => {
            if !(0.0..1.0).contains(eccentricity) {
                return Err(("scene.eccentricity", format!("must lie in [0, 1), got {eccentricity}")));
            }
            integrator
        }
        Scene::Fluid { pressure_tolerance: Some(tol), .. } => {
            positive("scene.pressure_tolerance", *tol)?;
            return Ok(());
        }
        Scene::Pbd { iterations, substeps, .. } => {
            for (field, count) in [("scene.iterations", iterations), ("scene.substeps", substeps)] {
                if let Some(k) = *count
                    && !(1..=MAX_PBD_COUNT).contains(&k)
                {
                    return Err((field, format!("must lie in [1, {MAX_PBD_COUNT}], got {k}")));
                }
            }
            return Ok(());
        }
        Scene::Mpm { particles_per_cell: Some(k), .. } if !(1..=8).contains(k) => {
            return Err(("scene.particles_per_cell", format!("must lie in [1, 8] (per axis), got {k}")));
        }
        Scene::Rigid { .. } | Scene::Mpm { .. } | Scene::Fem { .. } | Scene::Fluid { .. } => return Ok(()),
        Scene::Flip { transfer, .. } => {
            if let Some(FlipTransfer::Flip(blend)) = transfer
                && !(0.0..=1.0).contains(blend)
            {
                return Err(("scene.transfer", format!("the FLIP blend must lie in [0, 1], got {blend}")));
            }
            return Ok(());
        }
        Scene::Skinning { preset, file, .. } => {
            if preset.is_some() == file.is_some() {
                return Err(("scene.preset", "give exactly one of `preset` and `file`".into()));
            }
            return Ok(());
        }
        Scene::Springs { integrator, .. } => match integrator {
            Some(i) => i,
            None => return Ok(()),
        },
    };
    integrator.validate().map_err(|m| ("scene.integrator", m))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        parse(text, Path::new("s.toml")).unwrap_err().to_string()
    }

    #[test]
    fn builtin_scenes_parse() {
        for (name, _, text) in BUILTIN {
            let s = parse(text, Path::new(name)).unwrap();
            assert_eq!(s.name, name);
        }
        assert!(builtin(DEFAULT_SCENE).is_some());
    }

    #[test]
    fn unknown_field_is_an_error_naming_file_line_and_field() {
        let text = KEPLER.replace("eccentricity = 0.5", "eccentricity = 0.5\neccentrcity = 0.2");
        let msg = err(&text);
        assert!(msg.starts_with("s.toml:"), "{msg}");
        assert!(msg.contains("eccentrcity"), "{msg}");
        let line = text.lines().position(|l| l.starts_with("eccentrcity")).unwrap() + 1;
        assert!(msg.contains(&format!(":{line}:")), "expected line {line}: {msg}");
    }

    #[test]
    fn bad_values_name_their_field() {
        let cases = [
            (KEPLER.replace("dt = 0.005", "dt = -1.0"), "run.dt"),
            (KEPLER.replace("frames = 400", "frames = 0"), "run.frames"),
            (KEPLER.replace("eccentricity = 0.5", "eccentricity = 1.5"), "scene.eccentricity"),
            (
                KEPLER.replace(
                    "integrator = \"velocity-verlet\"",
                    "integrator = { beta-blend = { beta = 2.0 } }",
                ),
                "scene.integrator",
            ),
            (OSCILLATOR.replace("mass = 1.0", "mass = 0.0"), "scene.mass"),
            (OSCILLATOR.replace("damping = 0.2", "damping = -0.2"), "scene.damping"),
            (KEPLER.replace("name = \"kepler\"", "name = \"../x\""), "name"),
        ];
        for (text, field) in cases {
            let msg = err(&text);
            assert!(msg.contains(&format!("field `{field}`")), "{field}: {msg}");
        }
    }

    #[test]
    fn unknown_integrator_and_wrong_types_are_parse_errors() {
        let msg = err(&KEPLER.replace("velocity-verlet", "warp-drive"));
        assert!(msg.contains("warp-drive") && msg.starts_with("s.toml:"), "{msg}");
        let msg = err(&KEPLER.replace("frames = 400", "frames = \"many\""));
        assert!(msg.starts_with("s.toml:"), "{msg}");
    }

    #[test]
    fn flip_scenes_parse_and_refuse_unknown_presets_and_blends_by_line_and_field() {
        let s = parse(FLIP_SLOSHING, Path::new("s.toml")).unwrap();
        assert!(matches!(
            s.scene,
            Scene::Flip { transfer: Some(FlipTransfer::Apic), resolution: Some(64), .. }
        ));
        let text = FLIP_DROP_2D.replace("resolution = 64", "transfer = { flip = 0.97 }");
        let s = parse(&text, Path::new("s.toml")).unwrap();
        assert!(
            matches!(s.scene, Scene::Flip { transfer: Some(FlipTransfer::Flip(b)), resolution: None, .. } if b == 0.97)
        );
        let text = FLIP_DROP_2D.replace("preset = \"drop-2d\"", "preset = \"drop-4d\"");
        let msg = err(&text);
        let line = text.lines().position(|l| l.starts_with("preset")).unwrap() + 1;
        assert!(msg.starts_with(&format!("s.toml:{line}:")), "expected line {line}: {msg}");
        assert!(msg.contains("drop-4d") && msg.contains("`preset`"), "{msg}");
        for name in anim_flip::scenes::NAMES {
            assert!(msg.contains(name), "{msg}");
        }
        let msg = err(&FLIP_DROP_2D.replace("resolution = 64", "transfer = { flip = 1.5 }"));
        assert!(msg.contains("field `scene.transfer`") && msg.contains("1.5"), "{msg}");
        let msg = err(&FLIP_DROP_2D.replace("resolution = 64", "transfer = \"mpm\""));
        assert!(msg.starts_with("s.toml:") && msg.contains("mpm"), "{msg}");
    }

    #[test]
    fn fem_and_fluid_method_fields_parse_and_bad_ones_name_their_field() {
        let text = BEAM.replace(
            "preset = \"cantilever-beam\"",
            "preset = \"cantilever-beam\"\nintegrator = \"symplectic-euler\"\nlinear_solver = \"jacobi-pcg\"",
        );
        let s = parse(&text, Path::new("s.toml")).unwrap();
        assert!(matches!(
            s.scene,
            Scene::Fem {
                integrator: Some(anim_fem::sim::TimeIntegrator::SymplecticEuler),
                linear_solver: Some(anim_fem::sim::LinearSolverChoice::JacobiPcg),
                ..
            }
        ));
        let msg = err(&text.replace("jacobi-pcg", "lu"));
        assert!(msg.starts_with("s.toml:") && msg.contains("lu"), "{msg}");
        let text = CAVITY.replace("resolution = 64", "pressure_solver = \"cg\"\npressure_tolerance = 1e-6");
        let s = parse(&text, Path::new("s.toml")).unwrap();
        assert!(matches!(
            s.scene,
            Scene::Fluid {
                pressure_solver: Some(PressureSolver(anim_fluid::pressure::PressureMethod::ConjugateGradient)),
                pressure_tolerance: Some(t),
                resolution: None,
                ..
            } if t == 1e-6
        ));
        // Written back, the solver keeps its report name.
        assert!(toml::to_string(&s).unwrap().contains("pressure_solver = \"cg\""));
        let bad = text.replace("\"cg\"", "\"sor\"");
        let msg = err(&bad);
        let line = bad.lines().position(|l| l.starts_with("pressure_solver")).unwrap() + 1;
        assert!(msg.starts_with(&format!("s.toml:{line}:")), "{msg}");
        assert!(
            msg.contains("unknown pressure solver `sor` (one of jacobi, rb-gauss-seidel, cg, mgpcg)"),
            "{msg}"
        );
        let msg = err(&text.replace("1e-6", "0.0"));
        assert!(
            msg.contains("field `scene.pressure_tolerance`: must be a positive finite number, got 0"),
            "{msg}"
        );
    }

    #[test]
    fn pbd_and_mpm_method_fields_parse_and_bad_ones_name_their_field() {
        let text = PBD_CLOTH.replace(
            "preset = \"hanging-cloth\"",
            "preset = \"hanging-cloth\"\nmethod = \"pbd\"\niterations = 3\nsubsteps = 5",
        );
        let s = parse(&text, Path::new("s.toml")).unwrap();
        assert!(matches!(
            s.scene,
            Scene::Pbd { method: Some(anim_pbd::Method::Pbd), iterations: Some(3), substeps: Some(5), .. }
        ));
        let msg = err(&text.replace("substeps = 5", "substeps = 0"));
        assert!(msg.contains("s.toml: field `scene.substeps`: must lie in [1, 100000], got 0"), "{msg}");
        let msg = err(&text.replace("iterations = 3", "iterations = 100001"));
        assert!(msg.contains("field `scene.iterations`") && msg.contains("100001"), "{msg}");
        let msg = err(&text.replace("\"pbd\"", "\"vbd\""));
        assert!(msg.starts_with("s.toml:") && msg.contains("vbd"), "{msg}");
        let text = MPM_DAM_BREAK_2D
            .replace("resolution = 64", "transfer = \"apic\"\nkernel = \"cubic\"\nparticles_per_cell = 3");
        let s = parse(&text, Path::new("s.toml")).unwrap();
        assert!(matches!(
            s.scene,
            Scene::Mpm {
                transfer: Some(MpmTransfer::Apic),
                kernel: Some(MpmKernel::Cubic),
                particles_per_cell: Some(3),
                resolution: None,
                ..
            }
        ));
        // Written back, the names are the ones read.
        let back = toml::to_string(&s).unwrap();
        assert!(back.contains("transfer = \"apic\"") && back.contains("kernel = \"cubic\""), "{back}");
        assert!(
            toml::to_string(&parse(&text.replace("\"apic\"", "\"mls-mpm\""), Path::new("s.toml")).unwrap())
                .unwrap()
                .contains("transfer = \"mls-mpm\"")
        );
        let msg = err(&text.replace("particles_per_cell = 3", "particles_per_cell = 9"));
        assert!(
            msg.contains("field `scene.particles_per_cell`: must lie in [1, 8] (per axis), got 9"),
            "{msg}"
        );
        let msg = err(&text.replace("particles_per_cell = 3", "particles_per_cell = 0"));
        assert!(msg.contains("field `scene.particles_per_cell`") && msg.contains("got 0"), "{msg}");
        for (bad, value) in [("\"apic\"", "\"pic\""), ("\"cubic\"", "\"quartic\"")] {
            let msg = err(&text.replace(bad, value));
            assert!(msg.starts_with("s.toml:") && msg.contains(value.trim_matches('"')), "{msg}");
        }
    }

    #[test]
    fn missing_file_names_the_path() {
        let msg = load(Path::new("/no/such/scene.toml")).unwrap_err().to_string();
        assert!(msg.contains("/no/such/scene.toml"), "{msg}");
    }

    #[test]
    fn fem_element_order_parses_and_a_bad_one_names_its_line() {
        let s = parse(
            &BEAM
                .replace("preset = \"cantilever-beam\"", "preset = \"cantilever-beam\"\nelement = \"tet10\""),
            Path::new("s.toml"),
        )
        .unwrap();
        assert!(matches!(
            s.scene,
            Scene::Fem { element: Some(anim_fem::model::ElementOrder::Quadratic), .. }
        ));
        let s = parse(BEAM, Path::new("s.toml")).unwrap();
        assert!(matches!(s.scene, Scene::Fem { element: None, .. }));
        let msg =
            err(&BEAM
                .replace("preset = \"cantilever-beam\"", "preset = \"cantilever-beam\"\nelement = \"tet7\""));
        // The tagged `[scene]` table (line 8) is where the toml parser places the error.
        assert!(msg.starts_with("s.toml:8:") && msg.contains("tet7") && msg.contains("tet10"), "{msg}");
    }

    #[test]
    fn beta_blend_table_form_parses() {
        let text = KEPLER
            .replace("integrator = \"velocity-verlet\"", "integrator = { beta-blend = { beta = 0.5 } }");
        let s = parse(&text, Path::new("s.toml")).unwrap();
        assert!(
            matches!(s.scene, Scene::KeplerOrbit { integrator: IntegratorKind::BetaBlend { beta }, .. } if beta == 0.5)
        );
    }
}
