//! # anim
//!
//! Every solver crate of the anim workspace behind one dependency, and the one list of their
//! scene kinds ([`KINDS`]) that the `anim` command line, `cargo xtask` and the Python bindings
//! walk. Nothing here knows what a crate simulates: each crate describes its own scenes as an
//! [`anim_core::scene::SceneKind`] (its scene-file parameters, its presets, its builder), and
//! every scene is driven through [`anim_core::scene::DynScene`].
//!
//! Adding a solver crate: write the crate with its `KIND`, then add one line to [`KINDS`] (and
//! the dependency to this crate's manifest).
//!
//! ```
//! // Every built-in scene by name, built from its preset's parameters and stepped once.
//! let (kind, preset) = anim::preset("kepler").expect("a preset");
//! let mut scene = (kind.build)(&preset.params, &Default::default())?;
//! scene.step(preset.run.dt)?;
//! assert!(scene.time() > 0.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use anim_core as core;
pub use anim_fem as fem;
pub use anim_flip as flip;
pub use anim_fluid as fluid;
pub use anim_mpm as mpm;
pub use anim_pbd as pbd;
pub use anim_rigid as rigid;
pub use anim_skin as skin;
pub use anim_springs as springs;

use anim_core::scene::{Preset, SceneKind};

/// Every registered scene kind, one line per crate, in the order `anim list` shows them.
pub const KINDS: [SceneKind; 10] = [
    anim_springs::KIND,
    anim_pbd::KIND,
    anim_rigid::KIND,
    anim_skin::KIND,
    anim_fem::KIND,
    anim_mpm::KIND,
    anim_fluid::KIND,
    anim_flip::KIND,
    anim_core::scene::systems::KINDS[0],
    anim_core::scene::systems::KINDS[1],
];

/// The kind a scene file names, if registered.
#[must_use]
pub fn kind(name: &str) -> Option<&'static SceneKind> {
    KINDS.iter().find(|k| k.kind == name)
}

/// Every preset with its kind, in registry order.
#[must_use]
pub fn presets() -> Vec<(&'static SceneKind, Preset)> {
    KINDS.iter().flat_map(|k| (k.presets)().into_iter().map(move |p| (k, p))).collect()
}

/// The preset named `name` and its kind.
#[must_use]
pub fn preset(name: &str) -> Option<(&'static SceneKind, Preset)> {
    presets().into_iter().find(|(_, p)| p.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_and_preset_names_are_unique_and_well_formed() {
        let mut kinds: Vec<&str> = KINDS.iter().map(|k| k.kind).collect();
        kinds.sort_unstable();
        kinds.dedup();
        assert_eq!(kinds.len(), KINDS.len(), "a kind is registered twice");
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
        for k in &KINDS {
            assert!(k.crate_name.starts_with("anim-"), "{}", k.kind);
            assert!(!(k.presets)().is_empty(), "{} has no preset", k.kind);
        }
    }
}
