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
use rand::{Rng, TryRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::convert::Infallible;

/// One SplitMix64 step: a bijective 64-bit mixer (Steele, Lea & Flood 2014).
pub fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Purposes of streams, so that independent draws never share a stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
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
    /// Each weight's mass ([`crate::study::plan::tolerance`]).
    MassTolerance = 5,
    /// Each weight's radius ([`crate::study::plan::tolerance`]).
    RadiusTolerance = 6,
    /// The race centre's offset from the axis ([`crate::study::plan::tolerance`]).
    EccentricityTolerance = 7,
    /// The couple unbalance of a two-plane rotor ([`crate::study::plan::couple`]).
    Couple = 8,
    /// Bootstrap resampling of a comparison at a look of a race
    /// (`crate::study::run::racing`).
    Racing = 9,
    /// An uncertain scene key (`super::uncertain`; the key's name is mixed
    /// into the seed, so each key has a stream of its own).
    Uncertain = 10,
    /// Bootstrap resampling of a sensitivity analysis's indices
    /// (`crate::study::sensitivity`).
    Sensitivity = 11,
    /// Draws of a rig's unknowns and synthetic measurement noise
    /// (`crate::calibrate`).
    Calibration = 12,
    /// Bootstrap resampling of #1 against another design within one third
    /// of an uncertain key's range (`crate::decide::robustness`).
    RobustnessThirds = 13,
    /// Permutations of the test of an uncertain key's share of #1's
    /// variance (`crate::decide::robustness`).
    RobustnessShares = 14,
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

/// An input of a run as a sensitivity analysis sees it: one purpose's
/// stream, or one uncertain scene key's (by [`key_hash`] of its name).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Input {
    /// Every draw of one purpose (the unbalance's size and direction, the
    /// start angles, one tolerance, the couple part).
    Stream(Purpose),
    /// One uncertain scene key.
    Key(u64),
}

/// Which of two independent sets of draws a run takes (the matrices A and B
/// of Saltelli's pick-freeze design): a study's own runs are A.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Matrix {
    /// Every input from the study's own streams.
    #[default]
    A,
    /// Every input from the second, independent set.
    B,
    /// A, but this one input from B (the matrix AB_i).
    AWithFromB(Input),
}

/// Mixed into the seed of the second set of draws (B): "SALTELLI".
const SECOND_SET: u64 = 0x5341_4C54_454C_4C49;

/// The streams of one run: the study's seed, the design index its streams
/// share (`None` under common random numbers), the sequence, and which set
/// each input draws from.
#[derive(Debug, Clone, Copy)]
pub struct RunStreams {
    /// The study's seed.
    pub seed: u64,
    /// The design index of the streams; `None` when every design meets the
    /// same draws.
    pub shared: Option<u32>,
    /// Pseudo-random or Sobol.
    pub sequence: Sequence,
    /// Which set of draws each input takes.
    pub matrix: Matrix,
}

impl RunStreams {
    /// The draws of `purpose` for sample `sample`.
    pub fn draws(&self, sample: u64, purpose: Purpose) -> Draws {
        let seed = self.seed_of(Input::Stream(purpose));
        draws(seed, self.shared, sample, purpose, self.sequence)
    }

    /// The draws of one uncertain key (its name's [`key_hash`]): the key is
    /// mixed into the seed, so that every key has a stream (and a Sobol
    /// scramble) of its own and adding a key changes no other draw.
    pub fn key_draws(&self, key: u64, sample: u64) -> Draws {
        let seed = splitmix64(self.seed_of(Input::Key(key)) ^ key);
        draws(seed, self.shared, sample, Purpose::Uncertain, self.sequence)
    }

    fn seed_of(&self, input: Input) -> u64 {
        let second = match self.matrix {
            Matrix::A => false,
            Matrix::B => true,
            Matrix::AWithFromB(i) => i == input,
        };
        if second {
            splitmix64(self.seed ^ SECOND_SET)
        } else {
            self.seed
        }
    }
}

/// FNV-1a of a key's name: a fixed hash (std's is randomised per process),
/// so that a key's stream is the same in every run of every build.
pub fn key_hash(key: &str) -> u64 {
    key.bytes().fold(0xCBF2_9CE4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01B3)
    })
}

/// Where a study's sampled inputs come from (`[sampling] sequence`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Sequence {
    /// Independent pseudo-random draws (xoshiro256++).
    #[default]
    Random,
    /// Sample k's draws are point k of an Owen-scrambled Sobol sequence
    /// (`sobol_burley`): the samples fill the unit cube more evenly; use a
    /// power of two of them, at most 2¹⁶.
    Sobol,
}

/// Most samples per design a Sobol study may draw (`sobol_burley`'s
/// sequence length).
pub const SOBOL_MAX_SAMPLES: u32 = 1 << 16;

/// A run's draws for one purpose: its own pseudo-random stream, or its
/// point of the study's scrambled Sobol sequence.
#[derive(Debug, Clone)]
pub enum Draws {
    /// [`Sequence::Random`].
    Random(Xoshiro256PlusPlus),
    /// [`Sequence::Sobol`].
    Sobol(SobolPoint),
}

/// Point `index` of an Owen-scrambled Sobol sequence, read one coordinate
/// per draw. Each purpose scrambles with a seed of its own, so that its
/// coordinates are stratified together (an unbalance's size and direction)
/// and independent of the other purposes' (Owen's padding).
#[derive(Debug, Clone)]
pub struct SobolPoint {
    index: u32,
    seed: u64,
    dimension: u32,
}

/// Coordinates of `sobol_burley`'s table; draws beyond it take the table
/// again under another scramble.
const SOBOL_DIMENSIONS: u32 = 256;

impl SobolPoint {
    /// The next coordinate as 64 bits: the scrambled coordinate's 24 bits
    /// (`sobol_burley` returns f32 multiples of 2⁻²⁴) on top, and below them
    /// 40 bits hashed from the point, the coordinate and the seed: a uniform
    /// draw within the coordinate's finest stratum, so that a caller reading
    /// 53 bits (an f64 in [0, 1)) gets no 2⁻²⁴ grid.
    fn next(&mut self) -> u64 {
        let round = self.dimension / SOBOL_DIMENSIONS;
        let seed = splitmix64(self.seed ^ u64::from(round));
        let x = sobol_burley::sample(
            self.index,
            self.dimension % SOBOL_DIMENSIONS,
            (seed >> 32) as u32,
        );
        let top = (f64::from(x) * f64::from(1u32 << 24)) as u64;
        let low =
            splitmix64(seed ^ (u64::from(self.index) << 32 | u64::from(self.dimension))) >> 24;
        self.dimension += 1;
        (top << 40) | low
    }
}

impl TryRng for Draws {
    type Error = Infallible;

    fn try_next_u32(&mut self) -> Result<u32, Infallible> {
        Ok((self.try_next_u64()? >> 32) as u32)
    }

    fn try_next_u64(&mut self) -> Result<u64, Infallible> {
        Ok(match self {
            Draws::Random(r) => r.next_u64(),
            Draws::Sobol(p) => p.next(),
        })
    }

    fn try_fill_bytes(&mut self, dst: &mut [u8]) -> Result<(), Infallible> {
        for chunk in dst.chunks_mut(8) {
            let bytes = self.try_next_u64()?.to_le_bytes();
            chunk.copy_from_slice(&bytes[..chunk.len()]);
        }
        Ok(())
    }
}

/// The draws of (seed, design, sample, purpose) under `sequence`; as
/// [`stream`] for random draws.
pub fn draws(
    seed: u64,
    design: Option<u32>,
    sample: u64,
    purpose: Purpose,
    sequence: Sequence,
) -> Draws {
    match sequence {
        Sequence::Random => Draws::Random(stream(seed, design, sample, purpose)),
        Sequence::Sobol => {
            let d = design.map_or(u64::MAX, u64::from);
            let mut h = splitmix64(seed);
            h = splitmix64(h ^ d);
            h = splitmix64(h ^ purpose as u64);
            Draws::Sobol(SobolPoint {
                index: u32::try_from(sample).expect("validated: at most 2^16 samples"),
                seed: h,
                dimension: 0,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    /// The first 2^m points of one purpose's two coordinates put exactly one
    /// point in each of the 2^m cells of a 2^(m/2) × 2^(m/2) grid (a
    /// (0, m, 2)-net, which Owen scrambling keeps); random draws do not.
    #[test]
    fn sobol_draws_fill_the_square_one_point_per_cell() {
        let cells_hit = |sequence| {
            let mut seen = [false; 256];
            for sample in 0..256u64 {
                let mut d = draws(7, None, sample, Purpose::Unbalance, sequence);
                let (x, y): (f64, f64) = (d.random(), d.random());
                seen[(x * 16.0) as usize * 16 + (y * 16.0) as usize] = true;
            }
            seen.iter().filter(|s| **s).count()
        };
        assert_eq!(cells_hit(Sequence::Sobol), 256);
        // 256 independent points miss about 256/e of the cells.
        assert!(cells_hit(Sequence::Random) < 200);
    }

    /// Every draw is a uniform in [0, 1) with 53 bits, whatever the
    /// coordinate (also past the table's 256), and another purpose or seed
    /// scrambles differently.
    #[test]
    fn sobol_draws_are_uniform_and_differ_between_purposes() {
        let mut d = draws(7, None, 3, Purpose::Initial, Sequence::Sobol);
        let xs: Vec<f64> = (0..600).map(|_| d.random()).collect();
        assert!(xs.iter().all(|x| (0.0..1.0).contains(x)));
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        assert!((mean - 0.5).abs() < 0.05, "{mean}");
        let first =
            |purpose, seed| -> f64 { draws(seed, None, 3, purpose, Sequence::Sobol).random() };
        assert_ne!(first(Purpose::Initial, 7), first(Purpose::Unbalance, 7));
        assert_ne!(first(Purpose::Initial, 7), first(Purpose::Initial, 8));
    }
}
