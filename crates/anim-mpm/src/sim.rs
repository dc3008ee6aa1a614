//! The simulation: parameters, the step with CFL-adaptive substeps, divergence detection and
//! the diagnostics every step reports.

use crate::boundary::{Boundary, Collider, GridCollider};
use crate::grid::SparseGrid;
use crate::kernel::{Cubic, Kernel, Quadratic, Spline};
use crate::material::{Compiled, Kind, Material, energy};
use crate::mesh_collider::MeshCollider;
use crate::particle_transfer::Ctx;
use crate::particles::Particles;
use crate::simd::{self, Avx2};
use crate::transfer;
use crate::{Mat, MpmError, Vector};
use anim_core::solver::{Solver, StepReport};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// The transfer scheme; `"apic"` or `"mls-mpm"` in scene files and serialised parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Transfer {
    /// APIC (Jiang et al. 2015): grid forces from `grad w_ip`, `F` updated with `sum v_i grad w_ip^T`.
    #[serde(rename = "apic")]
    Apic,
    /// MLS-MPM (Hu et al. 2018): stress fused into the affine momentum, `F` updated with `C_p`.
    #[default]
    #[serde(rename = "mls-mpm")]
    Mls,
}

/// What to do with a particle that leaves the domain.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum OutOfDomain {
    /// Clamp its position back to the domain edge (counted).
    #[default]
    Clamp,
    /// Remove it from the state (counted).
    Remove,
}

/// Simulation parameters. The domain is `[0, size]^D` with `resolution` cells per axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct MpmParams {
    /// Cells per axis `n` (grid spacing `h = size / n`); default 64. At least 8.
    pub resolution: usize,
    /// Side of the cubic domain; default 1.
    pub size: f64,
    /// Transfer scheme; default MLS-MPM.
    pub transfer: Transfer,
    /// Interpolation kernel; default quadratic.
    pub kernel: Kernel,
    /// Gravity (the first `D` components are used); default `(0, -9.81, 0)`.
    pub gravity: [f64; 3],
    /// Boundary condition on the domain walls; default separating, frictionless.
    pub wall: Boundary,
    /// Grid nodes within this many nodes of a wall get the wall condition; default 3 (at least
    /// 2, so that no particle stencil reaches outside the grid).
    pub wall_nodes: usize,
    /// Analytic colliders; default none.
    pub colliders: Vec<Collider>,
    /// Largest allowed advective CFL number `max |v_p| dt / h` per substep; default 1.
    pub cfl: f64,
    /// Largest allowed elastic-wave CFL number `max c_p dt / h` (`c_p^2 = (lambda + 2 mu) / rho`,
    /// hardened for snow); default 1. `f64::INFINITY` disables the check.
    pub wave_cfl: f64,
    /// Largest number of substeps a step may take to meet the CFL limits; default 256.
    pub max_substeps: usize,
    /// Policy for particles leaving the domain; default clamp.
    pub out_of_domain: OutOfDomain,
}

impl Default for MpmParams {
    fn default() -> Self {
        Self {
            resolution: 64,
            size: 1.0,
            transfer: Transfer::Mls,
            kernel: Kernel::Quadratic,
            gravity: [0.0, -9.81, 0.0],
            wall: Boundary::SeparateFrictionless,
            wall_nodes: 3,
            colliders: Vec::new(),
            cfl: 1.0,
            wave_cfl: 1.0,
            max_substeps: 256,
            out_of_domain: OutOfDomain::Clamp,
        }
    }
}

impl MpmParams {
    /// Default parameters with `resolution` cells per axis.
    #[must_use]
    pub fn with_resolution(resolution: usize) -> Self {
        Self { resolution, ..Self::default() }
    }

    /// Grid spacing `h`.
    #[must_use]
    pub fn h(&self) -> f64 {
        self.size / self.resolution as f64
    }

    /// The allowed particle coordinate range `[2h, size - 2h]`.
    #[must_use]
    pub fn particle_range(&self) -> (f64, f64) {
        let h = self.h();
        (2.0 * h, self.size - 2.0 * h)
    }
}

/// Counters of the last step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct StepStats {
    /// Substeps taken.
    pub substeps: usize,
    /// Advective CFL number `max |v| dt / h` of the whole step (before splitting).
    pub cfl: f64,
    /// Elastic-wave CFL number `max c dt / h` of the whole step.
    pub wave_cfl: f64,
    /// Particles that left the domain during the step (clamped or removed).
    pub out_of_domain: u64,
    /// Particles removed during the step.
    pub removed: u64,
    /// Occupied particle blocks at the last substep.
    pub particle_blocks: usize,
    /// Allocated grid nodes at the last substep.
    pub grid_nodes: usize,
}

/// Totals over the particles (in `f64`, summed in a fixed order).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Totals {
    /// Total mass.
    pub mass: f64,
    /// Linear momentum `sum m v` (trailing components zero in 2D).
    pub momentum: [f64; 3],
    /// Angular momentum about the origin including APIC's affine part,
    /// `sum m (x x v) + m eps : (C D_p)^T`; in 2D only the third component is nonzero.
    pub angular_momentum: [f64; 3],
    /// Kinetic energy `sum m |v|^2 / 2`.
    pub kinetic: f64,
    /// Elastic energy `sum V psi(F)`.
    pub elastic: f64,
    /// Gravitational potential energy `-sum m g . x`.
    pub potential: f64,
}

/// An MPM simulation in `D = 2` or `3` dimensions: the model (parameters and materials) and the
/// scratch of a step (the sparse grid, the sort, the double buffer). The particles are the
/// separate [`Particles`] state.
#[derive(Debug, Clone)]
pub struct MpmSimulation<const D: usize> {
    params: MpmParams,
    materials: Vec<Material>,
    compiled: Vec<Compiled>,
    /// The colliders in the grid's `f32`, converted once here.
    colliders: Vec<GridCollider>,
    /// The fixed triangle-mesh obstacles ([`MpmSimulation::set_mesh_colliders`]).
    meshes: Vec<MeshCollider>,
    pub(crate) grid: SparseGrid<D>,
    out: Particles<D>,
    backup: Particles<D>,
    remove: Vec<bool>,
    partials: Vec<[f64; 12]>,
    /// The AVX2 transfer kernels, when the CPU has them (`None`: the portable kernels).
    pub(crate) simd: Option<Avx2>,
    steps: u64,
    time: f64,
    stats: StepStats,
}

/// Particles per chunk of the ordered reductions.
const CHUNK: usize = 2048;

impl<const D: usize> MpmSimulation<D> {
    /// A simulation with the given parameters and material table.
    ///
    /// # Errors
    /// [`MpmError::Dimension`] unless `D` is 2 or 3; [`MpmError::BadParameter`] /
    /// [`MpmError::BadMaterial`] / [`MpmError::BadCollider`] naming the offending field.
    pub fn new(params: MpmParams, materials: Vec<Material>) -> Result<Self, MpmError> {
        if D != 2 && D != 3 {
            return Err(MpmError::Dimension(D));
        }
        let bad = |name: &'static str, reason: String| Err(MpmError::BadParameter { name, reason });
        let max = max_resolution(D);
        if params.resolution < 8 || params.resolution > max {
            return bad("resolution", format!("{} must lie in [8, {max}] in {D}D", params.resolution));
        }
        if !(params.size > 0.0) || !params.size.is_finite() {
            return bad("size", format!("{} must be finite and > 0", params.size));
        }
        if params.gravity.iter().any(|g| !g.is_finite()) {
            return bad("gravity", format!("{:?} must be finite", params.gravity));
        }
        if params.wall_nodes < 2 || params.wall_nodes > params.resolution / 2 {
            return bad("wall_nodes", format!("{} must lie in [2, resolution / 2]", params.wall_nodes));
        }
        if !(params.cfl > 0.0) {
            return bad("cfl", format!("{} must be > 0", params.cfl));
        }
        if !(params.wave_cfl > 0.0) {
            return bad("wave_cfl", format!("{} must be > 0", params.wave_cfl));
        }
        if params.max_substeps == 0 {
            return bad("max_substeps", "must be >= 1".into());
        }
        if materials.is_empty() || materials.len() > usize::from(u16::MAX) {
            return bad("materials", format!("{} materials; need 1 to 65535", materials.len()));
        }
        params.wall.validate("wall friction")?;
        let colliders = params
            .colliders
            .iter()
            .enumerate()
            .map(|(i, c)| c.compile(i, D))
            .collect::<Result<Vec<_>, _>>()?;
        let compiled =
            materials.iter().enumerate().map(|(i, m)| m.compile(i)).collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            grid: SparseGrid::new(params.resolution),
            params,
            materials,
            compiled,
            colliders,
            meshes: Vec::new(),
            out: Particles::new(),
            backup: Particles::new(),
            remove: Vec::new(),
            partials: Vec::new(),
            simd: Avx2::detect(),
            steps: 0,
            time: 0.0,
            stats: StepStats::default(),
        })
    }

    /// The parameters.
    #[must_use]
    pub fn params(&self) -> &MpmParams {
        &self.params
    }

    /// Sets the fixed triangle-mesh obstacles ([`MeshCollider`], level sets sampled on this
    /// simulation's grid), applied in the grid update after the analytic colliders.
    ///
    /// # Errors
    /// [`MpmError::BadParameter`] in 2D (mesh obstacles are 3D).
    pub fn set_mesh_colliders(&mut self, meshes: Vec<MeshCollider>) -> Result<(), MpmError> {
        if D != 3 && !meshes.is_empty() {
            return Err(MpmError::BadParameter {
                name: "mesh colliders",
                reason: format!("mesh obstacles are 3D; this simulation is {D}D"),
            });
        }
        self.meshes = meshes;
        Ok(())
    }

    /// The fixed triangle-mesh obstacles.
    #[must_use]
    pub fn mesh_colliders(&self) -> &[MeshCollider] {
        &self.meshes
    }

    /// The material table.
    #[must_use]
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// Simulated time.
    #[must_use]
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Completed steps.
    #[must_use]
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// What the simulation carries from one step to the next (step count and time; the grid is
    /// rebuilt from the particles every step), for checkpoints: with the [`Particles`], it
    /// continues a run bit for bit.
    #[must_use]
    pub fn memory(&self) -> serde_json::Value {
        anim_core::solver::StepClock { steps: self.steps, time: self.time }.to_memory()
    }

    /// Restores what [`MpmSimulation::memory`] returned.
    ///
    /// # Errors
    /// [`MpmError::Checkpoint`] when a field is missing or the time is not finite.
    pub fn restore_memory(&mut self, memory: &serde_json::Value) -> Result<(), MpmError> {
        let clock =
            anim_core::solver::StepClock::from_memory(memory).map_err(|e| MpmError::Checkpoint(e.into()))?;
        self.steps = clock.steps;
        self.time = clock.time;
        Ok(())
    }

    /// Counters of the last step.
    #[must_use]
    pub fn stats(&self) -> StepStats {
        self.stats
    }

    /// Grid nodes of the last substep with mass: `(position, mass, velocity)` (velocities after
    /// the grid update). For diagnostics and tests.
    pub fn grid_nodes(&self) -> impl Iterator<Item = (Vector<D>, f32, Vector<D>)> + '_ {
        let bn = SparseGrid::<D>::BN;
        let h = self.params.h() as f32;
        self.grid.gblocks.iter().enumerate().flat_map(move |(g, &key)| {
            let block = self.grid.coords(key);
            (0..bn).filter_map(move |l| {
                let node = self.grid.nodes[g * bn + l].to_array();
                if node[0] <= 0.0 {
                    return None;
                }
                let mut r = l;
                let mut x = Vector::<D>::zeros();
                for a in 0..D {
                    x[a] = (block[a] as usize * 4 + r % 4) as f32 * h;
                    r /= 4;
                }
                Some((x, node[0], Vector::<D>::from_fn(|a, _| node[1 + a])))
            })
        })
    }

    /// Mass, linear momentum and angular momentum about the origin (`sum m x x v`) of the grid
    /// nodes of the last step ([`grid_nodes`](Self::grid_nodes)), summed in `f64` in node order:
    /// what the transfers must carry over from and back to the particles ([`totals`](Self::totals)).
    #[must_use]
    pub fn grid_totals(&self) -> (f64, [f64; 3], [f64; 3]) {
        let (mut gm, mut gp, mut gl) = (0.0f64, [0.0f64; 3], [0.0f64; 3]);
        for (x, m, v) in self.grid_nodes() {
            let m = f64::from(m);
            gm += m;
            let x3 = [f64::from(x[0]), f64::from(x[1]), if D == 3 { f64::from(x[2]) } else { 0.0 }];
            let v3 = [f64::from(v[0]), f64::from(v[1]), if D == 3 { f64::from(v[2]) } else { 0.0 }];
            for a in 0..3 {
                gp[a] += m * v3[a];
            }
            gl[0] += m * (x3[1] * v3[2] - x3[2] * v3[1]);
            gl[1] += m * (x3[2] * v3[0] - x3[0] * v3[2]);
            gl[2] += m * (x3[0] * v3[1] - x3[1] * v3[0]);
        }
        (gm, gp, gl)
    }

    /// Mass, momenta and energies of a particle state, summed in `f64` in a fixed order
    /// (identical for any thread count).
    pub fn totals(&mut self, st: &Particles<D>) -> Totals {
        let n = st.len();
        let chunks = n.div_ceil(CHUNK);
        self.partials.resize(chunks, [0.0; 12]);
        let d_inv = f64::from(self.params.kernel.d_inv());
        let h = self.params.h();
        let dp = h * h / d_inv;
        let g = self.params.gravity;
        let compiled = &self.compiled;
        self.partials.par_iter_mut().enumerate().for_each(|(c, acc)| {
            *acc = [0.0; 12];
            for p in c * CHUNK..((c + 1) * CHUNK).min(n) {
                let m = f64::from(st.mass[p]);
                let x = st.position(p);
                let v = st.velocity(p);
                let cm = st.affine(p);
                let x3 = [f64::from(x[0]), f64::from(x[1]), if D == 3 { f64::from(x[2]) } else { 0.0 }];
                let v3 = [f64::from(v[0]), f64::from(v[1]), if D == 3 { f64::from(v[2]) } else { 0.0 }];
                acc[0] += m;
                for a in 0..3 {
                    acc[1 + a] += m * v3[a];
                }
                // x x v.
                let l = [
                    x3[1] * v3[2] - x3[2] * v3[1],
                    x3[2] * v3[0] - x3[0] * v3[2],
                    x3[0] * v3[1] - x3[1] * v3[0],
                ];
                // Affine part: B = C D_p; angular momentum eps_abc B_cb (the skew part of B^T).
                let b = |i: usize, j: usize| -> f64 {
                    if i < D && j < D { f64::from(cm[(i, j)]) * dp } else { 0.0 }
                };
                let la = [b(2, 1) - b(1, 2), b(0, 2) - b(2, 0), b(1, 0) - b(0, 1)];
                for a in 0..3 {
                    acc[4 + a] += m * (l[a] + la[a]);
                }
                acc[7] += 0.5 * m * (v3[0] * v3[0] + v3[1] * v3[1] + v3[2] * v3[2]);
                let mat = &compiled[usize::from(st.material[p]).min(compiled.len() - 1)];
                acc[8] += f64::from(st.volume[p]) * f64::from(energy(mat, &st.deformation(p), st.plastic[p]));
                acc[9] -= m * (g[0] * x3[0] + g[1] * x3[1] + if D == 3 { g[2] * x3[2] } else { 0.0 });
            }
        });
        let mut t = [0.0; 12];
        for acc in &self.partials {
            for i in 0..12 {
                t[i] += acc[i];
            }
        }
        Totals {
            mass: t[0],
            momentum: [t[1], t[2], t[3]],
            angular_momentum: [t[4], t[5], t[6]],
            kinetic: t[7],
            elastic: t[8],
            potential: t[9],
        }
    }

    /// Checks the state and measures the CFL numbers of a step of `dt`.
    fn survey(&self, st: &Particles<D>, dt: f64) -> Result<(f64, f64), MpmError> {
        st.check_lengths()?;
        let (lo, hi) = self.params.particle_range();
        let (lo, hi) = (lo as f32, hi as f32);
        let nmat = self.compiled.len();
        let compiled = &self.compiled;
        let n = st.len();
        let ok = |p: usize| {
            let x = &st.x[p * D..p * D + D];
            usize::from(st.material[p]) < nmat
                && x.iter().all(|c| *c >= lo && *c <= hi)
                && st.v[p * D..p * D + D].iter().all(|c| c.is_finite())
                && st.f[p * D * D..(p + 1) * D * D].iter().all(|c| c.is_finite())
                && st.c[p * D * D..(p + 1) * D * D].iter().all(|c| c.is_finite())
                && st.mass[p] > 0.0
                && st.volume[p] > 0.0
        };
        // Per chunk of particles: (max |v|^2, max c^2, first bad particle). The checks run as
        // flat passes over each array (integer tests on the bits where that is exact); only a
        // chunk that fails one is searched particle by particle.
        let (v2, c2, bad) = (0..n.div_ceil(CHUNK))
            .into_par_iter()
            .map(|chunk| {
                simd::with_simd(
                    self.simd,
                    #[inline(always)]
                    || {
                        let r = chunk * CHUNK..((chunk + 1) * CHUNK).min(n);
                        // An infinity or a NaN has all exponent bits set.
                        let any_non_finite = |a: &[f32]| {
                            a.iter().fold(false, |m, c| m | (c.to_bits() & 0x7f80_0000 == 0x7f80_0000))
                        };
                        let out_of_range = st.x[r.start * D..r.end * D]
                            .iter()
                            .fold(false, |b, c| b | !(*c >= lo && *c <= hi));
                        let material = st.material[r.clone()].iter().fold(0u16, |m, &k| m.max(k));
                        let non_finite = any_non_finite(&st.v[r.start * D..r.end * D])
                            | any_non_finite(&st.f[r.start * D * D..r.end * D * D])
                            | any_non_finite(&st.c[r.start * D * D..r.end * D * D]);
                        let non_positive = st.mass[r.clone()]
                            .iter()
                            .chain(&st.volume[r.clone()])
                            .fold(false, |b, m| b | !(*m > 0.0));
                        if out_of_range || usize::from(material) >= nmat || non_finite || non_positive {
                            let p = r.clone().find(|&p| !ok(p)).unwrap_or(r.start);
                            return (0.0f32, 0.0f32, p);
                        }
                        // `min` and `max` of finite values, without the NaN handling of `f32::min`.
                        let (fmin, fmax) = (
                            |a: f32, b: f32| if b < a { b } else { a },
                            |a: f32, b: f32| if b > a { b } else { a },
                        );
                        let v2 = st.v[r.start * D..r.end * D]
                            .chunks_exact(D)
                            .fold(0.0f32, |m, v| fmax(m, v.iter().map(|c| c * c).sum::<f32>()));
                        let c2 = if !st.material[r.clone()].iter().fold(false, |b, &k| b | (k != material)) {
                            // One material: its wave speed is monotone in J (fluid) or J_P (snow) and
                            // constant otherwise, so the largest is at one end of their range.
                            let m = &compiled[usize::from(material)];
                            match m.kind {
                                Kind::Fluid => {
                                    let (lo_j, hi_j) = st.f[r.start * D * D..r.end * D * D]
                                        .chunks_exact(D * D)
                                        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), f| {
                                            // The clamp of `wave_speed2` (which also turns the NaN of
                                            // an overflowing determinant into 1e-3).
                                            let j = anim_material::decomposition::determinant(
                                                &Mat::<D>::from_column_slice(f),
                                            )
                                            .max(1e-3);
                                            (fmin(a, j), fmax(b, j))
                                        });
                                    m.wave_speed2(1.0, lo_j).max(m.wave_speed2(1.0, hi_j))
                                }
                                Kind::Snow => {
                                    let (lo_p, hi_p) = st.plastic[r.clone()]
                                        .iter()
                                        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &jp| {
                                            (fmin(a, jp), fmax(b, jp))
                                        });
                                    m.wave_speed2(lo_p, 1.0).max(m.wave_speed2(hi_p, 1.0))
                                }
                                _ => m.wave_speed2(1.0, 1.0),
                            }
                        } else {
                            r.clone().fold(0.0f32, |c2, p| {
                                let m = &compiled[usize::from(st.material[p])];
                                let j = anim_material::decomposition::determinant(&st.deformation(p));
                                c2.max(m.wave_speed2(st.plastic[p], j))
                            })
                        };
                        (v2, c2, usize::MAX)
                    },
                )
            })
            .reduce(|| (0.0, 0.0, usize::MAX), |a, b| (a.0.max(b.0), a.1.max(b.1), a.2.min(b.2)));
        if bad != usize::MAX {
            let p = bad;
            let x = &st.x[p * D..p * D + D];
            let reason = if usize::from(st.material[p]) >= nmat {
                format!("material index {} but only {nmat} materials", st.material[p])
            } else if !x.iter().all(|c| *c >= lo && *c <= hi) {
                format!("position {x:?} outside the particle range [{lo}, {hi}]")
            } else {
                "non-finite velocity, affine matrix or deformation gradient, or non-positive mass or volume"
                    .to_string()
            };
            return Err(MpmError::BadParticle { index: st.id[p] as usize, reason });
        }
        let h = self.params.h();
        Ok((f64::from(v2).sqrt() * dt / h, f64::from(c2).sqrt() * dt / h))
    }

    fn substep<K: Spline>(&mut self, st: &mut Particles<D>, dt: f64) -> Result<(u64, u64), MpmError> {
        let ctx = substep_ctx(
            &self.params,
            &self.colliders,
            &self.meshes,
            &self.compiled,
            self.time,
            self.simd,
            dt,
        );
        let n = st.len();
        self.grid.bin(&st.x, ctx.inv_h, self.params.kernel, self.simd);
        transfer::p2g::<D, K>(&mut self.grid, st, &ctx);
        transfer::grid_update(&mut self.grid, &ctx);
        transfer::gather(&mut self.grid, self.simd);
        self.out.resize(n);
        let removing = self.params.out_of_domain == OutOfDomain::Remove;
        self.remove.resize(n, false);
        let outcome = transfer::g2p::<D, K>(&self.grid, st, &mut self.out, &mut self.remove, &ctx);
        if outcome.first_bad != u32::MAX {
            let s = outcome.first_bad as usize;
            let p = self.grid.order[s] as usize;
            let bad = |a: &[f32]| a.iter().position(|c| !c.is_finite());
            let out = &self.out;
            let (field, component, value) = if let Some(k) = bad(&out.x[s * D..s * D + D]) {
                ("position", k, out.x[s * D + k])
            } else if let Some(k) = bad(&out.v[s * D..s * D + D]) {
                ("velocity", k, out.v[s * D + k])
            } else if let Some(k) = bad(&out.f[s * D * D..(s + 1) * D * D]) {
                ("deformation gradient", k, out.f[s * D * D + k])
            } else if let Some(k) = bad(&out.c[s * D * D..(s + 1) * D * D]) {
                ("affine matrix", k, out.c[s * D * D + k])
            } else {
                ("plastic state", 0, out.plastic[s])
            };
            // The caller restores the particles of the step's start and fills in `last_finite`.
            return Err(MpmError::NonFinite {
                step: self.steps,
                particle: st.id[p] as usize,
                field,
                component,
                value: f64::from(value),
                last_finite: Vec::new(),
            });
        }
        st.swap(&mut self.out);
        let mut removed = 0;
        if removing && outcome.outside > 0 {
            st.retain(&self.remove);
            removed = outcome.outside;
        }
        self.time += dt;
        Ok((outcome.outside, removed))
    }

    /// Advances the particles by `dt`, splitting the step into substeps so that both CFL
    /// numbers stay within their limits.
    ///
    /// # Errors
    /// [`MpmError::BadParameter`] for `dt <= 0`; [`MpmError::BadParticle`] / [`MpmError::BadState`]
    /// for an inconsistent state or a particle outside the domain;
    /// [`MpmError::TooManySubsteps`] when the CFL limits need more than `max_substeps`;
    /// [`MpmError::NonFinite`] when the step diverges, naming the step and particle. On error
    /// the state is left as it was.
    pub fn advance(&mut self, st: &mut Particles<D>, dt: f64) -> Result<StepStats, MpmError> {
        if !(dt > 0.0) || !dt.is_finite() {
            return Err(MpmError::BadParameter {
                name: "dt",
                reason: format!("{dt} must be finite and > 0"),
            });
        }
        let (cfl, wave) = self.survey(st, dt)?;
        let need = (cfl / self.params.cfl).max(wave / self.params.wave_cfl).ceil().max(1.0);
        if need > self.params.max_substeps as f64 {
            return Err(MpmError::TooManySubsteps {
                step: self.steps,
                cfl,
                wave_cfl: wave,
                needed: need,
                limit: self.params.max_substeps,
            });
        }
        let substeps = need as usize;
        if substeps > 1 {
            self.backup.copy_from(st);
        }
        let time0 = self.time;
        let sub_dt = dt / substeps as f64;
        let (mut outside, mut removed) = (0, 0);
        for _ in 0..substeps {
            let r = match self.params.kernel {
                Kernel::Quadratic => self.substep::<Quadratic>(st, sub_dt),
                Kernel::Cubic => self.substep::<Cubic>(st, sub_dt),
            };
            match r {
                Ok((o, rm)) => {
                    outside += o;
                    removed += rm;
                }
                Err(mut e) => {
                    if substeps > 1 {
                        st.copy_from(&self.backup);
                    }
                    self.time = time0;
                    if let MpmError::NonFinite { particle, field, last_finite, .. } = &mut e {
                        *last_finite = last_finite_of(st, *particle, field);
                    }
                    return Err(e);
                }
            }
        }
        self.time = time0 + dt;
        self.steps += 1;
        self.stats = StepStats {
            substeps,
            cfl,
            wave_cfl: wave,
            out_of_domain: outside,
            removed,
            particle_blocks: self.grid.pblocks.len(),
            grid_nodes: self.grid.allocated_nodes(),
        };
        Ok(self.stats)
    }
}

/// Timing hooks of the transfers for the roofline table (`crate::cases`): the binned P2G and
/// the G2P into the scratch output, each repeatable without advancing the state.
#[cfg(feature = "cases")]
impl<const D: usize> MpmSimulation<D> {
    /// Runs the stages of a substep of `dt` on `st` up to G2P without changing `st`: bins the
    /// particles, P2G, the grid update and the gather into the particle blocks' windows; after
    /// it, [`Self::time_g2p`] reads the gathered velocities. Returns the bytes of the windows.
    pub(crate) fn prepare_transfers(&mut self, st: &Particles<D>, dt: f64) -> usize {
        match self.params.kernel {
            Kernel::Quadratic => self.stages::<Quadratic>(st, dt, true),
            Kernel::Cubic => self.stages::<Cubic>(st, dt, true),
        }
        self.grid.windows.len() * std::mem::size_of::<wide::f32x4>()
    }

    /// P2G of `st` into the windows of the last [`Self::prepare_transfers`] (same binning).
    pub(crate) fn time_p2g(&mut self, st: &Particles<D>, dt: f64) {
        match self.params.kernel {
            Kernel::Quadratic => self.stages::<Quadratic>(st, dt, false),
            Kernel::Cubic => self.stages::<Cubic>(st, dt, false),
        }
    }

    /// G2P of `st` from the gathered windows into the scratch output (`st` unchanged); returns
    /// the particles found outside the domain.
    pub(crate) fn time_g2p(&mut self, st: &Particles<D>, dt: f64) -> u64 {
        match self.params.kernel {
            Kernel::Quadratic => self.g2p_only::<Quadratic>(st, dt),
            Kernel::Cubic => self.g2p_only::<Cubic>(st, dt),
        }
    }

    /// The transfers' context for a substep of `dt` (as `substep` builds it), passed to `f`
    /// with the grid and the scratch.
    fn with_ctx<R>(
        &mut self,
        dt: f64,
        f: impl FnOnce(&mut SparseGrid<D>, &mut Particles<D>, &mut Vec<bool>, &Ctx<'_, D>) -> R,
    ) -> R {
        let ctx = substep_ctx(
            &self.params,
            &self.colliders,
            &self.meshes,
            &self.compiled,
            self.time,
            self.simd,
            dt,
        );
        f(&mut self.grid, &mut self.out, &mut self.remove, &ctx)
    }

    fn stages<K: Spline>(&mut self, st: &Particles<D>, dt: f64, all: bool) {
        let kernel = self.params.kernel;
        self.with_ctx(dt, |grid, _, _, ctx| {
            if all {
                grid.bin(&st.x, ctx.inv_h, kernel, ctx.simd);
            }
            transfer::p2g::<D, K>(grid, st, ctx);
            if all {
                transfer::grid_update(grid, ctx);
                transfer::gather(grid, ctx.simd);
            }
        });
    }

    fn g2p_only<K: Spline>(&mut self, st: &Particles<D>, dt: f64) -> u64 {
        let n = st.len();
        self.with_ctx(dt, |grid, out, remove, ctx| {
            out.resize(n);
            remove.resize(n, false);
            transfer::g2p::<D, K>(grid, st, out, remove, ctx).outside
        })
    }
}

/// The quantity `field` of the particle with id `id` in `st` (the particles before the step),
/// widened to `f64`; runs only on the error path.
fn last_finite_of<const D: usize>(st: &Particles<D>, id: usize, field: &str) -> Vec<f64> {
    let Some(p) = st.id.iter().position(|&i| i as usize == id) else { return Vec::new() };
    let values: &[f32] = match field {
        "position" => &st.x[p * D..p * D + D],
        "velocity" => &st.v[p * D..p * D + D],
        "deformation gradient" => &st.f[p * D * D..(p + 1) * D * D],
        "affine matrix" => &st.c[p * D * D..(p + 1) * D * D],
        _ => std::slice::from_ref(&st.plastic[p]),
    };
    values.iter().map(|&v| f64::from(v)).collect()
}

impl<const D: usize> Solver for MpmSimulation<D> {
    type State = Particles<D>;
    type Error = MpmError;

    /// [`advance`](MpmSimulation::advance), then the totals: `iterations` is the number of
    /// substeps, `energy` kinetic + elastic + gravitational, momenta as in [`Totals`].
    fn step(&mut self, state: &mut Particles<D>, dt: f64) -> Result<StepReport, MpmError> {
        let stats = self.advance(state, dt)?;
        let t = self.totals(state);
        let mut r = StepReport::at_time(self.time);
        r.iterations = stats.substeps;
        r.energy = Some(t.kinetic + t.elastic + t.potential);
        r.energy_parts = Some(anim_core::solver::EnergyParts {
            kinetic: t.kinetic,
            gravity: t.potential,
            elastic: t.elastic,
        });
        r.linear_momentum = Some(t.momentum);
        r.angular_momentum = Some(t.angular_momentum);
        Ok(r)
    }
}

/// The finest grid in `D` dimensions that the sparse grid's `u32` block keys address: its dense
/// tables hold `(n / 4 + 2)^D` blocks, at most `u32::MAX`, so 262,135 cells per axis in 2D and
/// 6,495 in 3D. Long before that the memory runs out (the tables take 12 bytes a block, 2048
/// cells per axis in 3D 1.6 GB before any matter): the `mpm` kind checks the memory a scene
/// will take against the memory available ([`crate::memory`]).
#[must_use]
pub const fn max_resolution(dim: usize) -> usize {
    if dim >= 3 { 6495 } else { 262_135 }
}

/// The transfers' context of a substep of `dt` starting at `time`: the parameters in the
/// kernels' `f32`, the colliders, meshes and compiled materials borrowed.
fn substep_ctx<'a, const D: usize>(
    params: &MpmParams,
    colliders: &'a [GridCollider],
    meshes: &'a [MeshCollider],
    materials: &'a [Compiled],
    time: f64,
    simd: Option<Avx2>,
    dt: f64,
) -> Ctx<'a, D> {
    let h = params.h();
    let (lo, hi) = params.particle_range();
    let g = params.gravity;
    Ctx {
        h: h as f32,
        inv_h: (1.0 / h) as f32,
        dt: dt as f32,
        apic: params.transfer == Transfer::Apic,
        gravity: Vector::<D>::from_fn(|a, _| g[a] as f32),
        wall_nodes: params.wall_nodes,
        wall: params.wall,
        colliders,
        meshes,
        time: time as f32,
        lo: lo as f32,
        hi: hi as f32,
        materials,
        simd,
    }
}
