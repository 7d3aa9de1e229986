//! Heap allocations of the ODE core, counted by a global allocator.
//!
//! This is a test binary of its own, apart from `tests/it`: a
//! `#[global_allocator]` replaces the allocator of the whole binary, and in
//! `tests/it` it would sit under every integration test.

// The benchmark's reference problem lives in the `study` binary, which a
// test cannot link against; its file uses the library only, so it is compiled in.
#[allow(dead_code)]
#[path = "../src/bin/autobal-bench/bench/problem.rs"]
mod problem;

use autobal::integrate::{Method, OdeSystem, Status};
use autobal::model::effect::gravity::Gravity;
use autobal::model::start::{StartMode, initial_state};
use problem::{BenchProblem, CARGO_COUNTS};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// Forwards to the system allocator and counts allocations per thread
/// (the test harness runs tests on parallel threads).
struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}

fn count() {
    // try_with: the allocator is still called while thread-locals are torn down.
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

// SAFETY: every call is forwarded unchanged to `System`.
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

/// Allocations made on this thread while `f` runs.
fn allocations_during(f: impl FnOnce()) -> u64 {
    let before = ALLOCATIONS.with(Cell::get);
    f();
    ALLOCATIONS.with(Cell::get) - before
}

#[test]
fn the_counter_sees_allocations() {
    let count = allocations_during(|| {
        std::hint::black_box(vec![1.0_f64; 8]);
    });
    assert_eq!(count, 1);
}

#[test]
fn rhs_never_allocates() {
    for &n in CARGO_COUNTS {
        let p = BenchProblem::new(n, 1e-6, 1.0);
        let mut dydt = vec![0.0; p.y0.len()];
        let count = allocations_during(|| {
            for i in 0..1000 {
                p.system.rhs(i as f64 * 0.01, &p.y0, &mut dydt);
            }
        });
        assert_eq!(count, 0, "n = {n}");
    }
}

#[test]
fn rhs_with_gravity_never_allocates() {
    let mut scene = problem::reference_scene(3);
    scene.effects.gravity = Some(Gravity {
        g: 9.81,
        axis_inclination_deg: 0.0,
    });
    let system = scene.build().unwrap();
    assert_eq!(system.effect_names(), ["drag", "gravity"]);
    let y = initial_state(&system, StartMode::LockedSteady, &[0.1, 0.2, 0.3]);
    let mut dydt = vec![0.0; y.len()];
    let count = allocations_during(|| {
        for i in 0..1000 {
            system.rhs(i as f64 * 0.01, &y, &mut dydt);
        }
    });
    assert_eq!(count, 0);
}

#[test]
fn solver_allocations_do_not_grow_with_the_horizon() {
    // Work vectors are allocated once per solve: ten times the steps, same count.
    let count = |revolutions: f64| {
        let p = BenchProblem::new(3, 1e-8, revolutions);
        let mut steps = 0;
        let n = allocations_during(|| {
            let report = p.solve(Method::Dp5);
            assert_eq!(report.status, Status::Finished);
            steps = report.stats.steps;
        });
        (n, steps)
    };
    let (short, short_steps) = count(5.0);
    let (long, long_steps) = count(50.0);
    assert!(
        long_steps > 5 * short_steps,
        "{short_steps} vs {long_steps}"
    );
    assert_eq!(short, long);
}
