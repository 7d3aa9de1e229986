//! The hold window: r² of its latest samples (for the residual, an RMS)
//! and the "holds continuously" rule that decides settling; the parts that
//! hold each sample to it, per watched plane and for the whole rotor.

use super::{Sample, SettlingObserver};
use crate::integrate::Flow;
use crate::metrics::reference::plane_whirls;

/// r² of the last hold window's samples, for the residual (an RMS).
#[derive(Debug, Clone)]
pub(super) struct SquareRing {
    values: Vec<f64>,
    pos: usize,
    filled: usize,
}

impl SquareRing {
    pub(super) fn new(len: usize) -> Self {
        SquareRing {
            values: vec![0.0; len],
            pos: 0,
            filled: 0,
        }
    }

    pub(super) fn len(&self) -> usize {
        self.values.len()
    }

    pub(super) fn push(&mut self, r2: f64) {
        self.values[self.pos] = r2;
        // A compare, not `%`: an integer division per sample is measurable.
        self.pos += 1;
        if self.pos == self.values.len() {
            self.pos = 0;
        }
        self.filled = (self.filled + 1).min(self.values.len());
    }

    /// Σ of the `count` most recent values (all there are, if fewer).
    pub(super) fn latest_sum(&self, count: usize) -> f64 {
        let (older, newer) = self.latest(count);
        older.iter().chain(newer).sum()
    }

    /// The root of the mean of the `count` most recent values (all there
    /// are, if fewer): the RMS whirl over them when the values are r².
    pub(super) fn latest_rms(&self, count: usize) -> f64 {
        let (older, newer) = self.latest(count);
        let n = older.len() + newer.len();
        (older.iter().chain(newer).sum::<f64>() / n.max(1) as f64).sqrt()
    }

    /// The `count` most recent values (all there are, if fewer), as the
    /// older and the newer part of the storage.
    pub(super) fn latest(&self, count: usize) -> (&[f64], &[f64]) {
        let count = count.min(self.filled);
        let newer = &self.values[self.pos.saturating_sub(count)..self.pos];
        let older_len = count - newer.len();
        let older = &self.values[self.values.len() - older_len..];
        (older, newer)
    }

    /// The largest of the `count` most recent values (0 when empty).
    pub(super) fn latest_max(&self, count: usize) -> f64 {
        let (older, newer) = self.latest(count);
        older.iter().chain(newer).fold(0.0, |m, &v| f64::max(m, v))
    }

    /// sqrt of the mean, 0 when empty; sums in storage order, as always.
    pub(super) fn rms(&self) -> f64 {
        if self.filled == 0 {
            return 0.0;
        }
        let sum: f64 = if self.filled == self.values.len() {
            self.values.iter().sum()
        } else {
            self.values[..self.filled].iter().sum()
        };
        (sum / self.filled as f64).sqrt()
    }
}

/// x ≤ limit, false for NaN: a prediction that is not a number bounds nothing.
pub(super) fn inside(x: f64, limit: f64) -> bool {
    x <= limit
}

/// Tracks one "holds continuously" rule (r ≤ band or ε ≤ band).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Hold {
    pub(super) stretch_start: Option<f64>,
    pub(super) met_at: Option<f64>,
}

impl Hold {
    pub(super) fn update(&mut self, t: f64, inside: bool, window: f64) {
        if self.met_at.is_some() {
            return;
        }
        if inside {
            let start = *self.stretch_start.get_or_insert(t);
            if t - start >= window {
                self.met_at = Some(start);
            }
        } else {
            self.stretch_start = None;
        }
    }

    /// t_s under the rule "for W revolutions or until the end", and whether the full window held.
    pub(super) fn settling_time(&self) -> (Option<f64>, bool) {
        match self.met_at {
            Some(t) => (Some(t), true),
            None => (self.stretch_start, false),
        }
    }
}

impl SettlingObserver<'_> {
    /// The part that holds each watched plane (rotors with several) to its
    /// own band; the sample is inside only when every plane is.
    pub(super) fn watch_planes(&mut self, s: &mut Sample) -> Flow {
        if let Some(pw) = &mut self.planes {
            plane_whirls(self.system, &self.scratch, &mut pw.r);
            for (((ring, r), hold), a_ref) in pw
                .rings
                .iter_mut()
                .zip(&pw.r)
                .zip(&mut pw.holds)
                .zip(&pw.a_ref)
            {
                ring.push(r * r);
                let inside = *r <= self.options.delta * a_ref;
                hold.update(s.t, s.operating && inside, self.window);
                s.planes_inside &= inside;
            }
        }
        Flow::Continue
    }

    /// The part that keeps the window's r² and updates the r and ε holds.
    pub(super) fn hold(&mut self, s: &mut Sample) -> Flow {
        self.ring.push(s.r * s.r);
        self.r_hold.update(
            s.t,
            s.operating && s.r <= self.band && s.planes_inside,
            self.window,
        );
        self.eps_hold
            .update(s.t, s.operating && s.eps_inside, self.window);
        Flow::Continue
    }

    /// The part that ends a settled run when the options say so (after the
    /// sample is recorded).
    pub(super) fn stop_if_settled(&mut self, _: &mut Sample) -> Flow {
        if self.options.stop_when_settled && self.r_hold.met_at.is_some() {
            Flow::Stop
        } else {
            Flow::Continue
        }
    }
}
