//! The counting allocator counts what a closure allocates, on any thread, and nothing else.

use anim_core::alloc_count::CountingAllocator;

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

/// The allocator counts every thread: the tests of this file take turns.
static TURN: std::sync::Mutex<()> = std::sync::Mutex::new(());

#[test]
fn counts_allocations_made_inside_the_closure_only() {
    let _turn = TURN.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let mut kept: Vec<Vec<u8>> = Vec::with_capacity(4);
    let before = vec![1u8; 8];
    assert_eq!(ALLOC.count(|| kept.push(Vec::with_capacity(16))), 1);
    assert_eq!(ALLOC.count(|| kept[0].extend_from_slice(&before)), 0, "within capacity");
    assert_eq!(ALLOC.count(|| kept[0].reserve(1024)), 1, "a reallocation counts");
    let other = ALLOC.count(|| {
        std::thread::scope(|s| {
            s.spawn(|| std::hint::black_box(vec![0u64; 32]));
        });
    });
    assert!(other >= 2, "the spawned thread's vector and the thread itself: {other}");
    let x = vec![2u8; 4];
    assert_eq!(ALLOC.count(|| drop(std::hint::black_box(x))), 0, "freeing is not counted");
}

#[test]
fn the_peak_is_the_most_bytes_held_at_once_inside_the_closure() {
    let _turn = TURN.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let kept = vec![0u8; 1 << 20];
    let peak = ALLOC.peak_bytes(|| {
        let a = std::hint::black_box(vec![1u8; 3000]);
        drop(a);
        let b = std::hint::black_box(vec![1u8; 2000]);
        let c = std::hint::black_box(vec![1u64; 100]);
        drop((b, c));
    });
    assert_eq!(peak, 3000, "the first vector alone, freed before the next two (2800 B) came");
    let mut grown: Vec<u8> = Vec::with_capacity(1000);
    let peak = ALLOC.peak_bytes(|| grown.reserve_exact(5000));
    assert_eq!(peak, 4000, "a reallocation holds its growth");
    // Freeing what was allocated before lowers what is held, never below the start.
    let peak = ALLOC.peak_bytes(|| drop(std::hint::black_box(kept)));
    assert_eq!(peak, 0);
    let peak = ALLOC.peak_bytes(|| {
        std::thread::scope(|s| {
            s.spawn(|| drop(std::hint::black_box(vec![0u8; 1 << 16])));
        });
    });
    assert!(peak >= 1 << 16, "another thread's allocation counts: {peak}");
}
