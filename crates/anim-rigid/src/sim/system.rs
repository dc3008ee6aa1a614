//! The articulated system: a model, its data and the forces of [`SimParams`], with the
//! acceleration by ABA. See [`crate::sim`].

use anim_core::integrate::SecondOrderSystem;

use crate::data::Data;
use crate::dynamics::{aba, forward_dynamics_cholesky, kinetic_energy, potential_energy, spatial_momentum};
use crate::model::{JointType, Model};
use crate::sim::error::SimError;
use crate::sim::params::{Servo, SimParams};
use crate::spatial::Force;

/// The energy of a state, by part (J).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Energy {
    /// Kinetic energy `½ vᵀ H v`.
    pub kinetic: f64,
    /// Gravitational potential energy `-Σ mᵢ g·cᵢ`.
    pub gravity: f64,
    /// Joint-limit penalty energy `Σ ½ k δ²`.
    pub limits: f64,
}

impl Energy {
    /// The total `kinetic + gravity + limits`.
    #[must_use]
    pub fn total(&self) -> f64 {
        self.kinetic + self.gravity + self.limits
    }
}

/// A tree with its workspace and the forces of [`SimParams`]; its acceleration is
/// `ABA(q, v, τ_applied + τ_servos - d v + τ_limits)`.
///
/// Implements anim-core's [`SecondOrderSystem`] (state `x = q`, `dof = nv`), meaningful when the
/// model is Euclidean ([`Model::is_euclidean`]); for spherical and free joints step it with
/// [`RigidSimulation`](crate::sim::RigidSimulation).
///
/// ```
/// use anim_core::integrate::{Integrator, IntegratorKind, State};
/// use anim_rigid::sim::{ArticulatedSystem, SimParams};
/// use anim_rigid::{parse_urdf, UrdfOptions};
///
/// let urdf = r#"<robot name="p"><link name="base"/>
///   <link name="rod"><inertial><origin xyz="1 0 0"/><mass value="1"/>
///     <inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>
///   <joint name="hinge" type="continuous"><parent link="base"/><child link="rod"/>
///     <axis xyz="0 1 0"/></joint></robot>"#;
/// let model = parse_urdf(urdf, &UrdfOptions::default())?;
/// let mut pendulum = ArticulatedSystem::new(model, SimParams::default())?;
/// let mut state = State::new(vec![0.0], vec![0.0]);
/// let mut rk4 = IntegratorKind::Rk4.build_explicit(1).expect("explicit");
/// let e0 = pendulum.energy_of(&state.x, &state.v).total();
/// for _ in 0..1000 {
///     rk4.step(&mut pendulum, &mut state, 1e-3)?;
/// }
/// assert!(state.x[0] > 0.5); // swung down: rotation about +y takes +x towards -z
/// assert!((pendulum.energy_of(&state.x, &state.v).total() - e0).abs() < 1e-9);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct ArticulatedSystem {
    model: Model,
    data: Data,
    params: SimParams,
    /// Scratch: the joint forces handed to ABA.
    tau: Vec<f64>,
    /// Per degree of freedom: whether joint damping applies (false on free joints).
    damped: Vec<bool>,
    /// Per degree of freedom: `(q index, lower, upper)` of bounded one-degree-of-freedom joints.
    limits: Vec<Option<(usize, f64, f64)>>,
    /// Per degree of freedom: `(q index, servo)` of the servoed ones.
    servos: Vec<Option<(usize, Servo)>>,
}

impl ArticulatedSystem {
    /// The system of `model` with the forces of `params`.
    ///
    /// # Errors
    /// [`SimError::BadParameter`] for a negative or non-finite damping or limit coefficient, a
    /// torque vector of the wrong length or with non-finite entries, a servo on a degree of
    /// freedom that is not a one-degree-of-freedom joint's (or servoed twice), with a non-finite
    /// target or a negative or non-finite gain, or bad Newton settings.
    pub fn new(model: Model, params: SimParams) -> Result<Self, SimError> {
        let servos = validate(&model, &params)?;
        let nv = model.nv();
        let mut damped = vec![true; nv];
        let mut limits = vec![None; nv];
        for j in &model.joints()[1..] {
            if matches!(j.kind, JointType::Free) {
                damped[j.idx_v..j.idx_v + 6].fill(false);
            }
            if j.nq() == 1 && (j.limits.lower.is_finite() || j.limits.upper.is_finite()) {
                limits[j.idx_v] = Some((j.idx_q, j.limits.lower, j.limits.upper));
            }
        }
        let data = Data::new(&model);
        Ok(Self { model, data, params, tau: vec![0.0; nv], damped, limits, servos })
    }

    /// The model.
    #[must_use]
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The workspace (results of the last evaluation).
    #[must_use]
    pub fn data(&self) -> &Data {
        &self.data
    }

    /// The workspace, mutable, for running other algorithms on this system's model.
    pub fn data_mut(&mut self) -> &mut Data {
        &mut self.data
    }

    /// The model and workspace together (to call `algorithm(&model, &mut data, ...)`).
    pub fn model_and_data(&mut self) -> (&Model, &mut Data) {
        (&self.model, &mut self.data)
    }

    /// The force parameters.
    #[must_use]
    pub fn params(&self) -> &SimParams {
        &self.params
    }

    /// Replaces the force parameters (between steps).
    ///
    /// # Errors
    /// As [`new`](Self::new); the parameters are unchanged on error.
    pub fn set_params(&mut self, params: SimParams) -> Result<(), SimError> {
        self.servos = validate(&self.model, &params)?;
        self.params = params;
        Ok(())
    }

    /// Sets the constant applied joint torques (length `nv`, or empty for none), in place: no
    /// allocation once the torque vector has had length `nv`, so a torque schedule can change
    /// it before every step.
    ///
    /// # Errors
    /// [`SimError::BadParameter`] for a wrong length or non-finite entries; the torques are
    /// unchanged on error.
    pub fn set_torque(&mut self, torque: &[f64]) -> Result<(), SimError> {
        validate_torque(&self.model, torque)?;
        self.params.torque.clear();
        self.params.torque.extend_from_slice(torque);
        Ok(())
    }

    /// The joint forces other than gravity and inertia at `(q, v)`: applied torques, damping and
    /// limit penalties, written into `out` (length `nv`).
    ///
    /// # Panics
    /// When a length does not match the model.
    #[track_caller]
    pub fn joint_forces(&self, q: &[f64], v: &[f64], out: &mut [f64]) {
        let nv = self.model.nv();
        assert_eq!(q.len(), self.model.nq(), "q has length {}, the model nq = {}", q.len(), self.model.nq());
        assert!(v.len() == nv && out.len() == nv, "v and out must have length nv = {nv}");
        for (k, o) in out.iter_mut().enumerate() {
            *o = self.joint_force(k, q, v);
        }
    }

    /// The force of [`joint_forces`](Self::joint_forces) on degree of freedom `k`.
    #[inline]
    fn joint_force(&self, k: usize, q: &[f64], v: &[f64]) -> f64 {
        let p = &self.params;
        let mut f = if p.torque.is_empty() { 0.0 } else { p.torque[k] };
        if self.damped[k] {
            f -= p.damping * v[k];
        }
        if let Some((iq, lo, hi)) = self.limits[k] {
            f += limit_force(q[iq], v[k], lo, hi, p.limit_stiffness, p.limit_damping);
        }
        if let Some((iq, servo)) = self.servos[k] {
            f += servo.kp * (servo.target - q[iq]) - servo.kd * v[k];
        }
        f
    }

    /// The acceleration `ABA(q, v, τ)` with the joint forces of [`joint_forces`](Self::joint_forces),
    /// written into `out`. A model with coupled joints ([`Model::mimic_joints`]), which ABA does
    /// not handle, takes [`forward_dynamics_cholesky`] (`H v̇ = τ - C`) instead; when its mass
    /// matrix is not positive definite `out` is NaN, which the steppers report as a non-finite
    /// state.
    ///
    /// # Panics
    /// When a length does not match the model.
    #[track_caller]
    pub fn acceleration_into(&mut self, q: &[f64], v: &[f64], out: &mut [f64]) {
        let mut tau = std::mem::take(&mut self.tau);
        self.joint_forces(q, v, &mut tau);
        if self.model.mimic_joints().is_empty() {
            out.copy_from_slice(aba(&self.model, &mut self.data, q, v, &tau));
        } else {
            match forward_dynamics_cholesky(&self.model, &mut self.data, q, v, &tau) {
                Ok(ddq) => out.copy_from_slice(ddq),
                Err(_) => out.fill(f64::NAN),
            }
        }
        self.tau = tau;
    }

    /// The energy of the state `(q, v)` by part.
    ///
    /// # Panics
    /// When a length does not match the model.
    #[track_caller]
    pub fn energy_of(&mut self, q: &[f64], v: &[f64]) -> Energy {
        let kinetic = kinetic_energy(&self.model, &mut self.data, q, v);
        let gravity = potential_energy(&self.model, &mut self.data, q);
        let k = self.params.limit_stiffness;
        let limits = self
            .limits
            .iter()
            .flatten()
            .map(|&(iq, lo, hi)| {
                let d = penetration(q[iq], lo, hi);
                0.5 * k * d * d
            })
            .sum();
        Energy { kinetic, gravity, limits }
    }

    /// The world spatial momentum `(linear, angular about the origin)` of the state.
    ///
    /// # Panics
    /// When a length does not match the model.
    #[track_caller]
    pub fn momentum_of(&mut self, q: &[f64], v: &[f64]) -> Force {
        spatial_momentum(&self.model, &mut self.data, q, v)
    }

    /// The rate of change of the total energy ([`Energy::total`]) at `(q, v)`:
    /// `Σ_k q̇_k (τ_k + τ_servo,k - d q̇_k + τ_limit,k + k δ_k)`, the power of applied torques,
    /// servos, damping and the dissipative part of the limit penalty. Zero for a conservative system.
    ///
    /// # Panics
    /// When a length does not match the model.
    #[track_caller]
    pub fn power(&self, q: &[f64], v: &[f64]) -> f64 {
        assert_eq!(q.len(), self.model.nq(), "q has length {}, the model nq = {}", q.len(), self.model.nq());
        assert_eq!(v.len(), self.model.nv(), "v has length {}, the model nv = {}", v.len(), self.model.nv());
        let k = self.params.limit_stiffness;
        let mut p = 0.0;
        for (i, vi) in v.iter().enumerate() {
            // The conservative part -k δ of the limit force is in the energy, not in the power.
            let elastic = self.limits[i].map_or(0.0, |(iq, lo, hi)| -k * penetration(q[iq], lo, hi));
            p += (self.joint_force(i, q, v) - elastic) * vi;
        }
        p
    }
}

impl SecondOrderSystem for ArticulatedSystem {
    fn dof(&self) -> usize {
        self.model.nv()
    }

    fn acceleration(&mut self, _t: f64, x: &[f64], v: &[f64], a: &mut [f64]) {
        self.acceleration_into(x, v, a);
    }

    fn energy(&mut self, _t: f64, x: &[f64], v: &[f64]) -> Option<f64> {
        Some(self.energy_of(x, v).total())
    }
}

impl SimParams {
    /// Whether these parameters suit `model`: the checks [`ArticulatedSystem::new`] makes,
    /// without building the system.
    ///
    /// # Errors
    /// As [`ArticulatedSystem::new`].
    pub fn check(&self, model: &Model) -> Result<(), SimError> {
        validate(model, self).map(|_| ())
    }
}

/// How far `q` is beyond its limits: positive above `hi`, negative below `lo`, zero inside.
#[inline]
fn penetration(q: f64, lo: f64, hi: f64) -> f64 {
    if q > hi {
        q - hi
    } else if q < lo {
        q - lo
    } else {
        0.0
    }
}

/// The one-sided penalty torque `-k δ - c q̇`, never pulling the joint further beyond its limit.
#[inline]
fn limit_force(q: f64, v: f64, lo: f64, hi: f64, k: f64, c: f64) -> f64 {
    let d = penetration(q, lo, hi);
    if d > 0.0 {
        (-k * d - c * v).min(0.0)
    } else if d < 0.0 {
        (-k * d - c * v).max(0.0)
    } else {
        0.0
    }
}

fn validate(model: &Model, p: &SimParams) -> Result<Vec<Option<(usize, Servo)>>, SimError> {
    let bad = |name, value: f64, requirement| SimError::BadParameter {
        name,
        value: value.to_string(),
        requirement,
    };
    if !(p.damping >= 0.0) || !p.damping.is_finite() {
        return Err(bad("damping", p.damping, "must be finite and >= 0"));
    }
    if !(p.limit_stiffness >= 0.0) || !p.limit_stiffness.is_finite() {
        return Err(bad("limit_stiffness", p.limit_stiffness, "must be finite and >= 0"));
    }
    if !(p.limit_damping >= 0.0) || !p.limit_damping.is_finite() {
        return Err(bad("limit_damping", p.limit_damping, "must be finite and >= 0"));
    }
    if !(p.newton_tolerance > 0.0) || !p.newton_tolerance.is_finite() {
        return Err(bad("newton_tolerance", p.newton_tolerance, "must be finite and > 0"));
    }
    if p.max_newton_iterations == 0 {
        return Err(bad("max_newton_iterations", 0.0, "must be at least 1"));
    }
    validate_torque(model, &p.torque)?;
    servos_by_dof(model, &p.servos)
}

fn validate_torque(model: &Model, torque: &[f64]) -> Result<(), SimError> {
    if !torque.is_empty() && torque.len() != model.nv() {
        return Err(SimError::BadParameter {
            name: "torque",
            value: format!("{} entries", torque.len()),
            requirement: "must be empty or have nv entries",
        });
    }
    if let Some(x) = torque.iter().find(|x| !x.is_finite()) {
        return Err(SimError::BadParameter {
            name: "torque",
            value: x.to_string(),
            requirement: "entries must be finite",
        });
    }
    Ok(())
}

/// The servos per degree of freedom, with the `q` index of each servoed joint.
fn servos_by_dof(model: &Model, servos: &[Servo]) -> Result<Vec<Option<(usize, Servo)>>, SimError> {
    let bad = |value: String, requirement| SimError::BadParameter { name: "servos", value, requirement };
    let mut out = vec![None; model.nv()];
    for s in servos {
        let Some(joint) = model.joints()[1..].iter().find(|j| j.nq() == 1 && j.idx_v == s.dof) else {
            return Err(bad(
                format!("dof {}", s.dof),
                "must be the velocity index of a one-degree-of-freedom joint",
            ));
        };
        if !s.target.is_finite() {
            return Err(bad(format!("{}: target {}", joint.name, s.target), "targets must be finite"));
        }
        if !(s.kp >= 0.0 && s.kp.is_finite() && s.kd >= 0.0 && s.kd.is_finite()) {
            return Err(bad(
                format!("{}: kp {}, kd {}", joint.name, s.kp, s.kd),
                "gains must be finite and >= 0",
            ));
        }
        if out[s.dof].replace((joint.idx_q, *s)).is_some() {
            return Err(bad(joint.name.clone(), "at most one servo per joint"));
        }
    }
    Ok(out)
}
