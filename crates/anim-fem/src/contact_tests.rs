//! Contact scenes checked against analytic references and against the frictionless results the
//! crate gave before friction existed.

use crate::scenes;
use crate::sim::{FemParams, TimeIntegrator};
use anim_core::integrate::State;
use anim_core::solver::Solver;

/// FNV-1a over the bits of every position and velocity coordinate.
fn state_hash(state: &State) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325_u64;
    for v in state.x.iter().chain(&state.v) {
        for b in v.to_bits().to_le_bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}

/// The soft cube drop (resolution 3) through its landing, with either integrator.
fn cube_drop_hash(integrator: TimeIntegrator, dt: f64, steps: usize) -> u64 {
    let mut scene = scenes::soft_cube_drop(3).unwrap();
    scene.params = FemParams { integrator, ..scene.params };
    let (mut sim, mut state) = scene.into_simulation().unwrap();
    let mut zmin = f64::INFINITY;
    for _ in 0..steps {
        sim.step(&mut state, dt).unwrap();
        zmin = state.x.chunks(3).map(|p| p[2]).fold(zmin, f64::min);
    }
    assert!(zmin < 1e-3, "the cube has not landed: lowest z {zmin}");
    state_hash(&state)
}

/// Frictionless contact (the default, `mu = 0`) gives bit for bit the states the crate produced
/// before friction was added: the hashes were recorded with that code (commit 11d4640e) on
/// x86_64 Linux. A change to any floating-point operation of the contact or time-stepping path
/// changes them.
#[test]
fn frictionless_contact_is_bitwise_unchanged() {
    let implicit = cube_drop_hash(TimeIntegrator::BackwardEuler, 1.0 / 120.0, 60);
    let explicit = cube_drop_hash(TimeIntegrator::SymplecticEuler, 2e-4, 3000);
    assert_eq!(implicit, 0x1a92_d5ba_b208_b87b);
    assert_eq!(explicit, 0xdc92_9e6e_3c40_aa75);
}
