//! Interpolation against hand-computed values, DQS against LBS, thread-count determinism, input
//! validation, the candy-wrapper volumes.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use anim_core::glam::{DMat4, DQuat, DVec3, DVec4};
use anim_skin::{
    Channel, Interpolation, Pose, Property, SkinError, Skinned, SkinnedMesh, SkinningMethod, Trs, scenes,
    skin,
};

fn v3(x: f64, y: f64, z: f64) -> DVec4 {
    DVec4::new(x, y, z, 0.0)
}

#[test]
fn step_linear_cubic_by_hand() {
    let times = vec![1.0, 3.0];
    let step = Channel::new(
        0,
        Property::Translation,
        Interpolation::Step,
        times.clone(),
        vec![v3(1.0, 2.0, 3.0), v3(5.0, 6.0, 7.0)],
    )
    .unwrap();
    assert_eq!(step.sample(2.9), v3(1.0, 2.0, 3.0));
    assert_eq!(step.sample(3.0), v3(5.0, 6.0, 7.0));
    assert_eq!(step.sample(0.0), v3(1.0, 2.0, 3.0)); // clamped before
    let lin = Channel::new(
        0,
        Property::Translation,
        Interpolation::Linear,
        times.clone(),
        vec![v3(1.0, 2.0, 3.0), v3(5.0, 6.0, 7.0)],
    )
    .unwrap();
    assert!((lin.sample(1.5) - v3(2.0, 3.0, 4.0)).length() < 1e-15);
    assert_eq!(lin.sample(10.0), v3(5.0, 6.0, 7.0)); // clamped after
    // Cubic: p0 = 0, p1 = 1, out-tangent b0 = 2, in-tangent a1 = -1, td = 2, s = 0.5:
    // h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = -0.125 -> 0 + 0.125*2*2 + 0.5 - 0.125*2*(-1) = 1.25
    let cub = Channel::new(
        0,
        Property::Translation,
        Interpolation::CubicSpline,
        times,
        vec![
            v3(9.0, 0.0, 0.0),
            v3(0.0, 0.0, 0.0),
            v3(2.0, 0.0, 0.0),
            v3(-1.0, 0.0, 0.0),
            v3(1.0, 0.0, 0.0),
            v3(9.0, 0.0, 0.0),
        ],
    )
    .unwrap();
    assert!((cub.sample(2.0).x - 1.25).abs() < 1e-15, "{}", cub.sample(2.0).x);
    assert_eq!(cub.sample(1.0).x, 0.0);
    assert_eq!(cub.sample(3.0).x, 1.0);
}

#[test]
fn bad_channels_are_errors() {
    assert!(
        Channel::new(0, Property::Scale, Interpolation::Linear, vec![1.0, 1.0], vec![v3(1.0, 1.0, 1.0); 2])
            .is_err()
    );
    assert!(
        Channel::new(
            0,
            Property::Scale,
            Interpolation::CubicSpline,
            vec![1.0, 2.0],
            vec![v3(1.0, 1.0, 1.0); 2]
        )
        .is_err()
    );
    assert!(
        Channel::new(0, Property::Rotation, Interpolation::Linear, vec![1.0], vec![DVec4::ZERO]).is_err()
    );
}

fn random_mesh(n: usize, k: usize, joints: usize, rigid_single: bool) -> SkinnedMesh {
    let mut s = 12345u64;
    let mut rnd = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let pos: Vec<[f64; 3]> = (0..n).map(|_| [rnd() - 0.5, rnd() - 0.5, rnd() - 0.5]).collect();
    let mut js = vec![0u16; n * k];
    let mut ws = vec![0.0; n * k];
    for v in 0..n {
        for i in 0..k {
            js[v * k + i] = (rnd() * joints as f64) as u16;
            ws[v * k + i] = if rigid_single && i > 0 { 0.0 } else { rnd() + 0.01 };
        }
    }
    SkinnedMesh::new(&pos, None, k, &js, &ws, vec![], joints).unwrap()
}

fn joint_matrices(joints: usize) -> Vec<DMat4> {
    (0..joints)
        .map(|j| {
            let a = j as f64;
            DMat4::from_rotation_translation(
                DQuat::from_axis_angle(DVec3::new(1.0, a, 0.5).normalize(), 0.7 * a + 2.5),
                DVec3::new(a, -0.5 * a, 0.1),
            )
        })
        .collect()
}

#[test]
fn dqs_equals_lbs_for_rigid_single_influence_vertices() {
    let mesh = random_mesh(5000, 4, 10, true);
    let m = joint_matrices(10);
    let (mut a, mut b) = (Skinned::new(&mesh), Skinned::new(&mesh));
    skin(&mesh, &m, SkinningMethod::Lbs, &mut a).unwrap();
    skin(&mesh, &m, SkinningMethod::Dqs, &mut b).unwrap();
    let mut worst = 0.0f64;
    for v in 0..mesh.len() {
        for d in 0..3 {
            worst = worst.max((a.position(v)[d] - b.position(v)[d]).abs());
            worst = worst.max((a.normal(v)[d] - b.normal(v)[d]).abs());
        }
    }
    assert!(worst <= 1e-12, "{worst:e}");
}

#[test]
fn bitwise_identical_for_1_2_4_threads() {
    let mesh = random_mesh(20_000, 8, 16, false);
    let m = joint_matrices(16);
    for method in [SkinningMethod::Lbs, SkinningMethod::Dqs] {
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let mut out = Skinned::new(&mesh);
            pool.install(|| skin(&mesh, &m, method, &mut out)).unwrap();
            (out.x, out.y, out.z, out.nx, out.ny, out.nz)
        };
        let one = run(1);
        for t in [2, 4] {
            let other = run(t);
            assert!(one.0.iter().zip(&other.0).all(|(a, b)| a.to_bits() == b.to_bits()));
            assert!(one.5.iter().zip(&other.5).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }
}

#[test]
fn bad_weights_and_joints_are_errors() {
    let p = [[0.0; 3]; 2];
    let e = SkinnedMesh::new(&p, None, 2, &[0, 1, 0, 1], &[1.0, -0.1, 1.0, 0.0], vec![], 2).unwrap_err();
    assert!(matches!(e, SkinError::BadWeight { vertex: 0, slot: 1, .. }), "{e}");
    let e = SkinnedMesh::new(&p, None, 2, &[0, 1, 0, 1], &[1.0, f64::NAN, 1.0, 0.0], vec![], 2).unwrap_err();
    assert!(matches!(e, SkinError::BadWeight { .. }), "{e}");
    let e = SkinnedMesh::new(&p, None, 2, &[0, 1, 0, 7], &[1.0, 1.0, 1.0, 0.5], vec![], 2).unwrap_err();
    assert!(matches!(e, SkinError::BadJoint { vertex: 1, slot: 1, joint: 7, .. }), "{e}");
    let e = SkinnedMesh::new(&p, None, 2, &[0, 1, 0, 1], &[0.0, 0.0, 1.0, 0.0], vec![], 2).unwrap_err();
    assert!(matches!(e, SkinError::BadWeight { vertex: 0, .. }), "{e}");
    // Zero weight on an out-of-range joint is skipped; weights are normalised.
    let m = SkinnedMesh::new(&p, None, 2, &[0, 9, 1, 0], &[2.0, 0.0, 1.0, 3.0], vec![], 2).unwrap();
    assert_eq!(m.weights(), &[1.0, 0.0, 0.25, 0.75]);
    assert!(SkinnedMesh::new(&p, None, 9, &[0; 18], &[1.0; 18], vec![], 2).is_err());
}

#[test]
fn candy_wrapper_lbs_collapses_dqs_keeps_volume() {
    let scene = scenes::twisted_cylinder(None).unwrap();
    let rest = scene.rest_volume();
    // Closed cylinder of radius 0.25, length 2, 32-gon: (32/2) sin(2 pi/32) r^2 * 2.
    let polygon = 16.0 * (std::f64::consts::TAU / 32.0).sin() * 0.0625 * 2.0;
    assert!((rest - polygon).abs() < 1e-12, "{rest} vs {polygon}");
    let mut data = scene.data();
    scene.pose(&mut data, 2.0, SkinningMethod::Lbs).unwrap();
    let lbs = scenes::volume(&scene.character, &data);
    scene.pose(&mut data, 2.0, SkinningMethod::Dqs).unwrap();
    let dqs = scenes::volume(&scene.character, &data);
    assert!(lbs < 0.7 * rest, "LBS volume {lbs} of {rest}");
    assert!((dqs - rest).abs() < 0.03 * rest, "DQS volume {dqs} of {rest}");
    // At t = 0 both are the rest shape.
    scene.pose(&mut data, 0.0, SkinningMethod::Lbs).unwrap();
    assert!((scenes::volume(&scene.character, &data) - rest).abs() < 1e-12);
}

#[test]
fn pose_blend_endpoints_and_midpoint() {
    let a = Pose { local: vec![Trs::new(DVec3::ZERO, DQuat::IDENTITY, DVec3::ONE)] };
    let b = Pose { local: vec![Trs::new(DVec3::X, DQuat::from_rotation_y(1.0), DVec3::splat(3.0))] };
    let mut out = a.clone();
    Pose::blend(&a, &b, 0.5, &mut out);
    assert!((out.local[0].translation - DVec3::new(0.5, 0.0, 0.0)).length() < 1e-15);
    assert!((out.local[0].scale - DVec3::splat(2.0)).length() < 1e-15);
    assert!(out.local[0].rotation.angle_between(DQuat::from_rotation_y(0.5)) < 1e-7);
    Pose::blend(&a, &b, 1.0, &mut out);
    assert!(out.local[0].rotation.angle_between(b.local[0].rotation) < 1e-7);
}

/// Joint matrices with non-uniform scale (LBS only) or rigid (both methods).
fn scaled_joint_matrices(joints: usize, scaled: bool) -> Vec<DMat4> {
    (0..joints)
        .map(|j| {
            let a = j as f64;
            let s = if scaled { DVec3::new(1.0 + 0.1 * a, 0.7, 1.3 - 0.05 * a) } else { DVec3::ONE };
            DMat4::from_scale_rotation_translation(
                s,
                DQuat::from_axis_angle(DVec3::new(0.3, 1.0, -a).normalize(), 0.9 * a - 1.0),
                DVec3::new(0.2 * a, 1.0, -0.3 * a),
            )
        })
        .collect()
}

type Raw = (Vec<[f64; 3]>, Vec<[f64; 3]>, Vec<u16>, Vec<f64>);

/// Random vertices (positions, unit normals, 4 joints and weights each, some weights zero).
fn raw_vertices(n: usize, joints: usize) -> Raw {
    let k = 4;
    let mut s = 777u64;
    let mut rnd = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let pos: Vec<[f64; 3]> = (0..n).map(|_| [rnd() - 0.5, rnd() - 0.5, rnd() - 0.5]).collect();
    let nrm: Vec<[f64; 3]> =
        (0..n).map(|_| DVec3::new(rnd() - 0.5, rnd() - 0.5, rnd() + 0.1).normalize().to_array()).collect();
    let js: Vec<u16> = (0..n * k).map(|_| (rnd() * joints as f64) as u16).collect();
    let ws: Vec<f64> = (0..n * k).map(|i| if i % 7 == 3 { 0.0 } else { rnd() + 0.01 }).collect();
    (pos, nrm, js, ws)
}

/// An odd vertex count spanning several parallel chunks.
const ODD: usize = 2 * anim_skin::skinning::CHUNK + 3;

/// A random mesh of `ODD` vertices, 4 influences.
fn odd_mesh(joints: usize) -> SkinnedMesh {
    let (pos, nrm, js, ws) = raw_vertices(ODD, joints);
    SkinnedMesh::new(&pos, Some(&nrm), 4, &js, &ws, vec![], joints).unwrap()
}

#[test]
fn lbs_matches_glam_matrix_blend_with_inverse_transpose_normals() {
    let joints = 9;
    let mesh = odd_mesh(joints);
    let m = scaled_joint_matrices(joints, true);
    let mut out = Skinned::new(&mesh);
    skin(&mesh, &m, SkinningMethod::Lbs, &mut out).unwrap();
    let k = mesh.influences();
    let (mut ep, mut en) = (0.0f64, 0.0f64);
    for v in 0..mesh.len() {
        let mut a = DMat4::ZERO;
        for i in 0..k {
            a += m[mesh.joints()[v * k + i] as usize] * mesh.weights()[v * k + i];
        }
        let p = a.transform_point3(DVec3::from_array(mesh.rest_position(v)));
        let n0 = DVec3::new(mesh.nx[v], mesh.ny[v], mesh.nz[v]);
        let n = (anim_core::glam::DMat3::from_mat4(a).inverse().transpose() * n0).normalize();
        ep = ep.max((DVec3::from_array(out.position(v)) - p).length());
        en = en.max((DVec3::from_array(out.normal(v)) - n).length());
    }
    assert!(ep < 1e-13 && en < 1e-12, "position error {ep:e}, normal error {en:e}");
}

#[test]
fn dqs_matches_glam_dual_quaternion_blend() {
    let joints = 9;
    let mesh = odd_mesh(joints);
    let m = scaled_joint_matrices(joints, false);
    let mut out = Skinned::new(&mesh);
    skin(&mesh, &m, SkinningMethod::Dqs, &mut out).unwrap();
    // Unit dual quaternion (q, d) with d = 1/2 (t, 0) q, built with glam quaternion algebra.
    let dq: Vec<(DQuat, DQuat)> = m
        .iter()
        .map(|m| {
            let (_, q, t) = m.to_scale_rotation_translation();
            (q, DQuat::from_xyzw(t.x, t.y, t.z, 0.0) * q * 0.5)
        })
        .collect();
    let k = mesh.influences();
    let (mut ep, mut en) = (0.0f64, 0.0f64);
    for v in 0..mesh.len() {
        let js = &mesh.joints()[v * k..(v + 1) * k];
        let ws = &mesh.weights()[v * k..(v + 1) * k];
        let dom = (0..k).fold(0, |d, i| if ws[i] > ws[d] { i } else { d });
        let q0 = dq[js[dom] as usize].0;
        let (mut bq, mut bd) = (DVec4::ZERO, DVec4::ZERO);
        for i in 0..k {
            let (q, d) = dq[js[i] as usize];
            let s = if q.dot(q0) < 0.0 { -ws[i] } else { ws[i] };
            bq += DVec4::from(q) * s;
            bd += DVec4::from(d) * s;
        }
        let len = bq.length();
        let (r, d) = (DQuat::from_vec4(bq / len), DQuat::from_vec4(bd / len));
        let t = d * r.conjugate() * 2.0;
        let p = r * DVec3::from_array(mesh.rest_position(v)) + DVec3::new(t.x, t.y, t.z);
        let n = (r * DVec3::new(mesh.nx[v], mesh.ny[v], mesh.nz[v])).normalize();
        ep = ep.max((DVec3::from_array(out.position(v)) - p).length());
        en = en.max((DVec3::from_array(out.normal(v)) - n).length());
    }
    assert!(ep < 1e-13 && en < 1e-13, "position error {ep:e}, normal error {en:e}");
}

#[test]
fn a_vertex_result_does_not_depend_on_its_batch_neighbour() {
    // Dropping the first vertex shifts every other vertex to the other SIMD lane and pairs it
    // with a different neighbour; its result must not change by a single bit.
    let joints = 9;
    let (pos, nrm, js, ws) = raw_vertices(ODD, joints);
    let (k, n) = (4, ODD);
    let mesh = SkinnedMesh::new(&pos, Some(&nrm), k, &js, &ws, vec![], joints).unwrap();
    let shifted =
        SkinnedMesh::new(&pos[1..], Some(&nrm[1..]), k, &js[k..], &ws[k..], vec![], joints).unwrap();
    for (method, m) in [
        (SkinningMethod::Lbs, scaled_joint_matrices(joints, true)),
        (SkinningMethod::Dqs, scaled_joint_matrices(joints, false)),
    ] {
        let (mut a, mut b) = (Skinned::new(&mesh), Skinned::new(&shifted));
        skin(&mesh, &m, method, &mut a).unwrap();
        skin(&shifted, &m, method, &mut b).unwrap();
        for v in 1..n {
            let (pa, pb) = (a.position(v), b.position(v - 1));
            let (na, nb) = (a.normal(v), b.normal(v - 1));
            for d in 0..3 {
                assert_eq!(pa[d].to_bits(), pb[d].to_bits(), "{method:?} vertex {v}");
                assert_eq!(na[d].to_bits(), nb[d].to_bits(), "{method:?} vertex {v}");
            }
        }
    }
}
