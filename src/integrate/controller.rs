//! Step-size control of the explicit methods: Hairer's PI controller
//! (DOPRI5, DOP853), h_new = h · safe / (err^(1/(q+1) − 0.75β) · err_old^β).
//! With β = 0 it is the plain I controller DOP853 uses by default.

/// The controller's constants and its memory of the last accepted error.
#[derive(Debug, Clone)]
pub struct PiController {
    exponent: f64,
    beta: f64,
    safe: f64,
    fac_min: f64,
    fac_max: f64,
    err_old: f64,
}

impl PiController {
    /// A controller for an error estimate of order q (`exponent` = 1/(q+1)),
    /// PI gain β, safety factor and bounds fac_min ≤ h_new/h ≤ fac_max.
    pub fn new(exponent: f64, beta: f64, safe: f64, fac_min: f64, fac_max: f64) -> Self {
        PiController {
            exponent: exponent - beta * 0.75,
            beta,
            safe,
            fac_min,
            fac_max,
            err_old: 1e-4,
        }
    }

    /// The next step size after a step of size `h` with scaled error `err`
    /// (accepted when `err` ≤ 1), and whether it was accepted.
    pub fn propose(&mut self, err: f64, h: f64) -> (bool, f64) {
        let fac11 = err.powf(self.exponent);
        if err <= 1.0 {
            let fac = (fac11 / self.err_old.powf(self.beta) / self.safe)
                .clamp(1.0 / self.fac_max, 1.0 / self.fac_min);
            self.err_old = err.max(1e-4);
            (true, h / fac)
        } else {
            (false, h / (fac11 / self.safe).min(1.0 / self.fac_min))
        }
    }

    /// The step to retry with after a trial whose error was not even finite:
    /// usually the step was far too large, so shrink as hard as allowed.
    pub fn after_non_finite(&self, h: f64) -> f64 {
        h * self.fac_min
    }
}
