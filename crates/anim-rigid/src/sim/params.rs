//! The forces that are not part of the model (viscous joint damping, the joint-limit penalty,
//! constant applied torques, joint servos) and the implicit midpoint's Newton settings; the
//! equations are in the module docs of `sim`.

/// Forces and solver settings that are not part of the [`Model`](crate::Model).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
#[non_exhaustive]
pub struct SimParams {
    /// Viscous damping coefficient `d` of every joint degree of freedom except free-joint ones
    /// (N·m·s/rad or N·s/m): the torque `-d q̇`. Default `0`.
    pub damping: f64,
    /// Stiffness `k` of the joint-limit penalty (N·m/rad or N/m). Default `1000`.
    pub limit_stiffness: f64,
    /// Damping `c` of the joint-limit penalty, active only beyond a limit. Default `5`.
    pub limit_damping: f64,
    /// Constant applied joint torques (length `nv`), or empty for none. Default empty.
    pub torque: Vec<f64>,
    /// Proportional-derivative servos on one-degree-of-freedom joints, at most one per degree of
    /// freedom. Default none.
    pub servos: Vec<Servo>,
    /// Implicit midpoint: stop Newton when `‖r‖∞ <= newton_tolerance · (1 + ‖v₀‖∞ + h ‖a₀‖∞)`
    /// (`a₀` the acceleration at the start of the step). When even a freshly formed Jacobian no
    /// longer shrinks the residual (the rounding floor of ABA), a residual up to 1000 times this
    /// bound is accepted. Default `1e-12`.
    pub newton_tolerance: f64,
    /// Implicit midpoint: give up after this many Newton iterations. Default `30`.
    pub max_newton_iterations: usize,
}

impl Default for SimParams {
    fn default() -> Self {
        Self {
            damping: 0.0,
            limit_stiffness: 1000.0,
            limit_damping: 5.0,
            torque: Vec::new(),
            servos: Vec::new(),
            newton_tolerance: 1e-12,
            max_newton_iterations: 30,
        }
    }
}

impl SimParams {
    /// These parameters with joint damping `d`.
    #[must_use]
    pub fn with_damping(mut self, d: f64) -> Self {
        self.damping = d;
        self
    }

    /// These parameters with the joint-limit penalty `(k, c)`.
    #[must_use]
    pub fn with_limits(mut self, stiffness: f64, damping: f64) -> Self {
        self.limit_stiffness = stiffness;
        self.limit_damping = damping;
        self
    }

    /// These parameters with constant applied torques.
    #[must_use]
    pub fn with_torque(mut self, torque: Vec<f64>) -> Self {
        self.torque = torque;
        self
    }

    /// These parameters with the joint servos `servos`.
    #[must_use]
    pub fn with_servos(mut self, servos: Vec<Servo>) -> Self {
        self.servos = servos;
        self
    }
}

/// A proportional-derivative servo on the one-degree-of-freedom joint whose velocity index is
/// `dof`: the joint torque `kp (target - q) - kd q̇`, added to the applied torques. It is a force
/// like the others, evaluated at every stage of every stepper (not held over a step), so a stiff
/// servo limits the stable step as a stiff spring does: the explicit steppers need
/// `dt` well below `sqrt(m / kp)` for the smallest effective inertia `m` it moves.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Servo {
    /// Velocity index of the joint (its [`Joint::idx_v`](crate::model::Joint::idx_v)).
    pub dof: usize,
    /// Target position (rad or m).
    pub target: f64,
    /// Proportional gain `kp` (N·m/rad or N/m), finite and `>= 0`.
    pub kp: f64,
    /// Derivative gain `kd` (N·m·s/rad or N·s/m), finite and `>= 0`.
    pub kd: f64,
}
