//! Unit tests: the rest state, small-strain agreement, tangent symmetry, the 2x2 SVD, the PSD
//! projection and parameter validation (the finite-difference, invariance, f32 and inversion checks
//! are the `cases` feature's conformance cases).

use crate::decomposition::{determinant, polar, svd, svd2};
use crate::samples::{KINDS, Kind, lame as lame64, rotation, sample};
use crate::*;
use nalgebra::{SVector, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

macro_rules! per_model {
    ($f:ident) => {
        $f(LinearElastic, "LinearElastic");
        $f(StVenantKirchhoff, "StVenantKirchhoff");
        $f(CorotatedLinear, "CorotatedLinear");
        $f(NeoHookean, "NeoHookean");
        $f(FixedCorotated, "FixedCorotated");
        $f(StableNeoHookean, "StableNeoHookean");
    };
}

trait AllImpls:
    Hyperelastic<f64, 2> + Hyperelastic<f64, 3> + Hyperelastic<f32, 2> + Hyperelastic<f32, 3> + Copy
{
}
impl<M: Hyperelastic<f64, 2> + Hyperelastic<f64, 3> + Hyperelastic<f32, 2> + Hyperelastic<f32, 3> + Copy>
    AllImpls for M
{
}

#[test]
fn rest_state_has_zero_energy_and_stress() {
    fn run<M: AllImpls>(m: M, name: &str) {
        fn one<M: Hyperelastic<f64, D>, const D: usize>(m: &M, name: &str) {
            let lame = lame64();
            let id = Mat::<f64, D>::identity();
            let e = m.energy(&lame, &id);
            let p = m.pk1(&lame, &id);
            // Rounding only: the energy is a difference of O(mu) terms.
            assert!(e.abs() <= 1e-12 * lame.mu, "{name} D={D}: psi(I) = {e:e}");
            assert!(p.norm() <= 1e-12 * lame.mu, "{name} D={D}: P(I) = {p}");
        }
        one::<M, 2>(&m, name);
        one::<M, 3>(&m, name);
    }
    per_model!(run);
}

/// Every model linearises to linear elasticity at rest: the tangents at `F = I` agree, and
/// `P(I + eps H) - P_lin(I + eps H) = O(eps^2)`.
#[test]
fn small_strain_agrees_with_linear_elasticity() {
    fn run<M: AllImpls>(m: M, name: &str) {
        fn one<M: Hyperelastic<f64, D>, const D: usize>(m: &M, name: &str, seed: u64) {
            let lame = lame64();
            let scale = lame.mu + lame.lambda;
            let id = Mat::<f64, D>::identity();
            let t = m.dpdf(&lame, &id);
            let t_lin = LinearElastic.dpdf(&lame, &id);
            let mut diff = 0.0f64;
            for k in 0..D {
                for l in 0..D {
                    diff = diff.max((t.d[k][l] - t_lin.d[k][l]).norm());
                }
            }
            assert!(diff <= 1e-12 * scale, "{name} D={D}: dP/dF(I) differs from linear by {diff:e}");
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            for _ in 0..10 {
                let h = Mat::<f64, D>::from_fn(|_, _| rng.random_range(-1.0..1.0));
                let err = |eps: f64| {
                    let f = id + h * eps;
                    (m.pk1(&lame, &f) - LinearElastic.pk1(&lame, &f)).norm() / scale
                };
                let (e1, e2) = (err(1e-3), err(1e-4));
                // Second order: 10x smaller strain, ~100x smaller difference (allow 60x for
                // the third-order term).
                assert!(e1 <= 1e-3 * 10.0, "{name} D={D}: difference {e1:e} at eps 1e-3");
                assert!(e2 <= e1 / 60.0, "{name} D={D}: difference not O(eps^2): {e1:e} -> {e2:e}");
            }
        }
        one::<M, 2>(&m, name, 7);
        one::<M, 3>(&m, name, 8);
    }
    per_model!(run);
}

#[test]
fn tangent_is_symmetric() {
    // dP_ij/dF_kl = d^2 psi / dF_ij dF_kl = dP_kl/dF_ij.
    fn run<M: AllImpls>(m: M, name: &str) {
        fn one<M: Hyperelastic<f64, D>, const D: usize>(m: &M, name: &str, seed: u64) {
            let lame = lame64();
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            for kind in [Kind::General, Kind::Rotation, Kind::Stretch, Kind::NearSingular] {
                let f = sample::<D>(kind, &mut rng);
                let t = m.dpdf(&lame, &f);
                let mut asym = 0.0f64;
                for i in 0..D {
                    for j in 0..D {
                        for k in 0..D {
                            for l in 0..D {
                                asym = asym.max((t.entry(i, j, k, l) - t.entry(k, l, i, j)).abs());
                            }
                        }
                    }
                }
                assert!(asym <= 1e-10 * t.norm(), "{name} D={D} {kind:?}: asymmetry {asym:e}");
            }
        }
        one::<M, 2>(&m, name, 11);
        one::<M, 3>(&m, name, 12);
    }
    per_model!(run);
}

/// The PSD projection: PSD, the identity on PSD input, and for the corotated models the analytic
/// eigensystem route equals the numerical one.
#[test]
fn psd_projection() {
    let lame = lame64();
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    for kind in [Kind::General, Kind::Stretch, Kind::Inverted, Kind::NearSingular] {
        for _ in 0..10 {
            let f = sample::<3>(kind, &mut rng);
            for (name, t, analytic) in [
                ("FixedCorotated", FixedCorotated.dpdf(&lame, &f), Some(FixedCorotated.dpdf_psd(&lame, &f))),
                (
                    "CorotatedLinear",
                    CorotatedLinear.dpdf(&lame, &f),
                    Some(CorotatedLinear.dpdf_psd(&lame, &f)),
                ),
                ("StableNeoHookean", StableNeoHookean.dpdf(&lame, &f), None),
                ("StVenantKirchhoff", StVenantKirchhoff.dpdf(&lame, &f), None),
            ] {
                let p = t.project_psd();
                let m = p.to_matrix();
                let ev = m.symmetric_eigenvalues();
                let min = ev.iter().copied().fold(f64::INFINITY, f64::min);
                assert!(min >= -1e-12 * m.norm(), "{name} {kind:?}: projected eigenvalue {min:e}");
                // Projection of a PSD matrix is itself.
                let again = p.project_psd().to_matrix();
                assert!((again - m).norm() <= 1e-12 * m.norm(), "{name}: not idempotent");
                // Unchanged where the original was already PSD.
                let orig = t.to_matrix();
                if orig.symmetric_eigenvalues().iter().all(|&x| x >= 0.0) {
                    assert!((orig - m).norm() <= 1e-12 * m.norm(), "{name}: PSD input changed");
                }
                if let Some(a) = analytic {
                    let diff = (a.to_matrix() - m).norm();
                    assert!(diff <= 1e-9 * m.norm(), "{name} {kind:?}: analytic projection off by {diff:e}");
                }
            }
        }
    }
    // 2D too.
    let f = Mat::<f64, 2>::new(0.3, 0.1, -0.2, -0.4);
    let a = FixedCorotated.dpdf_psd(&lame, &f).to_matrix();
    let n = FixedCorotated.dpdf(&lame, &f).project_psd().to_matrix();
    assert!((a - n).norm() <= 1e-9 * n.norm());
    // Round trip of the flattening.
    let t = StableNeoHookean.dpdf(&lame, &f);
    assert_eq!(Tangent::<f64, 2>::from_matrix(&t.to_matrix()), t);
}

#[test]
fn svd2_properties() {
    let mut rng = ChaCha8Rng::seed_from_u64(14);
    let mut cases: Vec<Mat<f64, 2>> = vec![
        Mat::zeros(),
        Mat::identity(),
        -Mat::<f64, 2>::identity(),
        Mat::<f64, 2>::new(1.0, 0.0, 0.0, -1.0),
        Mat::<f64, 2>::new(-1.0, 0.0, 0.0, 1.0),
        Mat::<f64, 2>::new(0.0, 1.0, 0.0, 0.0),
        Mat::<f64, 2>::new(2.0, 0.0, 0.0, 2.0),
        Mat::<f64, 2>::new(1e-300, 0.0, 0.0, 1e-300),
        Mat::<f64, 2>::new(0.0, -3.0, 3.0, 0.0),
        Mat::<f64, 2>::new(1.0, 2.0, 2.0, 4.0),
    ];
    for _ in 0..2000 {
        cases.push(Mat::from_fn(|_, _| rng.random_range(-1.0..1.0)));
        let r = rotation::<2>(&mut rng);
        let c: f64 = rng.random_range(0.1..3.0);
        cases.push(r * c);
    }
    for f in cases {
        let s = svd2(&f);
        let norm = f.norm().max(f64::MIN_POSITIVE);
        let rec = (s.u * Mat::from_diagonal(&s.sigma) * s.v.transpose() - f).norm() / norm;
        assert!(rec <= 1e-14, "reconstruction {rec:e} for {f}");
        for q in [s.u, s.v] {
            assert!((q.transpose() * q - Mat::identity()).norm() <= 1e-14);
            assert!((determinant(&q) - 1.0).abs() <= 1e-14);
        }
        assert!(s.sigma[0] >= s.sigma[1].abs(), "ordering {:?}", s.sigma);
        let det = determinant(&f);
        if det.abs() > 1e-12 * norm * norm {
            assert_eq!(s.sigma[1] < 0.0, det < 0.0, "sign of sigma_1 for {f}");
        }
        // Independent magnitudes: eigenvalues of F^T F in closed form.
        if f == Mat::<f64, 2>::zeros() {
            assert_eq!(s.sigma, SVector::<f64, 2>::zeros());
            continue;
        }
        let fu = f / norm;
        let c = fu.transpose() * fu;
        let (tr, dt) = (c.trace(), c.determinant());
        let disc = (0.25 * tr * tr - dt).max(0.0).sqrt();
        let (l0, l1) = (0.5 * tr + disc, (0.5 * tr - disc).max(0.0));
        assert!((s.sigma[0] / norm - l0.sqrt()).abs() <= 1e-14, "{f}");
        if l1 > 1e-6 {
            assert!((s.sigma[1].abs() / norm - l1.sqrt()).abs() <= 1e-12, "{f}");
        }
    }
    // Polar: F = R S, R a rotation, S symmetric, in 2D and 3D.
    let mut rng = ChaCha8Rng::seed_from_u64(15);
    for kind in KINDS {
        let f = sample::<3>(kind, &mut rng);
        let (r, s) = polar(&f);
        assert!((r * s - f).norm() <= 1e-13 * f.norm());
        assert!((determinant(&r) - 1.0).abs() <= 1e-13);
        assert_eq!(s, s.transpose());
        let f2 = sample::<2>(kind, &mut rng);
        let (r2, s2) = polar(&f2);
        assert!((r2 * s2 - f2).norm() <= 1e-13 * f2.norm());
    }
}

#[test]
fn neo_hookean_is_undefined_when_inverted() {
    let lame = lame64();
    for f in [Mat::<f64, 3>::from_diagonal(&Vector3::new(1.0, 1.0, -0.5)), Mat::<f64, 3>::zeros()] {
        assert!(!NeoHookean::is_defined(&f));
        assert_eq!(NeoHookean.energy(&lame, &f), f64::INFINITY);
        assert!(NeoHookean.pk1(&lame, &f).iter().all(|x| x.is_nan()));
        assert!(!NeoHookean.dpdf(&lame, &f).is_finite());
    }
    // Barrier: the energy grows without bound as J -> 0+.
    let e = |j: f64| NeoHookean.energy(&lame, &Mat::<f64, 3>::from_diagonal(&Vector3::new(1.0, 1.0, j)));
    assert!(e(1e-6) > e(1e-3) && e(1e-3) > e(1e-1));
    // NaN input stays NaN, no panic.
    let nan = Mat::<f64, 2>::from_element(f64::NAN);
    assert!(NeoHookean.energy(&lame, &nan).is_nan());
}

#[test]
fn lame_validation() {
    let ok = Lame::<f64>::from_young_poisson(1e4, 0.3);
    assert!(ok.is_ok());
    let l = ok.unwrap_or(Lame { mu: 0.0, lambda: 0.0 });
    assert!((l.mu - 1e4 / 2.6).abs() <= 1e-9 && (l.lambda - 1e4 * 0.3 / (1.3 * 0.4)).abs() <= 1e-9);
    assert!((l.young() - 1e4).abs() <= 1e-8 && (l.poisson() - 0.3).abs() <= 1e-12);
    assert_eq!(Lame::<f64>::from_young_poisson(0.0, 0.3), Err(MaterialError::YoungModulus(0.0)));
    assert_eq!(Lame::<f64>::from_young_poisson(-1.0, 0.3), Err(MaterialError::YoungModulus(-1.0)));
    assert!(matches!(Lame::<f64>::from_young_poisson(f64::NAN, 0.3), Err(MaterialError::YoungModulus(_))));
    assert!(matches!(
        Lame::<f64>::from_young_poisson(f64::INFINITY, 0.3),
        Err(MaterialError::YoungModulus(_))
    ));
    assert_eq!(Lame::<f32>::from_young_poisson(1.0, 0.5), Err(MaterialError::PoissonRatio(0.5)));
    assert_eq!(Lame::<f32>::from_young_poisson(1.0, -1.0), Err(MaterialError::PoissonRatio(-1.0)));
    assert!(matches!(Lame::<f32>::from_young_poisson(1.0, f64::NAN), Err(MaterialError::PoissonRatio(_))));
    assert_eq!(Lame::<f64>::new(0.0, 1.0), Err(MaterialError::ShearModulus(0.0)));
    assert_eq!(Lame::<f64>::new(3.0, -2.5), Err(MaterialError::FirstLame { lambda: -2.5, mu: 3.0 }));
    assert!(matches!(Lame::<f64>::new(3.0, f64::INFINITY), Err(MaterialError::FirstLame { .. })));
    assert!(Lame::<f64>::new(3.0, -1.9).is_ok());
    let msg = MaterialError::PoissonRatio(0.7).to_string();
    assert!(msg.contains("nu = 0.7"), "{msg}");
    let s = Lame { mu: 2.0, lambda: 3.0 }.scaled(0.5);
    assert_eq!(s, Lame { mu: 1.0, lambda: 1.5 });
}

#[test]
fn svd_3d_wrapper_reconstructs() {
    let mut rng = ChaCha8Rng::seed_from_u64(16);
    for kind in KINDS {
        let f = sample::<3>(kind, &mut rng);
        let s = svd(&f);
        assert!((s.u * Mat::from_diagonal(&s.sigma) * s.v.transpose() - f).norm() <= 1e-13 * f.norm());
        assert!(s.sigma[0] >= s.sigma[1] && s.sigma[1] >= s.sigma[2].abs());
    }
}

#[test]
fn combined_evaluation_matches_separate_calls() {
    fn run<M: AllImpls>(m: M, name: &str) {
        let lame = lame64();
        let mut rng = ChaCha8Rng::seed_from_u64(17);
        for kind in [Kind::General, Kind::Stretch, Kind::Rotation] {
            let f = sample::<3>(kind, &mut rng);
            let (e, p, t) = m.energy_pk1_dpdf(&lame, &f);
            assert_eq!(e, m.energy(&lame, &f), "{name}");
            assert_eq!(p, m.pk1(&lame, &f), "{name}");
            assert_eq!(t, m.dpdf(&lame, &f), "{name}");
        }
    }
    per_model!(run);
}

/// `|a - b| / |b|` over the flattened tensors (`|a - b|` itself when `b = 0`).
fn tangent_rel_diff<const D: usize>(a: &Tangent<f64, D>, b: &Tangent<f64, D>) -> f64 {
    let mut diff = Tangent::<f64, D>::zeros();
    for k in 0..D {
        for l in 0..D {
            diff.d[k][l] = a.d[k][l] - b.d[k][l];
        }
    }
    // `dP/dF(0) = 0` in 3D: there the difference itself must vanish.
    diff.norm() / b.norm().max(f64::MIN_POSITIVE)
}

/// Stable Neo-Hookean deformation gradients beyond [`KINDS`]: repeated and sign-paired singular
/// values (`sigma_i = -sigma_j`, where the corotated tangents are singular but this model is
/// smooth), two tiny singular values and `F = 0`.
fn snh_special<const D: usize>(rng: &mut ChaCha8Rng) -> Vec<Mat<f64, D>> {
    let mut out = Vec::new();
    let diag = |v: [f64; 3]| Mat::<f64, D>::from_fn(|i, j| if i == j { v[i] } else { 0.0 });
    for v in [
        [1.3, 1.3, 1.3],
        [0.7, 0.7, 0.7],
        [1.0, 1.0, 1.0],
        [1.5, 0.8, -0.8],
        [0.9, 0.9, -0.9],
        [1.2, -1.2, 0.5],
        [1e-3, 1e-3, 1e-3],
        [1.1, 1e-3, 1e-3],
        [1.1, 1e-3, -1e-3],
        [0.0, 0.0, 0.0],
        [2.0, 2.0, 0.3],
        [-0.5, 1.0, 1.0],
    ] {
        let (r1, r2) = (rotation::<D>(rng), rotation::<D>(rng));
        out.push(r1 * diag(v) * r2.transpose());
        out.push(diag(v));
    }
    out
}

/// Stable Neo-Hookean: the analytic eigensystem (Smith, de Goes & Kim 2019) without clamping
/// rebuilds the invariant-based `dP/dF`, its eigenvalues are those of the flattened tensor, and
/// its clamped version ([`Hyperelastic::dpdf_psd`]) equals the numerical eigenvalue clamping.
#[test]
fn stable_neo_hookean_analytic_projection() {
    use crate::models::principal::{self, PrincipalEnergy};
    fn one<const D: usize>(f: &Mat<f64, D>, label: &str, worst: &mut [f64; 2]) {
        let lame = lame64();
        let p = StableNeoHookean::params::<f64, D>(&lame);
        let direct = StableNeoHookean.dpdf(&lame, f);
        // The energy and stress in the singular values agree with the invariant-based ones.
        let psi = PrincipalEnergy::<f64, D>::psi_hat(&StableNeoHookean, p.mu, p.lambda, &svd(f).sigma);
        let psi_ref = StableNeoHookean.energy(&lame, f);
        assert!(
            (psi - psi_ref).abs() <= 1e-10 * (1.0 + psi_ref.abs()),
            "{D}D {label}: psi {psi} vs {psi_ref}"
        );
        let pk = principal::pk1(&StableNeoHookean, p.mu, p.lambda, f);
        let pk_ref = StableNeoHookean.pk1(&lame, f);
        assert!(
            (pk - pk_ref).norm() <= 1e-10 * (lame.mu + pk_ref.norm()),
            "{D}D {label}: P {pk} vs {pk_ref}"
        );
        let rebuilt = principal::dpdf(&StableNeoHookean, p.mu, p.lambda, f);
        let e = tangent_rel_diff(&rebuilt, &direct);
        assert!(e <= 1e-10, "{D}D {label}: eigensystem reconstruction off by {e:e}, F = {f}");
        let analytic = StableNeoHookean.dpdf_psd(&lame, f);
        let numerical = direct.project_psd();
        let e2 = tangent_rel_diff(&analytic, &numerical);
        assert!(e2 <= 1e-9, "{D}D {label}: analytic projection off by {e2:e}, F = {f}");
        worst[0] = worst[0].max(e);
        worst[1] = worst[1].max(e2);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(29);
    let mut worst = [0.0f64; 2];
    for kind in KINDS {
        for _ in 0..20 {
            one::<3>(&sample::<3>(kind, &mut rng), &format!("{kind:?}"), &mut worst);
            one::<2>(&sample::<2>(kind, &mut rng), &format!("{kind:?}"), &mut worst);
        }
    }
    for f in snh_special::<3>(&mut rng) {
        one::<3>(&f, "special", &mut worst);
    }
    for f in snh_special::<2>(&mut rng) {
        one::<2>(&f, "special", &mut worst);
    }
    // The clamping must have mattered: some samples are indefinite.
    let lame = lame64();
    let inverted = Mat::<f64, 3>::from_diagonal(&Vector3::new(1.5, 1.2, -0.4));
    let h = StableNeoHookean.dpdf(&lame, &inverted).to_matrix();
    assert!(h.symmetric_eigenvalues().min() < -1e-3 * h.norm());
    // The eigenvalues: twist and flip per pair and the eigenvalues of the 3x3 Hessian of
    // psi_hat are exactly the spectrum of the flattened 9x9 tangent.
    for kind in KINDS {
        for _ in 0..10 {
            let f = sample::<3>(kind, &mut rng);
            let p = StableNeoHookean::params::<f64, 3>(&lame);
            let s = svd(&f).sigma;
            let m = &StableNeoHookean;
            let mut analytic: Vec<f64> = Vec::new();
            for (i, j) in [(0, 1), (0, 2), (1, 2)] {
                analytic.push(PrincipalEnergy::<f64, 3>::twist(m, p.mu, p.lambda, &s, i, j));
                analytic.push(PrincipalEnergy::<f64, 3>::flip(m, p.mu, p.lambda, &s, i, j));
            }
            let hess = PrincipalEnergy::<f64, 3>::hessian(m, p.mu, p.lambda, &s);
            analytic.extend(hess.symmetric_eigenvalues().iter());
            analytic.sort_by(f64::total_cmp);
            let h = StableNeoHookean.dpdf(&lame, &f).to_matrix();
            let mut numerical: Vec<f64> = h.symmetric_eigenvalues().iter().copied().collect();
            numerical.sort_by(f64::total_cmp);
            for (a, n) in analytic.iter().zip(&numerical) {
                assert!((a - n).abs() <= 1e-10 * h.norm(), "{kind:?}: eigenvalue {a} vs {n}");
            }
        }
    }
    // f32 follows f64 to single-precision rounding of the tangent's scale.
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let lame32 = Lame::<f32> { mu: lame.mu as f32, lambda: lame.lambda as f32 };
    for kind in KINDS {
        for _ in 0..10 {
            let f = sample::<3>(kind, &mut rng).map(|x| x as f32);
            let a32 = StableNeoHookean.dpdf_psd(&lame32, &f).to_matrix().map(f64::from);
            let a64 = StableNeoHookean.dpdf_psd(&lame, &f.map(f64::from)).to_matrix();
            let e = (a32 - a64).norm() / a64.norm();
            assert!(e <= 1e-4, "f32 {kind:?}: {e:e}");
        }
    }
    eprintln!("stable Neo-Hookean: reconstruction {:.2e}, projection {:.2e}", worst[0], worst[1]);
}
