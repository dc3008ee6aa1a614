//! Deformation gradients for the material checks, shared by the unit tests and the `cases`
//! feature: random rotations and `F` of six kinds (general, rotation, stretch, near-singular,
//! inverted, degenerate), drawn from a seeded ChaCha generator.

use crate::{Lame, Mat};
use nalgebra::{Rotation2, Rotation3, SVector, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// The Lamé parameters of the checks: E = 1e4, nu = 0.3 (mu ~ 3846, lambda ~ 5769).
pub(crate) fn lame() -> Lame<f64> {
    Lame::from_young_poisson(1e4, 0.3).unwrap_or(Lame { mu: f64::NAN, lambda: f64::NAN })
}

pub(crate) fn rotation<const D: usize>(rng: &mut ChaCha8Rng) -> Mat<f64, D> {
    if D == 2 {
        let r = Rotation2::new(rng.random_range(-std::f64::consts::PI..std::f64::consts::PI));
        Mat::<f64, D>::from_fn(|i, j| r.matrix()[(i, j)])
    } else {
        let axis: Vector3<f64> = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let r = Rotation3::new(axis * (3.0 / axis.norm().max(1e-3)) * rng.random_range(0.0..1.0));
        Mat::<f64, D>::from_fn(|i, j| r.matrix()[(i, j)])
    }
}

/// Test deformation gradients by kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Kind {
    /// `R1 diag(s) R2^T`, `s` in [0.5, 2].
    General,
    /// A pure rotation.
    Rotation,
    /// Diagonal stretches, with repeated values half of the time.
    Stretch,
    /// `det F ~ 1e-3` (smallest singular value 1e-3).
    NearSingular,
    /// `det F < 0` (reflection on the last singular value).
    Inverted,
    /// `det F = 0` exactly in the singular values.
    Degenerate,
}

pub(crate) const KINDS: [Kind; 6] =
    [Kind::General, Kind::Rotation, Kind::Stretch, Kind::NearSingular, Kind::Inverted, Kind::Degenerate];

pub(crate) fn sample<const D: usize>(kind: Kind, rng: &mut ChaCha8Rng) -> Mat<f64, D> {
    let mut s = SVector::<f64, D>::from_fn(|_, _| rng.random_range(0.5..2.0));
    let (r1, r2) = (rotation::<D>(rng), rotation::<D>(rng));
    match kind {
        Kind::General => r1 * Mat::from_diagonal(&s) * r2.transpose(),
        Kind::Rotation => r1,
        Kind::Stretch => {
            if rng.random_bool(0.5) {
                s[1] = s[0];
            }
            Mat::from_diagonal(&s)
        }
        Kind::NearSingular => {
            s[D - 1] = 1e-3;
            r1 * Mat::from_diagonal(&s) * r2.transpose()
        }
        Kind::Inverted => {
            // Keep sigma_{d-2} + sigma_{d-1} away from 0, where the corotated rotation is
            // not differentiable.
            // The negative value is the smallest in magnitude, so the others are >= 1.
            for k in 0..D - 1 {
                s[k] = rng.random_range(1.0..2.0);
            }
            s[D - 1] = -rng.random_range(0.05..0.6);
            r1 * Mat::from_diagonal(&s) * r2.transpose()
        }
        Kind::Degenerate => {
            s[D - 1] = 0.0;
            r1 * Mat::from_diagonal(&s) * r2.transpose()
        }
    }
}
