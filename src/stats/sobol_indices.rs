//! Variance-based sensitivity indices by pick-freeze (Sobol indices).
//!
//! For k inputs (or groups of inputs) and N rows, f(A), f(B) and f(AB_i)
//! are the model's outputs on two independent sample matrices and on A
//! with column(s) i taken from B (Saltelli 2010's layout, as SALib's
//! `sobol.sample` with `calc_second_order=False`). The first-order index
//! S_i (Saltelli et al. 2010) is the share of the output's variance that
//! input i explains alone; the total index S_Ti (Jansen 1999) the share
//! left unexplained when every other input is known, interactions included.
//!
//! [`indices`] follows SALib's `sobol.analyze` step for step so that its
//! estimates agree with SALib's on the same outputs (a test checks 1e-12):
//! the outputs are first centred on the mean of all N (k + 2) of them,
//! V is the population variance of the 2N values of f(A) and f(B), and the
//! bootstrap resamples the N rows jointly. Its intervals are percentile
//! intervals where SALib reports a normal-approximation half-width.
//!
//! Nothing here knows what the model is: the caller brings its outputs,
//! and its random stream for the bootstrap, so that it decides what the
//! intervals are reproducible by.

use super::quantile::{Interpolation, quantile_sorted};
use rand::{Rng, RngExt};

/// Outputs of a pick-freeze design for k inputs (or groups of inputs):
/// f(A), f(B) and f(AB_i), each of N rows, where AB_i is A with column(s) i
/// taken from B (Saltelli 2010's layout, as SALib's `sobol.sample` with
/// `calc_second_order=False`).
#[derive(Debug, Clone, Copy)]
pub struct PickFreeze<'a> {
    /// f(A).
    pub a: &'a [f64],
    /// f(B).
    pub b: &'a [f64],
    /// f(AB_i), one vector per input (or group).
    pub ab: &'a [Vec<f64>],
}

/// One input's indices with their 95 % percentile-bootstrap intervals.
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
        /// Rows of the first AB_i that differs from A (A's own when only B differs).
        ab: usize,
    },
    /// Fewer than two rows.
    #[error("{0} row(s): at least two are needed")]
    TooFew(usize),
    /// An output, or the variance of the outputs, is infinite or NaN.
    #[error("an output or its variance is not finite")]
    NotFinite,
    /// The output does not vary: every index is 0/0.
    #[error("the output does not vary (every run gave the same value): no input explains anything")]
    Constant,
    /// No bootstrap resample could be estimated, so there is no interval.
    #[error("none of the {0} bootstrap resample(s) varied: no interval")]
    NoResamples(usize),
}

/// Saltelli et al. (2010): mean(f_B (f_ABi − f_A)) / V, on the outputs as
/// given ([`indices`] centres them first, as SALib does: this estimator
/// is not invariant to a shift of the output).
pub fn first_order(a: &[f64], b: &[f64], ab_i: &[f64]) -> Result<f64, SobolError> {
    check(a, b, [ab_i])?;
    Ok(first_with(a, b, ab_i, usable_variance(a, b)?))
}

/// Jansen (1999): mean((f_A − f_ABi)²) / (2 V); V needs f(B) too.
pub fn total_order(a: &[f64], b: &[f64], ab_i: &[f64]) -> Result<f64, SobolError> {
    check(a, b, [ab_i])?;
    Ok(total_with(a, ab_i, usable_variance(a, b)?))
}

/// Every input's indices, with 95 % percentile-bootstrap intervals from
/// `resamples` resamples of the rows (the same rows for A, B and every AB_i).
pub fn indices(
    design: &PickFreeze<'_>,
    resamples: usize,
    rng: &mut impl Rng,
) -> Result<Vec<SobolIndex>, SobolError> {
    check(design.a, design.b, design.ab.iter().map(Vec::as_slice))?;
    let (a, b, ab) = centred(design);
    let v = usable_variance(&a, &b)?;
    let (firsts, totals) = bootstrap(&a, &b, &ab, resamples, rng);
    let interval = |mut estimates: Vec<f64>| {
        percentile_interval(&mut estimates).ok_or(SobolError::NoResamples(resamples))
    };
    ab.iter()
        .zip(firsts.into_iter().zip(totals))
        .map(|(ab_i, (firsts, totals))| {
            Ok(SobolIndex {
                first: first_with(&a, &b, ab_i, v),
                first_ci: interval(firsts)?,
                total: total_with(&a, ab_i, v),
                total_ci: interval(totals)?,
            })
        })
        .collect()
}

/// Equal lengths, two rows or more, all finite, and some spread in f(A) ∪ f(B).
fn check<'s>(
    a: &[f64],
    b: &[f64],
    ab: impl IntoIterator<Item = &'s [f64]> + Clone,
) -> Result<(), SobolError> {
    let n = a.len();
    let ab_lengths: Vec<usize> = ab.clone().into_iter().map(<[f64]>::len).collect();
    if b.len() != n || ab_lengths.iter().any(|&len| len != n) {
        let ab = ab_lengths.into_iter().find(|&len| len != n).unwrap_or(n);
        let b = b.len();
        return Err(SobolError::Lengths { a: n, b, ab });
    }
    if n < 2 {
        return Err(SobolError::TooFew(n));
    }
    let finite = |values: &[f64]| values.iter().all(|v| v.is_finite());
    if !(finite(a) && finite(b) && ab.into_iter().all(finite)) {
        return Err(SobolError::NotFinite);
    }
    if a.iter().chain(b).all(|&v| v == a[0]) {
        return Err(SobolError::Constant);
    }
    Ok(())
}

/// V of checked outputs, refused when it is 0 or overflows (outputs within
/// a few ulps of each other, or beyond about 1e154).
fn usable_variance(a: &[f64], b: &[f64]) -> Result<f64, SobolError> {
    match variance(a, b) {
        v if !v.is_finite() => Err(SobolError::NotFinite),
        v if v <= 0.0 => Err(SobolError::Constant),
        v => Ok(v),
    }
}

/// Population variance (ddof = 0) of the 2N values of f(A) and f(B), as
/// SALib's `np.var(np.r_[A, B])`.
fn variance(a: &[f64], b: &[f64]) -> f64 {
    let n = (a.len() + b.len()) as f64;
    let mean = a.iter().chain(b).sum::<f64>() / n;
    a.iter().chain(b).map(|v| (v - mean).powi(2)).sum::<f64>() / n
}

/// [`first_order`] with V already known (the bootstrap shares it across inputs).
fn first_with(a: &[f64], b: &[f64], ab_i: &[f64], v: f64) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .zip(ab_i)
        .map(|((a, b), ab)| b * (ab - a))
        .sum();
    sum / a.len() as f64 / v
}

/// [`total_order`] with V already known.
fn total_with(a: &[f64], ab_i: &[f64], v: f64) -> f64 {
    let sum: f64 = a.iter().zip(ab_i).map(|(a, ab)| (a - ab).powi(2)).sum();
    0.5 * sum / a.len() as f64 / v
}

/// The outputs less the mean of all N (k + 2) of them, as SALib's
/// `Y - Y.mean()`: Saltelli's first-order estimator picks up a term
/// proportional to the output's mean, noise that centring removes
/// (SALib also divides by the standard deviation, which no index sees).
fn centred(design: &PickFreeze<'_>) -> (Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
    let all = || {
        let ab = design.ab.iter().flatten();
        design.a.iter().chain(design.b).chain(ab)
    };
    let mean = all().sum::<f64>() / all().count() as f64;
    let less = |values: &[f64]| values.iter().map(|v| v - mean).collect::<Vec<f64>>();
    let ab = design.ab.iter().map(|ab_i| less(ab_i)).collect();
    (less(design.a), less(design.b), ab)
}

/// First-order and total estimates per input over `resamples` resamples
/// of the rows, drawn as SALib draws them: one set of rows for A, B and
/// every AB_i, so that each resample is a pick-freeze design itself.
fn bootstrap(
    a: &[f64],
    b: &[f64],
    ab: &[Vec<f64>],
    resamples: usize,
    rng: &mut impl Rng,
) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let n = a.len();
    let mut firsts = vec![Vec::with_capacity(resamples); ab.len()];
    let mut totals = firsts.clone();
    let (mut ra, mut rb, mut rab) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut rows = vec![0; n];
    for _ in 0..resamples {
        rows.iter_mut().for_each(|r| *r = rng.random_range(0..n));
        gather(a, &rows, &mut ra);
        gather(b, &rows, &mut rb);
        // A resample whose A and B rows repeat one value has no variance
        // to share out: it says nothing about the indices.
        let Ok(v) = usable_variance(&ra, &rb) else {
            continue;
        };
        for (i, ab_i) in ab.iter().enumerate() {
            gather(ab_i, &rows, &mut rab);
            firsts[i].push(first_with(&ra, &rb, &rab, v));
            totals[i].push(total_with(&ra, &rab, v));
        }
    }
    (firsts, totals)
}

/// `into[j] = from[rows[j]]`.
fn gather(from: &[f64], rows: &[usize], into: &mut [f64]) {
    for (slot, &r) in into.iter_mut().zip(rows) {
        *slot = from[r];
    }
}

/// The 2.5 % and 97.5 % percentiles of bootstrap estimates, by the
/// nearest-rank rule of every percentile bootstrap here; `None` when empty.
fn percentile_interval(estimates: &mut [f64]) -> Option<(f64, f64)> {
    estimates.sort_by(f64::total_cmp);
    let at = |q| quantile_sorted(estimates, q, Interpolation::Nearest);
    Some((at(0.025)?, at(0.975)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;
    use std::f64::consts::PI;

    fn test_rng(seed: u64) -> Xoshiro256PlusPlus {
        Xoshiro256PlusPlus::seed_from_u64(seed)
    }

    /// Bootstrap resamples in the tests: enough for steady 2.5 % tails.
    const RESAMPLES: usize = 1000;

    /// Outputs of a pick-freeze design: f(A), f(B), f(AB_i).
    type Outputs = (Vec<f64>, Vec<f64>, Vec<Vec<f64>>);

    /// Pick-freeze outputs of `f` over k inputs uniform on [0, 1), N rows
    /// of an Owen-scrambled Sobol sequence (A: dimensions 0..k, B: k..2k).
    fn design(f: impl Fn(&[f64]) -> f64, k: usize, n: u32) -> Outputs {
        scrambled_design(f, k, n, 0x5EED)
    }

    /// As [`design`], under the scramble `seed`.
    fn scrambled_design(f: impl Fn(&[f64]) -> f64, k: usize, n: u32, seed: u32) -> Outputs {
        let k32 = k as u32;
        let point = |j: u32, dims: std::ops::Range<u32>| -> Vec<f64> {
            dims.map(|d| f64::from(sobol_burley::sample(j, d, seed)))
                .collect()
        };
        pick_freeze(
            f,
            k,
            (0..n).map(|j| (point(j, 0..k32), point(j, k32..2 * k32))),
        )
    }

    /// As [`design`], the matrices drawn pseudo-randomly (seeded) instead.
    fn random_design(f: impl Fn(&[f64]) -> f64, k: usize, n: u32, seed: u64) -> Outputs {
        let mut rng = test_rng(seed);
        let mut point = || (0..k).map(|_| rng.random::<f64>()).collect::<Vec<f64>>();
        let rows: Vec<_> = (0..n).map(|_| (point(), point())).collect();
        pick_freeze(f, k, rows)
    }

    /// f(A), f(B) and f(AB_i) over rows of (A's inputs, B's inputs).
    fn pick_freeze(
        f: impl Fn(&[f64]) -> f64,
        k: usize,
        rows: impl IntoIterator<Item = (Vec<f64>, Vec<f64>)>,
    ) -> Outputs {
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let mut ab = vec![Vec::new(); k];
        for (xa, xb) in rows {
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

    fn estimate((a, b, ab): &Outputs, seed: u64) -> Vec<SobolIndex> {
        let design = PickFreeze { a, b, ab };
        indices(&design, RESAMPLES, &mut test_rng(seed)).unwrap()
    }

    /// The analytic values inside the intervals, and the intervals narrower
    /// than 0.1 (an interval that covers everything proves nothing).
    fn within(got: &SobolIndex, first: f64, total: f64) {
        let inside = |(lo, hi): (f64, f64), v: f64| lo <= v && v <= hi;
        assert!(inside(got.first_ci, first), "S1 {first} outside {got:?}");
        assert!(inside(got.total_ci, total), "ST {total} outside {got:?}");
        assert!(got.first_ci.1 - got.first_ci.0 < 0.1, "{got:?}");
        assert!(got.total_ci.1 - got.total_ci.0 < 0.1, "{got:?}");
    }

    /// Ishigami's function (a = 7, b = 0.1) of u on [0, 1)^3, x = −π + 2π u.
    fn ishigami(u: &[f64]) -> f64 {
        let x: Vec<f64> = u.iter().map(|u| -PI + 2.0 * PI * u).collect();
        x[0].sin() + 7.0 * x[1].sin().powi(2) + 0.1 * x[2].powi(4) * x[0].sin()
    }

    /// Ishigami (a = 7, b = 0.1) at N = 2^12: S1 = 0.3139, 0.4424, 0 and
    /// ST = 0.5576, 0.4424, 0.2437 (to four places; computed in full from
    /// Sobol & Levitan 1999's variances) each inside its interval.
    #[test]
    fn ishigami_indices_are_inside_their_intervals() {
        let got = estimate(&design(ishigami, 3, 1 << 12), 3);
        let (a, b) = (7.0, 0.1);
        let v1 = 0.5 * (1.0 + b * PI.powi(4) / 5.0).powi(2);
        let v2 = a * a / 8.0;
        let v13 = b * b * PI.powi(8) * (1.0 / 18.0 - 1.0 / 50.0);
        let v = v1 + v2 + v13;
        let analytic = [(v1 / v, (v1 + v13) / v), (v2 / v, v2 / v), (0.0, v13 / v)];
        let published = [(0.3139, 0.5576), (0.4424, 0.4424), (0.0, 0.2437)];
        for ((s1, st), (p1, pt)) in analytic.into_iter().zip(published) {
            assert!(
                (s1 - p1).abs() < 5e-5 && (st - pt).abs() < 5e-5,
                "{s1} {st}"
            );
        }
        for (g, (s1, st)) in got.iter().zip(analytic) {
            within(g, s1, st);
        }
    }

    /// Sobol's g function, a = (0, 1, 4.5, 9, 99, 99), at N = 2^12:
    /// V_i = (1/3)/(1 + a_i)², V = Π(1 + V_i) − 1, S_i = V_i / V and
    /// S_Ti = V_i Π_{j≠i}(1 + V_j) / V, each inside its interval.
    #[test]
    fn g_function_indices_are_inside_their_intervals() {
        let a_i = [0.0, 1.0, 4.5, 9.0, 99.0, 99.0];
        let g = |x: &[f64]| {
            x.iter()
                .zip(a_i)
                .map(|(u, a)| ((4.0 * u - 2.0).abs() + a) / (1.0 + a))
                .product::<f64>()
        };
        let v_i = a_i.map(|a| (1.0 / 3.0) / (1.0 + a).powi(2));
        let v = v_i.iter().map(|v| 1.0 + v).product::<f64>() - 1.0;
        let got = estimate(&design(g, 6, 1 << 12), 4);
        for (i, g) in got.iter().enumerate() {
            let others: f64 = (0..6).filter(|&j| j != i).map(|j| 1.0 + v_i[j]).product();
            within(g, v_i[i] / v, v_i[i] * others / v);
        }
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

    /// SALib 1.6.0's `sobol.analyze` on its own Ishigami outputs (N = 2^10,
    /// bench/sobol/salib_ishigami.py): the same S1 and ST to 1e-12.
    #[test]
    fn agrees_with_salib() {
        let fixture = include_str!("../../tests/fixtures/salib_ishigami.csv");
        let (mut y, mut s1, mut st) = (Vec::new(), Vec::new(), Vec::new());
        for line in fixture.lines().skip(1) {
            let fields: Vec<&str> = line.split(',').collect();
            let value: f64 = fields[2].parse().unwrap();
            match fields[0] {
                "Y" => y.push(value),
                "S1" => s1.push(value),
                "ST" => st.push(value),
                other => panic!("unknown row kind {other}"),
            }
        }
        let k = s1.len();
        assert_eq!((k, st.len(), y.len()), (3, 3, 1024 * (k + 2)));
        // SALib's rows (separate_output_values, calc_second_order=False):
        // per base sample j, A_j, AB_1j, ..., AB_kj, B_j.
        let rows: Vec<&[f64]> = y.chunks(k + 2).collect();
        let a: Vec<f64> = rows.iter().map(|r| r[0]).collect();
        let b: Vec<f64> = rows.iter().map(|r| r[k + 1]).collect();
        let ab: Vec<Vec<f64>> = (0..k)
            .map(|i| rows.iter().map(|r| r[i + 1]).collect())
            .collect();
        let got = indices(
            &PickFreeze {
                a: &a,
                b: &b,
                ab: &ab,
            },
            10,
            &mut test_rng(5),
        )
        .unwrap();
        let mut uncentred: f64 = 0.0;
        for (i, g) in got.iter().enumerate() {
            let (d1, dt) = ((g.first - s1[i]).abs(), (g.total - st[i]).abs());
            assert!(
                d1 < 1e-12 && dt < 1e-12,
                "input {i}: {g:?}, SALib {} {}",
                s1[i],
                st[i]
            );
            let raw = first_order(&a, &b, &ab[i]).unwrap();
            uncentred = uncentred.max((raw - s1[i]).abs());
        }
        // The raw outputs (mean 3.5) give first-order estimates 1e-4 to 1e-3
        // away: the test tells SALib's centring from its absence.
        assert!(uncentred > 1e-5, "{uncentred}");
    }

    /// Centring makes the indices blind to a shift of the output, and one
    /// seed gives one result.
    #[test]
    fn a_shifted_output_gives_the_same_indices() {
        let outputs = design(ishigami, 3, 1 << 8);
        let shift = |v: &[f64]| v.iter().map(|v| v + 1e3).collect::<Vec<f64>>();
        let shifted = (
            shift(&outputs.0),
            shift(&outputs.1),
            outputs.2.iter().map(|v| shift(v)).collect(),
        );
        let (plain, moved) = (estimate(&outputs, 6), estimate(&shifted, 6));
        assert_eq!(plain, estimate(&outputs, 6));
        for (p, m) in plain.iter().zip(&moved) {
            let pairs = [
                (p.first, m.first),
                (p.first_ci.0, m.first_ci.0),
                (p.first_ci.1, m.first_ci.1),
                (p.total, m.total),
                (p.total_ci.0, m.total_ci.0),
                (p.total_ci.1, m.total_ci.1),
            ];
            for (x, y) in pairs {
                assert!((x - y).abs() < 1e-9, "{p:?} against {m:?}");
            }
        }
    }

    /// The estimators on four rows worked by hand: V = 1.25 (the values
    /// 1, 3, 2, 0, 0, 2, 3, 1 about their mean 1.5), S1 = mean(0, 0, 3, 0) / V,
    /// ST = mean(1, 0, 1, 0) / (2 V).
    #[test]
    fn estimators_match_a_hand_computation() {
        let (a, b, ab) = (
            [1.0, 3.0, 2.0, 0.0],
            [0.0, 2.0, 3.0, 1.0],
            [0.0, 3.0, 3.0, 0.0],
        );
        assert_eq!(first_order(&a, &b, &ab), Ok(0.6));
        assert_eq!(total_order(&a, &b, &ab), Ok(0.2));
    }

    /// Bad input is an error the caller can record: never a panic, never NaN.
    #[test]
    fn undefined_indices_are_errors_not_nan() {
        let x: Vec<f64> = (0..8).map(f64::from).collect();
        let c = vec![1.0; 8];
        let (ab_x, ab_c) = (vec![x.clone()], vec![c.clone()]);
        let run = |a: &[f64], b: &[f64], ab: &[Vec<f64>], resamples| {
            indices(&PickFreeze { a, b, ab }, resamples, &mut test_rng(1))
        };
        // Constant output, even when the AB_i vary.
        assert_eq!(run(&c, &c, &ab_c, 10), Err(SobolError::Constant));
        assert_eq!(run(&c, &c, &ab_x, 10), Err(SobolError::Constant));
        assert_eq!(first_order(&c, &c, &x), Err(SobolError::Constant));
        assert_eq!(total_order(&c, &c, &x), Err(SobolError::Constant));
        // Mismatched lengths, in B or in an AB_i.
        let short = vec![1.0; 7];
        let lengths = |b, ab| SobolError::Lengths { a: 8, b, ab };
        let two = [x.clone(), short.clone()];
        assert_eq!(run(&x, &x, &two, 10), Err(lengths(8, 7)));
        assert_eq!(run(&x, &short, &ab_x, 10), Err(lengths(7, 8)));
        assert_eq!(first_order(&x, &x, &short), Err(lengths(8, 7)));
        // Too few rows, non-finite outputs, no resamples.
        assert_eq!(
            run(&[1.0], &[2.0], &[vec![3.0]], 10),
            Err(SobolError::TooFew(1))
        );
        assert_eq!(run(&[], &[], &[], 10), Err(SobolError::TooFew(0)));
        let mut nan = x.clone();
        nan[3] = f64::NAN;
        assert_eq!(run(&x, &x, &[nan], 10), Err(SobolError::NotFinite));
        assert_eq!(run(&x, &c, &ab_x, 0), Err(SobolError::NoResamples(0)));
        // Outputs so large that V overflows.
        let huge: Vec<f64> = x.iter().map(|v| v * 1e300).collect();
        assert_eq!(run(&huge, &x, &ab_x, 10), Err(SobolError::NotFinite));
    }
}
