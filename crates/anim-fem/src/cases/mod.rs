//! anim-fem: every material model's stress and tangent against finite differences of its energy
//! (random F with rotations, reflections and det F near 0), rotation invariance, the patch test,
//! momentum conservation of the internal forces, a cantilever against Euler-Bernoulli theory with
//! its mesh-convergence table (linear and quadratic tetrahedra), Cook's membrane against
//! Elguedj et al. (2008) with the locking linear element beside the quadratic one; hard cases
//! (fully inverted mesh, E = 1e8 at dt = 1/24 s, nu = 0.49, 10:1 grading, explicit divergence,
//! the speed up to which the penalty contact catches cubes thrown at a 1 cm mesh plate);
//! and the beam work-precision study (explicit vs implicit, per material).
//!
//! The determinism check runs the benchmark beam on 1, 2 and 4 threads; the soak run steps the
//! stiff beam for `cargo xtask stability --long`.

mod conformance;
mod determinism;
mod hard_cases;
mod soak;
mod static_problems;
mod study;
mod thin_plate;

pub use study::study_problem;

use crate::FemError;
use crate::generate::box_mesh;
use crate::material::{Material, MaterialModel};
use crate::model::{EARTH_GRAVITY, FemModel};
use crate::sim::{FemParams, FemSimulation};
use anim_core::cases::{ConformanceCase, Outcome, Registry, SoakCase, StabilityCase, Study, StudyUse};
use conformance::{material_derivatives, patch_and_momentum};
use hard_cases::{
    explicit_divergence, graded, inverted_recovery_fc, inverted_recovery_snh, near_incompressible,
    stiff_large_dt,
};
use static_problems::{cantilever, cook};
use study::beam_study;

const CRATE: &str = "anim-fem";

/// Registers the crate's conformance checks, hard cases, study, determinism check and soak run, in
/// the order the suites print them.
pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "FEM material P(F), dP/dF vs finite differences of psi",
        run: Box::new(material_derivatives),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "FEM patch test and momentum conservation",
        run: Box::new(patch_and_momentum),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "FEM cantilever vs Euler-Bernoulli (mesh convergence)",
        run: Box::new(cantilever),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "FEM Cook's membrane, nearly incompressible Neo-Hookean",
        run: Box::new(cook),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "determinism: benchmark beam (backward Euler) on 1, 2, 4 threads",
        run: Box::new(determinism::fem_beam),
    });
    let stable = || Outcome::Stable(String::new());
    let diverged = || Outcome::Diverged(String::new());
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "FEM fully inverted initial mesh recovers, fixed corotated",
        expected: stable,
        run: inverted_recovery_fc,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "FEM fully inverted initial mesh recovers, stable Neo-Hookean",
        expected: stable,
        run: inverted_recovery_snh,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "FEM E = 1e8 Pa beam, backward Euler at dt = 1/24 s",
        expected: stable,
        run: stiff_large_dt,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "FEM nu = 0.49 near-incompressible drop",
        expected: stable,
        run: near_incompressible,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "FEM 10:1 mesh-size grading",
        expected: stable,
        run: graded,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "FEM cubes thrown at a 1 cm mesh plate: the speed the penalty catches",
        expected: stable,
        run: thin_plate::thin_mesh_plate,
    });
    r.stability.push(StabilityCase {
        crate_name: CRATE,
        name: "FEM explicit step far above its stability limit",
        expected: diverged,
        run: explicit_divergence,
    });
    r.studies.push(Study { crate_name: CRATE, name: "FEM beam work-precision", run: beam_study });
    r.study_uses.push(StudyUse {
        problem: study_problem,
        ..StudyUse::scene("fem-beam", "fem/cantilever-beam", Some(0.5))
    });
    r.soak.push(SoakCase {
        crate_name: CRATE,
        name: "E = 1e8 Pa stable Neo-Hookean cantilever, backward Euler at dt = 1/24 s",
        bound: "total energy never above its initial value",
        run: soak::fem_stiff_beam,
    });
}

/// Mean displacement along axis `c` of the vertices `select` picks.
fn tip_average(positions: &[[f64; 3]], x: &[f64], select: impl Fn([f64; 3]) -> bool, c: usize) -> f64 {
    let mut s = 0.0;
    let mut n = 0.0;
    for (i, p) in positions.iter().enumerate() {
        if select(*p) {
            s += x[3 * i + c] - p[c];
            n += 1.0;
        }
    }
    s / n
}

/// Density of the dynamic cantilevers (kg/m^3).
const CANTILEVER_DENSITY: f64 = 1000.0;

/// A 1 m x 0.1 m x 0.1 m cantilever under gravity, clamped at x = 0, with `cells` cells across.
fn cantilever_dynamic(
    young: f64,
    poisson: f64,
    model: MaterialModel,
    cells: usize,
) -> Result<FemSimulation, FemError> {
    let mesh = box_mesh([0.0; 3], [1.0, 0.1, 0.1], [10 * cells, cells, cells])?;
    let mut m = FemModel::new(mesh, Material::new(model, young, poisson, CANTILEVER_DENSITY)?)?
        .with_gravity(EARTH_GRAVITY);
    let clamp = m.vertices_where(|p| p[0] < 1e-9);
    m.pin_vertices(&clamp)?;
    FemSimulation::new(m, FemParams::default())
}

anim_core::quick_cases_test!(crate::cases::register);
