//! Fuzz-style robustness: every reader gets every prefix of every test file and thousands of
//! seeded corruptions of it. Each call must return `Ok` or `Err`; a panic fails the test (and an
//! accepted mesh must survive validation and the helpers that index it).

use anim_io::gmsh::parse_gmsh;
use anim_io::obj::{Polygons, parse_obj};
use anim_io::tetgen::parse_tetgen;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::PathBuf;

fn data(name: &str) -> Vec<u8> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("testdata").join(name);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Bytes as text the way the file readers see them: invalid UTF-8 is an error, not a panic.
fn text(bytes: &[u8]) -> Option<String> {
    String::from_utf8(bytes.to_vec()).ok()
}

/// Runs every reader that takes this kind of file on `bytes`; returns whether it was accepted.
fn exercise(kind: &str, bytes: &[u8], partner: &[u8]) -> bool {
    let Some(s) = text(bytes) else {
        return false;
    };
    match kind {
        "msh" => match parse_gmsh(&s, "f.msh") {
            Ok(m) => {
                let t = m.tet_mesh();
                let _ = (t.validate(), t.boundary_triangles());
                for e in 0..=t.tets.len() {
                    assert_eq!(t.signed_volume6(e).is_some(), e < t.tets.len());
                }
                let r = m.tri_mesh();
                let _ = (r.validate(), r.vertex_normals(), m.skipped_volume_elements());
                assert_eq!(m.tets.len(), m.tet_physical.len());
                assert!(
                    m.tets
                        .iter()
                        .flatten()
                        .chain(m.triangles.iter().flatten())
                        .all(|&i| i < m.positions.len())
                );
                true
            }
            Err(e) => {
                assert!(matches!(e, anim_io::IoError::Parse { line, .. } if line >= 1), "{e}");
                false
            }
        },
        "obj" => {
            let mut ok = false;
            for polygons in [Polygons::Triangulate, Polygons::Reject] {
                if let Ok(m) = parse_obj(&s, "f.obj", polygons) {
                    assert!(
                        m.triangles
                            .iter()
                            .flatten()
                            .chain(m.lines.iter().flatten())
                            .all(|&i| i < m.positions.len())
                    );
                    let t = m.into_tri_mesh();
                    let _ = (t.validate(), t.vertex_normals());
                    ok = true;
                }
            }
            ok
        }
        "node" | "ele" => {
            let Some(p) = text(partner) else { return false };
            let (node, ele) = if kind == "node" { (&s, &p) } else { (&p, &s) };
            match parse_tetgen(node, "f.node", ele, "f.ele") {
                Ok(m) => {
                    assert!(m.tets.iter().flatten().all(|&i| i < m.positions.len()));
                    let t = m.tet_mesh();
                    let _ = (t.validate(), t.boundary_triangles());
                    true
                }
                Err(_) => false,
            }
        }
        other => panic!("unknown kind {other}"),
    }
}

const FILES: [(&str, &str, &str); 9] = [
    ("cube_v22.msh", "msh", ""),
    ("cube_v41.msh", "msh", ""),
    ("cube_meshio_v22.msh", "msh", ""),
    ("cube_meshio_v41.msh", "msh", ""),
    ("cube.node", "node", "cube.ele"),
    ("cube.ele", "ele", "cube.node"),
    ("cube_meshio.node", "node", "cube_meshio.ele"),
    ("cube_meshio.ele", "ele", "cube_meshio.node"),
    ("cloth.obj", "obj", ""),
];

#[test]
fn every_prefix_is_handled() {
    for (file, kind, partner) in FILES {
        let bytes = data(file);
        let partner = if partner.is_empty() { Vec::new() } else { data(partner) };
        assert!(exercise(kind, &bytes, &partner), "{file} itself must be accepted");
        let mut accepted = 0;
        for len in 0..bytes.len() {
            accepted += usize::from(exercise(kind, &bytes[..len], &partner));
        }
        // A truncated Gmsh file lacks its `$EndElements`; TetGen and OBJ have no end marker, so a
        // cut inside their last number can still be a well-formed file.
        if kind == "msh" {
            let trailing_ws = bytes.iter().rev().take_while(|b| b.is_ascii_whitespace()).count();
            assert!(accepted <= trailing_ws, "{file}: {accepted} truncated versions were accepted");
        }
    }
}

/// Replacement bytes biased toward what breaks parsers: digits, signs, separators, newlines,
/// section markers, invalid UTF-8.
const NASTY: &[u8] = b"0123456789-+.eE \t\n\r$#/\"\xff\xc3";

#[test]
fn seeded_corruptions_are_handled() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed_0001);
    let mut rejected = 0usize;
    let mut total = 0usize;
    for (file, kind, partner) in FILES {
        let original = data(file);
        let partner = if partner.is_empty() { Vec::new() } else { data(partner) };
        for _ in 0..1500 {
            let mut bytes = original.clone();
            match rng.random_range(0..4) {
                // Flip random bits.
                0 => {
                    for _ in 0..rng.random_range(1..4) {
                        let i = rng.random_range(0..bytes.len());
                        bytes[i] ^= 1 << rng.random_range(0..8);
                    }
                }
                // Overwrite with a nasty byte.
                1 => {
                    for _ in 0..rng.random_range(1..4) {
                        let i = rng.random_range(0..bytes.len());
                        bytes[i] = NASTY[rng.random_range(0..NASTY.len())];
                    }
                }
                // Delete or duplicate a span.
                2 => {
                    let i = rng.random_range(0..bytes.len());
                    let j = (i + rng.random_range(1..40)).min(bytes.len());
                    if rng.random_bool(0.5) {
                        bytes.drain(i..j);
                    } else {
                        let span: Vec<u8> = bytes[i..j].to_vec();
                        bytes.splice(i..i, span);
                    }
                }
                // Replace a number with an extreme one.
                _ => {
                    let s = String::from_utf8_lossy(&bytes).into_owned();
                    let starts: Vec<usize> = s
                        .char_indices()
                        .filter(|&(i, c)| {
                            c.is_ascii_digit() && (i == 0 || !s.as_bytes()[i - 1].is_ascii_digit())
                        })
                        .map(|(i, _)| i)
                        .collect();
                    let at = starts[rng.random_range(0..starts.len())];
                    let end = s[at..].find(|c: char| !c.is_ascii_digit()).map_or(s.len(), |k| at + k);
                    let big =
                        ["0", "-1", "18446744073709551616", "999999999999", "1e308", "4294967297", "nan"];
                    let mut t = s[..at].to_string();
                    t.push_str(big[rng.random_range(0..big.len())]);
                    t.push_str(&s[end..]);
                    bytes = t.into_bytes();
                }
            }
            total += 1;
            rejected += usize::from(!exercise(kind, &bytes, &partner));
        }
    }
    // The mutations must actually reach the error paths.
    assert!(rejected > total / 3, "only {rejected} of {total} corruptions were rejected");
}

#[test]
fn huge_counts_fail_fast_without_huge_allocations() {
    let start = std::time::Instant::now();
    let msh = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n18446744073709551615\n1 0 0 0\n$EndNodes\n";
    assert!(parse_gmsh(msh, "f.msh").is_err());
    let msh41 =
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 999999999999999 1 2\n3 1 0 999999999999999\n1\n";
    assert!(parse_gmsh(msh41, "f.msh").is_err());
    let node = "999999999999999999 3 0 0\n1 0 0 0\n";
    assert!(parse_tetgen(node, "f.node", "0 4 0\n", "f.ele").is_err());
    let node = "1 3 99999999999 0\n1 0 0 0\n";
    assert!(parse_tetgen(node, "f.node", "0 4 0\n", "f.ele").is_err());
    assert!(start.elapsed().as_secs_f64() < 1.0);
}
