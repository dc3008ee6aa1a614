//! The solver settings: PBD or XPBD ([`Method`]), the constraint sweep ([`SolverKind`]) and the
//! iteration, substep, damping and guard parameters ([`PbdParams`]), with their valid ranges.

use super::error::PbdError;

/// PBD (stiffness `k`) or XPBD (compliance `alpha`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum Method {
    /// Position based dynamics with a stiffness `k` in `[0, 1]` (Müller et al. 2007).
    Pbd,
    /// Extended PBD with compliance and multipliers (Macklin et al. 2016): stiffness independent of the
    /// iteration count and time step. The default.
    #[default]
    Xpbd,
}

/// How the constraints are swept in each iteration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum SolverKind {
    /// Sequential Gauss-Seidel in model order, as in Müller et al. 2007. The default.
    #[default]
    GaussSeidel,
    /// Graph-coloured Gauss-Seidel, parallel within a colour.
    ColoredGaussSeidel,
    /// Jacobi with averaging, parallel.
    Jacobi,
}

impl SolverKind {
    /// Every kind.
    pub const ALL: [SolverKind; 3] =
        [SolverKind::GaussSeidel, SolverKind::ColoredGaussSeidel, SolverKind::Jacobi];

    /// Short name for reports.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            SolverKind::GaussSeidel => "gauss-seidel",
            SolverKind::ColoredGaussSeidel => "colored-gauss-seidel",
            SolverKind::Jacobi => "jacobi",
        }
    }
}

/// Solver settings. Every field's default is in its doc.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
#[non_exhaustive]
pub struct PbdParams {
    /// PBD or XPBD. Default [`Method::Xpbd`].
    pub method: Method,
    /// Constraint sweep. Default [`SolverKind::GaussSeidel`].
    pub solver: SolverKind,
    /// Solver iterations per substep (`>= 1`). Default 10.
    pub iterations: usize,
    /// Substeps per step (`>= 1`). Default 1.
    pub substeps: usize,
    /// Müller et al.'s velocity damping `k_damping` in `[0, 1]` (line 6): the velocities'
    /// deviation from the rigid motion of all free particles is reduced by this fraction every
    /// substep. Default 0.
    pub velocity_damping: f64,
    /// Use `k' = 1 - (1 - k)^(1/iterations)` in PBD (Müller et al. 2007, 3.3). Default `true`.
    pub stiffness_correction: bool,
    /// Jacobi relaxation `omega` in `(0, 2]`. Default 1.
    pub jacobi_relaxation: f64,
    /// A step after which a distance constraint is stretched beyond this multiple of its rest
    /// length fails with [`PbdError::Diverged`] (`f64::INFINITY` disables the guard). Default 100.
    pub max_stretch: f64,
    /// Speculative contact margin (m, >= 0): line (8) also generates a contact for a particle
    /// whose predicted position is within `thickness + margin + |p - x|` of a collider, so that
    /// internal constraints cannot push it through the surface during the iterations unseen
    /// (an inactive contact costs one test per iteration). Default `0.005`.
    pub contact_margin: f64,
}

impl Default for PbdParams {
    fn default() -> Self {
        Self {
            method: Method::Xpbd,
            solver: SolverKind::GaussSeidel,
            iterations: 10,
            substeps: 1,
            velocity_damping: 0.0,
            stiffness_correction: true,
            jacobi_relaxation: 1.0,
            max_stretch: 100.0,
            contact_margin: 0.005,
        }
    }
}

impl PbdParams {
    /// Settings with the given method, solver, iterations and substeps; the rest default.
    #[must_use]
    pub fn new(method: Method, solver: SolverKind, iterations: usize, substeps: usize) -> Self {
        Self { method, solver, iterations, substeps, ..Self::default() }
    }

    /// Checks every setting against its range.
    pub(super) fn validate(&self) -> Result<(), PbdError> {
        let bad = |name, requirement, value: String| Err(PbdError::BadParameter { name, requirement, value });
        if self.iterations == 0 {
            return bad("iterations", "must be at least 1", self.iterations.to_string());
        }
        if self.substeps == 0 {
            return bad("substeps", "must be at least 1", self.substeps.to_string());
        }
        if !(0.0..=1.0).contains(&self.velocity_damping) {
            return bad("velocity_damping", "must lie in [0, 1]", self.velocity_damping.to_string());
        }
        if !(self.jacobi_relaxation > 0.0 && self.jacobi_relaxation <= 2.0) {
            return bad("jacobi_relaxation", "must lie in (0, 2]", self.jacobi_relaxation.to_string());
        }
        if !(self.contact_margin >= 0.0 && self.contact_margin.is_finite()) {
            return bad("contact_margin", "must be non-negative and finite", self.contact_margin.to_string());
        }
        if !(self.max_stretch > 1.0) {
            return bad("max_stretch", "must exceed 1", self.max_stretch.to_string());
        }
        Ok(())
    }
}
