//! The Sommerfeld effect: the torque a whirling, unbalanced rotor takes from
//! its drive, and the speed at which a drive of limited torque is held by it
//! (derivation in docs/model.md, "The Sommerfeld effect").

/// A plane rotor on isotropic supports, as the whirl load sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneWhirl {
    /// Mass that moves with the shaft centre, M_Σ (kg), weights included.
    pub mass: f64,
    /// Support stiffness k (N/m).
    pub stiffness: f64,
    /// Support damping b (N·s/m).
    pub damping: f64,
}

impl PlaneWhirl {
    /// Natural frequency ω_n = sqrt(k / M_Σ) (rad/s).
    pub fn natural_frequency(&self) -> f64 {
        (self.stiffness / self.mass).sqrt()
    }

    /// Radius of the steady synchronous whirl of unbalance `u` (kg·m) at spin
    /// rate Ω: A = U Ω² / |k − M_Σ Ω² + i b Ω|.
    pub fn amplitude(&self, u: f64, omega: f64) -> f64 {
        let w2 = omega * omega;
        u * w2 / (self.stiffness - self.mass * w2).hypot(self.damping * omega)
    }

    /// Torque the steady whirl takes from the drive, b A² Ω: the support
    /// damping dissipates b (A Ω)², and only the spin can supply it.
    pub fn torque(&self, u: f64, omega: f64) -> f64 {
        let a = self.amplitude(u, omega);
        self.damping * a * a * omega
    }
}

/// The linear motor characteristic M_s (1 − Ω/ω_sync) (N·m).
pub fn motor_torque(stall_torque: f64, omega_sync: f64, omega: f64) -> f64 {
    stall_torque * (1.0 - omega / omega_sync)
}

/// The lowest spin rate in (0, `upto`] at which the drive's torque no longer
/// exceeds the load, found by a scan of `steps` points and bisection: a
/// run-up from rest is held there (if that balance is stable; it is where the
/// load rises faster than the motor's torque falls). `None`: the drive
/// exceeds the load all the way, and the rotor passes.
pub fn held_speed(
    drive: impl Fn(f64) -> f64,
    load: impl Fn(f64) -> f64,
    upto: f64,
    steps: usize,
) -> Option<f64> {
    let surplus = |w: f64| drive(w) - load(w);
    let h = upto / steps as f64;
    let mut lo = 0.0;
    for i in 1..=steps {
        let hi = i as f64 * h;
        if surplus(hi) <= 0.0 {
            let (mut a, mut b) = (lo, hi);
            for _ in 0..200 {
                let m = 0.5 * (a + b);
                if surplus(m) > 0.0 { a = m } else { b = m }
            }
            return Some(0.5 * (a + b));
        }
        lo = hi;
    }
    None
}

/// Weights that run together as one lump of unbalance S = n m l (pendulums
/// can; solid balls and rollers cannot), dragged by the rotor through their
/// viscous coefficient: drag torque c (Ω − ω_b), c = Σ β_j l_j².
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LumpedWeights {
    /// Unbalance of the lump S (kg·m).
    pub unbalance: f64,
    /// Σ β_j l_j² (N·m·s).
    pub drag: f64,
}

/// A rotor held below its operating speed, and where its weights whirl.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Held {
    /// Spin rate of the rotor Ω (rad/s).
    pub spin: f64,
    /// Inertial whirl rate of the weights ω_b (rad/s), near ω_n.
    pub weights: f64,
}

impl LumpedWeights {
    /// Where the lump whirls when the rotor spins at Ω: the first rate at
    /// which its drag c (Ω − ω_b) no longer exceeds the load its own whirl
    /// takes, b ω_b A(S, ω_b)²; `None` once the drag exceeds that load's
    /// peak (about S² ω_n³ / b) and the lump is carried round with the rotor.
    pub fn whirl_rate(&self, rotor: &PlaneWhirl, spin: f64) -> Option<f64> {
        let peak = 1.5 * rotor.natural_frequency();
        held_speed(
            |w| self.drag * (spin - w),
            |w| rotor.torque(self.unbalance, w),
            spin.min(peak),
            4000,
        )
    }

    /// The run-up from rest of a rotor of unbalance `u` (kg·m) with these
    /// weights under the motor M_s (1 − Ω/ω_sync): where it is held, by the
    /// torque balance M_s (1 − Ω/ω_sync) = c (Ω − ω_b(Ω)) + b Ω A(U, Ω)²;
    /// `None` when it passes to the motor's speed.
    pub fn held(
        &self,
        rotor: &PlaneWhirl,
        u: f64,
        stall_torque: f64,
        omega_sync: f64,
    ) -> Option<Held> {
        let load = |w: f64| {
            let lump = self
                .whirl_rate(rotor, w)
                .map_or(0.0, |wb| self.drag * (w - wb));
            lump + rotor.torque(u, w)
        };
        // Past ~0.9 ω_sync the rotor counts as through (the lump has escaped).
        let spin = held_speed(
            |w| motor_torque(stall_torque, omega_sync, w),
            load,
            0.9 * omega_sync,
            4000,
        )?;
        let weights = self.whirl_rate(rotor, spin)?;
        Some(Held { spin, weights })
    }
}
