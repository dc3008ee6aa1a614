//! The counting allocator counts what a closure allocates, on any thread, and nothing else.

use anim_core::alloc_count::CountingAllocator;

#[global_allocator]
static ALLOC: CountingAllocator = CountingAllocator::new();

#[test]
fn counts_allocations_made_inside_the_closure_only() {
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
