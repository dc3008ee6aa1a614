//! Keyframed animation clips and their interpolation, as glTF 2.0 defines it.
//!
//! A [`Channel`] animates one property (translation, rotation or scale) of one joint with key
//! times `t_0 < t_1 < ... < t_{n-1}` and values `v_k`. Sampling at `t` clamps to the first value
//! before `t_0` and to the last after `t_{n-1}`; inside `[t_k, t_{k+1}]`, with
//! `t_d = t_{k+1} - t_k` and `s = (t - t_k) / t_d` (glTF 2.0, Appendix C):
//!
//! - **STEP**: `v_k`.
//! - **LINEAR**: `(1 - s) v_k + s v_{k+1}` for translations and scales; [`slerp`] along the
//!   shorter arc for rotations.
//! - **CUBICSPLINE**: each key stores an in-tangent `a_k`, a value `v_k` and an out-tangent
//!   `b_k`; the Hermite polynomial
//!   `(2s^3 - 3s^2 + 1) v_k + (s^3 - 2s^2 + s) t_d b_k + (-2s^3 + 3s^2) v_{k+1} + (s^3 - s^2) t_d a_{k+1}`,
//!   the result normalised for rotations.
//!
//! [`Clip::sample`] writes a whole [`Pose`]: un-animated properties keep the skeleton's rest
//! values. Blending two sampled poses is [`Pose::blend`].

use crate::SkinError;
use crate::skeleton::{Pose, Skeleton};
use anim_core::glam::{DQuat, DVec3, DVec4};

pub use crate::rotation::slerp;

/// How values between keys are computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Interpolation {
    /// The value of the previous key.
    Step,
    /// Linear for vectors, shortest-path slerp for rotations.
    Linear,
    /// Cubic Hermite with per-key in/out tangents scaled by the key interval.
    CubicSpline,
}

/// Which part of a joint's local transform a channel drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Property {
    /// Translation (values `(x, y, z, 0)`).
    Translation,
    /// Rotation (unit quaternions `(x, y, z, w)`).
    Rotation,
    /// Scale (values `(x, y, z, 0)`).
    Scale,
}

/// Keyframes of one property of one joint.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Channel {
    joint: usize,
    property: Property,
    interpolation: Interpolation,
    times: Vec<f64>,
    /// One value per key, or `(in-tangent, value, out-tangent)` per key for cubic splines.
    values: Vec<DVec4>,
}

impl Channel {
    /// A channel. For [`Interpolation::CubicSpline`], `values` holds three entries per key
    /// (in-tangent, value, out-tangent); otherwise one. Vectors use `(x, y, z, _)`, rotations
    /// `(x, y, z, w)`. Rotation key values (not tangents) are normalised.
    ///
    /// # Errors
    /// [`SkinError::BadChannel`] if there are no keys, times are not finite and strictly
    /// increasing, the value count does not match, a value is not finite, or a rotation key is
    /// zero.
    pub fn new(
        joint: usize,
        property: Property,
        interpolation: Interpolation,
        times: Vec<f64>,
        mut values: Vec<DVec4>,
    ) -> Result<Self, SkinError> {
        let bad = |why: String| Err(SkinError::BadChannel { joint, why });
        if times.is_empty() {
            return bad("no keyframes".into());
        }
        if let Some(k) = times.iter().position(|t| !t.is_finite()) {
            return bad(format!("key time {k} is not finite"));
        }
        if let Some(k) = times.windows(2).position(|w| !(w[1] > w[0])) {
            return bad(format!(
                "key times {k} and {} are not strictly increasing ({} then {})",
                k + 1,
                times[k],
                times[k + 1]
            ));
        }
        let per_key = if interpolation == Interpolation::CubicSpline { 3 } else { 1 };
        if values.len() != per_key * times.len() {
            return bad(format!(
                "{} keys need {} values, got {}",
                times.len(),
                per_key * times.len(),
                values.len()
            ));
        }
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            return bad(format!("value {k} is not finite"));
        }
        if property == Property::Rotation {
            let offset = per_key / 2; // the value inside (in, value, out)
            for k in 0..times.len() {
                let v = &mut values[per_key * k + offset];
                let n = v.length();
                if !(n > 1e-12) {
                    return bad(format!("rotation key {k} is a zero quaternion"));
                }
                *v /= n;
            }
        }
        Ok(Self { joint, property, interpolation, times, values })
    }

    /// The animated joint.
    #[must_use]
    pub fn joint(&self) -> usize {
        self.joint
    }

    /// The animated property.
    #[must_use]
    pub fn property(&self) -> Property {
        self.property
    }

    /// The interpolation mode.
    #[must_use]
    pub fn interpolation(&self) -> Interpolation {
        self.interpolation
    }

    /// Key times.
    #[must_use]
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// The value at time `t` (clamped outside the key range). Rotations are unit quaternions.
    #[must_use]
    pub fn sample(&self, t: f64) -> DVec4 {
        let n = self.times.len();
        let cubic = self.interpolation == Interpolation::CubicSpline;
        let value = |k: usize| if cubic { self.values[3 * k + 1] } else { self.values[k] };
        // Keys with t_k <= t.
        let after = self.times.partition_point(|&tk| tk <= t);
        if after == 0 {
            return value(0);
        }
        if after >= n {
            return value(n - 1);
        }
        let k = after - 1;
        let td = self.times[k + 1] - self.times[k];
        let s = (t - self.times[k]) / td;
        let rotation = self.property == Property::Rotation;
        match self.interpolation {
            Interpolation::Step => value(k),
            Interpolation::Linear => {
                if rotation {
                    let q = slerp(to_quat(value(k)), to_quat(value(k + 1)), s);
                    DVec4::new(q.x, q.y, q.z, q.w)
                } else {
                    value(k).lerp(value(k + 1), s)
                }
            }
            Interpolation::CubicSpline => {
                let (s2, s3) = (s * s, s * s * s);
                let v0 = self.values[3 * k + 1];
                let b0 = self.values[3 * k + 2];
                let a1 = self.values[3 * (k + 1)];
                let v1 = self.values[3 * (k + 1) + 1];
                let p = (2.0 * s3 - 3.0 * s2 + 1.0) * v0
                    + (s3 - 2.0 * s2 + s) * td * b0
                    + (-2.0 * s3 + 3.0 * s2) * v1
                    + (s3 - s2) * td * a1;
                if rotation {
                    let l = p.length();
                    if l > 0.0 { p / l } else { v0 }
                } else {
                    p
                }
            }
        }
    }
}

fn to_quat(v: DVec4) -> DQuat {
    DQuat::from_xyzw(v.x, v.y, v.z, v.w)
}

/// A named set of channels.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Clip {
    /// Name (from the file, or made up).
    pub name: String,
    channels: Vec<Channel>,
    start: f64,
    end: f64,
}

impl Clip {
    /// A clip over a skeleton of `num_joints` joints.
    ///
    /// # Errors
    /// [`SkinError::BadChannel`] if a channel's joint is out of range.
    pub fn new(
        name: impl Into<String>,
        channels: Vec<Channel>,
        num_joints: usize,
    ) -> Result<Self, SkinError> {
        if let Some(c) = channels.iter().find(|c| c.joint >= num_joints) {
            return Err(SkinError::BadChannel {
                joint: c.joint,
                why: format!("skeleton has {num_joints} joints"),
            });
        }
        let start = channels.iter().map(|c| c.times[0]).fold(f64::INFINITY, f64::min);
        let end = channels.iter().map(|c| c.times[c.times.len() - 1]).fold(f64::NEG_INFINITY, f64::max);
        let (start, end) = if channels.is_empty() { (0.0, 0.0) } else { (start, end) };
        Ok(Self { name: name.into(), channels, start, end })
    }

    /// The channels.
    #[must_use]
    pub fn channels(&self) -> &[Channel] {
        &self.channels
    }

    /// First key time over all channels (0 for an empty clip).
    #[must_use]
    pub fn start(&self) -> f64 {
        self.start
    }

    /// Last key time over all channels (0 for an empty clip).
    #[must_use]
    pub fn end(&self) -> f64 {
        self.end
    }

    /// The pose at time `t`: the skeleton's rest pose with every animated property replaced by
    /// its channel's sample. Reuses `pose`'s storage.
    ///
    /// # Panics
    /// If the clip was built for a larger skeleton (API misuse).
    #[track_caller]
    pub fn sample(&self, skeleton: &Skeleton, t: f64, pose: &mut Pose) {
        pose.reset(skeleton);
        for c in &self.channels {
            let v = c.sample(t);
            let local = &mut pose.local[c.joint];
            match c.property {
                Property::Translation => local.translation = DVec3::new(v.x, v.y, v.z),
                Property::Rotation => local.rotation = to_quat(v),
                Property::Scale => local.scale = DVec3::new(v.x, v.y, v.z),
            }
        }
    }
}
