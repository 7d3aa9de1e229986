//! Kendall's rank correlation τ-b between two rankings with ties.
//!
//! Written here because the comparison is a dozen lines over a few dozen
//! designs (O(n²) is instant) and the crates that have it bring a whole
//! statistics stack for one function.

/// Kendall's τ-b of paired values (Kendall 1945; the tie correction of
/// SciPy's `kendalltau`): (concordant − discordant) /
/// √((pairs − ties in x)(pairs − ties in y)). `None` when fewer than two
/// pairs, the lengths differ, a value is NaN, or every value of one side ties.
pub fn kendall_tau_b(x: &[f64], y: &[f64]) -> Option<f64> {
    if x.len() != y.len() || x.len() < 2 || x.iter().chain(y).any(|v| v.is_nan()) {
        return None;
    }
    let (mut concordant, mut discordant, mut tied_x, mut tied_y) = (0i64, 0i64, 0i64, 0i64);
    for i in 0..x.len() {
        for j in i + 1..x.len() {
            let dx = x[i].total_cmp(&x[j]) as i64;
            let dy = y[i].total_cmp(&y[j]) as i64;
            match (dx, dy) {
                (0, 0) => {
                    tied_x += 1;
                    tied_y += 1;
                }
                (0, _) => tied_x += 1,
                (_, 0) => tied_y += 1,
                _ if dx == dy => concordant += 1,
                _ => discordant += 1,
            }
        }
    }
    let pairs = (x.len() * (x.len() - 1) / 2) as i64;
    let denominator = (((pairs - tied_x) * (pairs - tied_y)) as f64).sqrt();
    (denominator > 0.0).then(|| (concordant - discordant) as f64 / denominator)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SciPy's documented example: `kendalltau([12, 2, 1, 12, 2], [1, 4, 7, 1, 0])`
    /// gives τ-b = −0.47140452079103173.
    #[test]
    fn scipys_example_with_ties() {
        let tau = kendall_tau_b(&[12.0, 2.0, 1.0, 12.0, 2.0], &[1.0, 4.0, 7.0, 1.0, 0.0]).unwrap();
        assert!((tau + 0.471_404_520_791_031_73).abs() < 1e-15, "{tau}");
    }

    /// The same order gives 1, the reversed order −1, a constant side none.
    #[test]
    fn identical_and_reversed_rankings() {
        let x = [1.0, 2.0, 3.0, 4.0];
        assert_eq!(kendall_tau_b(&x, &[10.0, 20.0, 30.0, 40.0]), Some(1.0));
        assert_eq!(kendall_tau_b(&x, &[4.0, 3.0, 2.0, 1.0]), Some(-1.0));
        assert_eq!(kendall_tau_b(&x, &[5.0; 4]), None);
    }
}
