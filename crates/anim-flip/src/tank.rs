//! A tank moved along one axis, simulated in the tank's own frame.
//!
//! The tank's displacement along `axis` is
//!
//! ```text
//! x_tank(t) = A sin(2 pi f t) + a t^2 / 2
//! ```
//!
//! (an oscillation, as on a shaking table, plus a constant acceleration, as on a braking
//! vehicle). In the frame moving with the tank the walls are at rest and the fluid feels the
//! fictitious force `-a_tank(t)` on top of gravity: the body acceleration is
//! `g - a_tank(t) e_axis` with `a_tank = -A (2 pi f)^2 sin(2 pi f t) + a`. A substep from `t` to
//! `t + dt` adds its exact integral `dt g - (v_tank(t + dt) - v_tank(t)) e_axis` to the grid
//! velocities ([`TankMotion::velocity_change`]), so the velocity the fluid gains relative to the
//! tank is exact for any substep length. Positions in the world frame are the tank-frame ones
//! plus [`TankMotion::displacement`] along `axis`.

use crate::error::FlipError;

/// The motion of the tank along one axis: `x_tank(t) = A sin(2 pi f t) + a t^2 / 2`.
/// Serialised as `{ axis, amplitude, frequency, acceleration }` (the last three default to 0).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
pub struct TankMotion {
    /// The axis the tank moves along (0 = x; less than the dimension).
    pub axis: usize,
    /// Amplitude `A` of the oscillation, m (non-negative). Default 0.
    #[serde(default)]
    pub amplitude: f64,
    /// Frequency `f` of the oscillation, Hz (non-negative). Default 0.
    #[serde(default)]
    pub frequency: f64,
    /// Constant acceleration `a` of the tank, m/s^2 (either sign). Default 0.
    #[serde(default)]
    pub acceleration: f64,
}

impl TankMotion {
    /// An oscillation `x_tank(t) = A sin(2 pi f t)` along `axis`.
    #[must_use]
    pub fn oscillation(axis: usize, amplitude: f64, frequency: f64) -> Self {
        Self { axis, amplitude, frequency, acceleration: 0.0 }
    }

    /// A constant acceleration `x_tank(t) = a t^2 / 2` along `axis`.
    #[must_use]
    pub fn accelerating(axis: usize, acceleration: f64) -> Self {
        Self { axis, amplitude: 0.0, frequency: 0.0, acceleration }
    }

    fn omega(&self) -> f64 {
        2.0 * std::f64::consts::PI * self.frequency
    }

    /// Displacement of the tank at time `t`, m.
    #[must_use]
    pub fn displacement(&self, t: f64) -> f64 {
        self.amplitude * (self.omega() * t).sin() + 0.5 * self.acceleration * t * t
    }

    /// Velocity of the tank at time `t`, m/s.
    #[must_use]
    pub fn velocity(&self, t: f64) -> f64 {
        let w = self.omega();
        self.amplitude * w * (w * t).cos() + self.acceleration * t
    }

    /// Acceleration of the tank at time `t`, m/s^2.
    #[must_use]
    pub fn acceleration_at(&self, t: f64) -> f64 {
        let w = self.omega();
        -self.amplitude * w * w * (w * t).sin() + self.acceleration
    }

    /// `v_tank(t + dt) - v_tank(t)`, written as
    /// `-2 A w sin(w (t + dt/2)) sin(w dt/2) + a dt` so that short substeps lose no digits to
    /// cancellation. The fluid's velocity relative to the tank changes by minus this.
    #[must_use]
    pub fn velocity_change(&self, t: f64, dt: f64) -> f64 {
        let w = self.omega();
        -2.0 * self.amplitude * w * (w * (t + 0.5 * dt)).sin() * (0.5 * w * dt).sin() + self.acceleration * dt
    }

    /// The largest `|a_tank(t)|` over all times, `A (2 pi f)^2 + |a|`, m/s^2.
    #[must_use]
    pub fn max_acceleration(&self) -> f64 {
        let w = self.omega();
        self.amplitude * w * w + self.acceleration.abs()
    }

    /// Checks the fields for a fluid of dimension `dim`.
    ///
    /// # Errors
    /// [`FlipError::BadParameter`] naming the field: an axis not below `dim`, a negative or
    /// non-finite amplitude or frequency, a non-finite acceleration, or a motion whose largest
    /// acceleration overflows.
    pub fn validate(&self, dim: usize) -> Result<(), FlipError> {
        let bad =
            |name, requirement, value: String| Err(FlipError::BadParameter { name, requirement, value });
        if self.axis >= dim {
            return bad("tank_motion.axis", "must be an axis of the grid (0 = x)", self.axis.to_string());
        }
        for (name, v) in
            [("tank_motion.amplitude", self.amplitude), ("tank_motion.frequency", self.frequency)]
        {
            if !(v >= 0.0 && v.is_finite()) {
                return bad(name, "must be non-negative and finite", v.to_string());
            }
        }
        if !self.acceleration.is_finite() {
            return bad("tank_motion.acceleration", "must be finite", self.acceleration.to_string());
        }
        if !self.max_acceleration().is_finite() {
            return bad(
                "tank_motion",
                "must have a finite largest acceleration A (2 pi f)^2 + |a|",
                self.max_acceleration().to_string(),
            );
        }
        Ok(())
    }
}
