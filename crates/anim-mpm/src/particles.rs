//! The material points: structure-of-arrays particle storage, the serialisable state of a
//! simulation.

use crate::{Mat, MpmError, Vector};
use serde::{Deserialize, Serialize};

/// Particles in `D` dimensions, stored as flat structure-of-arrays `f32` vectors.
///
/// Vectors are stored with stride `D` (`x[p * D + a]`), matrices with stride `D * D` in
/// column-major order (`c[p * D * D + a + D * b]` is entry `(a, b)`).
///
/// **Ordering.** A step sorts the particles by grid block (this is what makes the scatter and
/// gather cache-friendly); the array order therefore changes from step to step. [`id`](Self::id)
/// keeps each particle's index at creation.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Particles<const D: usize> {
    /// Positions.
    pub x: Vec<f32>,
    /// Velocities.
    pub v: Vec<f32>,
    /// The affine velocity matrix `C_p` of APIC / MLS-MPM (`C = B D^-1`).
    pub c: Vec<f32>,
    /// The deformation gradient `F` (its elastic part `F_E` for snow and sand).
    pub f: Vec<f32>,
    /// Plastic scalar state: `J_P = det F_P` for snow, the hardening state `q` for sand,
    /// unused (1) for elastic bodies and fluids.
    pub plastic: Vec<f32>,
    /// Mass.
    pub mass: Vec<f32>,
    /// Rest volume `V_p^0`.
    pub volume: Vec<f32>,
    /// Index into the simulation's material table.
    pub material: Vec<u16>,
    /// Index of the particle at creation (unchanged by sorting).
    pub id: Vec<u32>,
}

impl<const D: usize> Particles<D> {
    /// No particles.
    #[must_use]
    pub fn new() -> Self {
        Self {
            x: Vec::new(),
            v: Vec::new(),
            c: Vec::new(),
            f: Vec::new(),
            plastic: Vec::new(),
            mass: Vec::new(),
            volume: Vec::new(),
            material: Vec::new(),
            id: Vec::new(),
        }
    }

    /// Number of particles.
    #[must_use]
    pub fn len(&self) -> usize {
        self.mass.len()
    }

    /// Whether there are none.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.mass.is_empty()
    }

    /// Adds an undeformed particle at rest in `F = I`, `C = 0`.
    ///
    /// # Errors
    /// [`MpmError::BadParticle`] for a non-finite position or velocity, or a mass or volume that
    /// is not finite and positive.
    pub fn push(
        &mut self,
        x: [f32; D],
        v: [f32; D],
        mass: f32,
        volume: f32,
        material: u16,
    ) -> Result<(), MpmError> {
        let index = self.len();
        if x.iter().chain(v.iter()).any(|c| !c.is_finite()) {
            return Err(MpmError::BadParticle { index, reason: "non-finite position or velocity".into() });
        }
        if !(mass > 0.0) || !mass.is_finite() {
            return Err(MpmError::BadParticle {
                index,
                reason: format!("mass {mass} must be finite and > 0"),
            });
        }
        if !(volume > 0.0) || !volume.is_finite() {
            return Err(MpmError::BadParticle {
                index,
                reason: format!("volume {volume} must be finite and > 0"),
            });
        }
        self.x.extend_from_slice(&x);
        self.v.extend_from_slice(&v);
        self.c.extend(std::iter::repeat_n(0.0, D * D));
        self.f.extend_from_slice(Mat::<D>::identity().as_slice());
        self.plastic.push(1.0);
        self.mass.push(mass);
        self.volume.push(volume);
        self.material.push(material);
        self.id.push(index as u32);
        Ok(())
    }

    /// Position of particle `p`.
    #[inline]
    #[must_use]
    pub fn position(&self, p: usize) -> Vector<D> {
        Vector::<D>::from_column_slice(&self.x[p * D..p * D + D])
    }

    /// Velocity of particle `p`.
    #[inline]
    #[must_use]
    pub fn velocity(&self, p: usize) -> Vector<D> {
        Vector::<D>::from_column_slice(&self.v[p * D..p * D + D])
    }

    /// Affine matrix `C_p`.
    #[inline]
    #[must_use]
    pub fn affine(&self, p: usize) -> Mat<D> {
        Mat::<D>::from_column_slice(&self.c[p * D * D..(p + 1) * D * D])
    }

    /// Deformation gradient `F_p` (elastic part for snow and sand).
    #[inline]
    #[must_use]
    pub fn deformation(&self, p: usize) -> Mat<D> {
        Mat::<D>::from_column_slice(&self.f[p * D * D..(p + 1) * D * D])
    }

    /// The Frobenius norm of the Green-Lagrange strain `(F^T F - I) / 2` of particle `p`'s
    /// deformation gradient (its elastic part for snow and sand): 0 at rest, dimensionless; a
    /// strain measure for pictures.
    #[must_use]
    pub fn strain(&self, p: usize) -> f64 {
        let f = self.deformation(p).cast::<f64>();
        0.5 * (f.transpose() * f - nalgebra::SMatrix::<f64, D, D>::identity()).norm()
    }

    /// Sets the velocity of every particle with material `material` to `v`.
    pub fn set_velocity(&mut self, material: u16, v: [f32; D]) {
        for p in 0..self.len() {
            if self.material[p] == material {
                self.v[p * D..p * D + D].copy_from_slice(&v);
            }
        }
    }

    /// Checks that every array has the length the particle count implies.
    ///
    /// # Errors
    /// [`MpmError::BadState`] naming the first inconsistent array.
    pub fn check_lengths(&self) -> Result<(), MpmError> {
        let n = self.len();
        let arrays: [(&'static str, usize, usize); 8] = [
            ("x", self.x.len(), n * D),
            ("v", self.v.len(), n * D),
            ("c", self.c.len(), n * D * D),
            ("f", self.f.len(), n * D * D),
            ("plastic", self.plastic.len(), n),
            ("volume", self.volume.len(), n),
            ("material", self.material.len(), n),
            ("id", self.id.len(), n),
        ];
        for (name, got, want) in arrays {
            if got != want {
                return Err(MpmError::BadState {
                    field: name,
                    reason: format!("length {got}, expected {want}"),
                });
            }
        }
        Ok(())
    }

    /// Resizes every array to `n` particles (scratch buffers; contents unspecified).
    pub(crate) fn resize(&mut self, n: usize) {
        self.x.resize(n * D, 0.0);
        self.v.resize(n * D, 0.0);
        self.c.resize(n * D * D, 0.0);
        self.f.resize(n * D * D, 0.0);
        self.plastic.resize(n, 0.0);
        self.mass.resize(n, 0.0);
        self.volume.resize(n, 0.0);
        self.material.resize(n, 0);
        self.id.resize(n, 0);
    }

    /// Copies everything from `other` (same length, no allocation).
    pub(crate) fn copy_from(&mut self, other: &Self) {
        self.resize(other.len());
        self.x.copy_from_slice(&other.x);
        self.v.copy_from_slice(&other.v);
        self.c.copy_from_slice(&other.c);
        self.f.copy_from_slice(&other.f);
        self.plastic.copy_from_slice(&other.plastic);
        self.mass.copy_from_slice(&other.mass);
        self.volume.copy_from_slice(&other.volume);
        self.material.copy_from_slice(&other.material);
        self.id.copy_from_slice(&other.id);
    }

    /// Exchanges the arrays with `other` (no copy).
    pub(crate) fn swap(&mut self, other: &mut Self) {
        std::mem::swap(self, other);
    }

    /// Removes the particles whose flag is set, keeping the order of the others (no allocation).
    pub(crate) fn retain(&mut self, remove: &[bool]) {
        let n = self.len();
        let mut k = 0;
        for p in 0..n {
            if remove[p] {
                continue;
            }
            if k != p {
                self.x.copy_within(p * D..p * D + D, k * D);
                self.v.copy_within(p * D..p * D + D, k * D);
                self.c.copy_within(p * D * D..(p + 1) * D * D, k * D * D);
                self.f.copy_within(p * D * D..(p + 1) * D * D, k * D * D);
                self.plastic[k] = self.plastic[p];
                self.mass[k] = self.mass[p];
                self.volume[k] = self.volume[p];
                self.material[k] = self.material[p];
                self.id[k] = self.id[p];
            }
            k += 1;
        }
        self.resize(k);
    }
}

#[cfg(test)]
mod tests {
    use super::Particles;

    /// `F = diag(s, 1)` has Green strain `diag((s^2 - 1) / 2, 0)`; a rotation has none.
    #[test]
    fn the_strain_is_the_green_strain_norm_of_f() {
        let mut p = Particles::<2>::new();
        let (c, s) = (0.6f32, 0.8f32);
        // Column-major: a stretch by 1.5 along x, then a rotation.
        p.f = vec![1.5, 0.0, 0.0, 1.0, c, s, -s, c];
        assert!((p.strain(0) - (1.5f64 * 1.5 - 1.0) / 2.0).abs() < 1e-6, "{}", p.strain(0));
        assert!(p.strain(1).abs() < 1e-6, "{}", p.strain(1));
    }
}
