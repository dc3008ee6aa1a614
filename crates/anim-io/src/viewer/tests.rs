use super::{Viewer, ViewerField};
use base64::Engine;

fn temp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("anim-io-viewer-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// The header (JSON) and the bytes of a frame script `ANIM.frame(k,{...},"...");`.
fn read_frame(path: &std::path::Path) -> (usize, serde_json::Value, Vec<u8>) {
    let text = std::fs::read_to_string(path).unwrap();
    let body = text.strip_prefix("ANIM.frame(").unwrap().strip_suffix(");\n").unwrap();
    let (k, rest) = body.split_once(',').unwrap();
    let (header, data) = rest.rsplit_once(",\"").unwrap();
    let data = data.strip_suffix('"').unwrap();
    let bytes = base64::engine::general_purpose::STANDARD.decode(data).unwrap();
    (k.parse().unwrap(), serde_json::from_str(header).unwrap(), bytes)
}

fn f32s(bytes: &[u8]) -> Vec<f32> {
    bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect()
}

/// The JSON inside `ANIM.NAME(...);`.
fn read_call(path: &std::path::Path, name: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap();
    let json = text.strip_prefix(&format!("ANIM.{name}(")).unwrap().strip_suffix(");\n").unwrap();
    serde_json::from_str(json).unwrap()
}

#[test]
fn a_frame_holds_its_points_and_fields_in_the_stated_layout() {
    let dir = temp("layout");
    let context = serde_json::json!({ "point_dim": 2, "props": [ { "Ground": { "height": 0.0 } } ] });
    let mut viewer = Viewer::create(&dir, "two points", &context, false).unwrap();
    // Two points in the plane (z filled with 0), a vector and a scalar per point.
    let x = [0.5, 1.25, -2.0, 3.0];
    let v = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
    let id = [0.0, 1.0];
    let fields = [ViewerField::points("velocity", 3, &v), ViewerField::points("material", 1, &id)];
    viewer.frame(7, 0.125, &x, 2, &fields).unwrap();
    let (k, header, bytes) = read_frame(&dir.join("viewer/f00007.js"));
    assert_eq!(k, 7);
    assert_eq!(header["t"], 0.125);
    assert_eq!(header["n"], 2);
    assert_eq!(
        header["parts"],
        serde_json::json!([["points", 3, "f32"], ["velocity", 3, "f32"], ["material", 1, "f32"]])
    );
    let values = f32s(&bytes);
    assert_eq!(values, [0.5, 1.25, 0.0, -2.0, 3.0, 0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 0.0, 1.0]);
    assert_eq!(read_call(&dir.join("viewer/context.js"), "context"), context);
    assert_eq!(
        read_call(&dir.join("viewer/index.js"), "index"),
        serde_json::json!({ "frames": [[0.125, "f00007.js"]] })
    );
    assert!(header.get("props").is_none(), "no moving props: none written");
    // A prop that moves with the scene is in its frame's header, as given.
    let pole =
        serde_json::json!([{ "Capsule": { "a": [0.0, 0.0, 0.1], "b": [0.0, 2.0, 0.1], "radius": 0.02 } }]);
    viewer.frame_with_props(8, 0.25, &x, 2, &fields, &pole).unwrap();
    let (_, header, _) = read_frame(&dir.join("viewer/f00008.js"));
    assert_eq!(header["props"], pole);
    let page = viewer.finish().unwrap();
    assert_eq!(page, dir.join("viewer.html"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn cell_fields_are_bytes_over_their_range_padded_to_four() {
    let dir = temp("cells");
    let mut viewer = Viewer::create(&dir, "grid", &serde_json::json!({}), false).unwrap();
    // Five cells over [1, 3]: 1 -> 0, 2 -> 127.5 (rounds to 128), 3 -> 255; outside clamps.
    let density = [1.0, 2.0, 3.0, 0.0, 9.0];
    viewer.frame(0, 0.0, &[], 3, &[ViewerField::cells("density", &density, (1.0, 3.0))]).unwrap();
    let (_, header, bytes) = read_frame(&dir.join("viewer/f00000.js"));
    assert_eq!(header["n"], 0);
    assert_eq!(header["parts"][1], serde_json::json!(["density", 1, "u8", 1.0, 3.0]));
    assert_eq!(bytes, [0, 128, 255, 0, 255, 0, 0, 0]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_frames_are_refused_naming_the_field_and_nothing_is_listed() {
    let dir = temp("bad");
    let mut viewer = Viewer::create(&dir, "bad", &serde_json::json!({}), false).unwrap();
    let x = [0.0, 1.0, 2.0];
    let e = viewer.frame(0, 0.0, &x, 3, &[ViewerField::points("velocity", 3, &[1.0, 2.0])]).unwrap_err();
    assert!(e.to_string().contains("field `velocity` has 2 values, not 3 per point for 1 points"), "{e}");
    let e = viewer.frame(0, 0.0, &[0.0, f64::NAN, 2.0], 3, &[]).unwrap_err();
    assert!(e.to_string().contains("`points` value 1 is NaN"), "{e}");
    let e = viewer.frame(0, 0.0, &[0.0; 4], 3, &[]).unwrap_err();
    assert!(e.to_string().contains("4 coordinates are not 3 per point"), "{e}");
    let e = viewer.frame(0, 0.0, &[0.0; 4], 4, &[]).unwrap_err();
    assert!(e.to_string().contains("points of 4 coordinates"), "{e}");
    assert!(viewer.is_empty());
    assert_eq!(read_call(&dir.join("viewer/index.js"), "index"), serde_json::json!({ "frames": [] }));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_resumed_run_lists_the_earlier_frames_present_and_continues_after_them() {
    let dir = temp("resume");
    let mut first = Viewer::create(&dir, "run", &serde_json::json!({}), false).unwrap();
    for k in 0..3 {
        first.frame(k, k as f64, &[0.0, 0.0, k as f64], 3, &[]).unwrap();
    }
    drop(first);
    // Frame 1 of the earlier part is gone (moved away by the user): it is not listed.
    std::fs::remove_file(dir.join("viewer/f00001.js")).unwrap();
    let mut resumed = Viewer::create(&dir, "run", &serde_json::json!({}), true).unwrap();
    resumed.frame(3, 3.0, &[0.0, 0.0, 3.0], 3, &[]).unwrap();
    assert_eq!(resumed.len(), 3);
    resumed.finish().unwrap();
    let index = read_call(&dir.join("viewer/index.js"), "index");
    assert_eq!(
        index,
        serde_json::json!({ "frames": [[0.0, "f00000.js"], [2.0, "f00002.js"], [3.0, "f00003.js"]] })
    );
    // A fresh run in the same folder lists only its own frames.
    let fresh = Viewer::create(&dir, "run", &serde_json::json!({}), false).unwrap();
    assert!(fresh.is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_page_embeds_three_and_the_viewer_and_escapes_its_title() {
    let dir = temp("page");
    Viewer::create(&dir, "a <b> & \"c\"", &serde_json::json!({}), false).unwrap();
    let page = std::fs::read_to_string(dir.join("viewer.html")).unwrap();
    assert!(page.contains("<title>a &lt;b&gt; &amp; &quot;c&quot; - anim viewer</title>"));
    // The import map's data URLs decode to the vendored files, byte for byte.
    let map = page.split("<script type=\"importmap\">").nth(1).unwrap().split("</script>").next().unwrap();
    let map: serde_json::Value = serde_json::from_str(map).unwrap();
    for (name, text) in [("three", super::THREE), ("three/orbit", super::ORBIT)] {
        let url = map["imports"][name].as_str().unwrap();
        let b64 = url.strip_prefix("data:text/javascript;base64,").unwrap();
        assert_eq!(base64::engine::general_purpose::STANDARD.decode(b64).unwrap(), text.as_bytes());
    }
    // The viewer's code is inline, and cannot end its script element early.
    assert!(page.contains("import { OrbitControls } from \"three/orbit\";"));
    assert!(!super::CODE.contains("</script"));
    assert!(page.contains("<script src=\"viewer/context.js\"></script>"));
    std::fs::remove_dir_all(&dir).unwrap();
}
