//! glTF 2.0 input through the `gltf` crate: `.gltf` with external or embedded (base64 data URI)
//! buffers, and `.glb`.
//!
//! What is read: the node hierarchy (every node becomes a [`Joint`], parents
//! first; `matrix` nodes are decomposed into TRS and rejected if they shear), skins (joints and
//! inverse bind matrices, identity when absent), every triangle primitive of every skinned mesh
//! node (`POSITION`, `NORMAL`, indices, `JOINTS_0/WEIGHTS_0` and `JOINTS_1/WEIGHTS_1` for up to 8
//! influences; joints as unsigned byte or short, weights as float or normalised unsigned
//! byte/short; one [`CharacterMesh`] per skinned node and primitive, which records them in its
//! [`GltfSource`]), and every animation's translation, rotation and scale channels with STEP,
//! LINEAR and CUBICSPLINE samplers.
//!
//! What is refused with a [`LoadError`]: morph targets on a skinned primitive, sparse accessors,
//! non-triangle primitives, any extension in `extensionsRequired`, and extensions that change
//! geometry even when only used (Draco, meshopt, mesh quantization, GPU instancing); a required
//! extension is named before anything else is checked, and invalid glTF names its first few
//! problems and counts the rest, so an error stays one line. What is
//! skipped with a warning in [`Loaded::warnings`]: meshes on nodes without a skin, morph target
//! weight channels, other used extensions (materials and the like do not change the pose).
//! What is changed, with a note there and a count in [`Loaded::renormalised`]: weights that do
//! not sum to 1 within [`WEIGHT_SUM_TOLERANCE`] are renormalised (as [`SkinnedMesh::new`] does
//! for any mesh), not refused.
//!
//! Buffers are resolved here rather than by `gltf::import` so the `image` decoders are not
//! compiled in: a GLB's binary chunk, `data:` URIs in base64, or files relative to the glTF file.

use crate::character::{Character, CharacterMesh, GltfSource};
use crate::clip::{Channel, Clip, Interpolation, Property};
use crate::mesh::SkinnedMesh;
use crate::skeleton::{Joint, Skeleton, Skin, Trs};
use anim_core::glam::{DMat4, DQuat, DVec3, DVec4};
use gltf::animation::util::ReadOutputs;
use std::path::{Path, PathBuf};

/// A glTF file that could not be loaded: the file, the element (node, mesh, accessor,
/// animation ... with its index) and the cause.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}: {element}: {cause}", file.display())]
pub struct LoadError {
    /// The file.
    pub file: PathBuf,
    /// The element, e.g. `mesh 0 primitive 1` or `accessor 7`.
    pub element: String,
    /// What is wrong.
    pub cause: String,
}

/// A loaded character and what was ignored.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// Skeleton (one joint per glTF node), skins, skinned meshes, clips.
    pub character: Character,
    /// Notes on reading the file: parts that were skipped (never ones that change a skinned
    /// pose) and vertices whose weights were renormalised (one note per primitive, as in
    /// [`Loaded::renormalised`]).
    pub warnings: Vec<String>,
    /// Skeleton joint of each glTF node index.
    pub node_joint: Vec<usize>,
    /// The meshes with vertices whose weights did not sum to 1 (within
    /// [`WEIGHT_SUM_TOLERANCE`]) and were renormalised.
    pub renormalised: Vec<Renormalised>,
}

/// Vertices of one mesh whose weights were renormalised on loading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Renormalised {
    /// Index into [`Character::meshes`].
    pub mesh: usize,
    /// Vertices whose weights did not sum to 1.
    pub vertices: usize,
    /// Vertices of the mesh.
    pub of: usize,
    /// Largest `|sum of weights - 1|` among them.
    pub max_deviation: f64,
}

/// A vertex's weights (as read, in f64) sum to 1 if within this: above the rounding of a sum of
/// 8 f32 weights (`8 * 2^-24 = 4.8e-7`) and far below any authored difference.
pub const WEIGHT_SUM_TOLERANCE: f64 = 1e-6;

/// How many vertices of `k` weights each do not sum to 1 within [`WEIGHT_SUM_TOLERANCE`], and
/// the largest deviation among them.
fn weight_sums_off(weights: &[f64], k: usize) -> (usize, f64) {
    let mut off = 0;
    let mut worst = 0.0f64;
    for w in weights.chunks_exact(k) {
        let d = (w.iter().sum::<f64>() - 1.0).abs();
        if d > WEIGHT_SUM_TOLERANCE {
            off += 1;
            worst = worst.max(d);
        }
    }
    (off, worst)
}

/// Extensions that change geometry or accessors: refused even if only "used".
const GEOMETRY_EXTENSIONS: [&str; 5] = [
    "KHR_draco_mesh_compression",
    "KHR_mesh_quantization",
    "EXT_meshopt_compression",
    "EXT_mesh_gpu_instancing",
    "KHR_materials_variants_geometry",
];

/// Loads a `.gltf` or `.glb` file.
///
/// # Errors
/// A [`LoadError`] naming the file, element and cause for unreadable files, invalid glTF,
/// unsupported features (see the module doc) and invalid data (bad weights, joint indices,
/// non-increasing key times, accessors out of their buffers).
pub fn load(path: impl AsRef<Path>) -> Result<Loaded, LoadError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| LoadError {
        file: path.to_path_buf(),
        element: "file".into(),
        cause: e.to_string(),
    })?;
    load_slice(&bytes, path)
}

/// Loads the bytes of a `.gltf` or `.glb` file. `path` names the file in errors, and external
/// buffers (relative URIs) are read from its folder.
///
/// # Errors
/// As [`load`].
pub fn load_slice(bytes: &[u8], path: &Path) -> Result<Loaded, LoadError> {
    let err = |element: &str, cause: String| LoadError {
        file: path.to_path_buf(),
        element: element.to_string(),
        cause,
    };
    // Parse, check the accessor indices of mesh primitives, then validate: the glTF crate's own
    // validation indexes the POSITION accessor before checking that it exists.
    let unchecked =
        gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| err("document", e.to_string()))?;
    {
        let json = unchecked.document.as_json();
        // Required extensions first: the glTF crate's validation reports every element an
        // unsupported extension (Draco, meshopt) leaves incomplete, hundreds of lines for one cause.
        if let Some(ext) = json.extensions_required.first() {
            return Err(err("extensionsRequired", format!("extension {ext} is required but not supported")));
        }
        let accessors = json.accessors.len();
        for (m, mesh) in json.meshes.iter().enumerate() {
            for (p, prim) in mesh.primitives.iter().enumerate() {
                if let Some(bad) =
                    prim.attributes.values().chain(&prim.indices).find(|i| i.value() >= accessors)
                {
                    return Err(err(
                        &format!("mesh {m} primitive {p}"),
                        format!("accessor {} does not exist (the file has {accessors})", bad.value()),
                    ));
                }
            }
        }
        // The glTF crate validates an animation's samplers but not its channels' targets: an
        // unknown path or a missing node would panic when read.
        for (a, anim) in json.animations.iter().enumerate() {
            for (c, ch) in anim.channels.iter().enumerate() {
                let el = format!("animation {a} channel {c}");
                if !matches!(ch.target.path, gltf::json::validation::Checked::Valid(_)) {
                    return Err(err(
                        &el,
                        "target path is not one of translation, rotation, scale, weights".into(),
                    ));
                }
                if ch.target.node.value() >= json.nodes.len() {
                    return Err(err(
                        &el,
                        format!(
                            "target node {} does not exist (the file has {})",
                            ch.target.node.value(),
                            json.nodes.len()
                        ),
                    ));
                }
            }
        }
    }
    let blob = unchecked.blob;
    let document =
        gltf::Document::from_json(unchecked.document.into_json()).map_err(|e| err("document", short(&e)))?;
    let gltf = gltf::Gltf { document, blob };
    let doc = &gltf.document;
    let mut warnings = Vec::new();

    for ext in doc.extensions_used() {
        if GEOMETRY_EXTENSIONS.contains(&ext) {
            return Err(err(
                "extensionsUsed",
                format!("extension {ext} changes geometry and is not supported"),
            ));
        }
        warnings.push(format!("extension {ext} is used and ignored (it does not change skinned geometry)"));
    }

    // Buffers.
    let base = path.parent().unwrap_or(Path::new("."));
    let mut buffers: Vec<Vec<u8>> = Vec::new();
    for b in doc.buffers() {
        let el = format!("buffer {}", b.index());
        let data = match b.source() {
            gltf::buffer::Source::Bin => gltf
                .blob
                .clone()
                .ok_or_else(|| err(&el, "refers to the GLB binary chunk, which is missing".into()))?,
            gltf::buffer::Source::Uri(uri) => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let (meta, payload) =
                        rest.split_once(',').ok_or_else(|| err(&el, "data URI without a comma".into()))?;
                    if !meta.ends_with(";base64") {
                        return Err(err(&el, format!("data URI {meta:?} is not base64")));
                    }
                    base64_decode(payload).map_err(|c| err(&el, c))?
                } else {
                    let file = base.join(percent_decode(uri));
                    std::fs::read(&file).map_err(|e| err(&el, format!("{}: {e}", file.display())))?
                }
            }
        };
        if data.len() < b.length() {
            return Err(err(&el, format!("holds {} bytes, byteLength says {}", data.len(), b.length())));
        }
        buffers.push(data);
    }
    let get = |b: gltf::Buffer<'_>| buffers.get(b.index()).map(Vec::as_slice);
    let check = |a: &gltf::Accessor<'_>| -> Result<(), LoadError> {
        let el = format!("accessor {}", a.index());
        if a.sparse().is_some() {
            return Err(err(&el, "sparse accessors are not supported".into()));
        }
        let view = a.view().ok_or_else(|| err(&el, "no bufferView (not supported)".into()))?;
        if a.count() == 0 {
            return Err(err(&el, "count is 0".into()));
        }
        let buf = buffers.get(view.buffer().index()).map_or(0, Vec::len);
        if view.offset() + view.length() > buf {
            return Err(err(&el, format!("bufferView {} overruns its buffer", view.index())));
        }
        let stride = view.stride().unwrap_or(a.size());
        let end = a.offset() + stride * (a.count() - 1) + a.size();
        if end > view.length() {
            return Err(err(
                &el,
                format!("needs {end} bytes of bufferView {}, which has {}", view.index(), view.length()),
            ));
        }
        Ok(())
    };

    // Node hierarchy, parents first.
    let n_nodes = doc.nodes().len();
    let mut parent: Vec<Option<usize>> = vec![None; n_nodes];
    for node in doc.nodes() {
        for c in node.children() {
            if let Some(p) = parent[c.index()] {
                return Err(err(
                    &format!("node {}", c.index()),
                    format!("has two parents ({p} and {})", node.index()),
                ));
            }
            parent[c.index()] = Some(node.index());
        }
    }
    let mut order = Vec::with_capacity(n_nodes);
    let mut stack: Vec<usize> = (0..n_nodes).rev().filter(|&i| parent[i].is_none()).collect();
    let nodes: Vec<gltf::Node<'_>> = doc.nodes().collect();
    while let Some(i) = stack.pop() {
        order.push(i);
        let children: Vec<usize> = nodes[i].children().map(|c| c.index()).collect();
        stack.extend(children.into_iter().rev());
    }
    if order.len() != n_nodes {
        return Err(err("nodes", "the node hierarchy has a cycle".into()));
    }
    let mut node_joint = vec![0; n_nodes];
    for (j, &i) in order.iter().enumerate() {
        node_joint[i] = j;
    }
    let mut joints = Vec::with_capacity(n_nodes);
    for &i in &order {
        let node = &nodes[i];
        let el = format!("node {i}");
        let rest = node_trs(node).map_err(|c| err(&el, c))?;
        joints.push(Joint {
            name: node.name().map_or_else(|| format!("node{i}"), str::to_string),
            parent: parent[i].map(|p| node_joint[p]),
            rest,
        });
    }
    let skeleton = Skeleton::new(joints).map_err(|e| err("nodes", e.to_string()))?;

    // Skins.
    let mut skins = Vec::new();
    for s in doc.skins() {
        let el = format!("skin {}", s.index());
        let js: Vec<usize> = s.joints().map(|n| node_joint[n.index()]).collect();
        let ibm = match s.inverse_bind_matrices() {
            Some(a) => {
                check(&a)?;
                let m: Vec<DMat4> = s
                    .reader(get)
                    .read_inverse_bind_matrices()
                    .ok_or_else(|| err(&el, "inverse bind matrices unreadable".into()))?
                    .map(|m| DMat4::from_cols_array_2d(&m.map(|c| c.map(f64::from))))
                    .collect();
                if m.len() != js.len() {
                    return Err(err(
                        &el,
                        format!("{} joints but {} inverse bind matrices", js.len(), m.len()),
                    ));
                }
                m
            }
            None => vec![DMat4::IDENTITY; js.len()],
        };
        skins.push(Skin::new(&skeleton, js, ibm).map_err(|e| err(&el, e.to_string()))?);
    }

    // Skinned meshes.
    let mut meshes = Vec::new();
    let mut renormalised = Vec::new();
    for node in &nodes {
        let Some(mesh) = node.mesh() else { continue };
        let Some(skin) = node.skin() else {
            warnings.push(format!("node {} has mesh {} without a skin: skipped", node.index(), mesh.index()));
            continue;
        };
        let n_joints = skins[skin.index()].len();
        for prim in mesh.primitives() {
            let el = format!("mesh {} primitive {}", mesh.index(), prim.index());
            if prim.morph_targets().next().is_some() {
                return Err(err(&el, "morph targets are not supported".into()));
            }
            if prim.mode() != gltf::mesh::Mode::Triangles {
                return Err(err(&el, format!("mode {:?} is not supported (triangles only)", prim.mode())));
            }
            for (semantic, a) in prim.attributes() {
                check(&a)?;
                attribute_types(&semantic, &a).map_err(|c| err(&format!("{el} {semantic:?}"), c))?;
            }
            if let Some(a) = prim.indices() {
                check(&a)?;
                use gltf::accessor::{DataType, Dimensions};
                if !matches!(a.data_type(), DataType::U8 | DataType::U16 | DataType::U32)
                    || a.dimensions() != Dimensions::Scalar
                {
                    return Err(err(
                        &format!("{el} indices"),
                        format!(
                            "{:?} {:?}: indices must be unsigned integer scalars",
                            a.data_type(),
                            a.dimensions()
                        ),
                    ));
                }
            }
            let r = prim.reader(get);
            let pos: Vec<[f64; 3]> = r
                .read_positions()
                .ok_or_else(|| err(&el, "no POSITION".into()))?
                .map(|p| p.map(f64::from))
                .collect();
            let n = pos.len();
            let nrm: Option<Vec<[f64; 3]>> =
                r.read_normals().map(|it| it.map(|p| p.map(f64::from)).collect());
            let has_second = r.read_joints(1).is_some() || r.read_weights(1).is_some();
            let k = if has_second { 8 } else { 4 };
            let mut joints = vec![0u16; n * k];
            let mut weights = vec![0.0f64; n * k];
            for set in 0..k / 4 {
                let js: Vec<[u16; 4]> = r
                    .read_joints(set as u32)
                    .ok_or_else(|| err(&el, format!("no JOINTS_{set}")))?
                    .into_u16()
                    .collect();
                let ws: Vec<[f32; 4]> = r
                    .read_weights(set as u32)
                    .ok_or_else(|| err(&el, format!("no WEIGHTS_{set}")))?
                    .into_f32()
                    .collect();
                if js.len() != n || ws.len() != n {
                    return Err(err(
                        &el,
                        format!("{n} positions, {} JOINTS_{set}, {} WEIGHTS_{set}", js.len(), ws.len()),
                    ));
                }
                for v in 0..n {
                    for i in 0..4 {
                        joints[v * k + 4 * set + i] = js[v][i];
                        weights[v * k + 4 * set + i] = f64::from(ws[v][i]);
                    }
                }
            }
            let idx: Vec<u32> = match r.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..n as u32).collect(),
            };
            if !idx.len().is_multiple_of(3) {
                return Err(err(&el, format!("{} indices is not a multiple of 3", idx.len())));
            }
            let tris: Vec<[u32; 3]> = idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            if let Some(nr) = &nrm
                && nr.len() != n
            {
                return Err(err(&el, format!("{n} positions but {} normals", nr.len())));
            }
            let (off, worst) = weight_sums_off(&weights, k);
            let m = SkinnedMesh::new(&pos, nrm.as_deref(), k, &joints, &weights, tris, n_joints)
                .map_err(|e| err(&el, e.to_string()))?;
            if off > 0 {
                warnings.push(format!(
                    "{el}: weights of {off} of {n} vertices do not sum to 1 (off by up to {worst:.1e}): renormalised"
                ));
                renormalised.push(Renormalised {
                    mesh: meshes.len(),
                    vertices: off,
                    of: n,
                    max_deviation: worst,
                });
            }
            meshes.push(CharacterMesh {
                name: format!(
                    "{}#{}",
                    mesh.name().map_or_else(|| format!("mesh{}", mesh.index()), str::to_string),
                    prim.index()
                ),
                skin: skin.index(),
                mesh: m,
                source: Some(GltfSource { node: node.index(), mesh: mesh.index(), primitive: prim.index() }),
            });
        }
    }

    // Animations.
    let mut clips = Vec::new();
    for anim in doc.animations() {
        let mut channels = Vec::new();
        for ch in anim.channels() {
            let el = format!("animation {} channel {}", anim.index(), ch.index());
            let sampler = ch.sampler();
            check(&sampler.input())?;
            check(&sampler.output())?;
            let r = ch.reader(get);
            let times: Vec<f64> =
                r.read_inputs().ok_or_else(|| err(&el, "input unreadable".into()))?.map(f64::from).collect();
            let outputs = r.read_outputs().ok_or_else(|| err(&el, "output unreadable".into()))?;
            let (property, values): (Property, Vec<DVec4>) = match outputs {
                ReadOutputs::Translations(it) => (Property::Translation, it.map(vec3).collect()),
                ReadOutputs::Scales(it) => (Property::Scale, it.map(vec3).collect()),
                ReadOutputs::Rotations(it) => {
                    (Property::Rotation, it.into_f32().map(|q| DVec4::from_array(q.map(f64::from))).collect())
                }
                ReadOutputs::MorphTargetWeights(_) => {
                    warnings.push(format!("{el}: morph target weights ignored"));
                    continue;
                }
            };
            let interpolation = match sampler.interpolation() {
                gltf::animation::Interpolation::Step => Interpolation::Step,
                gltf::animation::Interpolation::Linear => Interpolation::Linear,
                gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
            };
            let joint = node_joint[ch.target().node().index()];
            channels.push(
                Channel::new(joint, property, interpolation, times, values)
                    .map_err(|e| err(&el, format!("node {}: {e}", ch.target().node().index())))?,
            );
        }
        let name = anim.name().map_or_else(|| format!("animation{}", anim.index()), str::to_string);
        clips.push(
            Clip::new(name, channels, skeleton.len())
                .map_err(|e| err(&format!("animation {}", anim.index()), e.to_string()))?,
        );
    }

    let character =
        Character::new(skeleton, skins, meshes, clips).map_err(|e| err("skins", e.to_string()))?;
    Ok(Loaded { character, warnings, node_joint, renormalised })
}

/// A glTF crate error, its validation list cut to the first [`SHOWN_ERRORS`] entries and a count.
fn short(e: &gltf::Error) -> String {
    match e {
        gltf::Error::Validation(list) if list.len() > SHOWN_ERRORS => {
            let shown: Vec<String> =
                list[..SHOWN_ERRORS].iter().map(|(path, e)| format!("{path}: {e}")).collect();
            format!("invalid glTF: {} (and {} more)", shown.join(", "), list.len() - SHOWN_ERRORS)
        }
        _ => e.to_string(),
    }
}

/// Validation errors named in a [`LoadError`]; the rest are counted.
const SHOWN_ERRORS: usize = 3;

fn vec3(v: [f32; 3]) -> DVec4 {
    DVec4::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2]), 0.0)
}

/// A node's TRS; `matrix` transforms are decomposed and must reconstruct within `1e-5`.
fn node_trs(node: &gltf::Node<'_>) -> Result<Trs, String> {
    let trs = match node.transform() {
        gltf::scene::Transform::Decomposed { translation, rotation, scale } => {
            let q = DQuat::from_array(rotation.map(f64::from));
            let l = q.length();
            if !(l > 0.0) || (l - 1.0).abs() > 1e-3 {
                return Err(format!("rotation {rotation:?} is not a unit quaternion"));
            }
            Trs::new(
                DVec3::from_array(translation.map(f64::from)),
                q / l,
                DVec3::from_array(scale.map(f64::from)),
            )
        }
        gltf::scene::Transform::Matrix { matrix } => {
            let m = DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from)));
            let (s, r, t) = m.to_scale_rotation_translation();
            let trs = Trs::new(t, r.normalize(), s);
            let back = trs.to_matrix();
            let dev = (back - m).to_cols_array().iter().fold(0.0f64, |a, b| a.max(b.abs()));
            if !(dev <= 1e-5 * m.to_cols_array().iter().fold(1.0f64, |a, b| a.max(b.abs()))) {
                return Err(format!(
                    "matrix is not a translation-rotation-scale (shear or projection; deviation {dev:.2e})"
                ));
            }
            trs
        }
    };
    if !trs.is_valid() {
        return Err("transform is not finite".into());
    }
    Ok(trs)
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let hex = |c: u8| (c as char).to_digit(16);
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%'
            && i + 2 < b.len()
            && let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2]))
        {
            out.push((h * 16 + l) as u8);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Standard base64 (RFC 4648, with or without padding).
fn base64_decode(s: &str) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(s.len() * 3 / 4);
    let (mut acc, mut bits) = (0u32, 0u32);
    for (i, c) in s.bytes().enumerate() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' => break,
            b' ' | b'\n' | b'\r' | b'\t' => continue,
            _ => return Err(format!("invalid base64 character {:?} at {i}", c as char)),
        };
        acc = (acc << 6) | u32::from(v);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Ok(out)
}

/// The component types and shapes glTF 2.0 allows for the attributes this loader reads
/// (specification 3.7.2.1); anything else is refused here rather than misread.
fn attribute_types(semantic: &gltf::Semantic, a: &gltf::Accessor<'_>) -> Result<(), String> {
    use gltf::Semantic;
    use gltf::accessor::{DataType, Dimensions};
    let (types, dims): (&[DataType], Dimensions) = match semantic {
        Semantic::Positions | Semantic::Normals => (&[DataType::F32], Dimensions::Vec3),
        Semantic::Joints(_) => (&[DataType::U8, DataType::U16], Dimensions::Vec4),
        Semantic::Weights(_) => (&[DataType::F32, DataType::U8, DataType::U16], Dimensions::Vec4),
        // Attributes the loader does not read (texture coordinates, colours, tangents).
        _ => return Ok(()),
    };
    let normalized_ok =
        a.data_type() == DataType::F32 || !matches!(semantic, Semantic::Weights(_)) || a.normalized();
    if types.contains(&a.data_type()) && a.dimensions() == dims && normalized_ok {
        Ok(())
    } else {
        Err(format!(
            "accessor {} is {:?} {:?}{}, the specification allows {:?} {:?}{}",
            a.index(),
            a.data_type(),
            a.dimensions(),
            if a.normalized() { " normalized" } else { "" },
            types,
            dims,
            if matches!(semantic, Semantic::Weights(_)) { " (integers normalized)" } else { "" }
        ))
    }
}
