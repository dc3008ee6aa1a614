//! Lines (5) and (7) of the loop: the external forces, then the predicted positions,
//!
//! ```text
//! (5)  v_i <- v_i + h w_i f_ext(x_i)          f_ext = m_i g + user force + wind
//! (7)  p_i <- x_i + h v_i
//! ```
//!
//! which together are XPBD's prediction `x~ = x^n + h v^n + h^2 M^-1 f_ext` (Macklin et al. 2016). Pinned
//! particles (`w_i = 0`) keep their velocity. The wind acts on the model's triangles as a drag
//! along each face normal, `f = drag A ((v_wind - u) . n) n` with `A` the area, `n` the normal
//! and `u` the mean velocity of the corners, the wind's speed modulated by `1 + gust sin(pi t)`;
//! each corner takes a third of its faces' forces, summed in the fixed order of the triangle
//! incidence list. Before them, the kinematic bodies are placed at their poses for the substep.

use super::parallel::for_each_chunk;
use super::scratch::Data;
use crate::model::PbdModel;
use anim_core::glam::DVec3;

/// The kinematic bodies' poses at the start and the end of substep `k` of `s`: linear between
/// their poses at the start and the end of the step.
pub(super) fn place_bodies(model: &PbdModel, d: &mut Data, k: usize, s: usize) {
    for b in 0..model.bodies.len() {
        d.pose_sub_prev[b] = d.pose_start[b].lerp(&d.pose_end[b], k as f64 / s as f64);
        d.pose_sub[b] = d.pose_start[b].lerp(&d.pose_end[b], (k + 1) as f64 / s as f64);
    }
}

/// Line (5) at time `t`: gravity, the user forces `forces` (per particle) and the wind change the
/// free particles' velocities over `h`.
pub(super) fn apply_external_forces(model: &PbdModel, d: &mut Data, forces: &[DVec3], t: f64, h: f64) {
    let wind = model.wind.is_some();
    if let Some(wnd) = model.wind {
        let speed = 1.0 + wnd.gust * (std::f64::consts::TAU * 0.5 * t).sin();
        let wv = DVec3::from_array(wnd.velocity) * speed;
        let (x, v) = (&d.x, &d.v);
        let tri = &model.triangles;
        for_each_chunk(&mut d.tri_force, |first, out| {
            for (m, f) in out.iter_mut().enumerate() {
                let [a, b, c] = tri[first + m];
                let nrm = (x[b] - x[a]).cross(x[c] - x[a]);
                let twice = nrm.length();
                *f = if twice > 0.0 {
                    let nh = nrm / twice;
                    let u = (v[a] + v[b] + v[c]) / 3.0;
                    nh * (wnd.drag * 0.5 * twice * (wv - u).dot(nh))
                } else {
                    DVec3::ZERO
                };
            }
        });
        let tf = &d.tri_force;
        for_each_chunk(&mut d.ext, |first, out| {
            for (m, e) in out.iter_mut().enumerate() {
                let i = first + m;
                let mut f = DVec3::ZERO;
                for &tk in &model.tri_inc[model.tri_ptr[i]..model.tri_ptr[i + 1]] {
                    f += tf[tk as usize];
                }
                *e = f / 3.0;
            }
        });
    }
    let g = model.gravity;
    let (w, forces, ext) = (&model.inv_mass, forces, &d.ext);
    for_each_chunk(&mut d.v, |first, out| {
        for (m, v) in out.iter_mut().enumerate() {
            let i = first + m;
            if w[i] > 0.0 {
                let f = if wind { forces[i] + ext[i] } else { forces[i] };
                *v += h * (g + w[i] * f);
            }
        }
    });
}

/// Line (7): `p <- x + h v`.
pub(super) fn predict_positions(d: &mut Data, h: f64) {
    let (x, v) = (&d.x, &d.v);
    for_each_chunk(&mut d.p, |first, out| {
        for (m, p) in out.iter_mut().enumerate() {
            let i = first + m;
            *p = x[i] + h * v[i];
        }
    });
}
