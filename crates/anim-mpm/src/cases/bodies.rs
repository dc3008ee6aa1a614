//! Elastic bodies: a block resting on the floor for 10 s and two colliding disks.

use super::CRATE;
use crate::scenes::fill;
use crate::{Boundary, Elastic, Material, MpmError, MpmParams, MpmSimulation, Particles, Transfer};
use anim_core::cases::{Check, Ctx, Judge};

// ---------------------------------------------------------------------------------------------
// Resting block.

/// A 2D elastic block resting on the floor for 10 s: drift of the centroid (mean over the
/// second second against the mean over the last second), its largest excursion after settling,
/// and the particle speeds in the last second.
pub(super) fn resting_block(ctx: &Ctx) -> Vec<Check> {
    let n = if ctx.quick { 64 } else { 128 };
    let result = (|| -> Result<(f64, f64, f64, f64), MpmError> {
        let mut params = MpmParams::with_resolution(n);
        params.wall = Boundary::Sticky;
        let h = params.h();
        // Stiff enough that the static sag rho g H^2 / (2 E) = 2e-4 m stays far below a cell.
        let mat =
            Material::Elastic(Elastic { young: 1e6, poisson: 0.3, density: 1000.0, ..Elastic::default() });
        let mut sim = MpmSimulation::<2>::new(params, vec![mat])?;
        let mut p = Particles::<2>::new();
        // The floor's sticky nodes are y < 3h; the block sits on them.
        let y0 = 3.0 * h;
        fill(&mut p, h, 2, [0.4, y0], [0.6, y0 + 0.2], 0, 1000.0, [0.0; 2], |_| true)?;
        let dt = 5e-4;
        let centroid = |p: &Particles<2>| {
            let (mut cx, mut cy) = (0.0, 0.0);
            for i in 0..p.len() {
                cx += f64::from(p.x[2 * i]);
                cy += f64::from(p.x[2 * i + 1]);
            }
            (cx / p.len() as f64, cy / p.len() as f64)
        };
        let per_second = (1.0 / dt) as usize;
        let steps = 10 * per_second;
        let (mut early, mut late) = ((0.0, 0.0), (0.0, 0.0));
        let mut samples = vec![];
        let mut max_speed_late: f64 = 0.0;
        for s in 0..steps {
            sim.advance(&mut p, dt)?;
            let c = centroid(&p);
            if s >= per_second {
                samples.push(c);
            }
            if (per_second..2 * per_second).contains(&s) {
                early.0 += c.0 / per_second as f64;
                early.1 += c.1 / per_second as f64;
            }
            if s >= steps - per_second {
                late.0 += c.0 / per_second as f64;
                late.1 += c.1 / per_second as f64;
                for i in 0..p.len() {
                    max_speed_late = max_speed_late.max(f64::from(p.velocity(i).norm()));
                }
            }
        }
        let drift = ((late.0 - early.0).powi(2) + (late.1 - early.1).powi(2)).sqrt();
        let max_dev = samples
            .iter()
            .map(|c| ((c.0 - early.0).powi(2) + (c.1 - early.1).powi(2)).sqrt())
            .fold(0.0, f64::max);
        Ok((drift / h, max_dev / h, max_speed_late, late.1))
    })();
    let (drift, dev, speed, _) = result.unwrap_or((f64::NAN, f64::NAN, f64::NAN, f64::NAN));
    let case = format!("0.2 m elastic block (E 1e6, nu 0.3) on a sticky floor, {n}^2, MLS, 10 s");
    vec![
        Check {
            crate_name: CRATE,
            case: case.clone(),
            metric: "centroid drift, mean over 9-10 s vs 1-2 s (cells)".into(),
            measured: drift,
            reference: 0.0,
            tolerance: 0.01,
            judge: Judge::AtMost,
            source: "a body at rest stays at rest",
        },
        Check {
            crate_name: CRATE,
            case: case.clone(),
            metric: "max centroid excursion from its 1-2 s mean after t = 1 s (cells)".into(),
            measured: dev,
            reference: 0.0,
            tolerance: 0.05,
            judge: Judge::AtMost,
            source: "no jitter above 0.05 cell",
        },
        Check {
            crate_name: CRATE,
            case,
            metric: "max particle speed in the last second (m/s)".into(),
            measured: speed,
            reference: 0.0,
            tolerance: 0.01,
            judge: Judge::AtMost,
            source: "no jitter above 1 cm/s",
        },
    ]
}

// ---------------------------------------------------------------------------------------------
// Colliding disks.

pub(super) fn colliding_disks(ctx: &Ctx) -> Vec<Check> {
    let n = if ctx.quick { 64 } else { 128 };
    let mut checks = vec![];
    for transfer in [Transfer::Mls, Transfer::Apic] {
        let result = (|| -> Result<(f64, f64, f64, f64, f64), MpmError> {
            let mut params = MpmParams::with_resolution(n);
            params.gravity = [0.0; 3];
            params.transfer = transfer;
            let h = params.h();
            let mat = Material::Elastic(Elastic {
                young: 1e4,
                poisson: 0.3,
                density: 1000.0,
                ..Elastic::default()
            });
            let mut sim = MpmSimulation::<2>::new(params, vec![mat, mat])?;
            let mut p = Particles::<2>::new();
            let v0 = 0.5f32;
            let r = 0.1;
            for (k, (cx, v)) in [(0.3, v0), (0.7, -v0)].into_iter().enumerate() {
                fill(&mut p, h, 2, [cx - r, 0.5 - r], [cx + r, 0.5 + r], k as u16, 1000.0, [v, 0.0], |x| {
                    (x[0] - cx).powi(2) + (x[1] - 0.5).powi(2) <= r * r
                })?;
            }
            let e0 = sim.totals(&p);
            let energy0 = e0.kinetic + e0.elastic;
            let dt = 5e-4;
            // Closing speed 1 m/s over a gap of 0.2 m: contact from 0.2 s to about 0.5 s; run to
            // 0.8 s, before the disks reach the walls.
            let mut min_energy = energy0;
            for _ in 0..(0.8 / dt) as usize {
                sim.advance(&mut p, dt)?;
                let t = sim.totals(&p);
                min_energy = min_energy.min(t.kinetic + t.elastic);
            }
            let t = sim.totals(&p);
            let mut vx = [0.0f64; 2];
            let mut mass = [0.0f64; 2];
            for i in 0..p.len() {
                let k = usize::from(p.material[i]);
                vx[k] += f64::from(p.mass[i]) * f64::from(p.v[2 * i]);
                mass[k] += f64::from(p.mass[i]);
            }
            let (v_left, v_right) = (vx[0] / mass[0], vx[1] / mass[1]);
            let p_scale = e0.mass * f64::from(v0);
            Ok((
                v_left / f64::from(v0),
                v_right / -f64::from(v0),
                (t.kinetic + t.elastic) / energy0,
                t.momentum[0].abs() / p_scale,
                min_energy / energy0,
            ))
        })();
        let (vl, vr, e_ratio, mom, e_min) =
            result.unwrap_or((f64::NAN, f64::NAN, f64::NAN, f64::NAN, f64::NAN));
        let case = format!("two elastic disks (r 0.1, E 1e4) at +-0.5 m/s, {n}^2, {transfer:?}, 0.8 s");
        let push =
            |checks: &mut Vec<Check>, metric: &str, measured: f64, tolerance: f64, judge: Judge, source| {
                checks.push(Check {
                    crate_name: CRATE,
                    case: case.clone(),
                    metric: metric.into(),
                    measured,
                    reference: 0.0,
                    tolerance,
                    judge,
                    source,
                })
            };
        push(
            &mut checks,
            "left disk velocity after / before (bounced back: < 0)",
            vl,
            -0.1,
            Judge::AtMost,
            "Sulsky et al. 1994: the disks separate",
        );
        push(
            &mut checks,
            "right disk velocity after / before (bounced back: < 0)",
            vr,
            -0.1,
            Judge::AtMost,
            "Sulsky et al. 1994: the disks separate",
        );
        push(
            &mut checks,
            "total energy at 0.8 s / initial (no energy gain)",
            e_ratio,
            1.0 + 1e-3,
            Judge::AtMost,
            "energy is conserved or dissipated, never created",
        );
        push(
            &mut checks,
            "minimum total energy / initial during the run (reported)",
            e_min,
            0.0,
            Judge::AtLeast,
            "report: dissipation of the transfers during contact",
        );
        push(
            &mut checks,
            "|total x momentum| / (M v0)",
            mom,
            1e-5,
            Judge::AtMost,
            "no external force: momentum conserved to f32 round-off",
        );
    }
    checks
}
