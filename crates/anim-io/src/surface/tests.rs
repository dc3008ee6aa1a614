//! Every refusal of `read_closed_surface` names the file, the element at fault and the cause,
//! and says which field of the table is at fault; a surface that reads is placed.

use super::*;

/// A folder of this test's own under the system's temporary folder.
fn folder(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("anim-io-surface-{}-{test}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).expect("temporary folder");
    dir
}

/// The unit cube `[0, 1]^3` as twelve outward triangles (anim-core's `cuboid`: corner `k` at
/// the bits of `k`), without the triangles in `missing`, its vertex 7 written `last`.
fn cube_obj(missing: &[usize], last: &str) -> String {
    let (p, t) = anim_core::surface::cuboid([0.0; 3], [1.0; 3]);
    let mut text: String = p[..7].iter().map(|v| format!("v {} {} {}\n", v[0], v[1], v[2])).collect();
    text += &format!("v {last}\n");
    for (_, f) in t.iter().enumerate().filter(|(k, _)| !missing.contains(k)) {
        text += &format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    text
}

#[test]
fn a_closed_surface_is_placed_scale_then_rotation_then_translation() {
    let dir = folder("placed");
    let path = dir.join("cube.obj");
    std::fs::write(&path, cube_obj(&[], "1 1 1")).expect("write");
    // Scaled by 2, turned a quarter about z (x -> y), moved by (10, 0, -1).
    let placement = Placement {
        scale: 2.0,
        rotate: [0.0, 0.0, std::f64::consts::FRAC_PI_2],
        translate: [10.0, 0.0, -1.0],
    };
    let s = read_closed_surface(&path, &placement).expect("reads");
    assert_eq!(s.triangles().len(), 12);
    let (lo, hi) = s.bounds();
    for (got, want) in lo.iter().chain(&hi).zip([8.0, 0.0, -1.0, 10.0, 2.0, 1.0]) {
        assert!((got - want).abs() < 1e-12, "{lo:?} {hi:?}");
    }
    // The file's numbering is kept: vertex 7 is the corner (1, 1, 1), placed.
    let v7 = s.positions()[7];
    assert!((v7.x - 8.0).abs() < 1e-12 && (v7.y - 2.0).abs() < 1e-12 && (v7.z - 1.0).abs() < 1e-12, "{v7}");
    // Polygons are split: a quad cube (six faces) reads as twelve triangles.
    let quads = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n\
                 f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
    std::fs::write(dir.join("quads.obj"), quads).expect("write");
    let s = read_closed_surface(&dir.join("quads.obj"), &Placement::default()).expect("reads");
    assert_eq!(s.triangles().len(), 12);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn each_refusal_names_the_file_the_element_the_cause_and_the_field() {
    let dir = folder("refused");
    let write = |name: &str, text: String| {
        let path = dir.join(name);
        std::fs::write(&path, text).expect("write");
        path
    };
    let fine = Placement::default();
    let refuse = |path: &Path, placement: &Placement| {
        let e = read_closed_surface(path, placement).expect_err("refused");
        (e.field().to_string(), e.to_string(), e)
    };
    let cube = write("cube.obj", cube_obj(&[], "1 1 1"));
    // The placement first, by its own field, before the file is looked at.
    let missing = dir.join("missing.obj");
    for (placement, field) in [
        (Placement { scale: 0.0, ..fine }, "scale"),
        (Placement { scale: f64::NAN, ..fine }, "scale"),
        (Placement { rotate: [0.0, f64::INFINITY, 0.0], ..fine }, "rotate"),
        (Placement { translate: [f64::NAN, 0.0, 0.0], ..fine }, "translate"),
    ] {
        let (f, m, e) = refuse(&missing, &placement);
        assert!(matches!(e, SurfaceFileError::Placement { .. }), "{e:?}");
        assert_eq!(f, field, "{m}");
    }
    // Not an OBJ name, a missing file, a line that does not parse: the file, and its line.
    let (f, m, _) = refuse(&write("cube.stl", cube_obj(&[], "1 1 1")), &fine);
    assert!(f == "mesh" && m.contains("cube.stl") && m.contains("OBJ"), "{m}");
    let (f, m, e) = refuse(&missing, &fine);
    assert!(f == "mesh" && m.contains("missing.obj") && matches!(e, SurfaceFileError::Read(_)), "{m}");
    let (f, m, _) = refuse(&write("bad.obj", cube_obj(&[], "1 1 one")), &fine);
    assert!(f == "mesh" && m.contains("bad.obj:8:"), "{m}");
    // A hole: the edge and its triangle; a flipped triangle: both triangles; numbered in the
    // file's order.
    let (f, m, _) = refuse(&write("holed.obj", cube_obj(&[7], "1 1 1")), &fine);
    assert!(f == "mesh" && m.contains("holed.obj") && m.contains("not closed: edge ("), "{m}");
    assert!(m.contains("numbered from 0 in file order") && !m.contains("polygons"), "{m}");
    let flipped = cube_obj(&[], "1 1 1").replace("f 5 6 8\n", "f 5 8 6\n");
    let (f, m, _) = refuse(&write("flipped.obj", flipped), &fine);
    assert!(f == "mesh" && m.contains("flipped.obj") && m.contains("inconsistently oriented"), "{m}");
    // A collapsed corner: a zero-area triangle, by number.
    let (f, m, _) = refuse(&write("flat.obj", cube_obj(&[], "1 1 0")), &fine);
    assert!(f == "mesh" && m.contains("flat.obj") && m.contains("zero area"), "{m}");
    // A coordinate of the file that is not finite is the file's fault, on its line; a finite
    // one placed past f64's range is the scale's.
    let (f, m, _) = refuse(&write("nan.obj", cube_obj(&[], "1 nan 1")), &fine);
    assert!(f == "mesh" && m.contains("nan.obj:8:"), "{m}");
    let (f, m, _) = refuse(&cube, &Placement { scale: 1e308, ..fine });
    assert!(f == "scale" && m.contains("cube.obj") && m.contains("scale it down"), "{m}");
    // As a scene file's error, under the kind's table.
    let e =
        read_closed_surface(&dir.join("holed.obj"), &fine).expect_err("refused").within("obstacle_meshes[3]");
    match e {
        BuildError::Invalid { field, message } => {
            assert_eq!(field, "obstacle_meshes[3].mesh");
            assert!(message.contains("holed.obj"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    std::fs::remove_dir_all(&dir).ok();
}
