//! The generated inverse dynamics (seed 003's punch, seed 000's mechanism
//! A) and the generated stiffness (3-RPS) allocate nothing on the heap: a
//! counting global allocator, counting on the calling thread only (the
//! other tests run in parallel threads of this binary), sees no allocation
//! while each is called many times after one preparation.

use crate::mechanisms::{Punch, PunchParams, Rps, RpsParams, SeedA, SeedAParams};
use pkm::runtime::primitives::Sign::{self, Minus, Plus};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::hint::black_box;

/// The system allocator, counting the allocations of each thread.
struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    // `try_with`: a thread being torn down has no counter, and is not counted.
    let _ = ALLOCATIONS.try_with(|n| n.set(n.get() + 1));
}

// SAFETY: every call is passed on to `System` unchanged; counting touches
// only a const-initialised thread-local `Cell` (no allocation of its own).
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// The allocations this thread makes while `f` runs.
fn allocations_in(f: impl FnOnce()) -> usize {
    let before = ALLOCATIONS.with(Cell::get);
    f();
    ALLOCATIONS.with(Cell::get) - before
}

/// The counter sees an allocation on this thread (else a zero below would
/// prove nothing).
#[test]
fn the_counter_counts() {
    let n = allocations_in(|| {
        black_box(vec![1.0f64; 3]);
    });
    assert_eq!(n, 1);
}

/// Seed 003's punch over a turn and seed 000's mechanism A near Table 1's
/// inputs in motion: every answer (an error's text may allocate, so the
/// calls counted are those that answer, found beforehand) allocating nothing.
#[test]
fn generated_inverse_dynamics_allocates_nothing() {
    let punch = Punch::prepare(&PunchParams::default());
    let inputs: Vec<(f64, [Sign; 3])> = (0..360)
        .flat_map(|k| [Plus, Minus].map(|last| ((k as f64 + 0.5).to_radians(), [Minus, Minus, last])))
        .filter(|(phi, signs)| punch.inverse_dynamics(&[*phi], *signs, &[1.0], &[0.0]).is_ok())
        .collect();
    assert!(inputs.len() >= 360, "{} of 720 solved", inputs.len());
    let n = allocations_in(|| {
        for (phi, signs) in &inputs {
            black_box(
                punch
                    .inverse_dynamics(black_box(&[*phi]), *signs, &[1.0], &[0.0])
                    .is_ok(),
            );
        }
    });
    assert_eq!(n, 0, "the punch's inverse dynamics allocated {n} times");

    let a = SeedA::prepare(&SeedAParams::default());
    let signs: [Sign; 3] = [Minus, Plus, Plus];
    let inputs: Vec<[f64; 3]> = (0..200)
        .map(|k| [-106.09 + 0.01 * k as f64, 181.67, -70.29])
        .filter(|q| {
            a.inverse_dynamics(q, signs, &[1.0, -0.5, 0.25], &[-2.0, 0.75, 1.5])
                .is_ok()
        })
        .collect();
    assert_eq!(inputs.len(), 200);
    let n = allocations_in(|| {
        for q in &inputs {
            black_box(
                a.inverse_dynamics(black_box(q), signs, &[1.0, -0.5, 0.25], &[-2.0, 0.75, 1.5])
                    .is_ok(),
            );
        }
    });
    assert_eq!(n, 0, "seed000_a's inverse dynamics allocated {n} times");
}

/// The 3-RPS at poses around its home (H = 75 mm): every call ok, none
/// allocating (the wrench analysis and what `stiffness` returns are held
/// inline, its SVDs on stack matrices).
#[test]
fn generated_stiffness_allocates_nothing() {
    let p = Rps::prepare(&RpsParams::default());
    let poses: Vec<[f64; 3]> = (0..100)
        .map(|k| {
            let t = k as f64 / 100.0;
            [70.0 + 10.0 * t, 0.1 * (t - 0.5), -0.1 * (t - 0.5)]
        })
        .collect();
    let signs: Vec<_> = poses
        .iter()
        .map(|g| {
            Rps::ik(&RpsParams::default(), g)
                .iter()
                .filter_map(|b| {
                    b.result
                        .as_ref()
                        .ok()
                        .map(|s| (s.q[1].abs() + s.q[4].abs() + s.q[7].abs(), b.signs))
                })
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .map(|(_, signs)| signs)
                .expect("an assembly")
        })
        .collect();
    for (g, s) in poses.iter().zip(&signs) {
        p.stiffness(g, *s).expect("a stiffness near home");
    }
    let n = allocations_in(|| {
        for (g, s) in poses.iter().zip(&signs) {
            black_box(p.stiffness(black_box(g), *s).is_ok());
        }
    });
    assert_eq!(n, 0, "the 3-RPS's stiffness allocated {n} times");
}
