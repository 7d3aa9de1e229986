//! Certified "will not settle": end a run early once its motion provably
//! repeats every revolution outside the settling band (or below the
//! operating speed), the twin of the certified hold.
//!
//! Once per revolution, at the revolution boundaries of the sample grid, the
//! observer hands this watch a *stroboscopic state*: the rotor's position
//! and velocity in the rotor's own (body) frame, the weights' angles (mod
//! 2π) and rates, and the spin rate, all scaled (positions by A_ref, rates
//! by ω), together with r at every sample of the revolution. The map from
//! one such state to the next is the Poincaré map over one revolution: its
//! fixed points are the periodic orbits of a horizontal axis under gravity
//! or an anisotropic rotor, and the fixed points of the rotating frame
//! (stuck weights at constant speed, a motor captured with its weights
//! locked) are fixed points of it too.
//!
//! Near a fixed point the change d_k between consecutive compared states
//! stops growing: it shrinks while the motion contracts onto the orbit, then
//! sits at the integration's own noise, or at a weight's constant creep
//! through its dead band. When the largest of the last [`WINDOW`] changes is
//! no larger than the largest of the [`WINDOW`] before them, every later
//! state is taken to lie within
//!
//!   T = [`GROWTH`] · max d · (steps left to the horizon)
//!
//! of the current one: every later step may change it by twice as much as
//! the largest recent one. (A geometric tail, d_k · q/(1 − q) from the
//! contraction ratio q, was tried and dropped: on `friction` and
//! `tolerances` the fast modes contract at q ≈ 0.85 while a weight's creep,
//! hidden beneath them, goes on, and the residual missed by up to 2 %.)
//! The run then ends as `not_settled` when, with T taken off, r still
//! leaves the band δ·A_ref by [`MARGIN`] in every [`LAG`] revolutions (the
//! hold can never complete), or the spin rate stays outside δ of the
//! operating speed (it is never reached); and when T moves the residual,
//! the RMS of r over the last hold window, by at most [`RESIDUAL_SHARE`]
//! (the window then repeats the last [`LAG`] revolutions).
//!
//! On a rotor with several watched planes (two supports), the state is
//! each plane's body-frame position and velocity, each scaled by the
//! plane's own A_ref, and r is compared per plane too: one plane whose
//! whirl leaves its own band every [`LAG`] revolutions keeps the hold from
//! completing. The watch runs only where the planes' displacements fix the
//! rotor's whole position (the two-support rigid rotor), so that no mode
//! of the rotor escapes the comparison.
//!
//! Like the certified hold, this is a checked bound, not a proof: a slower
//! mode the last revolutions have not excited, or a basin left later, would
//! escape it. `tests/it/never_settles.rs` compares it run by run with the
//! full integration on every shipped study. Weights that circulate
//! relative to the rotor (a quasi-periodic motion: most runs of
//! `gravity_horizontal` and of a captured motor in `sommerfeld`) and
//! weights creeping through their dead band at a constant rate never meet
//! the contraction test, so they run to the horizon as before.

/// States are compared [`LAG`] revolutions apart: the map is that over two
/// revolutions. Its fixed points are the orbits of period one and two: a
/// step-size pattern that repeats every two revolutions leaves the state
/// alternating by 1e-7 (rtol 1e-6) about an orbit of period one, which a
/// one-revolution comparison would take for a drift.
pub const LAG: usize = 2;
/// Changes in each of the two windows compared (recent against earlier).
pub const WINDOW: usize = 7;
/// The tail bound's allowance for later changes larger than the recent ones.
pub const GROWTH: f64 = 2.0;
/// r minus the tail bound must exceed the band by this fraction of it (and
/// the spin rate's distance from the operating speed its band likewise).
pub const MARGIN: f64 = 0.02;
/// The tail bound may move the residual by at most this fraction of it.
pub const RESIDUAL_SHARE: f64 = 0.005;
/// Revolutions from the start before the first comparison: the start's
/// own transient is never a fixed point.
pub const FIRST_REVS: u64 = 10;

/// One revolution boundary's stroboscopic state and the revolution before it.
#[derive(Debug, Clone)]
pub struct Stroboscope {
    /// Scaled state: rotor body-frame positions and velocities, weight rates, spin rate.
    pub smooth: Vec<f64>,
    /// Weight angles relative to the rotor (rad; compared mod 2π).
    pub angles: Vec<f64>,
    /// r / A_ref at every sample of the revolution that ends here.
    pub r: Vec<f64>,
    /// On a rotor with several watched planes, each plane's r over its own
    /// A_ref at the same samples (each plane has its own band); empty on a
    /// plane rotor.
    pub plane_r: Vec<Vec<f64>>,
}

/// The largest sample-by-sample difference of two series (∞ when their
/// lengths differ).
fn series_change(a: &[f64], b: &[f64]) -> f64 {
    if a.len() == b.len() {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    } else {
        f64::INFINITY
    }
}

/// The peak and the RMS of one series of scaled whirls.
fn peak_and_rms(r: &[f64]) -> (f64, f64) {
    let peak = r.iter().copied().fold(0.0, f64::max);
    let mean_square = r.iter().map(|r| r * r).sum::<f64>() / r.len().max(1) as f64;
    (peak, mean_square.sqrt())
}

/// What the watch certified: the run will not settle before its horizon.
#[derive(Debug, Clone, PartialEq)]
pub struct NeverSettles {
    /// Bound T on how far any later revolution's state (and r, scaled) lies from the last.
    pub tail: f64,
    /// The largest recent change per [`LAG`] revolutions (scaled).
    pub largest: f64,
    /// Why the hold cannot complete, in words.
    pub why: String,
}

/// The decision inputs besides the states: band, operating speed.
#[derive(Debug, Clone, Copy)]
pub struct Criteria {
    /// δ (the band is δ·A_ref on r and δ·ω on the spin rate).
    pub delta: f64,
    /// Whether the run is at its operating speed.
    pub operating: bool,
    /// Spin rate over the nominal speed, at the boundary.
    pub spin_ratio: f64,
    /// Revolutions from this boundary to the horizon.
    pub remaining_revs: f64,
}

/// Watches the stroboscopic states of one run for a contracting fixed point.
#[derive(Debug, Default)]
pub struct RepeatWatch {
    /// The states [`LAG`] and LAG − 1 revolutions back, oldest first.
    previous: Vec<Stroboscope>,
    /// The most recent changes d_k, oldest first (at most 2 · WINDOW).
    changes: Vec<f64>,
}

/// The largest scaled difference between two stroboscopic states (angles
/// compared mod 2π; r sample by sample).
fn change(a: &Stroboscope, b: &Stroboscope) -> f64 {
    let smooth = a
        .smooth
        .iter()
        .zip(&b.smooth)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    let angles = a
        .angles
        .iter()
        .zip(&b.angles)
        .map(|(x, y)| crate::model::effect::contact::wrapped(x - y).abs())
        .fold(0.0, f64::max);
    let r = series_change(&a.r, &b.r);
    let planes = if a.plane_r.len() == b.plane_r.len() {
        a.plane_r
            .iter()
            .zip(&b.plane_r)
            .map(|(x, y)| series_change(x, y))
            .fold(0.0, f64::max)
    } else {
        f64::INFINITY
    };
    smooth.max(angles).max(r).max(planes)
}

impl RepeatWatch {
    /// Record the state at a revolution boundary; `Some` once the run is
    /// certified never to settle.
    pub fn observe(&mut self, state: Stroboscope, criteria: Criteria) -> Option<NeverSettles> {
        let d = match self.previous.first() {
            Some(p) if self.previous.len() == LAG => change(p, &state),
            _ => f64::NAN,
        };
        let verdict = if d.is_finite() {
            self.changes.push(d);
            if self.changes.len() > 2 * WINDOW {
                self.changes.remove(0);
            }
            self.decide(&state, criteria)
        } else {
            None
        };
        if self.previous.len() == LAG {
            self.previous.remove(0);
        }
        self.previous.push(state);
        verdict
    }

    fn decide(&self, state: &Stroboscope, criteria: Criteria) -> Option<NeverSettles> {
        if self.changes.len() < 2 * WINDOW {
            return None;
        }
        let (earlier, recent) = self.changes.split_at(WINDOW);
        let largest = recent.iter().copied().fold(0.0, f64::max);
        let before = earlier.iter().copied().fold(0.0, f64::max);
        // Growing changes bound nothing; otherwise every later step may
        // change the state by as much as the largest recent one.
        // (NaN compares false: a change that is not a number bounds nothing.)
        if largest.partial_cmp(&before) == Some(std::cmp::Ordering::Greater)
            || largest.is_nan()
            || before.is_nan()
        {
            return None;
        }
        let steps_left = (criteria.remaining_revs / LAG as f64).max(1.0);
        let tail = GROWTH * largest * steps_left;
        let (peak, rms) = peak_and_rms(&state.r);
        let planes: Vec<(f64, f64)> = state.plane_r.iter().map(|r| peak_and_rms(r)).collect();
        // r moves by at most `tail` per sample, the RMS likewise: every
        // residual reported (the rotor's and each plane's) must stay put.
        if tail.is_nan()
            || tail > RESIDUAL_SHARE * rms
            || planes.iter().any(|&(_, rms)| tail > RESIDUAL_SHARE * rms)
        {
            return None;
        }
        let limit = (1.0 + MARGIN) * criteria.delta;
        let why = if criteria.operating {
            // The hold needs r and every plane inside their bands: one
            // leaving its band every LAG revolutions is enough.
            let outside_plane = planes.iter().position(|&(peak, _)| peak - tail > limit);
            if peak - tail > limit {
                format!(
                    "r reaches {peak:.4} A_ref every {LAG} revolutions, outside the band {}",
                    criteria.delta
                )
            } else {
                let p = outside_plane?;
                format!(
                    "plane {p}'s whirl reaches {:.4} of its A_ref every {LAG} revolutions, outside the band {}",
                    planes[p].0, criteria.delta
                )
            }
        } else {
            let off = (criteria.spin_ratio - 1.0).abs();
            (off - tail > limit).then(|| {
                format!(
                    "the spin rate stays at {:.4} of the operating speed, outside the band {}",
                    criteria.spin_ratio, criteria.delta
                )
            })?
        };
        Some(NeverSettles { tail, largest, why })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(offset: f64, r: f64) -> Stroboscope {
        Stroboscope {
            smooth: vec![offset, 0.5],
            angles: vec![1.0 + offset, 2.0 * std::f64::consts::PI + 3.0],
            r: vec![r + offset; 8],
            plane_r: Vec::new(),
        }
    }

    fn at_speed(remaining_revs: f64) -> Criteria {
        Criteria {
            delta: 0.05,
            operating: true,
            spin_ratio: 1.0,
            remaining_revs,
        }
    }

    /// Feeds the offsets (one per LAG revolutions of a run of `revs`) to a
    /// watch; the step at which it certified and its verdict, if it did.
    fn watch(offsets: &[f64], r: f64, revs: f64) -> Option<(usize, NeverSettles)> {
        let mut watch = RepeatWatch::default();
        // Every boundary is observed; states LAG apart are compared, so each
        // offset is held for LAG boundaries.
        for (k, &x) in offsets.iter().enumerate() {
            for _ in 0..LAG {
                let left = revs - (k * LAG) as f64;
                if let Some(v) = watch.observe(state(x, r), at_speed(left)) {
                    return Some((k, v));
                }
            }
        }
        None
    }

    #[test]
    fn a_contracting_orbit_outside_the_band_is_certified_and_its_tail_bounded() {
        let offsets: Vec<f64> = (0..200).map(|k| 1e-3 * 0.5f64.powi(k)).collect();
        let (k, v) = watch(&offsets, 0.3, 400.0).expect("certified");
        assert!(v.why.contains("0.3"), "{}", v.why);
        let rest = (offsets[k] - offsets[offsets.len() - 1]).abs();
        assert!(rest <= v.tail, "{rest} beyond the tail {}", v.tail);
    }

    #[test]
    fn a_creep_beneath_a_fast_contraction_stays_within_the_tail() {
        // The fast mode contracts ×0.85 per step while a creep of 2e-7 per
        // step goes on: the case that sank a geometric tail.
        let offsets: Vec<f64> = (0..300)
            .map(|k| 1e-2 * 0.85f64.powi(k) + 2e-7 * f64::from(k))
            .collect();
        let (k, v) = watch(&offsets, 0.3, 600.0).expect("certified");
        let rest = (offsets[k] - offsets[offsets.len() - 1]).abs();
        assert!(rest <= v.tail, "{rest} beyond the tail {}", v.tail);
    }

    #[test]
    fn inside_the_band_growing_or_drifting_too_fast_is_never_certified() {
        let contracting: Vec<f64> = (0..100).map(|k| 1e-3 * 0.5f64.powi(k)).collect();
        assert!(watch(&contracting, 0.04, 400.0).is_none());
        // A slow instability: the changes grow.
        let growing: Vec<f64> = (0..100).map(|k| 1e-9 * 1.1f64.powi(k)).collect();
        assert!(watch(&growing, 0.3, 400.0).is_none());
        // A weight circulating: 1e-3 per step moves r by far more than the
        // residual share over the steps left.
        let circulating: Vec<f64> = (0..100).map(|k| 1e-3 * f64::from(k)).collect();
        assert!(watch(&circulating, 0.3, 400.0).is_none());
    }

    #[test]
    fn one_plane_outside_its_band_is_enough_and_each_plane_is_compared() {
        // The rotor's r inside its band, plane 1 outside its own: certified,
        // naming the plane.
        let mut watch = RepeatWatch::default();
        let mut verdict = None;
        for k in 0..80 {
            let x = 1e-3 * 0.5f64.powi(k / 2);
            let mut s = state(x, 0.01);
            s.plane_r = vec![vec![0.01 + x; 8], vec![0.3 + x; 8]];
            verdict = verdict.or(watch.observe(s, at_speed(400.0)));
        }
        assert!(verdict.expect("certified").why.contains("plane 1"));
        // Every plane inside its band: never.
        let mut watch = RepeatWatch::default();
        for k in 0..80 {
            let x = 1e-3 * 0.5f64.powi(k / 2);
            let mut s = state(x, 0.01);
            s.plane_r = vec![vec![0.01 + x; 8], vec![0.02 + x; 8]];
            assert!(watch.observe(s, at_speed(400.0)).is_none());
        }
        // A plane's series that keeps changing is a change like any other.
        let a = state(0.0, 0.3);
        let (mut b, mut c) = (a.clone(), a.clone());
        b.plane_r = vec![vec![0.1; 8]];
        c.plane_r = vec![vec![0.2; 8]];
        assert!((change(&b, &c) - 0.1).abs() < 1e-12);
    }

    #[test]
    fn angles_are_compared_mod_two_pi() {
        let a = state(0.0, 0.3);
        let mut b = a.clone();
        for x in &mut b.angles {
            *x -= 2.0 * std::f64::consts::PI;
        }
        assert!(change(&a, &b) < 1e-12);
    }

    #[test]
    fn below_the_operating_speed_the_spin_rate_decides() {
        let captured = Criteria {
            delta: 0.05,
            operating: false,
            spin_ratio: 0.5,
            remaining_revs: 1000.0,
        };
        let mut watch = RepeatWatch::default();
        let mut verdict = None;
        for k in 0..80 {
            let x = 1e-3 * 0.3f64.powi(k / 2);
            verdict = verdict.or(watch.observe(state(x, 0.01), captured));
        }
        assert!(verdict.expect("certified").why.contains("spin rate"));
    }
}
