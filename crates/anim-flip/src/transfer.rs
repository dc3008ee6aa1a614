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
//! P2G is a scatter in slabs of cells (see `p2g`): the particles of slabs too far apart to reach
//! the same faces add to them in parallel, and every face receives its sums in a fixed order
//! (that of [`crate::classify::Bins`]), so the result is bitwise identical for any thread count.
//! G2P is parallel over particles.

use crate::classify::Bins;
use crate::mac::{MacGrid, strides};
use crate::par;
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

/// Cell layers per slab of the scatter form of P2G (`p2g`). A particle's stencil reaches at
/// most 2 face layers below its cell and 3 above along the slab axis (cubic kernel, on the
/// lattice of that axis), so slabs of 5 or more layers, two apart, never write the same face.
const SLAB: usize = 6;

/// Copies the particles into `sorted` in the order of `bins` (particle `bins.order[i]` at `i`), so
/// that the transfers read them, and the grid around them, in memory order. `sorted` grows only
/// when the particle count grows.
pub(crate) fn sort<const D: usize>(particles: &Particles<D>, bins: &Bins, sorted: &mut Particles<D>) {
    let count = particles.len();
    sorted.x.resize(count, [0.0; D]);
    sorted.v.resize(count, [0.0; D]);
    sorted.c.resize(count, [[0.0; D]; D]);
    let Particles { x, v, c } = sorted;
    x.par_iter_mut()
        .zip(v.par_iter_mut())
        .zip(c.par_iter_mut())
        .zip(bins.order.par_iter())
        .with_min_len(par::min_len(par::MIN_PARTICLES, 1))
        .for_each(|(((x, v), c), &p)| {
            let p = p as usize;
            *x = particles.x[p];
            *v = particles.v[p];
            *c = particles.c[p];
        });
}

/// Particle-to-grid from the particles `sorted` by [`sort`]: face velocities (`grid.u`) and
/// weight sums (`grid.weight`); faces with no weight get zero velocity. The affine term is used
/// when `apic`.
///
/// A scatter in slabs: the cells are cut into slabs of `SLAB` layers along the last axis, and
/// the particles of each slab (contiguous in the order of [`Bins`]) add their weights and
/// weighted velocities to the faces of their stencils, the even slabs first, then the odd ones.
/// Within a phase the slabs write disjoint ranges of faces, so they run in parallel with no
/// atomics, and every face receives its sums in a fixed order (slab by slab, particles in bin
/// order): the partition depends on the grid only, so the result does not depend on the thread
/// count. Each particle evaluates its `3 D` (quadratic) or `4 D` (cubic) 1D weights once per
/// component.
pub(crate) fn p2g<const D: usize>(
    grid: &mut MacGrid<D>,
    particles: &Particles<D>,
    bins: &Bins,
    kernel: Kernel,
    apic: bool,
) {
    let n = grid.n;
    let h = grid.h;
    let outer = n[D - 1];
    let cell_plane: usize = n[..D - 1].iter().product();
    let slabs = outer.div_ceil(SLAB);
    let split = if par::pays(particles.len(), par::MIN_PARTICLES) { 1 } else { usize::MAX };
    for a in 0..D {
        let fd = grid.face_dims(a);
        let plane: usize = fd[..D - 1].iter().product();
        let (mom, weight) = (&mut grid.u[a], &mut grid.weight[a]);
        mom.fill(0.0);
        weight.fill(0.0);
        for phase in 0..2 {
            // Slab `k = phase + 2 i` owns the face layers `[(k - 1) SLAB + 3, (k + 1) SLAB + 3)`
            // (from 0 for the first), which hold every face its particles reach.
            let first = (((phase + 1) * SLAB + 3) * plane).min(mom.len());
            let (m0, m1) = mom.split_at_mut(first);
            let (w0, w1) = weight.split_at_mut(first);
            let chunk = 2 * SLAB * plane;
            rayon::iter::once((m0, w0))
                .chain(m1.par_chunks_mut(chunk).zip(w1.par_chunks_mut(chunk)))
                .enumerate()
                .with_min_len(split)
                .for_each(|(i, (m, w))| {
                    let slab = phase + 2 * i;
                    if slab >= slabs {
                        return;
                    }
                    let offset = if i == 0 { 0 } else { first + (i - 1) * chunk };
                    let cells = (slab * SLAB * cell_plane, ((slab + 1) * SLAB).min(outer) * cell_plane);
                    let range = bins.start[cells.0] as usize..bins.start[cells.1] as usize;
                    for p in range {
                        let x = &particles.x[p];
                        let s = Stencil::new(h, fd, kernel, a, x);
                        // The affine term per node, `C_p,a . (x_i - x_p)`, summed over axes
                        // from its 1D parts `h c_b (node_b - xs_b)`.
                        let mut t = [[0.0f64; 4]; D];
                        if apic {
                            let c = &particles.c[p][a];
                            for b in 0..D {
                                for k in 0..s.support {
                                    t[b][k] = h * c[b] * s.d1[b][k];
                                }
                            }
                        }
                        let v = particles.v[p][a];
                        s.for_each(|wk, face, k| {
                            let Some(local) = face.checked_sub(offset).filter(|&l| l < m.len()) else {
                                return;
                            };
                            let mut vel = v;
                            if apic {
                                for b in 0..D {
                                    vel += t[b][k[b]];
                                }
                            }
                            w[local] += wk;
                            m[local] += wk * vel;
                        });
                    }
                });
        }
        let lines = par::min_len(par::MIN_ENTRIES, fd[0]);
        mom.par_chunks_mut(fd[0]).zip(weight.par_chunks(fd[0])).with_min_len(lines).for_each(|(u, w)| {
            for (u, &w) in u.iter_mut().zip(w) {
                *u = if w > 0.0 { *u / w } else { 0.0 };
            }
        });
    }
}

/// Grid-to-particle by `transfer`, from `grid.u` (and `grid.u_old` for FLIP): computed on the
/// copy `sorted` by [`sort`] with the bins `bins` (in memory order, reading the grid along the
/// cells), then copied back to `particles`.
pub(crate) fn g2p<const D: usize>(
    grid: &MacGrid<D>,
    particles: &mut Particles<D>,
    sorted: &mut Particles<D>,
    bins: &Bins,
    kernel: Kernel,
    transfer: Transfer,
) {
    g2p_in_place(grid, sorted, kernel, transfer);
    let split = par::min_len(par::MIN_PARTICLES, 1);
    let sorted: &Particles<D> = sorted;
    particles
        .v
        .par_iter_mut()
        .zip(particles.c.par_iter_mut())
        .zip(bins.rank.par_iter())
        .with_min_len(split)
        .for_each(|((v, c), &i)| {
            *v = sorted.v[i as usize];
            *c = sorted.c[i as usize];
        });
}

/// Grid-to-particle by `transfer` on `particles` in place.
fn g2p_in_place<const D: usize>(
    grid: &MacGrid<D>,
    particles: &mut Particles<D>,
    kernel: Kernel,
    transfer: Transfer,
) {
    let inv_h = 1.0 / grid.h;
    let d_inv = f64::from(kernel.d_inv());
    let Particles { x, v, c } = particles;
    let x: &[[f64; D]] = x;
    let split = par::min_len(par::MIN_PARTICLES, 1);
    v.par_iter_mut().zip(c.par_iter_mut()).enumerate().with_min_len(split).for_each(|(p, (vp, cp))| {
        for a in 0..D {
            match transfer {
                Transfer::Pic => {
                    vp[a] = gather_pic(grid, kernel, a, &x[p]);
                    cp[a] = [0.0; D];
                }
                Transfer::Flip(alpha) => {
                    let (pic, old) = gather_flip(grid, kernel, a, &x[p]);
                    vp[a] = (1.0 - alpha) * pic + alpha * (vp[a] + pic - old);
                    cp[a] = [0.0; D];
                }
                Transfer::Apic => {
                    let (pic, grad) = gather(grid, kernel, a, &x[p]);
                    vp[a] = pic;
                    cp[a] = std::array::from_fn(|b| d_inv * inv_h * grad[b]);
                }
            }
        }
    });
}

/// The B-spline stencil of the face lattice of axis `a` around `x` (m): its first node, the 1D
/// weights per axis (zero for nodes outside the lattice), the offsets `node - xs` of the nodes
/// from the position `xs` in that lattice's node units, and the lattice's strides.
struct Stencil<const D: usize> {
    base: [isize; D],
    w1: [[f64; 4]; D],
    d1: [[f64; 4]; D],
    st: [usize; D],
    support: usize,
}

impl<const D: usize> Stencil<D> {
    /// The stencil on the face lattice `fd` of axis `a` of a grid of cell size `h`.
    #[inline]
    fn new(h: f64, fd: [usize; D], kernel: Kernel, a: usize, x: &[f64; D]) -> Self {
        let inv_h = 1.0 / h;
        let support = kernel.support();
        let mut base = [0isize; D];
        let mut w1 = [[0.0f64; 4]; D];
        let mut d1 = [[0.0f64; 4]; D];
        for b in 0..D {
            let xs = x[b] * inv_h - if b == a { 0.0 } else { 0.5 };
            match kernel {
                Kernel::Quadratic => {
                    // `N(x)` at the three nodes `base + k`, `fx = xs - base` in `[0.5, 1.5)`.
                    let lo = (xs - 0.5).floor();
                    let fx = xs - lo;
                    base[b] = lo as isize;
                    w1[b][..3].copy_from_slice(&[
                        0.5 * (1.5 - fx) * (1.5 - fx),
                        0.75 - (fx - 1.0) * (fx - 1.0),
                        0.5 * (fx - 0.5) * (fx - 0.5),
                    ]);
                    d1[b][..3].copy_from_slice(&[-fx, 1.0 - fx, 2.0 - fx]);
                }
                Kernel::Cubic => {
                    let lo = (xs - 1.0).floor();
                    base[b] = lo as isize;
                    for k in 0..4 {
                        d1[b][k] = lo + k as f64 - xs;
                        w1[b][k] = kernel.n(d1[b][k]);
                    }
                }
            }
            // Nodes outside the lattice (only next to the grid's edge) weigh nothing.
            if base[b] < 0 || base[b] + support as isize > fd[b] as isize {
                for k in 0..support {
                    let node = base[b] + k as isize;
                    if node < 0 || node as usize >= fd[b] {
                        w1[b][k] = 0.0;
                    }
                }
            }
        }
        Self { base, w1, d1, st: strides(fd), support }
    }

    /// Calls `f(w, face, k)` for every node `k` of the stencil with a non-zero weight `w`, in a
    /// fixed order (first axis fastest); rows whose weight in the other axes is zero are skipped
    /// whole.
    #[inline(always)]
    fn for_each(&self, f: impl FnMut(f64, usize, &[usize; D])) {
        if self.support == 3 { self.each::<3>(f) } else { self.each::<4>(f) }
    }

    /// [`Stencil::for_each`] with `S` nodes per axis known at compile time (`D` is 2 or 3).
    #[inline(always)]
    fn each<const S: usize>(&self, mut f: impl FnMut(f64, usize, &[usize; D])) {
        let planes = if D == 3 { S } else { 1 };
        for k2 in 0..planes {
            let (w2, r2) = if D == 3 {
                let l = D - 1;
                (self.w1[l][k2], (self.base[l] + k2 as isize) * self.st[l] as isize)
            } else {
                (1.0, 0)
            };
            if w2 == 0.0 {
                continue;
            }
            for k1 in 0..S {
                let w21 = w2 * self.w1[1][k1];
                if w21 == 0.0 {
                    continue;
                }
                let row = r2 + (self.base[1] + k1 as isize) * self.st[1] as isize + self.base[0];
                for k0 in 0..S {
                    let w = w21 * self.w1[0][k0];
                    if w != 0.0 {
                        let mut k = [0usize; D];
                        k[0] = k0;
                        k[1] = k1;
                        k[D - 1] = if D == 3 { k2 } else { k1 };
                        f(w, (row + k0 as isize) as usize, &k);
                    }
                }
            }
        }
    }
}

/// Velocity component `a` at `x` (m) gathered from the face lattice of axis `a`: the
/// interpolated velocity and the unscaled APIC moment `sum_i w_ip u_i (x_i - x_p) / h`.
#[inline]
fn gather<const D: usize>(grid: &MacGrid<D>, kernel: Kernel, a: usize, x: &[f64; D]) -> (f64, [f64; D]) {
    let s = Stencil::new(grid.h, grid.face_dims(a), kernel, a, x);
    let u = &grid.u[a];
    let mut pic = 0.0;
    let mut grad = [0.0; D];
    s.for_each(|w, f, k| {
        let wu = w * u[f];
        pic += wu;
        for b in 0..D {
            grad[b] += wu * s.d1[b][k[b]];
        }
    });
    (pic, grad)
}

/// Velocity component `a` at `x` (m) interpolated from the face lattice of axis `a`.
#[inline]
fn gather_pic<const D: usize>(grid: &MacGrid<D>, kernel: Kernel, a: usize, x: &[f64; D]) -> f64 {
    let u = &grid.u[a];
    let mut pic = 0.0;
    Stencil::new(grid.h, grid.face_dims(a), kernel, a, x).for_each(|w, f, _| pic += w * u[f]);
    pic
}

/// Velocity component `a` at `x` (m) and its pre-force value (`u_old`), interpolated from the
/// face lattice of axis `a`.
#[inline]
fn gather_flip<const D: usize>(grid: &MacGrid<D>, kernel: Kernel, a: usize, x: &[f64; D]) -> (f64, f64) {
    let (u, old) = (&grid.u[a], &grid.u_old[a]);
    let (mut pic, mut before) = (0.0, 0.0);
    Stencil::new(grid.h, grid.face_dims(a), kernel, a, x).for_each(|w, f, _| {
        pic += w * u[f];
        before += w * old[f];
    });
    (pic, before)
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
        let (pic, grad) = gather(grid, kernel, a, x);
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
    std::array::from_fn(|a| gather_pic(grid, kernel, a, x))
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

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use crate::mac::unflatten;

    /// P2G by its definition, every face against every particle:
    /// `u_i = sum_p w_ip (v_p,a + C_p,a . (x_i - x_p)) / sum_p w_ip`.
    fn p2g_brute<const D: usize>(grid: &MacGrid<D>, p: &Particles<D>, kernel: Kernel) -> [Vec<f64>; D] {
        let h = grid.h;
        std::array::from_fn(|a| {
            let fd = grid.face_dims(a);
            (0..fd.iter().product::<usize>())
                .map(|f| {
                    let idx = unflatten(fd, f);
                    let q: [f64; D] = std::array::from_fn(|b| idx[b] as f64 + if b == a { 0.0 } else { 0.5 });
                    let (mut ws, mut m) = (0.0, 0.0);
                    for ((x, v), c) in p.x.iter().zip(&p.v).zip(&p.c) {
                        let w: f64 = (0..D).map(|b| kernel.n(x[b] / h - q[b])).product();
                        let vel = v[a] + (0..D).map(|b| c[a][b] * (q[b] * h - x[b])).sum::<f64>();
                        ws += w;
                        m += w * vel;
                    }
                    if ws > 0.0 { m / ws } else { 0.0 }
                })
                .collect()
        })
    }

    /// A deterministic scatter of particles over the fluid box of `n` cells (border `border`),
    /// with velocities and affine matrices varying from particle to particle.
    fn particles<const D: usize>(n: [usize; D], h: f64, border: usize, count: usize) -> Particles<D> {
        let mut p = Particles::new();
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..count {
            let x = std::array::from_fn(|a| (border as f64 + next() * (n[a] - 2 * border) as f64) * h);
            let v = std::array::from_fn(|_| next() - 0.5);
            p.push(x, v);
            let last = p.c.len() - 1;
            p.c[last] = std::array::from_fn(|_| std::array::from_fn(|_| 4.0 * next() - 2.0));
        }
        p
    }

    fn check<const D: usize>(n: [usize; D], kernel: Kernel, count: usize) {
        let h = 0.1;
        let border = if kernel == Kernel::Cubic { 2 } else { 1 };
        let p = particles(n, h, border, count);
        let mut grid = MacGrid::new(n, h);
        let mut bins = Bins::new(n.iter().product());
        bins.bin(&p.x, n, h);
        let mut sorted = Particles::new();
        sort(&p, &bins, &mut sorted);
        p2g(&mut grid, &sorted, &bins, kernel, true);
        let want = p2g_brute(&grid, &p, kernel);
        for a in 0..D {
            for (f, (got, want)) in grid.u[a].iter().zip(&want[a]).enumerate() {
                let err = (got - want).abs();
                assert!(
                    err <= 1e-12 * (1.0 + want.abs()),
                    "{n:?} {kernel:?} axis {a} face {f}: {got} vs {want}"
                );
            }
        }
        // Every face a particle's stencil reaches received weight (no contribution was dropped
        // at a slab boundary): the weights sum to the particle count on every lattice.
        for a in 0..D {
            let total: f64 = grid.weight[a].iter().sum();
            assert!(
                (total - count as f64).abs() < 1e-9 * count as f64,
                "axis {a}: weight {total} of {count}"
            );
        }
    }

    /// The slab scatter equals P2G summed face by face over all particles, for grids whose last
    /// axis is shorter than one slab, a few slabs, and not a multiple of the slab width.
    #[test]
    fn slab_scatter_matches_the_definition() {
        for kernel in [Kernel::Quadratic, Kernel::Cubic] {
            check::<2>([9, 5], kernel, 60);
            check::<2>([8, 23], kernel, 400);
            check::<3>([6, 7, 19], kernel, 500);
            check::<3>([7, 6, 30], kernel, 700);
        }
    }
}
