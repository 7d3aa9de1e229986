//! Deterministic pseudo-random numbers for unit tests across the crate
//! (a 64-bit LCG; no RNG crate or seed plumbing needed). Here, at the bottom
//! of the layers, so that tests of any module can use it without importing
//! a higher one.

/// The next number in [0, 1) of the stream kept in `state`.
pub(crate) fn uniform(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}
