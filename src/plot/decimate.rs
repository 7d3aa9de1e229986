//! Thin a long time series for drawing without losing its envelope.
//!
//! A run records 32+ samples per revolution for up to thousands of
//! revolutions; a figure a thousand pixels wide cannot show more than a few
//! thousand points, and an SVG with 60 000 points per line is megabytes. Each
//! bucket keeps its smallest and largest value, in time order, so peaks and
//! the oscillation envelope survive.

/// At most about `max_points` (t, y) pairs that keep each bucket's extremes.
pub fn min_max(t: &[f64], y: &[f64], max_points: usize) -> Vec<(f64, f64)> {
    let len = t.len().min(y.len());
    if len <= max_points.max(2) {
        return t.iter().copied().zip(y.iter().copied()).take(len).collect();
    }
    let buckets = (max_points / 2).max(1);
    let size = len.div_ceil(buckets);
    let mut out = Vec::with_capacity(2 * buckets + 2);
    // The ends are kept so that the thinned line spans the same time.
    out.push((t[0], y[0]));
    for start in (0..len).step_by(size) {
        let end = (start + size).min(len);
        let (mut lo, mut hi) = (start, start);
        for i in start..end {
            if y[i] < y[lo] {
                lo = i;
            }
            if y[i] > y[hi] {
                hi = i;
            }
        }
        let (a, b) = if lo <= hi { (lo, hi) } else { (hi, lo) };
        for i in [a, b] {
            if out.last().is_none_or(|p| p.0 < t[i]) {
                out.push((t[i], y[i]));
            }
        }
    }
    if let Some(&(last_t, _)) = out.last()
        && last_t < t[len - 1]
    {
        out.push((t[len - 1], y[len - 1]));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::min_max;

    #[test]
    fn short_series_pass_through() {
        let t = [0.0, 1.0, 2.0];
        let y = [3.0, 1.0, 2.0];
        assert_eq!(
            min_max(&t, &y, 10),
            vec![(0.0, 3.0), (1.0, 1.0), (2.0, 2.0)]
        );
    }

    #[test]
    fn long_series_keep_extremes_and_ends() {
        let t: Vec<f64> = (0..10_000).map(f64::from).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|x| (x * 0.37).sin() * (1.0 + x / 1e4))
            .collect();
        let d = min_max(&t, &y, 500);
        assert!(d.len() <= 503, "{}", d.len());
        let peak = y.iter().copied().fold(f64::MIN, f64::max);
        assert!(d.iter().any(|p| p.1 == peak));
        assert_eq!(d.first().unwrap().0, 0.0);
        assert_eq!(d.last().unwrap().0, 9999.0);
        assert!(d.windows(2).all(|w| w[0].0 < w[1].0));
    }
}
