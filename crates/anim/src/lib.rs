#![doc = include_str!("../README.md")]

pub use anim_core as core;
pub use anim_fem as fem;
pub use anim_flip as flip;
pub use anim_fluid as fluid;
pub use anim_io as io;
pub use anim_material as material;
pub use anim_mpm as mpm;
pub use anim_pbd as pbd;
pub use anim_rigid as rigid;
pub use anim_skin as skin;
pub use anim_springs as springs;

use anim_core::scene::{Preset, SceneKind};

/// One crate of the workspace: its scene kinds and, with the `cases` feature, its cases.
#[derive(Clone, Copy)]
pub struct Member {
    /// The crate's name (`anim-fem`).
    pub name: &'static str,
    /// The scene kinds it registers (none for the crates that only read or model: `anim-io`,
    /// `anim-material`).
    pub kinds: &'static [SceneKind],
    /// Registers the crate's conformance checks, hard cases, soak runs and studies.
    #[cfg(feature = "cases")]
    pub cases: fn(&mut anim_core::cases::Registry),
}

/// A [`Member`] from the crate's name, its library path and its kinds.
macro_rules! member {
    ($name:literal, $lib:ident, $kinds:expr) => {
        Member {
            name: $name,
            kinds: $kinds,
            #[cfg(feature = "cases")]
            cases: $lib::cases::register,
        }
    };
}

/// Every crate, one line each, in the order `anim list` and the reports show them.
pub const CRATES: [Member; 11] = [
    member!("anim-springs", anim_springs, std::slice::from_ref(&anim_springs::KIND)),
    member!("anim-pbd", anim_pbd, std::slice::from_ref(&anim_pbd::KIND)),
    member!("anim-rigid", anim_rigid, std::slice::from_ref(&anim_rigid::KIND)),
    member!("anim-skin", anim_skin, std::slice::from_ref(&anim_skin::KIND)),
    member!("anim-fem", anim_fem, std::slice::from_ref(&anim_fem::KIND)),
    member!("anim-mpm", anim_mpm, std::slice::from_ref(&anim_mpm::KIND)),
    member!("anim-fluid", anim_fluid, std::slice::from_ref(&anim_fluid::KIND)),
    member!("anim-flip", anim_flip, std::slice::from_ref(&anim_flip::KIND)),
    member!("anim-material", anim_material, &[]),
    member!("anim-io", anim_io, &[]),
    member!("anim-core", anim_core, &anim_core::scene::systems::KINDS),
];

/// Every registered scene kind, in [`CRATES`] order.
pub fn kinds() -> impl Iterator<Item = &'static SceneKind> {
    CRATES.iter().flat_map(|m| m.kinds.iter())
}

/// The kind a scene file names, if registered.
#[must_use]
pub fn kind(name: &str) -> Option<&'static SceneKind> {
    kinds().find(|k| k.kind == name)
}

/// Every preset with its kind, in registry order.
#[must_use]
pub fn presets() -> Vec<(&'static SceneKind, Preset)> {
    kinds().flat_map(|k| (k.presets)().into_iter().map(move |p| (k, p))).collect()
}

/// The preset named `name` and its kind.
#[must_use]
pub fn preset(name: &str) -> Option<(&'static SceneKind, Preset)> {
    presets().into_iter().find(|(_, p)| p.name == name)
}

/// Every crate's cases in one registry (feature `cases`), in [`CRATES`] order.
#[cfg(feature = "cases")]
#[must_use]
pub fn cases() -> anim_core::cases::Registry {
    let mut r = anim_core::cases::Registry::default();
    for m in &CRATES {
        (m.cases)(&mut r);
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_and_preset_names_are_unique_and_well_formed() {
        let mut kinds: Vec<&str> = kinds().map(|k| k.kind).collect();
        kinds.sort_unstable();
        kinds.dedup();
        assert_eq!(kinds.len(), super::kinds().count(), "a kind is registered twice");
        let all = presets();
        let mut names: Vec<&str> = all.iter().map(|(_, p)| p.name).collect();
        names.sort_unstable();
        let before = names.len();
        names.dedup();
        assert_eq!(names.len(), before, "two presets share a name");
        for (kind, p) in &all {
            let plain = p.name.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-');
            assert!(plain && !p.name.is_empty(), "{}: {:?} is not a plain name", kind.kind, p.name);
            assert!(p.run.dt > 0.0 && p.run.frames > 0 && p.run.steps_per_frame > 0, "{}", p.name);
            assert!(p.params.is_object() && p.params.get("kind").is_none(), "{}", p.name);
            assert!(!p.description.is_empty(), "{}", p.name);
        }
        for k in super::kinds() {
            assert!(k.crate_name.starts_with("anim-"), "{}", k.kind);
            assert!(!(k.presets)().is_empty(), "{} has no preset", k.kind);
        }
    }
}
