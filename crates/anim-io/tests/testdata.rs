//! Readers on the committed files of `testdata/` (written by hand and by meshio), and our
//! writers' output read back by our readers.

use anim_io::gmsh::{PhysicalName, SkippedElements, read_gmsh};
use anim_io::obj::{Polygons, read_obj, write_obj};
use anim_io::tetgen::read_tetgen;
use anim_io::{IoError, TetMesh, read_tet_mesh, read_tri_mesh};
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("testdata").join(name)
}

/// The cube of `testdata/README.md`, computed independently of any file.
fn cube() -> TetMesh {
    let positions = (0..8)
        .map(|i| {
            let (x, y, z) = ((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64);
            [0.1 * x - 0.3, 0.7 * y + 0.01, 0.123456789 * z + 1.0 / 3.0]
        })
        .collect();
    let tets = vec![[0, 1, 3, 7], [0, 1, 7, 5], [0, 2, 7, 3], [0, 2, 6, 7], [0, 4, 5, 7], [0, 4, 7, 6]];
    TetMesh { positions, tets }
}

/// Triangles as a sorted list of their smallest-index-first rotations (orientation kept).
fn canonical(tris: &[[usize; 3]]) -> Vec<[usize; 3]> {
    let mut out: Vec<[usize; 3]> = tris
        .iter()
        .map(|&[a, b, c]| {
            let m = a.min(b).min(c);
            if m == a {
                [a, b, c]
            } else if m == b {
                [b, c, a]
            } else {
                [c, a, b]
            }
        })
        .collect();
    out.sort_unstable();
    out
}

#[test]
fn the_cube_is_valid_and_has_twelve_outward_faces() {
    let c = cube();
    assert!(c.validate().is_ok(), "{}", c.validate());
    assert_eq!(c.boundary_triangles().len(), 12);
}

#[test]
fn gmsh_files_by_hand_and_by_meshio_agree_with_the_cube() {
    let c = cube();
    let boundary = canonical(&c.boundary_triangles());
    // meshio's 4.1 writer cannot name a surface entity for nodes that are also volume nodes, so
    // its file holds the tetrahedra only.
    for (file, version, has_triangles) in [
        ("cube_v22.msh", "2.2", true),
        ("cube_v41.msh", "4.1", true),
        ("cube_meshio_v22.msh", "2.2", true),
        ("cube_meshio_v41.msh", "4.1", false),
    ] {
        let m = read_gmsh(data(file)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.version, version, "{file}");
        assert_eq!(m.tet_mesh(), c, "{file}");
        assert_eq!(m.node_tags, (1..=8).collect::<Vec<u64>>(), "{file}");
        assert_eq!(m.tet_physical, vec![2; 6], "{file}");
        if has_triangles {
            assert_eq!(canonical(&m.triangles), boundary, "{file}: boundary triangles and their orientation");
            assert_eq!(m.triangle_physical, vec![1; 12], "{file}");
        } else {
            assert!(m.triangles.is_empty() && m.triangle_physical.is_empty(), "{file}");
        }
        assert!(m.tri_mesh().validate().is_ok(), "{file}");
        assert_eq!(read_tet_mesh(data(file)).unwrap(), c, "{file}");
    }
    let hand = read_gmsh(data("cube_v22.msh")).unwrap();
    assert_eq!(hand.skipped, vec![SkippedElements { element_type: 15, count: 1 }]);
    let names = vec![
        PhysicalName { dim: 2, tag: 1, name: "boundary".into() },
        PhysicalName { dim: 3, tag: 2, name: "solid".into() },
    ];
    assert_eq!(hand.physical_names, names);
    assert_eq!(read_gmsh(data("cube_v41.msh")).unwrap().physical_names, names);
}

#[test]
fn tetgen_pairs_numbered_from_one_and_from_zero_agree_with_the_cube() {
    let c = cube();
    let hand = read_tetgen(data("cube.node")).unwrap();
    assert_eq!(hand.first_index, 1);
    assert_eq!(hand.tet_mesh(), c);
    assert_eq!(hand.node_markers, Some(vec![1; 8]));
    assert_eq!((hand.tet_attribute_count, hand.tet_attributes.clone()), (1, vec![2.0; 6]));
    let meshio = read_tetgen(data("cube_meshio.ele")).unwrap();
    assert_eq!(meshio.first_index, 0);
    assert_eq!(meshio.tet_mesh(), c);
    assert_eq!(meshio.node_markers, None);
    // The stem alone works too, and the generic reader validates.
    assert_eq!(read_tetgen(data("cube")).unwrap(), hand);
    assert_eq!(read_tet_mesh(data("cube.ele")).unwrap(), c);
}

#[test]
fn obj_cloth_patch() {
    let m = read_obj(data("cloth.obj"), Polygons::Triangulate).unwrap();
    assert_eq!(m.positions.len(), 9);
    assert_eq!(m.positions[4], [0.5, 0.5, 0.0625]);
    assert_eq!(m.positions[8], [1.0, 1.0, 1e-3]);
    assert_eq!(
        m.triangles,
        vec![[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4], [3, 4, 7], [3, 7, 6], [4, 5, 8], [4, 8, 7]]
    );
    assert_eq!(m.lines, vec![[0, 1], [1, 2]]);
    assert_eq!(m.triangulated_polygons, 2);
    // Every triangle is counter-clockwise seen from +z, as in the file.
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| m.positions[i]);
        assert!((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0.0, "{t:?}");
    }
    let e = read_obj(data("cloth.obj"), Polygons::Reject).unwrap_err().to_string();
    assert!(e.ends_with("cloth.obj:22: face with 4 vertices; only triangles are accepted"), "{e}");
    assert_eq!(read_tri_mesh(data("cloth.obj")).unwrap().triangles.len(), 8);
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("anim-io-testdata-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    dir.join(name)
}

#[test]
fn obj_writer_output_reads_back_identically() {
    let c = cube();
    let tris = c.boundary_triangles();
    let segs = [[0, 7], [3, 4]];
    let path = tmp("cube.obj");
    write_obj(&path, &c.positions, &tris, &segs).unwrap();
    let back = read_obj(&path, Polygons::Reject).unwrap();
    assert_eq!(back.positions, c.positions);
    assert_eq!(back.triangles, tris);
    assert_eq!(back.lines, segs.to_vec());
    // f32 positions print as f32 and read back to the same f32.
    let p32: Vec<[f32; 3]> = c.positions.iter().map(|p| p.map(|x| x as f32)).collect();
    write_obj(&path, &p32, &tris, &[]).unwrap();
    let back = read_obj(&path, Polygons::Reject).unwrap();
    let again: Vec<[f32; 3]> = back.positions.iter().map(|p| p.map(|x| x as f32)).collect();
    assert_eq!(again, p32);
}

#[test]
fn invalid_meshes_are_reported_by_element() {
    // Swap two corners of tetrahedron 3 (1-based 4): it becomes inverted.
    let ele = std::fs::read_to_string(data("cube.ele")).unwrap().replace("4  1 3 7 8  2", "4  1 3 8 7  2");
    std::fs::copy(data("cube.node"), tmp("bad.node")).unwrap();
    std::fs::write(tmp("bad.ele"), ele).unwrap();
    match read_tet_mesh(tmp("bad.ele")) {
        Err(IoError::InvalidMesh { report, .. }) => {
            assert_eq!(report.inverted, vec![3]);
            assert!(report.degenerate.is_empty() && report.out_of_range.is_empty());
        }
        other => panic!("expected an invalid-mesh error, got {other:?}"),
    }
    // A flat tetrahedron: all four corners on the bottom face.
    let ele = std::fs::read_to_string(data("cube.ele")).unwrap().replace("2  1 2 8 6  2", "2  1 2 4 3  2");
    std::fs::write(tmp("bad.ele"), ele).unwrap();
    let e = read_tet_mesh(tmp("bad.ele")).unwrap_err();
    assert!(e.to_string().contains("1 degenerate (zero-area or zero-volume) elements (1)"), "{e}");
    // A zero-area triangle in an OBJ.
    std::fs::write(tmp("flat.obj"), "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 4\nf 1 2 3\n").unwrap();
    match read_tri_mesh(tmp("flat.obj")) {
        Err(IoError::InvalidMesh { report, .. }) => assert_eq!(report.degenerate, vec![1]),
        other => panic!("expected an invalid-mesh error, got {other:?}"),
    }
}
