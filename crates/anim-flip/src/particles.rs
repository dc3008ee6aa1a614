//! Fluid particles: positions, velocities and APIC's affine velocity matrix, structure of arrays.
//!
//! Every particle stands for the same fluid volume (the cell volume divided by the seeding
//! density), so its mass drops out of the transfers. `c[p][a]` is the row of the affine matrix
//! `C_p` for velocity component `a`: the particle's estimate of `grad v_a` (APIC, Jiang et
//! al. 2015: `C_p = B_p D_p^-1`); PIC and FLIP leave it zero.

use crate::error::FlipError;

/// The particles of a fluid in `D` dimensions.
/// Serialised as flat arrays `{ "dim", "x", "v", "c" }` (row-major per particle).
#[derive(Debug, Default, PartialEq)]
pub struct Particles<const D: usize> {
    /// Positions, m.
    pub x: Vec<[f64; D]>,
    /// Velocities, m/s.
    pub v: Vec<[f64; D]>,
    /// Affine velocity matrices (rows per velocity component), 1/s.
    pub c: Vec<[[f64; D]; D]>,
}

/// `clone_from` copies into the arrays' existing buffers (the step's backup of the particles
/// allocates nothing once it has their size).
impl<const D: usize> Clone for Particles<D> {
    fn clone(&self) -> Self {
        Self { x: self.x.clone(), v: self.v.clone(), c: self.c.clone() }
    }

    fn clone_from(&mut self, source: &Self) {
        self.x.clone_from(&source.x);
        self.v.clone_from(&source.v);
        self.c.clone_from(&source.c);
    }
}

impl<const D: usize> Particles<D> {
    /// No particles.
    #[must_use]
    pub fn new() -> Self {
        Self { x: Vec::new(), v: Vec::new(), c: Vec::new() }
    }

    /// Adds a particle at `x` with velocity `v` and zero affine matrix.
    pub fn push(&mut self, x: [f64; D], v: [f64; D]) {
        self.x.push(x);
        self.v.push(v);
        self.c.push([[0.0; D]; D]);
    }

    /// Number of particles.
    #[must_use]
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether there are none.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Checks array lengths and finiteness.
    ///
    /// # Errors
    /// [`FlipError::BadParticle`] naming the first bad particle and array.
    pub fn validate(&self) -> Result<(), FlipError> {
        let n = self.x.len();
        for (field, len) in [("v", self.v.len()), ("c", self.c.len())] {
            if len != n {
                return Err(FlipError::BadParticle {
                    index: len.min(n),
                    field,
                    cause: format!("array has {len} entries, positions have {n}"),
                });
            }
        }
        for p in 0..n {
            let bad = |field, cause: String| Err(FlipError::BadParticle { index: p, field, cause });
            if let Some(x) = self.x[p].iter().find(|x| !x.is_finite()) {
                return bad("x", format!("is not finite ({x})"));
            }
            if let Some(x) = self.v[p].iter().find(|x| !x.is_finite()) {
                return bad("v", format!("is not finite ({x})"));
            }
            if let Some(x) = self.c[p].iter().flatten().find(|x| !x.is_finite()) {
                return bad("c", format!("is not finite ({x})"));
            }
        }
        Ok(())
    }

    /// Total linear momentum per unit particle mass, `sum_p v_p`.
    #[must_use]
    pub fn linear_momentum(&self) -> [f64; D] {
        let mut m = [0.0; D];
        for v in &self.v {
            for a in 0..D {
                m[a] += v[a];
            }
        }
        m
    }

    /// Total angular momentum per unit particle mass about `origin`, `sum_p (x_p - o) x v_p`
    /// (in 2D only the z component is non-zero).
    #[must_use]
    pub fn angular_momentum(&self, origin: [f64; D]) -> [f64; 3] {
        let mut l = [0.0; 3];
        for (x, v) in self.x.iter().zip(&self.v) {
            let mut r3 = [0.0; 3];
            let mut v3 = [0.0; 3];
            for a in 0..D {
                r3[a] = x[a] - origin[a];
                v3[a] = v[a];
            }
            l[0] += r3[1] * v3[2] - r3[2] * v3[1];
            l[1] += r3[2] * v3[0] - r3[0] * v3[2];
            l[2] += r3[0] * v3[1] - r3[1] * v3[0];
        }
        l
    }

    /// Kinetic energy per unit particle mass, `sum_p |v_p|^2 / 2`.
    #[must_use]
    pub fn kinetic_energy(&self) -> f64 {
        self.v.iter().map(|v| 0.5 * v.iter().map(|x| x * x).sum::<f64>()).sum()
    }

    /// Gravitational potential energy per unit particle mass in the field `gravity`, relative to
    /// the frame's origin (the grid's lower corner, below every particle): `sum_p -g . x_p`.
    #[must_use]
    pub fn potential_energy(&self, gravity: &[f64; D]) -> f64 {
        self.x.iter().map(|x| -(0..D).map(|a| gravity[a] * x[a]).sum::<f64>()).sum()
    }

    /// Largest particle speed.
    #[must_use]
    pub fn max_speed(&self) -> f64 {
        self.v.iter().map(|v| v.iter().map(|x| x * x).sum::<f64>().sqrt()).fold(0.0, f64::max)
    }
}

/// The serialised form of [`Particles`].
#[derive(serde::Serialize, serde::Deserialize)]
struct Flat {
    dim: usize,
    x: Vec<f64>,
    v: Vec<f64>,
    c: Vec<f64>,
}

impl<const D: usize> serde::Serialize for Particles<D> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        Flat {
            dim: D,
            x: self.x.iter().flatten().copied().collect(),
            v: self.v.iter().flatten().copied().collect(),
            c: self.c.iter().flatten().flatten().copied().collect(),
        }
        .serialize(s)
    }
}

impl<'de, const D: usize> serde::Deserialize<'de> for Particles<D> {
    fn deserialize<De: serde::Deserializer<'de>>(d: De) -> Result<Self, De::Error> {
        use serde::de::Error;
        let f = Flat::deserialize(d)?;
        if f.dim != D {
            return Err(De::Error::custom(format!("particles of dimension {} read as dimension {D}", f.dim)));
        }
        let n = f.x.len() / D;
        if f.x.len() != n * D || f.v.len() != n * D || f.c.len() != n * D * D {
            return Err(De::Error::custom("particle arrays of inconsistent lengths"));
        }
        let vecs =
            |a: &[f64]| a.chunks_exact(D).map(|c| std::array::from_fn(|k| c[k])).collect::<Vec<[f64; D]>>();
        let x = vecs(&f.x);
        let v = vecs(&f.v);
        let c =
            f.c.chunks_exact(D * D)
                .map(|m| std::array::from_fn(|r| std::array::from_fn(|k| m[r * D + k])))
                .collect();
        Ok(Self { x, v, c })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Energy per unit mass: `|v|^2 / 2` plus `-g . x`, by hand for two particles.
    #[test]
    fn kinetic_and_potential_energy_per_unit_mass() {
        let mut p = Particles::<2>::new();
        p.push([0.5, 0.25], [3.0, 4.0]);
        p.push([0.1, 1.0], [0.0, -1.0]);
        assert_eq!(p.kinetic_energy(), 12.5 + 0.5);
        assert_eq!(p.potential_energy(&[0.0, -9.81]), 9.81 * 0.25 + 9.81 * 1.0);
        // A tilted gravity weighs both components.
        assert_eq!(p.potential_energy(&[1.0, -2.0]), (-0.5 + 0.5) + (-0.1 + 2.0));
    }
}
