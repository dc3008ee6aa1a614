//! The staggered (MAC, Harlow and Welch 1965) grid: velocity component `a` lives on the faces
//! normal to axis `a`, pressure and cell labels at cell centres.
//!
//! Layout follows `anim_fluid::mac`: `n` cells per axis of size `h`, cell `(i, j, k)` covers
//! `[i h, (i+1) h) x ...` and is stored at `i + nx (j + ny k)`; the faces of axis `a` form a
//! lattice of `n` points per axis except `n_a + 1` along `a`, the face `(i, j, k)` of axis `a`
//! lying at the low side of cell `(i, j, k)` (position `i h` along `a`, cell centres along the
//! other axes) and stored x fastest in the same way.
//!
//! Besides the velocities the grid keeps, per face, the kernel-weight sum of the last transfer,
//! the pre-force velocities FLIP differences against, and a validity flag used by the
//! extrapolation of velocities from the fluid into the air and solid faces the particles'
//! stencils reach.

use rayon::prelude::*;

/// Face velocities and their scratch, sized once.
#[derive(Debug, Clone)]
pub struct MacGrid<const D: usize> {
    /// Cells per axis.
    pub(crate) n: [usize; D],
    /// Cell size, m.
    pub(crate) h: f64,
    /// Face velocities per axis, m/s.
    pub(crate) u: [Vec<f64>; D],
    /// Face velocities after the transfer, before forces and projection (FLIP's reference).
    pub(crate) u_old: [Vec<f64>; D],
    /// Kernel-weight sums of the last particle-to-grid transfer.
    pub(crate) weight: [Vec<f64>; D],
    /// Whether a face holds a known velocity (for extrapolation).
    pub(crate) valid: [Vec<bool>; D],
    /// Extrapolation scratch.
    tmp: [Vec<f64>; D],
    valid_tmp: [Vec<bool>; D],
}

impl<const D: usize> MacGrid<D> {
    /// A zero grid of `n` cells of size `h`.
    pub(crate) fn new(n: [usize; D], h: f64) -> Self {
        let sizes: [usize; D] = std::array::from_fn(|a| face_dims(n, a).iter().product());
        let zeros = || std::array::from_fn(|a| vec![0.0; sizes[a]]);
        let falses = || std::array::from_fn(|a| vec![false; sizes[a]]);
        Self {
            n,
            h,
            u: zeros(),
            u_old: zeros(),
            weight: zeros(),
            valid: falses(),
            tmp: zeros(),
            valid_tmp: falses(),
        }
    }

    /// Cells per axis.
    #[must_use]
    pub fn cells(&self) -> [usize; D] {
        self.n
    }

    /// Cell size.
    #[must_use]
    pub fn h(&self) -> f64 {
        self.h
    }

    /// Face lattice extents of axis `a`.
    #[must_use]
    pub fn face_dims(&self, a: usize) -> [usize; D] {
        face_dims(self.n, a)
    }

    /// The velocities on the faces of axis `a` (x fastest).
    #[must_use]
    pub fn velocity(&self, a: usize) -> &[f64] {
        &self.u[a]
    }

    /// Fills every face not marked valid with the mean of its valid lattice neighbours, `layers`
    /// times (each layer reads only the previous one, so the result does not depend on the
    /// thread count).
    pub(crate) fn extrapolate(&mut self, layers: usize) {
        for a in 0..D {
            let fd = self.face_dims(a);
            let strides = strides(fd);
            for _ in 0..layers {
                let (u, valid) = (&self.u[a], &self.valid[a]);
                self.tmp[a]
                    .par_chunks_mut(fd[0])
                    .zip(self.valid_tmp[a].par_chunks_mut(fd[0]))
                    .enumerate()
                    .with_min_len(crate::par::min_len(crate::par::MIN_ENTRIES, fd[0]))
                    .for_each(|(line, (tu, tv))| {
                        let base = line * fd[0];
                        let idx = unflatten(fd, base);
                        for i in 0..fd[0] {
                            let f = base + i;
                            if valid[f] {
                                tu[i] = u[f];
                                tv[i] = true;
                                continue;
                            }
                            let mut sum = 0.0;
                            let mut count = 0u32;
                            for b in 0..D {
                                let coord = if b == 0 { i } else { idx[b] };
                                if coord > 0 && valid[f - strides[b]] {
                                    sum += u[f - strides[b]];
                                    count += 1;
                                }
                                if coord + 1 < fd[b] && valid[f + strides[b]] {
                                    sum += u[f + strides[b]];
                                    count += 1;
                                }
                            }
                            if count > 0 {
                                tu[i] = sum / f64::from(count);
                                tv[i] = true;
                            } else {
                                tu[i] = 0.0;
                                tv[i] = false;
                            }
                        }
                    });
                std::mem::swap(&mut self.u[a], &mut self.tmp[a]);
                std::mem::swap(&mut self.valid[a], &mut self.valid_tmp[a]);
            }
        }
    }
}

impl<const D: usize> MacGrid<D> {
    /// Sets the normal-velocity faces behind the box walls (the `border` cell layers of every
    /// side) to the negated mirror image of the faces in front of them, `u(w - k h) = -u(w + k h)`
    /// about the wall face `w`, whose own velocity is zero. The B-spline kernels do not
    /// interpolate: a particle at a wall would otherwise see a weighted share of the faces behind
    /// it and of the first interior face, and be carried into the wall with about an eighth of
    /// the interior normal velocity (quadratic kernel), where it is stopped and piles up with
    /// others. With the odd extension every symmetric kernel gives exactly zero normal velocity
    /// at the wall.
    pub(crate) fn reflect_walls(&mut self, border: usize) {
        for a in 0..D {
            let fd = self.face_dims(a);
            let stride = strides(fd)[a];
            let (lo_wall, hi_wall) = (border, self.n[a] - border);
            let u = &mut self.u[a];
            // The faces of one line along `a` are `base + i stride`, with the axes below `a`
            // (`rest`) and above it (`outer`) fixed.
            for line in 0..u.len() / fd[a] {
                let (outer, rest) = (line / stride, line % stride);
                let base = outer * stride * fd[a] + rest;
                for k in 1..=border {
                    u[base + (lo_wall - k) * stride] = -u[base + (lo_wall + k) * stride];
                    u[base + (hi_wall + k) * stride] = -u[base + (hi_wall - k) * stride];
                }
            }
        }
    }
}

/// Face lattice extents of axis `a` for `n` cells.
pub(crate) fn face_dims<const D: usize>(n: [usize; D], a: usize) -> [usize; D] {
    let mut d = n;
    d[a] += 1;
    d
}

/// Flat-index strides of a lattice (x fastest).
pub(crate) fn strides<const D: usize>(d: [usize; D]) -> [usize; D] {
    let mut s = [1; D];
    for a in 1..D {
        s[a] = s[a - 1] * d[a - 1];
    }
    s
}

/// Lattice index of flat index `f`.
pub(crate) fn unflatten<const D: usize>(d: [usize; D], mut f: usize) -> [usize; D] {
    let mut idx = [0; D];
    for a in 0..D {
        idx[a] = f % d[a];
        f /= d[a];
    }
    idx
}

/// Flat index of a lattice index.
#[inline]
pub(crate) fn flatten<const D: usize>(d: [usize; D], idx: [usize; D]) -> usize {
    let mut f = 0;
    for a in (0..D).rev() {
        f = f * d[a] + idx[a];
    }
    f
}
