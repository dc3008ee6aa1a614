//! Ready-to-pose scenes for the command line, examples and the conformance suite.
//!
//! | scene | what |
//! | --- | --- |
//! | [`twisted_cylinder`] | a closed cylinder on two joints, the second twisting by 180 degrees about the axis over 2 s: LBS collapses the middle to the axis (the candy wrapper), DQS keeps its volume |
//! | `from_gltf` | any skinned glTF 2.0 file, its first animation (feature `gltf`) |
//!
//! A [`SkinScene`] is posed at time `t` with either method into positions and normals
//! ([`SkinScene::pose`], then [`CharacterData::positions`]); [`Character::triangles`] gives the
//! triangles.

use crate::SkinError;
use crate::character::{Character, CharacterData, CharacterMesh};
use crate::clip::{Channel, Clip, Interpolation, Property};
#[cfg(feature = "gltf")]
use crate::gltf_io::{self, LoadError};
use crate::mesh::{SkinnedMesh, signed_volume};
use crate::skeleton::{Joint, Skeleton, Skin, Trs};
use crate::skinning::SkinningMethod;
use anim_core::glam::{DMat4, DQuat, DVec3, DVec4};
#[cfg(feature = "gltf")]
use std::path::Path;

/// A character with the clip to play and how long to play it.
#[derive(Debug, Clone)]
pub struct SkinScene {
    /// Short name.
    pub name: String,
    /// One-line description.
    pub description: String,
    /// The model.
    pub character: Character,
    /// The clip to play (`None`: the rest pose).
    pub clip: Option<usize>,
    /// Suggested duration (s): the clip's end.
    pub duration: f64,
    /// Suggested method.
    pub method: SkinningMethod,
    /// What the loader skipped.
    pub warnings: Vec<String>,
}

impl SkinScene {
    /// Buffers for posing (make once, reuse every frame).
    #[must_use]
    pub fn data(&self) -> CharacterData {
        self.character.data()
    }

    /// Poses the scene's clip at `t` with `method` into `data`.
    ///
    /// # Errors
    /// [`SkinError::NonRigidJoint`] for DQS on scaled joints.
    pub fn pose(&self, data: &mut CharacterData, t: f64, method: SkinningMethod) -> Result<(), SkinError> {
        self.character.pose(data, self.clip, t, method)
    }

    /// Enclosed volume of the rest pose (meaningful for closed meshes).
    #[must_use]
    pub fn rest_volume(&self) -> f64 {
        self.character
            .meshes
            .iter()
            .map(|m| signed_volume(&m.mesh.x, &m.mesh.y, &m.mesh.z, m.mesh.triangles()))
            .sum()
    }
}

/// Enclosed signed volume of the posed meshes in `data`.
#[must_use]
pub fn volume(character: &Character, data: &CharacterData) -> f64 {
    character
        .meshes
        .iter()
        .zip(&data.skinned)
        .map(|(m, s)| signed_volume(&s.x, &s.y, &s.z, m.mesh.triangles()))
        .sum()
}

/// The built-in scene names.
pub const NAMES: [&str; 1] = ["twisted-cylinder"];

/// Twisted cylinder: radius 0.25, length 2 along +x, closed by caps; joint 0 at the origin, joint
/// 1 at `x = 1`; weights ramp linearly from joint 0 to joint 1 over `0.5 <= x <= 1.5`. The clip
/// rotates joint 1 about x by 0, 90 and 180 degrees at t = 0, 1, 2 s (LINEAR). `resolution` is
/// the number of segments around (default 32; rings along the axis are `1.25 x` that).
///
/// # Errors
/// [`SkinError::BadMesh`] if `resolution < 3`.
pub fn twisted_cylinder(resolution: Option<usize>) -> Result<SkinScene, SkinError> {
    let seg = resolution.unwrap_or(32);
    if seg < 3 {
        return Err(SkinError::BadMesh(format!("twisted cylinder needs 3 or more segments, got {seg}")));
    }
    let rings = seg * 5 / 4 + 1;
    let (radius, length) = (0.25, 2.0);
    let weight1 = |x: f64| ((x - 0.5) / 1.0).clamp(0.0, 1.0);
    let mut pos = Vec::new();
    let mut w = Vec::new();
    for r in 0..rings {
        let x = length * r as f64 / (rings - 1) as f64;
        for s in 0..seg {
            let a = std::f64::consts::TAU * s as f64 / seg as f64;
            pos.push([x, radius * a.cos(), radius * a.sin()]);
            w.push(weight1(x));
        }
    }
    let c0 = pos.len() as u32;
    pos.push([0.0, 0.0, 0.0]);
    w.push(weight1(0.0));
    let c1 = pos.len() as u32;
    pos.push([length, 0.0, 0.0]);
    w.push(weight1(length));
    let id = |r: usize, s: usize| (r * seg + s % seg) as u32;
    let mut tris = Vec::new();
    for r in 0..rings - 1 {
        for s in 0..seg {
            // Outward (counter-clockwise seen from outside): the circle runs y -> z, i.e.
            // counter-clockwise about +x.
            tris.push([id(r, s), id(r, s + 1), id(r + 1, s)]);
            tris.push([id(r + 1, s), id(r, s + 1), id(r + 1, s + 1)]);
        }
    }
    for s in 0..seg {
        tris.push([c0, id(0, s + 1), id(0, s)]);
        tris.push([c1, id(rings - 1, s), id(rings - 1, s + 1)]);
    }
    let joints: Vec<u16> = (0..pos.len()).flat_map(|_| [0u16, 1]).collect();
    let weights: Vec<f64> = w.iter().flat_map(|&b| [1.0 - b, b]).collect();
    let mesh = SkinnedMesh::new(&pos, None, 2, &joints, &weights, tris, 2)?;
    let skeleton = Skeleton::new(vec![
        Joint { name: "root".into(), parent: None, rest: Trs::IDENTITY },
        Joint {
            name: "twist".into(),
            parent: Some(0),
            rest: Trs::new(DVec3::X, DQuat::IDENTITY, DVec3::ONE),
        },
    ])?;
    let skin = Skin::new(&skeleton, vec![0, 1], vec![DMat4::IDENTITY, DMat4::from_translation(-DVec3::X)])?;
    let keys: Vec<DVec4> = [0.0, 90.0, 180.0]
        .iter()
        .map(|d: &f64| DVec4::from(DQuat::from_rotation_x(d.to_radians())))
        .collect();
    let channel = Channel::new(1, Property::Rotation, Interpolation::Linear, vec![0.0, 1.0, 2.0], keys)?;
    let clip = Clip::new("twist", vec![channel], 2)?;
    let character = Character::new(
        skeleton,
        vec![skin],
        vec![CharacterMesh { name: "cylinder".into(), skin: 0, mesh, source: None }],
        vec![clip],
    )?;
    Ok(SkinScene {
        name: "twisted-cylinder".into(),
        description:
            "a cylinder on two joints twisted by 180 degrees: LBS collapses (candy wrapper), DQS keeps volume"
                .into(),
        character,
        clip: Some(0),
        duration: 2.0,
        method: SkinningMethod::Dqs,
        warnings: Vec::new(),
    })
}

/// A scene from a skinned glTF 2.0 file (`.gltf` or `.glb`) (feature `gltf`), playing its first animation (the
/// rest pose if it has none) with LBS, which handles scaled joints.
///
/// # Errors
/// What [`gltf_io::load`] returns.
#[cfg(feature = "gltf")]
pub fn from_gltf(path: impl AsRef<Path>) -> Result<SkinScene, LoadError> {
    let path = path.as_ref();
    scene_of(gltf_io::load(path)?, path)
}

/// The scene of a skinned glTF given as bytes (`.gltf` JSON or `.glb`); `path` names it in
/// errors and is the folder external buffers are read from.
///
/// # Errors
/// As [`from_gltf`].
#[cfg(feature = "gltf")]
pub fn from_gltf_slice(bytes: &[u8], path: &Path) -> Result<SkinScene, LoadError> {
    scene_of(gltf_io::load_slice(bytes, path)?, path)
}

#[cfg(feature = "gltf")]
fn scene_of(loaded: gltf_io::Loaded, path: &Path) -> Result<SkinScene, LoadError> {
    let character = loaded.character;
    let clip = (!character.clips.is_empty()).then_some(0);
    let duration = clip.map_or(0.0, |c| character.clips[c].end());
    Ok(SkinScene {
        name: path.file_stem().map_or_else(|| "gltf".into(), |s| s.to_string_lossy().into_owned()),
        description: format!("skinned glTF {}", path.display()),
        character,
        clip,
        duration,
        method: SkinningMethod::Lbs,
        warnings: loaded.warnings,
    })
}
