//! How far the weights stopped from balance, as an angle: the smallest,
//! over the rotor's balanced states, of the largest angle between a weight
//! and its position in that state (`balance_angle_error_deg`).
//!
//! With three or more weights in a plane the balanced states form a
//! continuum {ψ : Σ_j c_j e^{iψ_j} = T} (c_j = m_j l_j, T the plane's
//! correction unbalance), so "the" balanced position of a weight is the one
//! of the balanced state nearest to where the weights stopped. For two
//! weights the set is two points (a triangle and its mirror image) and the
//! answer is closed form; for more, the smallest t whose arcs
//! {c_j e^{i(φ_j + δ)} : |δ| ≤ t} can still sum to T is found by bisection,
//! each t decided by exact coordinate-wise minimisation of the distance to
//! T over the arcs, from several starts. A t whose arcs provably cannot
//! reach T (a line separates T from their convex hull by more than the
//! tolerance) is decided without the minimisation: the descents could not
//! have reached it either, so the answer is the same to the bit.
//!
//! The weights are treated as points here: the gaps between solid weights
//! are not a constraint of the balanced set (a nearest balanced state of
//! weights that stopped apart keeps them apart in every case checked).

use num_complex::Complex64;
use std::f64::consts::PI;

/// Angle in (−π, π].
fn wrap(a: f64) -> f64 {
    // `rem_euclid` without its fmod where that is a no-op (same bits).
    let r = if (0.0..2.0 * PI).contains(&a) {
        a
    } else if a < 0.0 && a > -2.0 * PI {
        a + 2.0 * PI
    } else {
        a.rem_euclid(2.0 * PI)
    };
    if r > PI { r - 2.0 * PI } else { r }
}

/// The smallest, over {ψ : Σ c_j e^{iψ_j} = target}, of max_j |ψ_j − φ_j|
/// (radians). `upper` is the value at one known balanced state (it bounds
/// the answer). `None` when the target cannot be reached at all.
pub fn nearest_balanced_angle(
    c: &[f64],
    phi: &[f64],
    target: Complex64,
    upper: f64,
) -> Option<f64> {
    let n = c.len();
    let total: f64 = c.iter().sum();
    if n == 0 || target.norm() > total * (1.0 + 1e-12) {
        return None;
    }
    match n {
        1 => Some(wrap(phi[0] - target.arg()).abs()),
        2 => Some(two_weights(c, phi, target)),
        _ => Some(bisect(c, phi, target, upper.min(PI))),
    }
}

/// Two weights: the two triangles with sides c_0, c_1, |T|.
fn two_weights(c: &[f64], phi: &[f64], target: Complex64) -> f64 {
    let rho = target.norm();
    let cos_of = |a: f64, b: f64| ((a * a + rho * rho - b * b) / (2.0 * a * rho)).clamp(-1.0, 1.0);
    let (a0, a1) = if rho > 0.0 {
        (cos_of(c[0], c[1]).acos(), cos_of(c[1], c[0]).acos())
    } else {
        // T = 0 needs equal weights opposite each other, at any angle: the
        // nearest such pair splits the difference.
        let gap = wrap(phi[1] - phi[0] - PI);
        return 0.5 * gap.abs();
    };
    let arg = target.arg();
    [1.0, -1.0]
        .iter()
        .map(|s| {
            let p0 = arg + s * a0;
            let p1 = arg - s * a1;
            wrap(p0 - phi[0]).abs().max(wrap(p1 - phi[1]).abs())
        })
        .fold(f64::INFINITY, f64::min)
}

/// Relative distance below which T counts as reached.
const REACHED: f64 = 1e-10;

/// The smallest t in [0, upper] at which the arcs reach T (bisection to
/// 1e-8 rad, 6·10⁻⁷°).
fn bisect(c: &[f64], phi: &[f64], target: Complex64, upper: f64) -> f64 {
    let scale: f64 = c.iter().sum();
    let threshold = REACHED * scale;
    // e^{−iφ_j}: turns T − rest into weight j's frame, to see without an
    // atan2 that it points well outside the arc.
    // Only for angles small enough that wrap(arg − φ_j) is good to far
    // better than the 1e-12 rad margin of `Arcs::tan_off`.
    let unturn: Vec<Complex64> = if phi.iter().all(|p| p.abs() < 100.0) {
        phi.iter()
            .map(|&p| Complex64::new(p.cos(), -p.sin()))
            .collect()
    } else {
        Vec::new()
    };
    // Whether a t is reached does not depend on the order of the starts
    // (any start that reaches decides it), so the start that reached last
    // is tried first.
    let mut first = 0;
    let mut reached = |t: f64| {
        let arcs = Arcs::new(c, phi, &unturn, target, t);
        arcs.reaches(threshold, &mut first)
    };
    if reached(0.0) {
        return 0.0;
    }
    let mut hi = upper;
    // The known balanced state should reach T; if the search misses it
    // there, widen the bracket rather than report a wrong bound.
    while !reached(hi) && hi < PI {
        hi = (2.0 * hi).min(PI);
    }
    let mut lo = 0.0;
    while hi - lo > 1e-8 {
        let mid = 0.5 * (lo + hi);
        if reached(mid) { hi = mid } else { lo = mid }
    }
    hi
}

/// The arcs {c_j e^{i(φ_j + δ)} : |δ| ≤ t} of one probe, with the ends'
/// points computed once.
struct Arcs<'a> {
    c: &'a [f64],
    phi: &'a [f64],
    unturn: &'a [Complex64],
    target: Complex64,
    t: f64,
    /// c_j e^{i(φ_j + t)} and c_j e^{i(φ_j − t)}.
    plus: Vec<Complex64>,
    minus: Vec<Complex64>,
    /// tan(t + 1e-12) when 1e-9 < t < 1 (a direction whose angle from φ_j
    /// has a tangent beyond it is off the arc whatever the rounding), else
    /// NaN (never beyond).
    tan_off: f64,
}

impl<'a> Arcs<'a> {
    fn new(
        c: &'a [f64],
        phi: &'a [f64],
        unturn: &'a [Complex64],
        target: Complex64,
        t: f64,
    ) -> Self {
        let plus = (0..c.len())
            .map(|j| Complex64::from_polar(c[j], phi[j] + t))
            .collect();
        let minus = (0..c.len())
            .map(|j| Complex64::from_polar(c[j], phi[j] + -t))
            .collect();
        let tan_off = if t > 1e-9 && t < 1.0 && !unturn.is_empty() {
            (t + 1e-12).tan()
        } else {
            f64::NAN
        };
        Arcs {
            c,
            phi,
            unturn,
            target,
            t,
            plus,
            minus,
            tan_off,
        }
    }

    /// Whether any start's descent (`descend`) reaches T within
    /// `threshold`, trying start `first` before the others and leaving in
    /// it the one that did.
    fn reaches(&self, threshold: f64, first: &mut usize) -> bool {
        if self.surely_unreached(threshold) {
            return false;
        }
        let count = 1 + 2 * (1usize << self.c.len().min(6));
        if self.descend(*first, threshold) {
            return true;
        }
        for start in (0..count).filter(|&s| s != *first) {
            if self.descend(start, threshold) {
                *first = start;
                return true;
            }
        }
        false
    }

    /// Whether T is provably farther than `threshold` from every sum of
    /// points on the arcs, by a direction u in which T lies beyond the
    /// arcs' extent: Re(ū T) − Σ_j max over arc j of Re(ū c_j e^{iθ}) is a
    /// lower bound of every distance the descents can return (the
    /// separating-line bound of the arcs' convex hull, with the arcs
    /// widened by 1e-12 rad and a margin of 1e-12 Σ c_j against rounding).
    fn surely_unreached(&self, threshold: f64) -> bool {
        if self.tan_off.is_nan() {
            return false;
        }
        let (c, phi, target) = (self.c, self.phi, self.target);
        let n = c.len();
        let wide = self.t + 1e-12;
        let ends: Vec<(Complex64, Complex64)> = (0..n)
            .map(|j| {
                (
                    Complex64::from_polar(c[j], phi[j] + wide),
                    Complex64::from_polar(c[j], phi[j] - wide),
                )
            })
            .collect();
        let limit = threshold + 1e-12 * c.iter().sum::<f64>();
        // How far T lies beyond the arcs in direction θ.
        let beyond = |theta: f64| {
            let u = Complex64::from_polar(1.0, theta);
            let dot = |z: Complex64| u.re * z.re + u.im * z.im;
            let mut gap = dot(target);
            for j in 0..n {
                gap -= if wrap(theta - phi[j]).abs() <= wide + 1e-9 {
                    c[j]
                } else {
                    dot(ends[j].0).max(dot(ends[j].1))
                };
            }
            gap
        };
        let centre: Complex64 = (0..n).map(|j| Complex64::from_polar(c[j], phi[j])).sum();
        let mut theta = (target - centre).arg();
        let mut best = beyond(theta);
        let mut step = 0.1;
        while best <= limit && step > 1e-9 {
            let (left, right) = (beyond(theta - step), beyond(theta + step));
            if left > best && left >= right {
                (theta, best) = (theta - step, left);
            } else if right > best {
                (theta, best) = (theta + step, right);
            } else {
                step *= 0.5;
            }
        }
        best > limit
    }

    /// The sign of weight j's best angle when T − rest (`w`) points clearly
    /// outside its arc, `None` when that takes the exact angle to decide.
    fn clearly_off(&self, j: usize, w: Complex64) -> Option<f64> {
        if self.tan_off.is_nan() {
            return None;
        }
        let r = w * self.unturn[j];
        let beyond = if r.re > 0.0 {
            r.im.abs() > self.tan_off * r.re
        } else {
            // Beyond a right angle (t < 1 here), unless so near ±π that the
            // wrapped angle's sign is in doubt.
            r.im.abs() > 1e-6 * -r.re
        };
        beyond.then(|| if r.im > 0.0 { 1.0 } else { -1.0 })
    }

    /// Whether the least |Σ c_j e^{i(φ_j + δ_j)} − T| that exact
    /// coordinate-wise minimisation reaches from start `start` is within
    /// `threshold`. Start 0 is the centre of every arc,
    /// then every pattern of arc ends (up to 2⁶ of them) at full and at half
    /// length. The problem is not convex; the starts cover the centre and
    /// both ends of every arc.
    fn descend(&self, start: usize, threshold: f64) -> bool {
        let (c, phi, target, t) = (self.c, self.phi, self.target, self.t);
        let n = c.len();
        let patterns = 1usize << n.min(6);
        let (mask, size) = match start {
            0 => (0, 0.0),
            s if s <= patterns => (s - 1, 1.0),
            s => (s - 1 - patterns, 0.5),
        };
        let mut terms: Vec<Complex64> = (0..n)
            .map(|j| {
                let up = mask >> (j % 6) & 1 == 1;
                if size == 1.0 {
                    if up { self.plus[j] } else { self.minus[j] }
                } else {
                    let sign = if up { 1.0 } else { -1.0 };
                    Complex64::from_polar(c[j], phi[j] + sign * size * t)
                }
            })
            .collect();
        let mut sum: Complex64 = terms.iter().sum();
        // The distances' moduli (`norm`, a hypot) are only taken when their
        // squares leave a decision in doubt.
        let mut last = sum - target;
        let mut within = false;
        for _ in 0..300 {
            for j in 0..n {
                let rest = sum - terms[j];
                // The best angle for weight j points it at T − rest, clamped
                // to its arc.
                let w = target - rest;
                let up = match self.clearly_off(j, w) {
                    Some(sign) => Some(sign > 0.0),
                    None => {
                        let want = wrap(w.arg() - phi[j]);
                        if want.abs() > t {
                            Some(want > 0.0)
                        } else {
                            terms[j] = Complex64::from_polar(c[j], phi[j] + want);
                            None
                        }
                    }
                };
                if let Some(up) = up {
                    // On a clamped arc the nearer end is the better one.
                    let (near, far) = if up {
                        (self.plus[j], self.minus[j])
                    } else {
                        (self.minus[j], self.plus[j])
                    };
                    terms[j] = if nearer(rest + far - target, rest + near - target) {
                        far
                    } else {
                        near
                    };
                }
                sum = rest + terms[j];
            }
            let now = sum - target;
            within = no_farther(now, threshold);
            if within || stalled(last, now) {
                break;
            }
            last = now;
        }
        within
    }
}

/// `a.norm() <= limit`, by the squares when they differ clearly.
fn no_farther(a: Complex64, limit: f64) -> bool {
    let (a2, limit2) = (a.norm_sqr(), limit * limit);
    if !(1e-100..1e100).contains(&limit) {
        a.norm() <= limit
    } else if a2 < limit2 * (1.0 - 1e-9) {
        true
    } else if a2 > limit2 * (1.0 + 1e-9) {
        false
    } else {
        a.norm() <= limit
    }
}

/// `last.norm() − now.norm() <= 1e-12 * last.norm()` (the descent gains
/// nothing more), by the squares when they differ clearly from the
/// boundary (1 − 1e-12)² ≈ 1 − 2·10⁻¹².
fn stalled(last: Complex64, now: Complex64) -> bool {
    let (l2, n2) = (last.norm_sqr(), now.norm_sqr());
    let exact = || last.norm() - now.norm() <= 1e-12 * last.norm();
    if !(1e-200..1e200).contains(&l2) {
        exact()
    } else if n2 > l2 * (1.0 - 2e-12 + 1e-13) {
        true
    } else if n2 < l2 * (1.0 - 2e-12 - 1e-13) {
        false
    } else {
        exact()
    }
}

/// `a.norm() < b.norm()`, by the squares when they differ clearly.
fn nearer(a: Complex64, b: Complex64) -> bool {
    let (a2, b2) = (a.norm_sqr(), b.norm_sqr());
    if a2 < b2 * (1.0 - 1e-9) {
        true
    } else if a2 > b2 * (1.0 + 1e-9) {
        false
    } else {
        a.norm() < b.norm()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_weights_closed_form_agrees_with_the_bisection() {
        let c = [1.0, 1.0];
        let phi = [0.3, 2.0];
        let target = Complex64::from_polar(1.2, 1.0);
        let exact = two_weights(&c, &phi, target);
        let search = bisect(&c, &phi, target, PI);
        assert!((exact - search).abs() < 1e-6, "{exact} {search}");
    }

    /// Final angles of runs of `studies/friction.toml` (weights' m·l, final
    /// angles in rad, the plane's correction unbalance T in kg·m), with the
    /// answer of an independent minimiser: SciPy 1.17's SLSQP on
    /// min t s.t. |ψ_j − φ_j| ≤ t, Σ c_j e^{iψ_j} = T, best of 12 starts.
    /// The last number is what the old metric (the Newton iteration's
    /// balanced state) reported, in degrees.
    #[allow(clippy::type_complexity)]
    const FRICTION_RUNS: [(&[f64], &[f64], (f64, f64), f64, f64); 6] = [
        (
            &[0.002408349836980457; 4],
            &[
                3.4611203086976317,
                0.4235440277825273,
                1.609005538531876,
                2.2886788027927487,
            ],
            (-0.001649229252214537, 0.004665480290987973),
            2.3154013554762374,
            27.085011471847768,
        ),
        (
            &[0.0038841866170820794; 4],
            &[
                1.7418589798544275,
                2.6276804252948156,
                3.7713673208942255,
                0.4570054027695349,
            ],
            (-0.003620766811916667, 0.005376944596684591),
            1.4059803890342495,
            19.31152543356672,
        ),
        (
            &[0.002408349836980457; 4],
            &[
                1.8365155606541,
                2.516188619743714,
                3.250011484683481,
                0.2859003986301256,
            ],
            (-0.0028800613630105215, 0.004276975344833639),
            2.8347076473674417,
            19.50569294976983,
        ),
        (
            &[0.002408349836980457; 4],
            &[
                4.271632315796458,
                1.3710938010248017,
                2.558685699518205,
                3.238358942788777,
            ],
            (-0.0051666554915805836, 0.0011476868178382056),
            2.334662026969469,
            16.409653747846797,
        ),
        (
            &[0.002408349836980457; 3],
            &[5.905318704769526, 1.2479690632833182, 4.8273044095979545],
            (0.003374064738071458, -0.001224516187494143),
            4.27021921082611,
            10.166506243841834,
        ),
        (
            &[0.002408349836980457; 3],
            &[3.6581445722205856, 0.4772908419826121, 1.6725645391575228],
            (-4.5875270434074233e-05, 0.0025720711470737633),
            6.572842999826157,
            12.14616576792995,
        ),
    ];

    #[test]
    fn agrees_with_an_independent_minimiser_to_a_hundredth_of_a_degree() {
        for (c, phi, (re, im), slsqp, old) in FRICTION_RUNS {
            let got = nearest_balanced_angle(c, phi, Complex64::new(re, im), old.to_radians())
                .unwrap()
                .to_degrees();
            assert!(
                (got - slsqp).abs() < 0.01,
                "{got} against SLSQP {slsqp} (old {old})"
            );
            // The old metric overstated by a wide margin in every one of these.
            assert!(old > got + 3.0);
        }
    }

    /// The bisection and minimiser as they were before the probes were made
    /// cheaper, to check that every answer is unchanged to the bit.
    mod reference {
        use super::super::{REACHED, wrap};
        use num_complex::Complex64;
        use std::f64::consts::PI;

        pub fn bisect(c: &[f64], phi: &[f64], target: Complex64, upper: f64) -> f64 {
            let scale: f64 = c.iter().sum();
            let reached = |t: f64| distance(c, phi, target, t) <= REACHED * scale;
            if reached(0.0) {
                return 0.0;
            }
            let mut hi = upper;
            while !reached(hi) && hi < PI {
                hi = (2.0 * hi).min(PI);
            }
            let mut lo = 0.0;
            while hi - lo > 1e-8 {
                let mid = 0.5 * (lo + hi);
                if reached(mid) { hi = mid } else { lo = mid }
            }
            hi
        }

        fn distance(c: &[f64], phi: &[f64], target: Complex64, t: f64) -> f64 {
            let n = c.len();
            let patterns = 1u32 << n.min(6);
            let starts = std::iter::once((0, 0.0))
                .chain((0..patterns).map(|m| (m, 1.0)))
                .chain((0..patterns).map(|m| (m, 0.5)));
            let mut best = f64::INFINITY;
            for (mask, size) in starts {
                let mut delta: Vec<f64> = (0..n)
                    .map(|j| {
                        let sign = if mask >> (j % 6) & 1 == 1 { 1.0 } else { -1.0 };
                        sign * size * t
                    })
                    .collect();
                let term = |j: usize, d: f64| Complex64::from_polar(c[j], phi[j] + d);
                let mut sum: Complex64 = (0..n).map(|j| term(j, delta[j])).sum();
                let mut last = (sum - target).norm();
                for _ in 0..300 {
                    for j in 0..n {
                        let rest = sum - term(j, delta[j]);
                        let want = wrap((target - rest).arg() - phi[j]);
                        let d = want.clamp(-t, t);
                        let d = if want.abs() > t {
                            let other = -d;
                            if (rest + term(j, other) - target).norm()
                                < (rest + term(j, d) - target).norm()
                            {
                                other
                            } else {
                                d
                            }
                        } else {
                            d
                        };
                        delta[j] = d;
                        sum = rest + term(j, d);
                    }
                    let now = (sum - target).norm();
                    if now <= REACHED * c.iter().sum::<f64>() || last - now <= 1e-12 * last {
                        last = now;
                        break;
                    }
                    last = now;
                }
                best = best.min(last);
                if best <= REACHED * c.iter().sum::<f64>() {
                    break;
                }
            }
            best
        }
    }

    fn same_as_reference(c: &[f64], phi: &[f64], target: Complex64, upper: f64) {
        let got = bisect(c, phi, target, upper);
        let want = reference::bisect(c, phi, target, upper);
        assert_eq!(
            got.to_bits(),
            want.to_bits(),
            "{c:?} {phi:?} {target} {upper}: {got} against {want}"
        );
    }

    #[test]
    fn cheaper_probes_give_the_same_bits() {
        for (c, phi, (re, im), _, old) in FRICTION_RUNS {
            same_as_reference(c, phi, Complex64::new(re, im), old.to_radians());
        }
        // Weights stopped at random near a balanced state, with random sizes
        // and angles beyond 2π; a small linear congruential generator.
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..60 {
            let n = 3 + case % 3;
            let c: Vec<f64> = (0..n).map(|_| 0.002 * (0.5 + uniform())).collect();
            let psi: Vec<f64> = (0..n).map(|_| 2.0 * PI * uniform()).collect();
            let spread = [0.02, 0.2, 1.0][case % 3];
            let phi: Vec<f64> = psi
                .iter()
                .map(|p| {
                    p + spread * (2.0 * uniform() - 1.0)
                        + if case % 7 == 0 { 4.0 * PI } else { 0.0 }
                })
                .collect();
            let target: Complex64 = (0..n).map(|j| Complex64::from_polar(c[j], psi[j])).sum();
            let upper = (0..n)
                .map(|j| wrap(phi[j] - psi[j]).abs())
                .fold(0.0, f64::max);
            same_as_reference(&c, &phi, target, upper.min(PI));
        }
    }

    #[test]
    fn weights_already_balanced_are_zero_degrees_away() {
        let c = [1.0, 1.0, 1.0];
        let phi = [0.0, 2.0 * PI / 3.0, 4.0 * PI / 3.0];
        assert_eq!(
            nearest_balanced_angle(&c, &phi, Complex64::new(0.0, 0.0), 0.5),
            Some(0.0)
        );
    }
}
