//! A Nelder–Mead simplex for Monte Carlo objectives: it stops when the
//! simplex's own values differ by less than their standard errors (noise,
//! not slope, is left), or when the evaluation budget is used up, and says
//! which. Written by hand because argmin 0.11's `NelderMead` keeps its
//! simplex private: its only stop rule is a fixed spread tolerance, which
//! cannot be tied to the standard errors of the vertices it holds.
//!
//! The coefficients are the standard ones (reflection 1, expansion 2,
//! contraction ½, shrink ½; Lagarias et al. 1998).

/// One evaluated point.
#[derive(Debug, Clone, PartialEq)]
pub struct Vertex {
    /// Where.
    pub x: Vec<f64>,
    /// The objective (lower is better).
    pub f: f64,
    /// Its Monte Carlo standard error (0 for exact objectives).
    pub se: f64,
}

/// Why the simplex stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SimplexStop {
    /// The vertices' values differ by less than their largest standard
    /// error (or, for an exact objective, the simplex has collapsed).
    Tolerance,
    /// The evaluation budget ran out first.
    Budget,
}

/// The objective and what is left of the evaluation budget.
pub trait Objective {
    /// f(x) and its standard error; `None` when the budget is used up.
    fn eval(&mut self, x: &[f64]) -> Option<(f64, f64)>;
}

/// Minimise from `start` with initial steps `steps` (one per coordinate).
/// Returns the final simplex, best vertex first, and why it stopped.
pub fn minimise(
    objective: &mut dyn Objective,
    start: &[f64],
    steps: &[f64],
) -> (Vec<Vertex>, SimplexStop) {
    let d = start.len();
    let mut simplex: Vec<Vertex> = Vec::with_capacity(d + 1);
    for i in 0..=d {
        let mut x = start.to_vec();
        if i > 0 {
            x[i - 1] += steps[i - 1];
        }
        let Some((f, se)) = objective.eval(&x) else {
            sort(&mut simplex);
            return (simplex, SimplexStop::Budget);
        };
        simplex.push(Vertex { x, f, se });
    }
    loop {
        sort(&mut simplex);
        if converged(&simplex, steps) {
            return (simplex, SimplexStop::Tolerance);
        }
        let worst = simplex[d].clone();
        let centroid: Vec<f64> = (0..d)
            .map(|k| simplex[..d].iter().map(|v| v.x[k]).sum::<f64>() / d as f64)
            .collect();
        let along = |t: f64| -> Vec<f64> {
            (0..d)
                .map(|k| centroid[k] + t * (worst.x[k] - centroid[k]))
                .collect()
        };
        macro_rules! eval_or_stop {
            ($x:expr) => {{
                let x = $x;
                match objective.eval(&x) {
                    Some((f, se)) => Vertex { x, f, se },
                    None => {
                        sort(&mut simplex);
                        return (simplex, SimplexStop::Budget);
                    }
                }
            }};
        }
        let reflected = eval_or_stop!(along(-1.0));
        if reflected.f < simplex[0].f {
            let expanded = eval_or_stop!(along(-2.0));
            simplex[d] = if expanded.f < reflected.f {
                expanded
            } else {
                reflected
            };
            continue;
        }
        if reflected.f < simplex[d - 1].f {
            simplex[d] = reflected;
            continue;
        }
        let contracted = if reflected.f < worst.f {
            eval_or_stop!(along(-0.5))
        } else {
            eval_or_stop!(along(0.5))
        };
        if contracted.f < reflected.f.min(worst.f) {
            simplex[d] = contracted;
            continue;
        }
        // Shrink towards the best vertex.
        let best = simplex[0].x.clone();
        for i in 1..=d {
            let x: Vec<f64> = (0..d)
                .map(|k| best[k] + 0.5 * (simplex[i].x[k] - best[k]))
                .collect();
            simplex[i] = eval_or_stop!(x);
        }
    }
}

fn sort(simplex: &mut [Vertex]) {
    simplex.sort_by(|a, b| a.f.total_cmp(&b.f));
}

/// The values differ by less than the largest standard error among the
/// vertices; or, without noise, by a relative 1e-9, or the simplex has
/// shrunk below 1e-6 of its first steps.
fn converged(simplex: &[Vertex], steps: &[f64]) -> bool {
    let spread = simplex[simplex.len() - 1].f - simplex[0].f;
    let se = simplex.iter().map(|v| v.se).fold(0.0, f64::max);
    if se > 0.0 {
        return spread <= se;
    }
    let small = spread <= 1e-9 * simplex[0].f.abs().max(1e-12);
    let collapsed = (0..steps.len()).all(|k| {
        let (lo, hi) = simplex
            .iter()
            .map(|v| v.x[k])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(x), b.max(x))
            });
        hi - lo <= 1e-6 * steps[k].abs()
    });
    small || collapsed
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Quadratic {
        calls: u64,
        budget: u64,
        noise_se: f64,
    }

    impl Objective for Quadratic {
        fn eval(&mut self, x: &[f64]) -> Option<(f64, f64)> {
            if self.calls == self.budget {
                return None;
            }
            self.calls += 1;
            let f = (x[0] - 1.0).powi(2) + 4.0 * (x[1] + 2.0).powi(2);
            Some((f, self.noise_se))
        }
    }

    /// A quadratic bowl with its minimum at `centre`, seen through the box
    /// [0, 1]² (points outside are clamped, as the optimiser does), plus
    /// Gaussian-like noise of standard error `se` that is a fixed function of
    /// the point (the same samples give the same value).
    struct NoisyBowl {
        centre: [f64; 2],
        se: f64,
        calls: u64,
    }

    impl Objective for NoisyBowl {
        fn eval(&mut self, x: &[f64]) -> Option<(f64, f64)> {
            if self.calls == 400 {
                return None;
            }
            self.calls += 1;
            let p = [x[0].clamp(0.0, 1.0), x[1].clamp(0.0, 1.0)];
            let bits = p[0].to_bits().wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ p[1].to_bits();
            // Sum of four uniforms on [−½, ½]: variance 1/3, scaled to se.
            let mut h = bits;
            let mut u = 0.0;
            for _ in 0..4 {
                h ^= h >> 33;
                h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
                h ^= h >> 33;
                u += (h >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            }
            let noise = self.se * u * 3f64.sqrt();
            let f = 100.0 * ((p[0] - self.centre[0]).powi(2) + (p[1] - self.centre[1]).powi(2));
            Some((f + noise, self.se))
        }
    }

    #[test]
    fn a_noisy_optimum_inside_the_box_is_found_within_the_noise() {
        let mut bowl = NoisyBowl {
            centre: [0.3, 0.6],
            se: 0.5,
            calls: 0,
        };
        let (s, stop) = minimise(&mut bowl, &[0.5, 0.5], &[0.25, 0.25]);
        assert_eq!(stop, SimplexStop::Tolerance);
        // Within the noise: 100 d² ≲ a few standard errors.
        let d2 = (s[0].x[0] - 0.3).powi(2) + (s[0].x[1] - 0.6).powi(2);
        assert!(100.0 * d2 < 4.0 * 0.5, "{s:?}");
    }

    #[test]
    fn a_noisy_optimum_beyond_the_box_ends_on_its_bound() {
        let mut bowl = NoisyBowl {
            centre: [1.4, 0.5],
            se: 0.5,
            calls: 0,
        };
        let (s, stop) = minimise(&mut bowl, &[0.5, 0.5], &[0.25, 0.25]);
        assert_eq!(stop, SimplexStop::Tolerance);
        // The value at the bound is 16; the best seen is within the noise of it.
        assert!(s[0].x[0] >= 0.95 && s[0].f < 16.0 + 4.0 * 0.5, "{s:?}");
    }

    #[test]
    fn finds_the_minimum_of_an_exact_quadratic() {
        let mut q = Quadratic {
            calls: 0,
            budget: 1000,
            noise_se: 0.0,
        };
        let (s, stop) = minimise(&mut q, &[0.0, 0.0], &[0.5, 0.5]);
        assert_eq!(stop, SimplexStop::Tolerance);
        assert!(
            (s[0].x[0] - 1.0).abs() < 1e-3 && (s[0].x[1] + 2.0).abs() < 1e-3,
            "{s:?}"
        );
    }

    #[test]
    fn stops_when_the_spread_is_within_the_standard_error_and_says_budget_otherwise() {
        let mut q = Quadratic {
            calls: 0,
            budget: 1000,
            noise_se: 0.05,
        };
        let (s, stop) = minimise(&mut q, &[0.0, 0.0], &[0.5, 0.5]);
        assert_eq!(stop, SimplexStop::Tolerance);
        assert!(s[s.len() - 1].f - s[0].f <= 0.05);
        let calls_with_noise = q.calls;
        let mut tight = Quadratic {
            calls: 0,
            budget: 1000,
            noise_se: 0.0,
        };
        minimise(&mut tight, &[0.0, 0.0], &[0.5, 0.5]);
        assert!(calls_with_noise < tight.calls);
        let mut short = Quadratic {
            calls: 0,
            budget: 5,
            noise_se: 0.0,
        };
        assert_eq!(
            minimise(&mut short, &[0.0, 0.0], &[0.5, 0.5]).1,
            SimplexStop::Budget
        );
    }
}
