//! Tests of the pressure solvers: relabelling, agreement of the methods, the Jacobi iteration
//! against a textbook one, multigrid's resolution independence and thread-count independence.

use super::*;
use crate::error::FluidError;

fn box_problem(n: usize, dim: usize, open_top: bool) -> Poisson {
    let dims = if dim == 2 { [n, n, 1] } else { [n, n, n] };
    let cells = dims[0] * dims[1] * dims[2];
    let mut labels = vec![CellLabel::Fluid; cells];
    // A solid block in the middle.
    for k in 0..dims[2] {
        for j in n / 3..n / 2 {
            for i in n / 3..n / 2 {
                labels[i + n * (j + n * k)] = CellLabel::Solid;
            }
        }
    }
    let mut open = [[false; 2]; 3];
    open[1][1] = open_top;
    Poisson::new(dims, dim, labels, open).unwrap()
}

fn rhs(op: &Poisson) -> Vec<f64> {
    (0..op.len()).map(|c| ((c * 7919) % 97) as f64 / 97.0 - 0.5).collect()
}

/// Labels of a free-surface problem on `dims`: solid border, fluid below `level` cells
/// (shifted by `tilt` per column), air above.
fn pool(dims: [usize; 3], level: usize, tilt: usize) -> Vec<CellLabel> {
    let mut labels = vec![CellLabel::Air; dims[0] * dims[1] * dims[2]];
    for (c, l) in labels.iter_mut().enumerate() {
        let (i, j, k) = (c % dims[0], (c / dims[0]) % dims[1], c / (dims[0] * dims[1]));
        let border = |x: usize, n: usize| n > 1 && (x == 0 || x + 1 == n);
        if border(i, dims[0]) || border(j, dims[1]) || border(k, dims[2]) {
            *l = CellLabel::Solid;
        } else if j < level + (i * tilt) / dims[0] {
            *l = CellLabel::Fluid;
        }
    }
    labels
}

/// A solver relabelled in place is the solver built for the new labels: every method gives
/// the same solution, bit for bit, and the operators are equal.
#[test]
fn relabelling_in_place_equals_building_anew() {
    for dims in [[20, 17, 1], [9, 10, 8]] {
        let dim = if dims[2] == 1 { 2 } else { 3 };
        let (first, second) = (pool(dims, 6, 0), pool(dims, 4, 5));
        for method in PressureMethod::ALL {
            let op = Poisson::new(dims, dim, first.clone(), [[false; 2]; 3]).unwrap();
            let mut reused = PressureSolver::new(op, method, 1e-9, 5000).unwrap();
            let b = rhs(reused.operator());
            let mut s = vec![0.0; b.len()];
            reused.solve(&b, &mut s);
            reused.relabel(&second).unwrap();
            let op = Poisson::new(dims, dim, second.clone(), [[false; 2]; 3]).unwrap();
            let mut fresh = PressureSolver::new(op, method, 1e-9, 5000).unwrap();
            assert_eq!(reused.levels(), fresh.levels());
            for (a, f) in reused.levels.iter().zip(&fresh.levels) {
                assert_eq!(
                    (&a.op.labels, &a.op.diag, &a.op.fluid_nbrs),
                    (&f.op.labels, &f.op.diag, &f.op.fluid_nbrs)
                );
                assert_eq!(a.op.singular, f.op.singular);
            }
            let (mut x, mut y) = (vec![0.0; b.len()], vec![0.0; b.len()]);
            let (i, j) = (reused.solve(&b, &mut x), fresh.solve(&b, &mut y));
            assert!(i.converged && i.iterations > 0, "{method:?} {dims:?}: {i:?}");
            assert_eq!(i, j, "{method:?} {dims:?}");
            assert!(x.iter().zip(&y).all(|(p, q)| p.to_bits() == q.to_bits()), "{method:?} {dims:?}");
        }
    }
    let mut op = box_problem(8, 2, true);
    let before = op.labels().to_vec();
    assert!(matches!(op.relabel(&before[1..]), Err(FluidError::BadLength { got: 63, expected: 64, .. })));
    assert_eq!(op.labels(), before);
}

/// Every method solves the same system: the residual it reports is the true one, and the
/// solutions agree with each other.
#[test]
fn all_methods_reach_tolerance_and_agree() {
    for (dim, n) in [(2, 24), (3, 10)] {
        for open_top in [false, true] {
            let op = box_problem(n, dim, open_top);
            let b = rhs(&op);
            let mut reference: Option<Vec<f64>> = None;
            for method in [
                PressureMethod::ConjugateGradient,
                PressureMethod::Mgpcg,
                PressureMethod::RedBlackGaussSeidel,
                PressureMethod::Jacobi,
            ] {
                let mut solver = PressureSolver::new(op.clone(), method, 1e-9, 200_000).unwrap();
                let mut s = vec![0.0; op.len()];
                let info = solver.solve(&b, &mut s);
                assert!(info.converged && info.residual <= 1e-9, "{method:?} dim {dim}: {info:?}");
                // Independent residual check.
                let mut bb = b.clone();
                for (c, v) in bb.iter_mut().enumerate() {
                    if op.diag[c] == 0.0 {
                        *v = 0.0;
                    }
                }
                if op.singular {
                    let fluid: Vec<usize> = (0..op.len()).filter(|&c| op.diag[c] > 0.0).collect();
                    let mean = fluid.iter().map(|&c| bb[c]).sum::<f64>() / fluid.len() as f64;
                    fluid.iter().for_each(|&c| bb[c] -= mean);
                }
                let mut y = vec![0.0; op.len()];
                op.apply(&s, &mut y);
                let bmax = bb.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let rmax = y.iter().zip(&bb).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                assert!(rmax / bmax <= 1.01e-9, "{method:?}: {}", rmax / bmax);
                match &reference {
                    None => reference = Some(s),
                    Some(r) => {
                        let d = r.iter().zip(&s).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                        assert!(d < 1e-5, "{method:?} differs from CG by {d}");
                    }
                }
            }
        }
    }
}

/// A fixed number of Jacobi sweeps, odd or even (the solver sweeps in pairs), matches a
/// textbook damped Jacobi written out here cell by cell from the labels.
#[test]
fn jacobi_sweeps_match_a_textbook_iteration() {
    for open_top in [false, true] {
        let n = 12;
        let op = box_problem(n, 2, open_top);
        let labels = op.labels().to_vec();
        let fluid = |i: isize, j: isize| -> Option<CellLabel> {
            if i < 0 || j < 0 || i >= n as isize {
                return Some(CellLabel::Solid);
            }
            if j >= n as isize {
                return Some(if open_top { CellLabel::Air } else { CellLabel::Solid });
            }
            Some(labels[i as usize + n * j as usize])
        };
        let mut b = rhs(&op);
        let cells: Vec<usize> = (0..op.len()).filter(|&c| labels[c] == CellLabel::Fluid).collect();
        let mean = |x: &[f64]| cells.iter().map(|&c| x[c]).sum::<f64>() / cells.len() as f64;
        for (c, v) in b.iter_mut().enumerate() {
            if labels[c] != CellLabel::Fluid {
                *v = 0.0;
            }
        }
        if !open_top {
            let m = mean(&b);
            cells.iter().for_each(|&c| b[c] -= m);
        }
        for sweeps in 1..=7 {
            let mut x = vec![0.0; op.len()];
            for _ in 0..sweeps {
                let mut next = vec![0.0; op.len()];
                for &c in &cells {
                    let (i, j) = ((c % n) as isize, (c / n) as isize);
                    let (mut diag, mut sum) = (0.0, 0.0);
                    for (di, dj) in [(-1, 0), (1, 0), (0, -1), (0, 1)] {
                        match fluid(i + di, j + dj) {
                            Some(CellLabel::Fluid) => {
                                diag += 1.0;
                                sum += x[(i + di) as usize + n * (j + dj) as usize];
                            }
                            Some(CellLabel::Air) => diag += 1.0,
                            _ => {}
                        }
                    }
                    next[c] = (1.0 - JACOBI_WEIGHT) * x[c] + JACOBI_WEIGHT * (b[c] + sum) / diag;
                }
                x = next;
            }
            if !open_top {
                let m = mean(&x);
                cells.iter().for_each(|&c| x[c] -= m);
            }
            let mut solver = PressureSolver::new(op.clone(), PressureMethod::Jacobi, 0.0, sweeps).unwrap();
            let mut s = vec![0.0; op.len()];
            let info = solver.solve(&rhs(&op), &mut s);
            assert_eq!(info.iterations, sweeps);
            let d = s.iter().zip(&x).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(d < 1e-13, "{sweeps} sweeps, open top {open_top}: differs by {d}");
        }
    }
}

#[test]
fn mgpcg_iterations_nearly_independent_of_resolution() {
    let mut its = Vec::new();
    for n in [32, 64, 128] {
        let op = box_problem(n, 2, false);
        let b = rhs(&op);
        let mut solver = PressureSolver::new(op, PressureMethod::Mgpcg, 1e-8, 1000).unwrap();
        let mut s = vec![0.0; b.len()];
        its.push(solver.solve(&b, &mut s).iterations);
    }
    assert!(its[2] <= its[0] * 2, "{its:?}");
}

#[test]
fn bitwise_identical_across_thread_counts() {
    let op = box_problem(40, 2, true);
    let b = rhs(&op);
    let run = |threads: usize, method| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut solver = PressureSolver::new(op.clone(), method, 1e-10, 10_000).unwrap();
            let mut s = vec![0.0; b.len()];
            solver.solve(&b, &mut s);
            s.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        })
    };
    for method in PressureMethod::ALL {
        assert_eq!(run(1, method), run(3, method), "{method:?}");
    }
}

#[test]
fn rejects_bad_labels() {
    assert!(matches!(
        Poisson::new([4, 4, 1], 2, vec![CellLabel::Fluid; 15], [[false; 2]; 3]),
        Err(FluidError::BadLength { .. })
    ));
    assert!(matches!(Poisson::new([0, 4, 1], 2, vec![], [[false; 2]; 3]), Err(FluidError::BadGrid { .. })));
}
