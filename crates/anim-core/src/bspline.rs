//! B-spline interpolation kernels (as in APIC, Jiang et al. 2015): quadratic and cubic weights and their gradients.
//!
//! Shared by the particle-grid transfers of `anim-mpm` (collocated grid) and `anim-flip`
//! (staggered MAC grid, where the same weights are evaluated at face-staggered offsets).
//!
//! A grid node `i` at `x_i` carries the tensor-product weight
//!
//! ```text
//! w_ip = N_i(x_p) = prod_a N((x_p,a - x_i,a) / h)
//! ```
//!
//! with the 1D quadratic and cubic B-splines:
//!
//! ```text
//! quadratic: N(x) = 3/4 - |x|^2                   0 <= |x| < 1/2
//!                   1/2 (3/2 - |x|)^2             1/2 <= |x| < 3/2     (support 3 nodes per axis)
//! cubic:     N(x) = 1/2 |x|^3 - |x|^2 + 2/3       0 <= |x| < 1
//!                   1/6 (2 - |x|)^3               1 <= |x| < 2         (support 4 nodes per axis)
//! ```
//!
//! Both are partitions of unity, `sum_i w_ip = 1`, reproduce linear functions,
//! `sum_i w_ip x_i = x_p`, and have the APIC inertia-like tensor
//! `D_p = sum_i w_ip (x_i - x_p)(x_i - x_p)^T = h^2/4 I` (quadratic) and `h^2/3 I` (cubic),
//! which is what makes `C_p = B_p D_p^-1` cheap: [`Kernel::d_inv`] is the factor `4` or `3` of
//! `D_p^-1 = d_inv / h^2 I`.
//!
//! A particle's stencil starts at its **base node** (per axis `floor(x/h - 1/2)` for the
//! quadratic, `floor(x/h) - 1` for the cubic kernel) and spans [`Kernel::support`] nodes per axis;
//! [`Kernel::weights`] returns the base, the weights and the derivatives `dN/d(x/h)` of the
//! `N` nodes from the particle's coordinate in cell units. The gradient with respect to the
//! particle position is `grad_a w_ip = N'_a / h * prod_{b != a} N_b`.

/// Which B-spline the transfers use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Kernel {
    /// Quadratic B-spline, 3 nodes per axis, `D_p = h^2/4 I` (the default: cheaper).
    #[default]
    Quadratic,
    /// Cubic B-spline, 4 nodes per axis, `D_p = h^2/3 I` (smoother, more stable, costlier).
    Cubic,
}

impl Kernel {
    /// Nodes per axis in a particle's stencil.
    #[inline]
    #[must_use]
    pub fn support(self) -> usize {
        match self {
            Kernel::Quadratic => Quadratic::N,
            Kernel::Cubic => Cubic::N,
        }
    }

    /// The factor `k` of `D_p^-1 = k / h^2 I` (4 quadratic, 3 cubic).
    #[inline]
    #[must_use]
    pub fn d_inv(self) -> f32 {
        match self {
            Kernel::Quadratic => Quadratic::D_INV,
            Kernel::Cubic => Cubic::D_INV,
        }
    }

    /// Base node, weights and derivatives along one axis for the coordinate `xs = x / h`; only
    /// the first [`support`](Self::support) entries are meaningful.
    #[inline]
    #[must_use]
    pub fn weights(self, xs: f32) -> (i32, [f32; 4], [f32; 4]) {
        match self {
            Kernel::Quadratic => Quadratic::weights(xs),
            Kernel::Cubic => Cubic::weights(xs),
        }
    }

    /// The 1D B-spline `N(x)` itself (for tests and plots).
    #[must_use]
    pub fn n(self, x: f64) -> f64 {
        let a = x.abs();
        match self {
            Kernel::Quadratic => {
                if a < 0.5 {
                    0.75 - a * a
                } else if a < 1.5 {
                    0.5 * (1.5 - a) * (1.5 - a)
                } else {
                    0.0
                }
            }
            Kernel::Cubic => {
                if a < 1.0 {
                    0.5 * a * a * a - a * a + 2.0 / 3.0
                } else if a < 2.0 {
                    (2.0 - a).powi(3) / 6.0
                } else {
                    0.0
                }
            }
        }
    }
}

/// A B-spline kernel known at compile time, so that the transfer loops unroll over its support.
pub trait Spline: Copy + Send + Sync + 'static {
    /// Nodes per axis.
    const N: usize;
    /// `D_p^-1 = D_INV / h^2 I`.
    const D_INV: f32;
    /// The base node is `floor(xs - OFFSET)`: `1/2` quadratic, `1` cubic.
    const OFFSET: f32;
    /// Base node, weights and `dN/d(x/h)` for the coordinate `xs = x/h` (first `N` entries).
    fn weights(xs: f32) -> (i32, [f32; 4], [f32; 4]);
    /// Weights and `dN/d(x/h)` for the particle at `fx = xs - base` cells from its base node
    /// (`fx` in `[1/2, 3/2)` quadratic, `[1, 2)` cubic): what [`weights`](Self::weights) returns
    /// after finding the base node.
    fn weights_at(fx: f32) -> ([f32; 4], [f32; 4]);
}

/// The quadratic B-spline.
#[derive(Debug, Clone, Copy)]
pub struct Quadratic;

impl Spline for Quadratic {
    const N: usize = 3;
    const D_INV: f32 = 4.0;
    const OFFSET: f32 = 0.5;

    #[inline(always)]
    fn weights(xs: f32) -> (i32, [f32; 4], [f32; 4]) {
        // Coordinates are positive (particles stay at least 2 cells inside the domain), so the
        // truncating cast is the floor; it avoids a libm call on baseline x86-64.
        let base = (xs - 0.5).max(0.0) as i32 as f32;
        let (w, dw) = Self::weights_at(xs - base);
        (base as i32, w, dw)
    }

    #[inline(always)]
    fn weights_at(fx: f32) -> ([f32; 4], [f32; 4]) {
        // fx in [0.5, 1.5): distance from the base node in cells.
        let a = 1.5 - fx;
        let b = fx - 1.0;
        let c = fx - 0.5;
        (
            [0.5 * a * a, 0.75 - b * b, 0.5 * c * c, 0.0],
            // d/dxs of N(xs - i): N'(d) with d = fx - k.
            [-a, -2.0 * b, c, 0.0],
        )
    }
}

/// The cubic B-spline.
#[derive(Debug, Clone, Copy)]
pub struct Cubic;

impl Spline for Cubic {
    const N: usize = 4;
    const D_INV: f32 = 3.0;
    const OFFSET: f32 = 1.0;

    #[inline(always)]
    fn weights(xs: f32) -> (i32, [f32; 4], [f32; 4]) {
        let base = xs.max(0.0) as i32 as f32 - 1.0;
        let (w, dw) = Self::weights_at(xs - base);
        (base as i32, w, dw)
    }

    #[inline(always)]
    fn weights_at(fx: f32) -> ([f32; 4], [f32; 4]) {
        // fx in [1, 2). Signed distances particle - node: d0 in [1,2), d1 in [0,1), d2 in
        // [-1,0), d3 in [-2,-1).
        let d0 = fx;
        let d1 = fx - 1.0;
        let d2 = 2.0 - fx; // |fx - 2|
        let d3 = 3.0 - fx; // |fx - 3|
        let far = |a: f32| {
            let t = 2.0 - a;
            t * t * t / 6.0
        };
        let near = |a: f32| 0.5 * a * a * a - a * a + 2.0 / 3.0;
        // N'(a) for a = |d| >= 0; the derivative in d is sign(d) N'(|d|).
        let dfar = |a: f32| {
            let t = 2.0 - a;
            -0.5 * t * t
        };
        let dnear = |a: f32| 1.5 * a * a - 2.0 * a;
        ([far(d0), near(d1), near(d2), far(d3)], [dfar(d0), dnear(d1), -dnear(d2), -dfar(d3)])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_identities(kernel: Kernel, d_factor: f64) {
        // Sweep positions across several cells, including exact node and half-node positions.
        for step in 0..=400 {
            let xs = 5.0 + step as f32 * 0.0025 * 3.0;
            let (base, w, dw) = kernel.weights(xs);
            let n = kernel.support();
            let (mut sum, mut first, mut second, mut dsum, mut dfirst) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for k in 0..n {
                let d = f64::from(base + k as i32) - f64::from(xs); // node - particle, in cells
                // Each weight agrees with the closed-form spline.
                let exact = kernel.n(d);
                assert!((f64::from(w[k]) - exact).abs() < 2e-6, "{kernel:?} xs {xs} k {k}");
                sum += f64::from(w[k]);
                first += f64::from(w[k]) * d;
                second += f64::from(w[k]) * d * d;
                dsum += f64::from(dw[k]);
                dfirst += f64::from(dw[k]) * d;
                // The derivative against a central finite difference of the closed form.
                let fd = (kernel.n(-(d - 1e-6)) - kernel.n(-(d + 1e-6))) / 2e-6;
                assert!((f64::from(dw[k]) - fd).abs() < 1e-4, "{kernel:?} xs {xs} k {k}: {} vs {fd}", dw[k]);
            }
            // Nodes outside the stencil carry no weight.
            assert!(kernel.n(f64::from(base - 1) - f64::from(xs)) < 1e-6);
            assert!(kernel.n(f64::from(base + n as i32) - f64::from(xs)) < 1e-6);
            assert!((sum - 1.0).abs() < 1e-6, "partition of unity {sum}");
            assert!(first.abs() < 2e-6, "linear reproduction {first}");
            assert!((second - d_factor).abs() < 2e-6, "D_p = {second} h^2, expected {d_factor}");
            assert!(dsum.abs() < 2e-6, "sum of gradients {dsum}");
            // sum_i (x_i - x_p) grad w_ip = I  (derivative of the linear reproduction).
            assert!((dfirst - 1.0).abs() < 2e-6, "sum (x_i - x_p) N' = {dfirst}");
        }
    }

    #[test]
    fn quadratic_identities() {
        check_identities(Kernel::Quadratic, 0.25);
        assert_eq!(Kernel::Quadratic.d_inv(), 4.0);
    }

    #[test]
    fn cubic_identities() {
        check_identities(Kernel::Cubic, 1.0 / 3.0);
        assert_eq!(Kernel::Cubic.d_inv(), 3.0);
    }

    #[test]
    fn tensor_product_partition_of_unity_3d() {
        for kernel in [Kernel::Quadratic, Kernel::Cubic] {
            let x = [7.31f32, 12.77, 9.5];
            let n = kernel.support();
            let ws: Vec<_> = x.iter().map(|&c| kernel.weights(c)).collect();
            let (mut sum, mut d) = (0.0f64, [[0.0f64; 3]; 3]);
            for i in 0..n {
                for j in 0..n {
                    for k in 0..n {
                        let w = f64::from(ws[0].1[i] * ws[1].1[j] * ws[2].1[k]);
                        let r = [
                            f64::from(ws[0].0 + i as i32) - f64::from(x[0]),
                            f64::from(ws[1].0 + j as i32) - f64::from(x[1]),
                            f64::from(ws[2].0 + k as i32) - f64::from(x[2]),
                        ];
                        sum += w;
                        for a in 0..3 {
                            for b in 0..3 {
                                d[a][b] += w * r[a] * r[b];
                            }
                        }
                    }
                }
            }
            let expected = 1.0 / f64::from(kernel.d_inv());
            assert!((sum - 1.0).abs() < 1e-6);
            for a in 0..3 {
                for b in 0..3 {
                    let e = if a == b { expected } else { 0.0 };
                    assert!((d[a][b] - e).abs() < 2e-6, "{kernel:?} D[{a}][{b}] = {}", d[a][b]);
                }
            }
        }
    }
}
