//! Study: the twisted cylinder rebound to chains of 2 to 33 twist joints, skinned by LBS and DQS
//! at three mesh sizes, shape error against the exact twist against the time of one skinning
//! pass.

use crate::{SkinError, Skinned, SkinnedMesh, SkinningMethod, scenes, skin};
use anim_core::cases::{Ctx, Point, Series, StudyResult, median_seconds};
use anim_core::glam::{DMat4, DQuat, DVec3};

/// The twist of the study: 180 degrees, the end pose of `scenes::twisted_cylinder`.
const TWIST: f64 = std::f64::consts::PI;

/// The exact twist's parameter along the axis: `scenes::twisted_cylinder` blends its two joints
/// linearly over `0.5 <= x <= 1.5` (its documented weight ramp), so the twist angle of the cross
/// section at `x` is `TWIST * ramp(x)`.
fn ramp(x: f64) -> f64 {
    (x - 0.5).clamp(0.0, 1.0)
}

/// The twisted cylinder's rest mesh rebound to a chain of `joints` twist joints spread evenly
/// over the blend span: joint `k` sits at `ramp = k / (joints - 1)` and is posed at its share
/// `TWIST k / (joints - 1)` of the twist (about the cylinder's axis, like the scene's joint 1);
/// each vertex is weighted linearly between the two joints around its `ramp` (the scene's
/// weights when `joints = 2`). Also the exact twist of every vertex and the cylinder radius.
struct TwistRig {
    mesh: SkinnedMesh,
    matrices: Vec<DMat4>,
    exact: Vec<DVec3>,
    radius: f64,
}

fn twist_rig(segments: usize, joints: usize) -> Result<TwistRig, SkinError> {
    if joints < 2 {
        return Err(SkinError::BadMesh(format!("a twist chain needs 2 or more joints, got {joints}")));
    }
    let scene = scenes::twisted_cylinder(Some(segments))?;
    let Some(rest) = scene.character.meshes.first().map(|m| &m.mesh) else {
        return Err(SkinError::BadMesh("the twisted cylinder has no mesh".into()));
    };
    let n = rest.len();
    let pos: Vec<[f64; 3]> = (0..n).map(|v| rest.rest_position(v)).collect();
    let normals: Vec<[f64; 3]> = (0..n).map(|v| [rest.nx[v], rest.ny[v], rest.nz[v]]).collect();
    let spans = joints - 1;
    let (mut js, mut ws) = (Vec::with_capacity(2 * n), Vec::with_capacity(2 * n));
    for p in &pos {
        let u = ramp(p[0]) * spans as f64;
        let k = (u.floor() as usize).min(spans - 1);
        let f = u - k as f64;
        js.extend([k as u16, k as u16 + 1]);
        ws.extend([1.0 - f, f]);
    }
    let mesh = SkinnedMesh::new(&pos, Some(&normals), 2, &js, &ws, rest.triangles().to_vec(), joints)?;
    let matrices = (0..joints).map(|k| DMat4::from_rotation_x(TWIST * k as f64 / spans as f64)).collect();
    let exact =
        pos.iter().map(|p| DQuat::from_rotation_x(TWIST * ramp(p[0])) * DVec3::from_array(*p)).collect();
    let radius = pos.iter().map(|p| p[1].hypot(p[2])).fold(0.0, f64::max);
    Ok(TwistRig { mesh, matrices, exact, radius })
}

/// Largest distance of a skinned vertex from its exact twisted position, over the radius.
fn twist_error(rig: &TwistRig, out: &Skinned) -> f64 {
    rig.exact
        .iter()
        .enumerate()
        .map(|(v, e)| (DVec3::from_array(out.position(v)) - *e).length())
        .fold(0.0, f64::max)
        / rig.radius
}

/// The twisted cylinder (`scenes::twisted_cylinder`, radius 0.25 m, length 2 m) twisted by 180
/// degrees over its middle metre, the twist carried by a chain of 2 (the scene's rig) to 33
/// evenly spaced twist joints, skinned by LBS and by DQS, with 16, 64 and 256 segments around
/// (338, 5186 and 82,178 vertices). Error: the largest distance of a vertex from its place in the
/// exact twist (each cross-section rotated rigidly by the angle that grows linearly along the
/// axis), over the radius: LBS's candy-wrapper collapse towards the axis (error 1 with two
/// joints: the middle ring shrinks to a point) and DQS's lag in angle between joints. Time: one
/// `skin` call (joint data and every vertex, positions and normals), median of repeated calls.
/// What a rigger picking a method and a twist-joint density wants: how many joints each method
/// needs for a given shape error, and what a pass costs.
pub(super) fn twist_study(ctx: &Ctx) -> StudyResult {
    let (segments, joints, batches, min_batch): (&[usize], &[usize], usize, f64) = if ctx.quick {
        (&[16, 64], &[2, 3, 5, 9, 17], 3, 0.02)
    } else {
        (&[16, 64, 256], &[2, 3, 4, 5, 7, 9, 13, 17, 33], 5, 0.1)
    };
    let mut series = vec![];
    for method in [SkinningMethod::Lbs, SkinningMethod::Dqs] {
        for &seg in segments {
            let mut vertices = 0;
            let points = joints
                .iter()
                .map(|&k| {
                    let measured = twist_rig(seg, k).and_then(|rig| {
                        let mut out = Skinned::new(&rig.mesh);
                        skin(&rig.mesh, &rig.matrices, method, &mut out)?;
                        let error = twist_error(&rig, &out);
                        let seconds = median_seconds(batches, min_batch, || {
                            // Same inputs as the call above: it cannot fail.
                            let _ = skin(&rig.mesh, &rig.matrices, method, &mut out);
                        });
                        vertices = rig.mesh.len();
                        Ok((seconds, error))
                    });
                    let (seconds, error) = measured.unwrap_or((f64::NAN, f64::NAN));
                    Point { param: k as f64, seconds, error }
                })
                .collect();
            let name = match method {
                SkinningMethod::Lbs => "LBS",
                SkinningMethod::Dqs => "DQS",
            };
            series.push(Series { label: format!("{name}, {vertices} vertices"), points });
        }
    }
    StudyResult {
        title: "Skinning a 180 degree twist: LBS vs DQS by twist-joint count (twisted cylinder)".into(),
        slug: "skin_twist_joints".into(),
        error_label: "max vertex distance from the exact twist / cylinder radius".into(),
        param_label: "twist joints".into(),
        series,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed form of one vertex's error (over its distance from the axis) between joints
    /// `Delta` apart in twist angle, at fraction `f` of the way: LBS blends the two rotations'
    /// matrices, `|(1 - f) + f e^{i Delta} - e^{i f Delta}|`; DQS blends and normalises their
    /// quaternions, a rotation by `phi` with `tan(phi / 2) = f sin(Delta / 2) / ((1 - f) + f
    /// cos(Delta / 2))`, off the exact `f Delta` by a chord of `2 |sin((phi - f Delta) / 2)|`.
    fn closed_form(method: SkinningMethod, f: f64, delta: f64) -> f64 {
        match method {
            SkinningMethod::Lbs => {
                let re = (1.0 - f) + f * delta.cos() - (f * delta).cos();
                let im = f * delta.sin() - (f * delta).sin();
                re.hypot(im)
            }
            SkinningMethod::Dqs => {
                let half = (f * (delta / 2.0).sin()).atan2((1.0 - f) + f * (delta / 2.0).cos());
                2.0 * (half - f * delta / 2.0).sin().abs()
            }
        }
    }

    #[test]
    fn two_joint_rig_is_the_scene_posed_at_its_end() {
        let scene = scenes::twisted_cylinder(Some(16)).unwrap();
        let rig = twist_rig(16, 2).unwrap();
        let mut data = scene.data();
        for method in [SkinningMethod::Lbs, SkinningMethod::Dqs] {
            scene.pose(&mut data, scene.duration, method).unwrap();
            let mut out = Skinned::new(&rig.mesh);
            skin(&rig.mesh, &rig.matrices, method, &mut out).unwrap();
            let worst = (0..rig.mesh.len())
                .map(|v| {
                    (DVec3::from_array(out.position(v)) - DVec3::from_array(data.skinned[0].position(v)))
                        .length()
                })
                .fold(0.0, f64::max);
            assert!(worst < 1e-12, "{method:?}: {worst}");
        }
        assert!((rig.radius - 0.25).abs() < 1e-15, "{}", rig.radius);
    }

    #[test]
    fn measured_error_is_the_closed_form_of_each_method() {
        for method in [SkinningMethod::Lbs, SkinningMethod::Dqs] {
            for joints in [2, 3, 5, 9, 33] {
                let rig = twist_rig(16, joints).unwrap();
                let mut out = Skinned::new(&rig.mesh);
                skin(&rig.mesh, &rig.matrices, method, &mut out).unwrap();
                let delta = TWIST / (joints - 1) as f64;
                let want = (0..rig.mesh.len())
                    .map(|v| {
                        let p = rig.mesh.rest_position(v);
                        let u = ramp(p[0]) * (joints - 1) as f64;
                        let f = u - u.floor();
                        p[1].hypot(p[2]) * closed_form(method, f, delta)
                    })
                    .fold(0.0, f64::max)
                    / 0.25;
                let got = twist_error(&rig, &out);
                assert!((got - want).abs() < 1e-12, "{method:?} {joints} joints: {got} vs {want}");
            }
        }
    }

    #[test]
    fn two_joints_lbs_collapses_the_middle_ring_and_dqs_does_not() {
        // 16 segments: 21 rings 0.1 apart, one at x = 1 (ramp 1/2): LBS takes it to the axis, an
        // error of exactly one radius. DQS turns the ring at ramp f by 2 atan(f / (1 - f)) instead
        // of pi f; over the rings' f = 0.1, 0.2, ..., 0.9 the worst is f = 0.2 (and 0.8), a chord
        // of 2 sin(pi / 10 - atan(1 / 4)) = 0.1383 radii.
        let rig = twist_rig(16, 2).unwrap();
        let mut out = Skinned::new(&rig.mesh);
        skin(&rig.mesh, &rig.matrices, SkinningMethod::Lbs, &mut out).unwrap();
        assert!((twist_error(&rig, &out) - 1.0).abs() < 1e-12);
        skin(&rig.mesh, &rig.matrices, SkinningMethod::Dqs, &mut out).unwrap();
        let want = 2.0 * (std::f64::consts::PI / 10.0 - 0.25f64.atan()).sin();
        assert!((twist_error(&rig, &out) - want).abs() < 1e-12, "{}", twist_error(&rig, &out));
    }

    #[test]
    fn study_reports_every_point_and_both_methods() {
        let r = twist_study(&Ctx { quick: true });
        assert_eq!(r.series.len(), 4);
        for s in &r.series {
            assert_eq!(s.points.len(), 5, "{}", s.label);
            assert!(s.points.iter().all(|p| p.error.is_finite() && p.seconds > 0.0), "{}", s.label);
            // More joints, smaller error (the closed forms fall monotonically with Delta).
            assert!(s.points.windows(2).all(|w| w[1].error < w[0].error), "{}", s.label);
        }
        assert_eq!(r.series[0].label, "LBS, 338 vertices");
    }
}
