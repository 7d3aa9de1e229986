//! Truncated normal draws with a bounded loop. Draws are rejection samples
//! (redrawn beyond the bounds), as every study has drawn them; the study
//! file is refused up front when the accepted mass is below
//! [`MIN_ACCEPTED_MASS`], and past [`MAX_REJECTIONS`] redraws the value comes
//! from the inverse CDF instead, so no input can make the loop endless.

use rand_distr::{Distribution as _, Normal};
use statrs::distribution::{ContinuousCDF, Normal as CdfNormal};

/// Smallest share of the normal that may lie inside the bounds: at 10⁻³ a
/// draw needs 1 000 tries on average, and 10⁵ tries fail with probability e⁻¹⁰⁰.
pub const MIN_ACCEPTED_MASS: f64 = 1e-3;

/// Redraws before the inverse CDF takes over (never reached above the floor).
pub const MAX_REJECTIONS: u32 = 100_000;

/// The share of Normal(mean, std) inside [min, max] (0 when it cannot be computed).
pub fn accepted_mass(mean: f64, std: f64, min: f64, max: f64) -> f64 {
    match CdfNormal::new(mean, std) {
        Ok(n) => (n.cdf(max) - n.cdf(min)).max(0.0),
        Err(_) => 0.0,
    }
}

/// A draw of Normal(mean, std) truncated to [min, max] (std > 0, min ≤ max, finite).
pub fn draw<R: rand::Rng + ?Sized>(rng: &mut R, mean: f64, std: f64, min: f64, max: f64) -> f64 {
    let normal = Normal::new(mean, std).expect("std validated positive and finite");
    for _ in 0..MAX_REJECTIONS {
        let v = normal.sample(rng);
        if (min..=max).contains(&v) {
            return v;
        }
    }
    // Only below the floor (a caller that skipped validation): the exact
    // inverse-CDF draw, bounded by construction.
    let cdf = CdfNormal::new(mean, std).expect("std validated positive and finite");
    let (lo, hi) = (cdf.cdf(min), cdf.cdf(max));
    let u: f64 = rand::RngExt::random(rng);
    cdf.inverse_cdf(lo + (hi - lo) * u).clamp(min, max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_xoshiro::Xoshiro256PlusPlus;

    #[test]
    fn draws_stay_inside_and_end_even_where_nothing_is_accepted() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        for _ in 0..100 {
            let v = draw(&mut rng, 0.5, 0.1, 0.4, 0.6);
            assert!((0.4..=0.6).contains(&v));
        }
        // A point interval and a vast spread: the loop would never end.
        assert_eq!(accepted_mass(0.5, 1e300, 0.4, 0.4), 0.0);
        let v = draw(&mut rng, 0.5, 0.1, 0.4, 0.4);
        assert_eq!(v, 0.4);
        let v = draw(&mut rng, 0.0, 1e300, 0.4, 0.5);
        assert!((0.4..=0.5).contains(&v), "{v}");
    }

    #[test]
    fn the_accepted_mass_is_the_normal_share_inside() {
        let within_one_sigma = accepted_mass(0.0, 1.0, -1.0, 1.0);
        assert!(
            (within_one_sigma - 0.682_689_492_137_086).abs() < 1e-9,
            "{within_one_sigma}"
        );
    }
}
