//! Posed glTF vertices against an independent numpy reference, DQS against LBS on rigid
//! single-influence vertices, glTF interpolation against hand-computed values, and the twisted
//! cylinder's volume under LBS and DQS (the candy-wrapper collapse).

use super::{NUMPY, check, testdata};
use crate::{Channel, Interpolation, Property, Skinned, SkinnedMesh, SkinningMethod, scenes, skin};
use anim_core::cases::{Check, Judge, nan_max};
use anim_core::glam::{DMat4, DQuat, DVec3, DVec4};

pub(super) fn gltf_reference() -> Vec<Check> {
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
            let scale = want.iter().map(|q| DVec3::from_array(*q).length()).fold(0.0, nan_max);
            let err = p
                .iter()
                .zip(&want)
                .map(|(a, b)| (DVec3::from_array(*a) - DVec3::from_array(*b)).length())
                .fold(0.0, nan_max);
            worst = nan_max(worst, err / scale);
            count += 1;
        }
        if count == 0 {
            worst = f64::NAN; // a reference without poses compares nothing
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

pub(super) fn dqs_vs_lbs() -> Vec<Check> {
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
                .fold(0.0, nan_max),
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

pub(super) fn interpolation() -> Vec<Check> {
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
            errs.iter().copied().fold(0.0, nan_max),
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

pub(super) fn candy_wrapper() -> Vec<Check> {
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
