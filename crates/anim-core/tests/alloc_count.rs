//! The counting allocator counts what a closure allocates, on any thread, and nothing else.

use anim_core::alloc_count::CountingAllocator;

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

/// The allocator counts every thread, the test harness's included: while one test runs, the
/// harness reports another one's end and allocates. So this file has a single test, which runs
/// the checks one after the other while the harness waits.
#[test]
fn the_counter_sees_the_closures_allocations_and_peak() {
    counts_allocations_made_inside_the_closure_only();
    the_peak_is_the_most_bytes_held_at_once_inside_the_closure();
}

/// A measurement that the test harness's own threads can disturb (the other test's thread
/// ending frees its buffers at any time): up to three tries, the first that gives `expected`
/// ends them, else the last is returned. Code that is wrong gives the wrong figure every time.
fn settled(expected: usize, mut measure: impl FnMut() -> usize) -> usize {
    let mut got = measure();
    for _ in 0..2 {
        if got == expected {
            break;
        }
        got = measure();
    }
    got
}

fn counts_allocations_made_inside_the_closure_only() {
    let pushed = settled(1, || {
        let mut kept: Vec<Vec<u8>> = Vec::with_capacity(4);
        ALLOC.count(|| kept.push(Vec::with_capacity(16)))
    });
    assert_eq!(pushed, 1);
    let within = settled(0, || {
        let mut kept: Vec<u8> = Vec::with_capacity(16);
        let before = vec![1u8; 8];
        ALLOC.count(|| kept.extend_from_slice(&before))
    });
    assert_eq!(within, 0, "within capacity");
    let grown = settled(1, || {
        let mut kept: Vec<u8> = Vec::with_capacity(16);
        ALLOC.count(|| kept.reserve(1024))
    });
    assert_eq!(grown, 1, "a reallocation counts");
    let other = ALLOC.count(|| {
        std::thread::scope(|s| {
            s.spawn(|| std::hint::black_box(vec![0u64; 32]));
        });
    });
    assert!(other >= 2, "the spawned thread's vector and the thread itself: {other}");
    let freed = settled(0, || {
        let x = vec![2u8; 4];
        ALLOC.count(|| drop(std::hint::black_box(x)))
    });
    assert_eq!(freed, 0, "freeing is not counted");
}

fn the_peak_is_the_most_bytes_held_at_once_inside_the_closure() {
    let kept = vec![0u8; 1 << 20];
    let peak = settled(3000, || {
        ALLOC.peak_bytes(|| {
            let a = std::hint::black_box(vec![1u8; 3000]);
            drop(a);
            let b = std::hint::black_box(vec![1u8; 2000]);
            let c = std::hint::black_box(vec![1u64; 100]);
            drop((b, c));
        })
    });
    assert_eq!(peak, 3000, "the first vector alone, freed before the next two (2800 B) came");
    let peak = settled(4000, || {
        let mut grown: Vec<u8> = Vec::with_capacity(1000);
        ALLOC.peak_bytes(|| grown.reserve_exact(5000))
    });
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
