//! anim-skin: posed glTF vertices against an independent numpy reference, DQS against LBS on
//! rigid single-influence vertices, glTF interpolation against hand-computed values, and the
//! twisted cylinder's volume under LBS and DQS (the candy-wrapper collapse). Study: the twisted
//! cylinder rebound to chains of 2 to 33 twist joints, skinned by LBS and DQS at three mesh
//! sizes, shape error against the exact twist against the time of one skinning pass.

use crate::registry::{
    Check, ConformanceCase, Ctx, Judge, Point, Registry, Series, Study, StudyResult, median_seconds,
};
use anim_core::glam::{DMat4, DQuat, DVec3, DVec4};
use anim_skin::{
    Channel, Interpolation, Property, SkinError, Skinned, SkinnedMesh, SkinningMethod, scenes, skin,
};
use std::path::{Path, PathBuf};

const CRATE: &str = "anim-skin";
const NUMPY: &str = "numpy + pygltflib, crates/anim-skin/testdata/reference.py";

pub fn register(r: &mut Registry) {
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "glTF posed vertices vs numpy reference",
        run: Box::new(|_| gltf_reference()),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "DQS equals LBS on rigid single-influence vertices",
        run: Box::new(|_| dqs_vs_lbs()),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "glTF interpolation step/linear/cubic by hand",
        run: Box::new(|_| interpolation()),
    });
    r.conformance.push(ConformanceCase {
        crate_name: CRATE,
        name: "twisted cylinder volume, LBS vs DQS",
        run: Box::new(|_| candy_wrapper()),
    });
    r.studies.push(Study { crate_name: CRATE, name: "LBS vs DQS by twist-joint count", run: twist_study });
}

fn testdata(file: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../crates/anim-skin/testdata").join(file)
}

fn check(
    case: &str,
    metric: String,
    measured: f64,
    tolerance: f64,
    judge: Judge,
    source: &'static str,
) -> Check {
    Check { crate_name: CRATE, case: case.into(), metric, measured, reference: 0.0, tolerance, judge, source }
}

fn gltf_reference() -> Vec<Check> {
    let case = "glTF posed vertices vs numpy reference";
    let fail = |why: String| vec![check(case, why, f64::NAN, 1e-5, Judge::AtMost, NUMPY)];
    let Ok(text) = std::fs::read_to_string(testdata("reference_poses.json")) else {
        return fail("reference_poses.json unreadable".into());
    };
    let Ok(r) = serde_json::from_str::<serde_json::Value>(&text) else {
        return fail("reference JSON invalid".into());
    };
    let Some(files) = r["files"].as_object() else { return fail("reference JSON has no files".into()) };
    let mut out = Vec::new();
    for (file, poses) in files {
        let scene = match scenes::from_gltf(testdata(file)) {
            Ok(s) => s,
            Err(e) => return fail(e.to_string()),
        };
        let mut data = scene.data();
        let (mut p, mut worst, mut count) = (Vec::new(), 0.0f64, 0);
        for pose in poses.as_array().map(Vec::as_slice).unwrap_or(&[]) {
            let t = pose["t"].as_f64().unwrap_or(f64::NAN);
            let want: Vec<[f64; 3]> = serde_json::from_value(pose["positions"].clone()).unwrap_or_default();
            if scene.pose(&mut data, t, SkinningMethod::Lbs).is_err()
                || want.len() != scene.character.num_vertices()
            {
                return fail(format!("{file} t = {t}: could not pose"));
            }
            data.positions(&mut p);
            let scale = want.iter().map(|q| DVec3::from_array(*q).length()).fold(0.0, f64::max);
            let err = p
                .iter()
                .zip(&want)
                .map(|(a, b)| (DVec3::from_array(*a) - DVec3::from_array(*b)).length())
                .fold(0.0, f64::max);
            worst = worst.max(err / scale);
            count += 1;
        }
        out.push(check(
            case,
            format!("{file}: max |p - p_ref| / max |p_ref| over {count} times, LBS, 8 influences"),
            worst,
            1e-5,
            Judge::AtMost,
            NUMPY,
        ));
    }
    out
}

fn dqs_vs_lbs() -> Vec<Check> {
    let (n, joints) = (20_000, 12);
    let mut s = 7u64;
    let mut rnd = move || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let pos: Vec<[f64; 3]> = (0..n).map(|_| [rnd() - 0.5, rnd() - 0.5, rnd() - 0.5]).collect();
    let js: Vec<u16> = (0..n * 4).map(|_| (rnd() * joints as f64) as u16).collect();
    let ws: Vec<f64> = (0..n * 4).map(|i| if i % 4 == 0 { 1.0 } else { 0.0 }).collect();
    let m: Vec<DMat4> = (0..joints)
        .map(|j| {
            let a = j as f64;
            DMat4::from_rotation_translation(
                DQuat::from_axis_angle(DVec3::new(1.0, a, -0.3).normalize(), 0.5 * a + 2.9),
                DVec3::new(a, 1.0, -a),
            )
        })
        .collect();
    let worst = (|| {
        let mesh = SkinnedMesh::new(&pos, None, 4, &js, &ws, vec![], joints).ok()?;
        let (mut a, mut b) = (Skinned::new(&mesh), Skinned::new(&mesh));
        skin(&mesh, &m, SkinningMethod::Lbs, &mut a).ok()?;
        skin(&mesh, &m, SkinningMethod::Dqs, &mut b).ok()?;
        Some(
            (0..n)
                .map(|v| (DVec3::from_array(a.position(v)) - DVec3::from_array(b.position(v))).length())
                .fold(0.0, f64::max),
        )
    })()
    .unwrap_or(f64::NAN);
    vec![check(
        "DQS equals LBS on rigid single-influence vertices",
        format!("max |p_DQS - p_LBS|, {n} vertices, {joints} rigid joints (rotations up to 8.4 rad)"),
        worst,
        1e-12,
        Judge::AtMost,
        "identity: one rigid influence is the same motion",
    )]
}

fn interpolation() -> Vec<Check> {
    let v = |x: f64| DVec4::new(x, 0.0, 0.0, 0.0);
    let t = vec![1.0, 3.0];
    let mut errs = Vec::new();
    let mut run = |interp, values: Vec<DVec4>, at: f64, want: f64| {
        let e = Channel::new(0, Property::Translation, interp, t.clone(), values)
            .map_or(f64::NAN, |c| (c.sample(at).x - want).abs());
        errs.push(e);
    };
    run(Interpolation::Step, vec![v(1.0), v(5.0)], 2.9, 1.0);
    run(Interpolation::Step, vec![v(1.0), v(5.0)], 0.0, 1.0);
    run(Interpolation::Linear, vec![v(1.0), v(5.0)], 1.5, 2.0);
    run(Interpolation::Linear, vec![v(1.0), v(5.0)], 9.0, 5.0);
    // p0 = 0, b0 = 2, a1 = -1, p1 = 1, td = 2, s = 1/2: 0.125*4 + 0.5 + 0.125*2 = 1.25.
    run(Interpolation::CubicSpline, vec![v(9.0), v(0.0), v(2.0), v(-1.0), v(1.0), v(9.0)], 2.0, 1.25);
    // s = 1/4: h10 = 9/64, h01 = 5/32, h11 = -3/64 -> 9/64*4 + 5/32 + 3/64*2 = 52/64 = 0.8125.
    run(Interpolation::CubicSpline, vec![v(9.0), v(0.0), v(2.0), v(-1.0), v(1.0), v(9.0)], 1.5, 0.8125);
    let q = Channel::new(
        0,
        Property::Rotation,
        Interpolation::Linear,
        vec![0.0, 1.0],
        vec![DQuat::IDENTITY.into(), (-DQuat::from_rotation_z(1.0)).into()],
    )
    .map_or(f64::NAN, |c| {
        let s = c.sample(0.25);
        DQuat::from_vec4(s).angle_between(DQuat::from_rotation_z(0.25))
    });
    vec![
        check(
            "glTF interpolation step/linear/cubic by hand",
            "max |sample - hand value| over step, linear, cubic spline (6 samples)".into(),
            errs.iter().fold(0.0, |a: f64, b| if b.is_nan() { f64::NAN } else { a.max(*b) }),
            1e-14,
            Judge::AtMost,
            "glTF 2.0 Appendix C, by hand",
        ),
        check(
            "glTF interpolation step/linear/cubic by hand",
            "slerp to an antipodal key: angle from the shortest-path rotation (rad)".into(),
            q,
            1e-7,
            Judge::AtMost,
            "glTF 2.0 Appendix C, by hand",
        ),
    ]
}

fn candy_wrapper() -> Vec<Check> {
    let case = "twisted cylinder volume, LBS vs DQS";
    let Ok(scene) = scenes::twisted_cylinder(None) else {
        return vec![check(case, "scene failed".into(), f64::NAN, 0.0, Judge::AtMost, "")];
    };
    let rest = scene.rest_volume();
    let mut data = scene.data();
    let mut vol = |m| {
        scene
            .pose(&mut data, scene.duration, m)
            .map_or(f64::NAN, |()| scenes::volume(&scene.character, &data))
    };
    let lbs = vol(SkinningMethod::Lbs);
    let dqs = vol(SkinningMethod::Dqs);
    let lbs_loss = 1.0 - lbs / rest;
    let dqs_change = (dqs / rest - 1.0).abs();
    let detail = format!(
        "rest {rest:.5}, LBS {lbs:.5} (-{:.1} %), DQS {dqs:.5} ({:+.2} %)",
        100.0 * lbs_loss,
        100.0 * (dqs / rest - 1.0)
    );
    vec![
        check(
            case,
            format!("DQS |V/V0 - 1| at 180 deg twist; {detail}"),
            dqs_change,
            0.03,
            Judge::AtMost,
            "volume of the rest cylinder",
        ),
        check(
            case,
            format!("LBS volume loss 1 - V/V0 at 180 deg twist (candy wrapper); {detail}"),
            lbs_loss,
            0.3,
            Judge::AtLeast,
            "volume of the rest cylinder",
        ),
    ]
}

// ---------------------------------------------------------------------------------------------
// Study: twist joints.

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
fn twist_study(ctx: &Ctx) -> StudyResult {
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
