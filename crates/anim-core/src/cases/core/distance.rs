//! Work-precision of the distance field of a triangle-mesh obstacle: the cell against the
//! error of the interpolated signed distance near a sphere mesh and the time to build the
//! field and answer a batch of queries.

use crate::cases::{Ctx, Point, Series, StudyResult, median_seconds, nan_max};
use crate::surface::{ClosedSurface, DistanceField, SurfaceError, icosphere};
use glam::DVec3;

/// Probe points in the shell `0.9 <= |x| <= 1.1` around the unit sphere, spread by the golden
/// angle (deterministic).
fn probes(count: usize) -> Vec<DVec3> {
    (0..count)
        .map(|n| {
            let t = n as f64 + 0.5;
            let z = 1.0 - 2.0 * t / count as f64;
            let a = t * 2.399_963_229_728_653;
            let r = 0.9 + 0.2 * ((n * 7919) % 1000) as f64 / 999.0;
            DVec3::new(a.cos() * (1.0 - z * z).sqrt(), a.sin() * (1.0 - z * z).sqrt(), z) * r
        })
        .collect()
}

/// The unit icosphere of `levels` subdivisions, `count` probes and the exact signed distance of
/// each to the polyhedron (its closest triangle by brute force, the sign of the winding number).
fn problem(levels: usize, count: usize) -> Result<(ClosedSurface, Vec<DVec3>, Vec<f64>), SurfaceError> {
    let (p, t) = icosphere(levels);
    let surface = ClosedSurface::new(p, t)?;
    let probes = probes(count);
    let exact = probes
        .iter()
        .map(|&x| {
            let d = (surface.closest_point(x) - x).length();
            if surface.contains(x.to_array()) { -d } else { d }
        })
        .collect();
    Ok((surface, probes, exact))
}

/// The largest error of the field of cell `cell` over the probes; NaN when the field cannot be
/// built or misses a probe (a failed measurement).
fn error(surface: &ClosedSurface, probes: &[DVec3], exact: &[f64], cell: f64) -> f64 {
    let Ok(field) = DistanceField::around(surface, cell, 0.3) else {
        return f64::NAN;
    };
    probes
        .iter()
        .zip(exact)
        .map(|(&x, &e)| field.sample(x).map_or(f64::NAN, |s| (s.distance - e).abs()))
        .fold(0.0, nan_max)
}

/// The study: an icosphere of unit radius (2,560 triangles quick, 10,240 full), its field at
/// cells from 0.2 down; the error is the largest difference, over the probes, between the
/// interpolated distance and the exact signed distance to the same polyhedron; the time is
/// building the field over the sphere's bounds widened by 0.3 plus one query per probe. A
/// surface that failed its check (never, for an icosphere) leaves the curve empty.
pub(super) fn distance_field_study(ctx: &Ctx) -> StudyResult {
    let (levels, count, cells) = if ctx.quick {
        (4, 400, vec![0.2, 0.1, 0.05])
    } else {
        (5, 2000, vec![0.2, 0.1, 0.05, 0.025, 0.0125])
    };
    let (batches, min_batch) = if ctx.quick { (3, 0.0) } else { (5, 0.05) };
    let points = match problem(levels, count) {
        Ok((surface, probes, exact)) => cells
            .into_iter()
            .map(|cell| {
                let error = error(&surface, &probes, &exact, cell);
                let seconds = median_seconds(batches, min_batch, || {
                    if let Ok(field) = DistanceField::around(&surface, cell, 0.3) {
                        let sum: f64 =
                            probes.iter().filter_map(|&x| field.sample(x)).map(|s| s.distance).sum();
                        std::hint::black_box(sum);
                    }
                });
                Point { param: cell, seconds, error }
            })
            .collect(),
        Err(_) => Vec::new(),
    };
    StudyResult {
        title: format!(
            "Distance field of a sphere mesh ({} triangles): interpolation error near the surface \
             against the time to build the field and answer {count} queries",
            20 << (2 * levels)
        ),
        slug: "core-distance-field".into(),
        error_label: "max |phi - exact| within 0.1 of the surface (m, radius 1)".into(),
        param_label: "cell".into(),
        series: vec![Series { label: "trilinear distance field".into(), points }],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quick study's error falls with the cell, at about second order (the sphere is
    /// smooth on the scale of the cells), and stays below the cell squared.
    #[test]
    fn the_error_falls_with_the_cell() {
        let (surface, probes, exact) = problem(4, 400).unwrap();
        let errors: Vec<f64> =
            [0.2, 0.1, 0.05].iter().map(|&c| error(&surface, &probes, &exact, c)).collect();
        for pair in errors.windows(2) {
            assert!(pair[1] < 0.5 * pair[0], "{errors:?}");
        }
        assert!(errors.iter().zip([0.2, 0.1, 0.05]).all(|(e, c)| *e < c * c), "{errors:?}");
    }
}
