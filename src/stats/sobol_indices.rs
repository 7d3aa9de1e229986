//! Variance-based sensitivity indices by pick-freeze (Sobol indices).
//!
//! For k inputs and N rows, f(A), f(B) and f(AB_i) are the model's outputs
//! on two independent sample matrices and on A with column (or group) i
//! taken from B. The first-order index S_i (Saltelli et al. 2010) is the
//! share of the output's variance that the input explains alone, the total
//! index S_Ti (Jansen 1999) the share that goes when everything but the
//! input is known, interactions included. Both use the variance of the 2N
//! values of f(A) and f(B), as SALib does, so the numbers agree with
//! SALib's `sobol.analyze` on the same outputs.

use super::quantile::{Interpolation, quantile_sorted};
use rand::{Rng, RngExt};

/// Outputs of a pick-freeze design for k inputs (or groups of inputs):
/// f(A), f(B) and f(AB_i), each of N rows, AB_i being A with input i from B.
#[derive(Debug, Clone, Copy)]
pub struct PickFreeze<'a> {
    /// f(A).
    pub a: &'a [f64],
    /// f(B).
    pub b: &'a [f64],
    /// f(AB_i), one vector per input.
    pub ab: &'a [Vec<f64>],
}

/// One input's indices with their 95 % bootstrap intervals.
#[derive(Debug, Clone, PartialEq)]
pub struct SobolIndex {
    /// First-order index S_i.
    pub first: f64,
    /// Its 95 % percentile-bootstrap interval.
    pub first_ci: (f64, f64),
    /// Total index S_Ti.
    pub total: f64,
    /// Its 95 % percentile-bootstrap interval.
    pub total_ci: (f64, f64),
}

/// Why indices cannot be estimated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SobolError {
    /// The matrices' outputs differ in length.
    #[error("the pick-freeze outputs differ in length (A {a}, B {b}, an AB_i {ab})")]
    Lengths {
        /// Rows of f(A).
        a: usize,
        /// Rows of f(B).
        b: usize,
        /// Rows of the first AB_i that differs.
        ab: usize,
    },
    /// Fewer than two rows.
    #[error("{0} row(s): at least two are needed")]
    TooFew(usize),
    /// The output does not vary: every index is 0/0.
    #[error("the output does not vary (every run gave the same value): no input explains anything")]
    Constant,
}

/// Population variance (ddof = 0) of the 2N values of f(A) and f(B).
fn variance(a: &[f64], b: &[f64]) -> f64 {
    let n = (a.len() + b.len()) as f64;
    let mean = a.iter().chain(b).sum::<f64>() / n;
    a.iter().chain(b).map(|v| (v - mean).powi(2)).sum::<f64>() / n
}

/// Saltelli et al. (2010): mean(f_B (f_ABi − f_A)) / V.
pub fn first_order(a: &[f64], b: &[f64], ab_i: &[f64]) -> f64 {
    let sum: f64 = (0..a.len()).map(|j| b[j] * (ab_i[j] - a[j])).sum();
    sum / a.len() as f64 / variance(a, b)
}

/// Jansen (1999): mean((f_A − f_ABi)²) / (2 V).
pub fn total_order(a: &[f64], b: &[f64], ab_i: &[f64]) -> f64 {
    let sum: f64 = (0..a.len()).map(|j| (a[j] - ab_i[j]).powi(2)).sum();
    0.5 * sum / a.len() as f64 / variance(a, b)
}

/// Every input's indices, with percentile-bootstrap intervals from
/// `resamples` resamples of the rows (the same rows for A, B and every AB_i).
pub fn indices(
    design: &PickFreeze<'_>,
    resamples: usize,
    rng: &mut impl Rng,
) -> Result<Vec<SobolIndex>, SobolError> {
    let n = design.a.len();
    if let Some(bad) = std::iter::once(design.b.len())
        .chain(design.ab.iter().map(Vec::len))
        .find(|&len| len != n)
    {
        return Err(SobolError::Lengths {
            a: n,
            b: design.b.len(),
            ab: bad,
        });
    }
    if n < 2 {
        return Err(SobolError::TooFew(n));
    }
    if variance(design.a, design.b) == 0.0 {
        return Err(SobolError::Constant);
    }
    let k = design.ab.len();
    let mut firsts = vec![Vec::with_capacity(resamples); k];
    let mut totals = vec![Vec::with_capacity(resamples); k];
    let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
    let mut ab = vec![0.0; n];
    let mut rows = vec![0usize; n];
    for _ in 0..resamples {
        rows.iter_mut().for_each(|r| *r = rng.random_range(0..n));
        for (j, &r) in rows.iter().enumerate() {
            a[j] = design.a[r];
            b[j] = design.b[r];
        }
        // A resample that happens to be constant says nothing: skipped.
        if variance(&a, &b) == 0.0 {
            continue;
        }
        for i in 0..k {
            for (j, &r) in rows.iter().enumerate() {
                ab[j] = design.ab[i][r];
            }
            firsts[i].push(first_order(&a, &b, &ab));
            totals[i].push(total_order(&a, &b, &ab));
        }
    }
    Ok((0..k)
        .map(|i| SobolIndex {
            first: first_order(design.a, design.b, &design.ab[i]),
            first_ci: interval(&mut firsts[i]),
            total: total_order(design.a, design.b, &design.ab[i]),
            total_ci: interval(&mut totals[i]),
        })
        .collect())
}

/// The 2.5 % and 97.5 % percentiles of bootstrap estimates (NaN-free).
fn interval(estimates: &mut [f64]) -> (f64, f64) {
    estimates.sort_by(f64::total_cmp);
    let at = |q| quantile_sorted(estimates, q, Interpolation::Linear).unwrap_or(f64::NAN);
    (at(0.025), at(0.975))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn test_rng(seed: u64) -> Xoshiro256PlusPlus {
        Xoshiro256PlusPlus::seed_from_u64(seed)
    }
    use std::f64::consts::PI;

    /// Pick-freeze outputs of `f` over k inputs uniform on [0, 1), N rows
    /// of an Owen-scrambled Sobol sequence (A: dimensions 0..k, B: k..2k).
    fn design(f: impl Fn(&[f64]) -> f64, k: usize, n: u32) -> (Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        scrambled_design(f, k, n, 0x5EED)
    }

    /// As [`design`], under the scramble `seed`.
    fn scrambled_design(
        f: impl Fn(&[f64]) -> f64,
        k: usize,
        n: u32,
        seed: u32,
    ) -> (Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        let point = |j: u32, dims: std::ops::Range<usize>| -> Vec<f64> {
            dims.map(|d| f64::from(sobol_burley::sample(j, d as u32, seed)))
                .collect()
        };
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let mut ab = vec![Vec::new(); k];
        for j in 0..n {
            let (xa, xb) = (point(j, 0..k), point(j, k..2 * k));
            a.push(f(&xa));
            b.push(f(&xb));
            for (i, out) in ab.iter_mut().enumerate() {
                let mut x = xa.clone();
                x[i] = xb[i];
                out.push(f(&x));
            }
        }
        (a, b, ab)
    }

    /// The analytic values inside the intervals, and the intervals no
    /// wider than `width` (an interval that covers everything proves nothing).
    /// As [`design`], the matrices drawn pseudo-randomly (seeded) instead.
    fn random_design(
        f: impl Fn(&[f64]) -> f64,
        k: usize,
        n: u32,
        seed: u64,
    ) -> (Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
        let mut rng = test_rng(seed);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let mut ab = vec![Vec::new(); k];
        for _ in 0..n {
            let xa: Vec<f64> = (0..k).map(|_| rng.random::<f64>()).collect();
            let xb: Vec<f64> = (0..k).map(|_| rng.random::<f64>()).collect();
            a.push(f(&xa));
            b.push(f(&xb));
            for (i, out) in ab.iter_mut().enumerate() {
                let mut x = xa.clone();
                x[i] = xb[i];
                out.push(f(&x));
            }
        }
        (a, b, ab)
    }

    fn ishigami(x: &[f64]) -> f64 {
        let x: Vec<f64> = x.iter().map(|u| -PI + 2.0 * PI * u).collect();
        x[0].sin() + 7.0 * x[1].sin().powi(2) + 0.1 * x[2].powi(4) * x[0].sin()
    }

    /// Sobol against plain random draws at equal runs (docs/statistics.md):
    /// over 40 independent replicates at N = 256 (1 280 evaluations each),
    /// the root-mean-square error of Ishigami's indices, and the mean width
    /// of the bootstrap interval. The scrambled Sobol design's error is the
    /// smaller; the bootstrap, which resamples rows as if they were
    /// independent, does not see that gain, so its intervals on a Sobol
    /// design are conservative. `cargo test --lib sobol_against_random --
    /// --nocapture` prints the table.
    #[test]
    fn sobol_against_random_draws_at_equal_runs() {
        let exact = [(0.3139, 0.5576), (0.4424, 0.4424), (0.0, 0.2437)];
        let replicates = 40u32;
        let mut table = Vec::new();
        for sobol in [true, false] {
            let (mut sq_first, mut sq_total, mut width) = (0.0, 0.0, 0.0);
            for r in 0..replicates {
                let (a, b, ab) = if sobol {
                    scrambled_design(ishigami, 3, 256, 0x1000 + r)
                } else {
                    random_design(ishigami, 3, 256, u64::from(r))
                };
                let got = indices(
                    &PickFreeze {
                        a: &a,
                        b: &b,
                        ab: &ab,
                    },
                    200,
                    &mut test_rng(9),
                )
                .unwrap();
                for (g, (s1, st)) in got.iter().zip(exact) {
                    sq_first += (g.first - s1).powi(2);
                    sq_total += (g.total - st).powi(2);
                    width += (g.total_ci.1 - g.total_ci.0) + (g.first_ci.1 - g.first_ci.0);
                }
            }
            let cells = f64::from(replicates) * 3.0;
            table.push((
                (sq_first / cells).sqrt(),
                (sq_total / cells).sqrt(),
                width / (2.0 * cells),
            ));
        }
        let (s, r) = (table[0], table[1]);
        println!("N = 256, 40 replicates: RMS error S1, RMS error ST, mean bootstrap width");
        println!("sobol  {:.4} {:.4} {:.4}", s.0, s.1, s.2);
        println!("random {:.4} {:.4} {:.4}", r.0, r.1, r.2);
        assert!(s.0 < r.0 && s.1 < r.1, "{table:?}");
    }

    fn within(got: &SobolIndex, first: f64, total: f64, width: f64) {
        let inside = |(lo, hi): (f64, f64), v: f64| lo - 1e-9 <= v && v <= hi + 1e-9;
        assert!(inside(got.first_ci, first), "S1 {first} outside {got:?}");
        assert!(inside(got.total_ci, total), "ST {total} outside {got:?}");
        assert!(got.first_ci.1 - got.first_ci.0 < width, "{got:?}");
        assert!(got.total_ci.1 - got.total_ci.0 < width, "{got:?}");
    }

    /// Ishigami (a = 7, b = 0.1): S1 = 0.3139, 0.4424, 0; ST = 0.5576,
    /// 0.4424, 0.2437, each inside its interval at N = 2^12.
    #[test]
    fn ishigami_indices_are_inside_their_intervals() {
        let (a, b, ab) = design(ishigami, 3, 1 << 12);
        let got = indices(
            &PickFreeze {
                a: &a,
                b: &b,
                ab: &ab,
            },
            500,
            &mut test_rng(3),
        )
        .unwrap();
        for (g, (s1, st)) in got
            .iter()
            .zip([(0.3139, 0.5576), (0.4424, 0.4424), (0.0, 0.2437)])
        {
            within(g, s1, st, 0.1);
        }
    }

    /// Sobol's g function, a = (0, 1, 4.5, 9, 99, 99): analytic indices.
    #[test]
    fn g_function_indices_are_inside_their_intervals() {
        let a_i = [0.0, 1.0, 4.5, 9.0, 99.0, 99.0];
        let g = |x: &[f64]| {
            x.iter()
                .zip(a_i)
                .map(|(u, a)| ((4.0 * u - 2.0).abs() + a) / (1.0 + a))
                .product::<f64>()
        };
        let v_i: Vec<f64> = a_i
            .iter()
            .map(|a| (1.0 / 3.0) / (1.0 + a).powi(2))
            .collect();
        let v = v_i.iter().map(|v| 1.0 + v).product::<f64>() - 1.0;
        let (a, b, ab) = design(g, 6, 1 << 12);
        let got = indices(
            &PickFreeze {
                a: &a,
                b: &b,
                ab: &ab,
            },
            500,
            &mut test_rng(4),
        )
        .unwrap();
        for (i, g) in got.iter().enumerate() {
            let others: f64 = (0..6).filter(|&j| j != i).map(|j| 1.0 + v_i[j]).product();
            // Saltelli's first-order estimator is noisier on g's
            // dominant input (width 0.14 at N = 2^12).
            within(g, v_i[i] / v, v_i[i] * others / v, 0.2);
        }
    }

    #[test]
    fn undefined_indices_are_errors_not_nan() {
        let c = vec![1.0; 8];
        let ab = vec![c.clone()];
        let mut rng = test_rng(1);
        let design = PickFreeze {
            a: &c,
            b: &c,
            ab: &ab,
        };
        assert_eq!(indices(&design, 10, &mut rng), Err(SobolError::Constant));
        let short = vec![vec![1.0; 7]];
        let x: Vec<f64> = (0..8).map(f64::from).collect();
        let design = PickFreeze {
            a: &x,
            b: &x,
            ab: &short,
        };
        assert!(matches!(
            indices(&design, 10, &mut rng),
            Err(SobolError::Lengths { .. })
        ));
    }
}
