//! The picker's typed view of the scene kinds its studies map: the `[scene]` table of a scene
//! file read into one enum, so that the transfers of `--tolerance` can read and set the fields
//! they know (integrators, solvers, resolutions, counts) and write the table back. Scenes are
//! built and run through the registry (`anim::KINDS`); this view only serves the picker.

use anim_core::integrate::IntegratorKind;
use anim_core::linalg::LinearSolverKind;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

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

/// The typed view of a scene file's `[scene]` table (`kind` and its parameters).
///
/// # Errors
/// serde's message when the table does not fit the view (a kind or field it does not know).
pub fn typed(spec: &crate::scene::SceneSpec) -> Result<Scene, String> {
    let mut map = spec.params.clone();
    map.insert("kind".into(), serde_json::Value::String(spec.kind.clone()));
    serde_json::from_value(serde_json::Value::Object(map)).map_err(|e| e.to_string())
}

/// The `[scene]` table of `scene`, with the fields it leaves unset left out.
///
/// # Errors
/// serde's message if the view cannot be written (it always can).
pub fn untyped(scene: &Scene) -> Result<crate::scene::SceneSpec, String> {
    let serde_json::Value::Object(mut map) = serde_json::to_value(scene).map_err(|e| e.to_string())? else {
        return Err("the scene view is not a table".into());
    };
    map.retain(|_, v| !v.is_null());
    let kind = match map.remove("kind") {
        Some(serde_json::Value::String(k)) => k,
        _ => return Err("the scene view has no kind".into()),
    };
    Ok(crate::scene::SceneSpec { kind, params: map })
}
