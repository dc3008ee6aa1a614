//! Particle-grid transfers on the MAC grid: PIC, FLIP (blended with PIC) and APIC (Jiang et al. 2015).
//!
//! Each velocity component `a` is transferred to the face lattice of axis `a` with the
//! B-spline weights of [`anim_core::bspline`] evaluated at face-staggered offsets,
//! `w_ip = prod_b N(x_p,b / h - q_i,b)` with `q_i` the face position in cells (`i` along `a`,
//! `i + 1/2` along the other axes).
//!
//! ```text
//! P2G:  u_i = sum_p w_ip (v_p,a + [APIC] c_p,a . (x_i - x_p)) / sum_p w_ip
//! G2P:  PIC   v_p,a = sum_i w_ip u_i
//!       FLIP  v_p,a = (1 - alpha) PIC + alpha (v_p,a + sum_i w_ip (u_i - u_i^old))
//!       APIC  v_p,a = sum_i w_ip u_i,   c_p,a = D_p^-1 sum_i w_ip u_i (x_i - x_p)
//! ```
//!
//! with `D_p^-1 = 4/h^2` (quadratic) or `3/h^2` (cubic). Because the B-splines reproduce linear
//! functions, APIC carries an affine field through P2G and G2P exactly, so it conserves angular
//! momentum over the transfers; PIC averages the rotation away, FLIP keeps it but accumulates
//! grid noise.
//!
//! P2G is written as a gather: every face sums over the particles of the cells its stencil
//! reaches, in the fixed order of [`crate::classify::Bins`], so it runs in parallel over faces
//! with no atomics and gives bitwise identical sums for any thread count. G2P is parallel over
//! particles.

use crate::classify::Bins;
use crate::mac::{MacGrid, flatten, strides};
use crate::particles::Particles;
use anim_core::bspline::Kernel;
use rayon::prelude::*;

/// How grid velocities return to the particles. Serialised as scene files write it: `"pic"`,
/// `"apic"`, or `{ "flip": 0.97 }` (TOML `{ flip = 0.97 }`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Transfer {
    /// Particle-in-cell: particles take the interpolated grid velocity (dissipative).
    Pic,
    /// Fluid-implicit-particle blended with PIC: `alpha = 1` is pure FLIP, `0` pure PIC.
    Flip(f64),
    /// Affine particle-in-cell: velocity and the affine matrix `C_p`.
    Apic,
}

impl Transfer {
    /// A short name for tables.
    #[must_use]
    pub fn name(self) -> String {
        match self {
            Transfer::Pic => "PIC".into(),
            Transfer::Flip(a) => format!("FLIP {a}"),
            Transfer::Apic => "APIC".into(),
        }
    }
}

/// Half-width of the kernel support in cells (1.5 quadratic, 2 cubic).
pub(crate) fn radius(kernel: Kernel) -> f64 {
    kernel.support() as f64 / 2.0
}

/// Particle-to-grid: face velocities (`grid.u`) and weight sums (`grid.weight`); faces with no
/// weight get zero velocity. The affine term is used when `apic`.
pub(crate) fn p2g<const D: usize>(
    grid: &mut MacGrid<D>,
    particles: &Particles<D>,
    bins: &Bins,
    kernel: Kernel,
    apic: bool,
) {
    let n = grid.n;
    let h = grid.h;
    let inv_h = 1.0 / h;
    let r = radius(kernel);
    for a in 0..D {
        let fd = grid.face_dims(a);
        let (u, weight) = (&mut grid.u[a], &mut grid.weight[a]);
        u.par_chunks_mut(fd[0]).zip(weight.par_chunks_mut(fd[0])).enumerate().for_each(|(line, (ur, wr))| {
            let rest = crate::mac::unflatten(fd, line * fd[0]);
            for i in 0..fd[0] {
                let mut idx = rest;
                idx[0] = i;
                let q: [f64; D] = std::array::from_fn(|b| idx[b] as f64 + if b == a { 0.0 } else { 0.5 });
                let lo: [usize; D] = std::array::from_fn(|b| (q[b] - r).floor().max(0.0) as usize);
                let hi: [usize; D] =
                    std::array::from_fn(|b| ((q[b] + r).floor().max(0.0) as usize).min(n[b] - 1));
                let mut wsum = 0.0;
                let mut mom = 0.0;
                let mut cell = lo;
                if lo.iter().zip(&hi).all(|(l, h)| l <= h) {
                    loop {
                        for &p in bins.cell(flatten(n, cell)) {
                            let p = p as usize;
                            let x = &particles.x[p];
                            let mut w = 1.0;
                            for b in 0..D {
                                w *= kernel.n(x[b] * inv_h - q[b]);
                            }
                            if w == 0.0 {
                                continue;
                            }
                            let mut vel = particles.v[p][a];
                            if apic {
                                let c = &particles.c[p][a];
                                for b in 0..D {
                                    vel += c[b] * (q[b] * h - x[b]);
                                }
                            }
                            wsum += w;
                            mom += w * vel;
                        }
                        if !odometer(&mut cell, &lo, &hi) {
                            break;
                        }
                    }
                }
                wr[i] = wsum;
                ur[i] = if wsum > 0.0 { mom / wsum } else { 0.0 };
            }
        });
    }
}

/// Advances `idx` through the box `lo..=hi` (first axis fastest); false when done.
#[inline]
fn odometer<const D: usize>(idx: &mut [usize; D], lo: &[usize; D], hi: &[usize; D]) -> bool {
    for b in 0..D {
        if idx[b] < hi[b] {
            idx[b] += 1;
            return true;
        }
        idx[b] = lo[b];
    }
    false
}

/// Grid-to-particle by `transfer`, from `grid.u` (and `grid.u_old` for FLIP).
pub(crate) fn g2p<const D: usize>(
    grid: &MacGrid<D>,
    particles: &mut Particles<D>,
    kernel: Kernel,
    transfer: Transfer,
) {
    let inv_h = 1.0 / grid.h;
    let d_inv = f64::from(kernel.d_inv());
    let Particles { x, v, c } = particles;
    let x: &[[f64; D]] = x;
    v.par_iter_mut().zip(c.par_iter_mut()).enumerate().for_each(|(p, (vp, cp))| {
        for a in 0..D {
            let (pic, old, grad) = gather(grid, kernel, a, &x[p]);
            match transfer {
                Transfer::Pic => {
                    vp[a] = pic;
                    cp[a] = [0.0; D];
                }
                Transfer::Flip(alpha) => {
                    vp[a] = (1.0 - alpha) * pic + alpha * (vp[a] + pic - old);
                    cp[a] = [0.0; D];
                }
                Transfer::Apic => {
                    vp[a] = pic;
                    cp[a] = std::array::from_fn(|b| d_inv * inv_h * grad[b]);
                }
            }
        }
    });
}

/// The B-spline stencil of the face lattice of axis `a` around `x` (m): the position in that
/// lattice's node units, its first node, the 1D weights per axis (zero for nodes outside the
/// lattice) and the lattice's strides.
struct Stencil<const D: usize> {
    xs: [f64; D],
    base: [isize; D],
    w1: [[f64; 4]; D],
    st: [usize; D],
}

impl<const D: usize> Stencil<D> {
    #[inline]
    fn new(grid: &MacGrid<D>, kernel: Kernel, a: usize, x: &[f64; D]) -> Self {
        let inv_h = 1.0 / grid.h;
        let r = radius(kernel);
        let fd = grid.face_dims(a);
        let xs: [f64; D] = std::array::from_fn(|b| x[b] * inv_h - if b == a { 0.0 } else { 0.5 });
        let base: [isize; D] = std::array::from_fn(|b| (xs[b] + 1.0 - r).floor() as isize);
        let mut w1 = [[0.0f64; 4]; D];
        for b in 0..D {
            for k in 0..kernel.support() {
                let node = base[b] + k as isize;
                if node >= 0 && (node as usize) < fd[b] {
                    w1[b][k] = kernel.n(xs[b] - node as f64);
                }
            }
        }
        Self { xs, base, w1, st: strides(fd) }
    }

    /// Calls `f(w, face, k)` for every node `k` of the stencil with a non-zero weight `w`, in a
    /// fixed order.
    #[inline]
    fn for_each(&self, kernel: Kernel, mut f: impl FnMut(f64, usize, &[usize; D])) {
        let mut k = [0usize; D];
        let hi = [kernel.support() - 1; D];
        loop {
            let mut w = 1.0;
            for b in 0..D {
                w *= self.w1[b][k[b]];
            }
            if w != 0.0 {
                let mut face = 0;
                for b in 0..D {
                    face += (self.base[b] + k[b] as isize) as usize * self.st[b];
                }
                f(w, face, &k);
            }
            if !odometer(&mut k, &[0; D], &hi) {
                break;
            }
        }
    }
}

/// Velocity component `a` at `x` (m) gathered from the face lattice of axis `a`: the
/// interpolated velocity, the interpolated pre-force velocity (`u_old`) and the unscaled APIC
/// moment `sum_i w_ip u_i (x_i - x_p) / h`.
#[inline]
fn gather<const D: usize>(grid: &MacGrid<D>, kernel: Kernel, a: usize, x: &[f64; D]) -> (f64, f64, [f64; D]) {
    let s = Stencil::new(grid, kernel, a, x);
    let mut pic = 0.0;
    let mut old = 0.0;
    let mut grad = [0.0; D];
    s.for_each(kernel, |w, f, k| {
        let uf = grid.u[a][f];
        pic += w * uf;
        old += w * grid.u_old[a][f];
        for b in 0..D {
            grad[b] += w * uf * ((s.base[b] + k[b] as isize) as f64 - s.xs[b]);
        }
    });
    (pic, old, grad)
}

/// The velocity and affine matrix a particle created at `x` (m) receives from the grid: the
/// interpolated velocity, and for APIC `C = D^-1 sum_i w_i u_i (x_i - x)^T` (zero otherwise, as
/// G2P gives PIC and FLIP particles).
pub(crate) fn sample_new<const D: usize>(
    grid: &MacGrid<D>,
    kernel: Kernel,
    transfer: Transfer,
    x: &[f64; D],
) -> ([f64; D], [[f64; D]; D]) {
    let inv_h = 1.0 / grid.h;
    let d_inv = f64::from(kernel.d_inv());
    let mut v = [0.0; D];
    let mut c = [[0.0; D]; D];
    for a in 0..D {
        let (pic, _, grad) = gather(grid, kernel, a, x);
        v[a] = pic;
        if transfer == Transfer::Apic {
            c[a] = std::array::from_fn(|b| d_inv * inv_h * grad[b]);
        }
    }
    (v, c)
}

/// The grid velocity at `x` (m), interpolated with the transfer kernel from every face lattice
/// (the PIC velocity a particle at `x` would receive).
pub(crate) fn sample<const D: usize>(grid: &MacGrid<D>, kernel: Kernel, x: &[f64; D]) -> [f64; D] {
    std::array::from_fn(|a| {
        let mut sum = 0.0;
        Stencil::new(grid, kernel, a, x).for_each(kernel, |w, f, _| sum += w * grid.u[a][f]);
        sum
    })
}

/// The grid velocity at `x` (m), multilinear between the faces of each lattice (the MAC grid's
/// own interpolation: exact at the faces, so zero normal velocity at a wall face).
pub(crate) fn sample_linear<const D: usize>(grid: &MacGrid<D>, x: &[f64; D]) -> [f64; D] {
    let inv_h = 1.0 / grid.h;
    std::array::from_fn(|a| {
        let fd = grid.face_dims(a);
        let mut base = [0usize; D];
        let mut frac = [0.0f64; D];
        for b in 0..D {
            // Face lattice coordinate: along a at i h, along the others at (j + 1/2) h.
            let g = x[b] * inv_h - if b == a { 0.0 } else { 0.5 };
            let g = g.clamp(0.0, (fd[b] - 1) as f64);
            let i = (g.floor() as usize).min(fd[b].saturating_sub(2));
            base[b] = i;
            frac[b] = g - i as f64;
        }
        let mut sum = 0.0;
        for corner in 0..(1usize << D) {
            let mut w = 1.0;
            let mut idx = base;
            for b in 0..D {
                if corner >> b & 1 == 1 {
                    idx[b] += 1;
                    w *= frac[b];
                } else {
                    w *= 1.0 - frac[b];
                }
            }
            sum += w * grid.u[a][crate::mac::flatten(fd, idx)];
        }
        sum
    })
}
