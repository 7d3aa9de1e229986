//! The watch for a run that never settles: once per revolution the state
//! is compared with earlier ones for a repeat outside the band
//! (`metrics::never_settles`).

use super::*;
use crate::model::rotor::DofVec;

impl SettlingObserver<'_> {
    /// The part that, once per revolution, asks the watch whether the state
    /// repeats outside the band; a certain repeat ends the run.
    pub(super) fn watch_repeats(&mut self, s: &mut Sample) -> Flow {
        // A run that settled (and goes on, `stop_when_settled = false`) has
        // its answer; identical weights that coincided end as `merged` or
        // not at all.
        // Revolution boundaries are counted, not computed: a compare per sample.
        let t = s.t;
        let boundary = self.repeats.is_some() && self.next_index - 1 == self.next_watch;
        if boundary {
            self.next_watch += self.per_rev();
        }
        if boundary && self.r_hold.met_at.is_none() && self.merged.is_none() && self.watch_open(t) {
            let state = self.stroboscope(t);
            // The stroboscope's last entry is the spin rate over ω.
            let spin_ratio = state.smooth.last().copied().unwrap_or(1.0);
            let criteria = self.repeat_criteria(t, s.operating, spin_ratio);
            if let Some(watch) = &mut self.repeats
                && let Some(never) = watch.observe(state, criteria)
                && self.eps_at_horizon(t).is_some()
            {
                self.never = Some((never, t, self.scratch.clone()));
                return Flow::Stop;
            }
        }
        Flow::Continue
    }

    /// Whether, at revolution boundary t, the horizon is more than a hold
    /// window away (a later hold could still complete before it).
    pub(super) fn watch_open(&self, t: f64) -> bool {
        let rev = self.dt * self.per_rev() as f64;
        t + self.window < self.t0 + self.options.t_end_revs * rev
    }

    /// The scratch state at a revolution boundary, as the watch compares
    /// it: the rotor's position and velocity in its body frame (scaled by
    /// A_ref and A_ref·ω; on a rotor with several watched planes, each
    /// plane's, scaled by the plane's A_ref), the weights' angles and rates
    /// (rates over ω), the spin rate over ω; and r/A_ref (and each plane's
    /// r over its A_ref) over the [`LAG`] revolutions that end here.
    pub(super) fn stroboscope(&self, t: f64) -> Stroboscope {
        let lay = self.system.layout();
        let nq = lay.nq();
        let y = &self.scratch;
        // The rotating frame already holds body-frame (u, v); inertial (x, y)
        // are turned back by the spin angle.
        let (angle, rate) = self.system.spin(t, y);
        let (s, c) = match self.frame {
            Some(_) => (0.0, 1.0),
            None => (-angle).sin_cos(),
        };
        let turn = |a: f64, b: f64| (a * c - b * s, a * s + b * c);
        let w = self.omega;
        let count = LAG * self.per_rev() as usize;
        let scaled_series = |ring: &SquareRing, a: f64| -> Vec<f64> {
            let (older, newer) = ring.latest(count);
            older.iter().chain(newer).map(|r2| r2.sqrt() / a).collect()
        };
        let mut smooth = Vec::new();
        let mut plane_r = Vec::new();
        match &self.planes {
            None => {
                let (u, v) = turn(y[0], y[1]);
                let (ud, vd) = turn(y[nq], y[nq + 1]);
                let a = self.a_ref;
                smooth.extend([u / a, v / a, ud / (a * w), vd / (a * w)]);
            }
            Some(pw) => {
                let k = self.system.rotor().dof();
                let along = |g: &DofVec, x: &[f64]| (0..k).map(|i| g[i] * x[i]).sum::<f64>();
                for (([gu, gv], &a), ring) in self
                    .system
                    .watch_maps()
                    .iter()
                    .zip(&pw.a_ref)
                    .zip(&pw.rings)
                {
                    let (u, v) = turn(along(gu, y), along(gv, y));
                    let (ud, vd) = turn(along(gu, &y[nq..]), along(gv, &y[nq..]));
                    smooth.extend([u / a, v / a, ud / (a * w), vd / (a * w)]);
                    plane_r.push(scaled_series(ring, a));
                }
            }
        }
        smooth.extend(y[nq + lay.head()..2 * nq].iter().map(|rate| rate / w));
        smooth.push(rate / w);
        Stroboscope {
            smooth,
            angles: y[lay.head()..nq].to_vec(),
            r: scaled_series(&self.ring, self.a_ref),
            plane_r,
        }
    }

    /// The ε settling time the full run would report at the horizon, for a
    /// state that repeats every revolution from boundary t on: a hold met,
    /// or a stretch begun revolutions before the repeat, stands; a stretch
    /// begun in the last revolution begins again, at the same phase, in
    /// every later one. `None` when neither is sure (a stretch begun a few
    /// revolutions ago); `Some(None)` for no stretch at the boundary.
    #[allow(clippy::option_option)]
    pub(super) fn eps_at_horizon(&self, t: f64) -> Option<Option<f64>> {
        let rev = self.dt * self.per_rev() as f64;
        let horizon = self.t0 + self.options.t_end_revs * rev;
        if let Some(met) = self.eps_hold.met_at {
            return Some(Some(met));
        }
        match self.eps_hold.stretch_start {
            None => Some(None),
            Some(start) if start <= t - (2 * WINDOW * LAG) as f64 * rev => Some(Some(start)),
            Some(start) if start > t - rev => Some(Some(start + (horizon - t))),
            Some(_) => None,
        }
    }

    /// The band, the speed and the revolutions left, at boundary time t.
    pub(super) fn repeat_criteria(&self, t: f64, operating: bool, spin_ratio: f64) -> Criteria {
        let rev = self.dt * self.per_rev() as f64;
        Criteria {
            delta: self.options.delta,
            operating,
            spin_ratio,
            remaining_revs: (self.t0 + self.options.t_end_revs * rev - t) / rev,
        }
    }
}
