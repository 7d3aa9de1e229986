//! The per-run random streams: one stream per (study seed, design, sample,
//! purpose), so that a run's draws depend on nothing but its indices.
//!
//! The seed, design index, sample index and purpose are mixed through
//! SplitMix64 steps into the seed of a xoshiro256++ stream: results do not
//! depend on thread count, scheduling or sharding, and independent draws
//! ([`Purpose`]) never share a stream. It sits at the bottom of the study's
//! units because every draw (sample, couple, tolerances, bootstrap) starts
//! here.

use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

/// One SplitMix64 step: a bijective 64-bit mixer (Steele, Lea & Flood 2014).
pub fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Purposes of streams, so that independent draws never share a stream.
#[derive(Debug, Clone, Copy)]
#[repr(u64)]
pub enum Purpose {
    /// Unbalance magnitude and direction.
    Unbalance = 1,
    /// Initial cargo positions.
    Initial = 2,
    /// Bootstrap resampling of a design's statistics.
    Bootstrap = 3,
    /// Bootstrap resampling of a comparison of two designs.
    Comparison = 4,
    /// Each weight's mass ([`super::tolerance`]).
    MassTolerance = 5,
    /// Each weight's radius ([`super::tolerance`]).
    RadiusTolerance = 6,
    /// The race centre's offset from the axis ([`super::tolerance`]).
    EccentricityTolerance = 7,
    /// The couple unbalance of a two-plane rotor ([`super::couple`]).
    Couple = 8,
}

/// The stream for (seed, design, sample, purpose); `design = None` for
/// streams shared by every design (common random numbers).
pub fn stream(seed: u64, design: Option<u32>, sample: u64, purpose: Purpose) -> Xoshiro256PlusPlus {
    let d = design.map_or(u64::MAX, u64::from);
    let mut h = splitmix64(seed);
    h = splitmix64(h ^ d);
    h = splitmix64(h ^ sample);
    h = splitmix64(h ^ purpose as u64);
    Xoshiro256PlusPlus::seed_from_u64(h)
}
