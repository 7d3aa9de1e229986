//! Seed 003's empirical criterion for the occurrence of auto-balancing: a
//! rigid axisymmetric rotor (mass M, transverse and polar moments of inertia
//! A and C) on two isotropic elastic supports, balanced by any number of
//! passive auto-balancers of any type ("zero approximation": the balancers'
//! mass and type are ignored).
//!
//! Supports: stiffness k1 at z = −l1 and k2 at z = +l2 from the centre of
//! mass, so that (eq 3) k11 = k1 + k2, k14 = k2 l2 − k1 l1,
//! k33 = k1 l1² + k2 l2². The criterion (eq 1) asks that, averaged over a
//! revolution, each correction plane's displacement caused by elementary
//! unbalances s_j in the planes points against them: ω² JᵀKJ / Δ(ω) < 0
//! (eq 29).
//!
//! Paper typos handled here (also in docs/rotors.md):
//! - eqs 21 and 23 (short rotor) print the terms −(C−A)k11 + Mk33 and
//!   (C−A)k11 − Mk33 swapped: the positive root of eq 11 for A < C is
//!   ω1² = [(C−A)k11 − Mk33 + √(…)] / (2M(C−A)) (with k14 = 0 it must give
//!   k11/M); ω2² of eq 23 is [Mk33 − (C−A)k11 + √(…)] / (2M(C−A)).
//! - the dynamic-balancing condition "ω > ω_p1 (ω > √(k33/(A−C)))": the
//!   bracket is ω_p2; the result (eq 31) is A > C, ω > ω2.
//! - eq 47's ω_0 is eq 23's ω2.

use num_complex::Complex64;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Mass, inertia and supports of the rigid two-support rotor (SI or dimensionless).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TwoSupportParams {
    /// Rotor mass M.
    pub mass: f64,
    /// Transverse moment of inertia A about an axis through the centre of mass.
    pub transverse_inertia: f64,
    /// Polar moment of inertia C about the spin axis.
    pub polar_inertia: f64,
    /// Stiffness k1 of the support at z = −l1.
    pub k1: f64,
    /// Distance l1 from the centre of mass to support 1 (support at z = −l1).
    pub l1: f64,
    /// Stiffness k2 of the support at z = +l2.
    pub k2: f64,
    /// Distance l2 from the centre of mass to support 2 (support at z = +l2).
    pub l2: f64,
}

/// Stiffness coefficients of eq 3.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stiffness {
    /// k11 = k1 + k2 (force per displacement).
    pub k11: f64,
    /// k14 = k2 l2 − k1 l1 (coupling of displacement and tilt).
    pub k14: f64,
    /// k33 = k1 l1² + k2 l2² (moment per tilt).
    pub k33: f64,
}

/// Long (A > C), spherical (A = C) or short (A < C) rotor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RotorShape {
    /// A > C: two resonance speeds.
    Long,
    /// A = C: one resonance speed.
    Spherical,
    /// A < C: one resonance speed.
    Short,
}

/// Why the criterion cannot be evaluated.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CriterionError {
    /// A quantity that must be positive and finite is not.
    #[error("{name} = {value}: must be positive and finite")]
    NotPositive {
        /// Name of the quantity.
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// A quantity that must be finite is not.
    #[error("{name} = {value}: must be finite")]
    NotFinite {
        /// Name of the quantity.
        name: &'static str,
        /// The offending value.
        value: f64,
    },
    /// l1 + l2 ≤ 0: the supports coincide (k11 k33 − k14² = k1 k2 (l1 + l2)² vanishes).
    #[error("l1 + l2 = {0}: the supports must be apart (l1 + l2 > 0)")]
    CoincidentSupports(f64),
    /// z_max (eq 36) exists only for short rotors.
    #[error("z_max needs a short rotor (C > A), got A = {a}, C = {c}")]
    NotShort {
        /// Transverse moment of inertia.
        a: f64,
        /// Polar moment of inertia.
        c: f64,
    },
}

fn positive(name: &'static str, value: f64) -> Result<f64, CriterionError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(CriterionError::NotPositive { name, value })
    }
}

fn finite(name: &'static str, value: f64) -> Result<f64, CriterionError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(CriterionError::NotFinite { name, value })
    }
}

/// Relative difference of A and C below which a rotor counts as spherical.
const SPHERICAL_TOL: f64 = 1e-12;

impl TwoSupportParams {
    /// Check every parameter: M, A, C, k1, k2 positive, l1, l2 finite with l1 + l2 > 0.
    pub fn validate(&self) -> Result<(), CriterionError> {
        positive("M", self.mass)?;
        positive("A", self.transverse_inertia)?;
        positive("C", self.polar_inertia)?;
        positive("k1", self.k1)?;
        positive("k2", self.k2)?;
        finite("l1", self.l1)?;
        finite("l2", self.l2)?;
        if self.l1 + self.l2 <= 0.0 {
            return Err(CriterionError::CoincidentSupports(self.l1 + self.l2));
        }
        Ok(())
    }

    /// k11, k14, k33 of eq 3.
    pub fn stiffness(&self) -> Stiffness {
        Stiffness {
            k11: self.k1 + self.k2,
            k14: self.k2 * self.l2 - self.k1 * self.l1,
            k33: self.k1 * self.l1 * self.l1 + self.k2 * self.l2 * self.l2,
        }
    }

    /// Long, spherical or short (|A − C| ≤ 1e-12 max(A, C) counts as spherical).
    pub fn shape(&self) -> RotorShape {
        let (a, c) = (self.transverse_inertia, self.polar_inertia);
        if (a - c).abs() <= SPHERICAL_TOL * a.max(c) {
            RotorShape::Spherical
        } else if a > c {
            RotorShape::Long
        } else {
            RotorShape::Short
        }
    }

    /// A − C, exactly zero for a spherical rotor.
    fn a_minus_c(&self) -> f64 {
        match self.shape() {
            RotorShape::Spherical => 0.0,
            _ => self.transverse_inertia - self.polar_inertia,
        }
    }
}

/// Frequency determinant Δ(ω) of eq 11: (k11 − Mω²)(k33 − (A − C)ω²) − k14².
pub fn determinant(p: &TwoSupportParams, omega: f64) -> f64 {
    let s = p.stiffness();
    let w2 = omega * omega;
    (s.k11 - p.mass * w2) * (s.k33 - p.a_minus_c() * w2) - s.k14 * s.k14
}

/// Partial frequencies of eq 16: ω_p1 = √(k11/M) and ω_p2 = √(k33/|A − C|)
/// (`None` for a spherical rotor).
pub fn partial_frequencies(p: &TwoSupportParams) -> Result<(f64, Option<f64>), CriterionError> {
    p.validate()?;
    let s = p.stiffness();
    let d = p.a_minus_c().abs();
    Ok((
        (s.k11 / p.mass).sqrt(),
        (d > 0.0).then(|| (s.k33 / d).sqrt()),
    ))
}

/// The speeds that shape Δ(ω) (eqs 15, 19, 21, 23).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resonances {
    /// Long, spherical or short.
    pub shape: RotorShape,
    /// First (for spherical and short rotors the only) resonance speed ω1.
    pub omega1: f64,
    /// Second resonance speed ω2 of a long rotor (eq 15); `None` otherwise.
    pub omega2: Option<f64>,
    /// For a short rotor, ω2 of eq 23: Δ = M(C − A)(ω1² − ω²)(ω2² + ω²) (not a resonance).
    pub omega2_aux: Option<f64>,
}

/// Resonance speeds: the positive roots ω² of Δ(ω) = 0 (eq 11).
///
/// Roots are computed in the cancellation-free form (the small root as
/// 2c/(b + √(b² − 4ac))), so nearly spherical rotors stay accurate.
pub fn resonances(p: &TwoSupportParams) -> Result<Resonances, CriterionError> {
    p.validate()?;
    let s = p.stiffness();
    let m = p.mass;
    let det0 = p.k1 * p.k2 * (p.l1 + p.l2).powi(2); // k11 k33 − k14² (eq 14)
    let shape = p.shape();
    Ok(match shape {
        RotorShape::Spherical => Resonances {
            shape,
            omega1: (det0 / (m * s.k33)).sqrt(), // eq 19
            omega2: None,
            omega2_aux: None,
        },
        RotorShape::Long => {
            // M d x² − b x + det0 = 0 with x = ω², d = A − C (eq 15).
            let d = p.transverse_inertia - p.polar_inertia;
            let b = d * s.k11 + m * s.k33;
            let root = (b * b - 4.0 * m * d * det0).max(0.0).sqrt();
            Resonances {
                shape,
                omega1: (2.0 * det0 / (b + root)).sqrt(),
                omega2: Some(((b + root) / (2.0 * m * d)).sqrt()),
                omega2_aux: None,
            }
        }
        RotorShape::Short => {
            // M d x² + (M k33 − d k11) x − det0 = 0 with d = C − A (eqs 21, 23 corrected).
            let d = p.polar_inertia - p.transverse_inertia;
            let b = m * s.k33 - d * s.k11;
            let root = (b * b + 4.0 * m * d * det0).sqrt();
            // Positive root x1 and the magnitude x2 of the negative root.
            let (x1, x2) = if b > 0.0 {
                (2.0 * det0 / (b + root), (b + root) / (2.0 * m * d))
            } else {
                ((root - b) / (2.0 * m * d), 2.0 * det0 / (root - b))
            };
            Resonances {
                shape,
                omega1: x1.sqrt(),
                omega2: None,
                omega2_aux: Some(x2.sqrt()),
            }
        }
    })
}

/// The extra speed ω̃ of a correction plane at z (eq 37; eq 46 when
/// A + Mz² < C): ω̃² = (k33 + k11 z² − 2 k14 z) / |A + Mz² − C|;
/// infinite when A + Mz² = C (e.g. a spherical rotor's plane at z = 0).
pub fn extra_speed(p: &TwoSupportParams, z: f64) -> Result<f64, CriterionError> {
    p.validate()?;
    finite("z", z)?;
    let s = p.stiffness();
    let num = s.k33 + s.k11 * z * z - 2.0 * z * s.k14;
    let den = (p.a_minus_c() + p.mass * z * z).abs();
    Ok(if den == 0.0 {
        f64::INFINITY
    } else {
        (num / den).sqrt()
    })
}

/// z_max = √((C − A)/M) of eq 36: a short rotor balances statically at every
/// speed above ω1 when its correction plane is closer than this to the centre of mass.
pub fn z_max(p: &TwoSupportParams) -> Result<f64, CriterionError> {
    p.validate()?;
    match p.shape() {
        RotorShape::Short => Ok(((p.polar_inertia - p.transverse_inertia) / p.mass).sqrt()),
        _ => Err(CriterionError::NotShort {
            a: p.transverse_inertia,
            c: p.polar_inertia,
        }),
    }
}

/// A union of open speed intervals (lo, hi); hi may be +∞.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct SpeedRanges(pub Vec<(f64, f64)>);

impl SpeedRanges {
    /// True when ω lies strictly inside one of the intervals.
    pub fn contains(&self, omega: f64) -> bool {
        self.0.iter().any(|&(lo, hi)| omega > lo && omega < hi)
    }

    /// True when there is no interval.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

/// Speeds at which auto-balancers in one correction plane at z balance the
/// rotor statically: long rotor (ω1, ω̃) ∪ (ω2, ∞) (eq 40), spherical
/// (ω1, ω̃) (eq 43), short with A + Mz² > C (ω1, ω̃) (eq 45), short with
/// A + Mz² ≤ C (ω1, ∞) (eq 48).
pub fn static_ranges(p: &TwoSupportParams, z: f64) -> Result<SpeedRanges, CriterionError> {
    let res = resonances(p)?;
    let tilde = extra_speed(p, z)?;
    Ok(SpeedRanges(match res.shape {
        RotorShape::Long => {
            let w2 = res.omega2.unwrap_or(f64::INFINITY);
            vec![(res.omega1, tilde), (w2, f64::INFINITY)]
        }
        RotorShape::Spherical => vec![(res.omega1, tilde)],
        RotorShape::Short => {
            if p.transverse_inertia + p.mass * z * z > p.polar_inertia {
                vec![(res.omega1, tilde)]
            } else {
                vec![(res.omega1, f64::INFINITY)]
            }
        }
    }))
}

/// Speeds at which auto-balancers in two or more correction planes balance
/// the rotor dynamically: (ω2, ∞) for a long rotor, none otherwise (eq 31).
pub fn dynamic_ranges(p: &TwoSupportParams) -> Result<SpeedRanges, CriterionError> {
    let res = resonances(p)?;
    Ok(SpeedRanges(match res.omega2 {
        Some(w2) if res.shape == RotorShape::Long => vec![(w2, f64::INFINITY)],
        _ => Vec::new(),
    }))
}

/// Complex amplitudes (D, E) of the steady forced response z = D e^{iωt},
/// ψ = α + iβ = E e^{iωt} to static and moment unbalances S, I (eqs 10, 13).
/// `None` at a resonance (Δ = 0).
pub fn forced_response(
    p: &TwoSupportParams,
    omega: f64,
    s: Complex64,
    i: Complex64,
) -> Option<(Complex64, Complex64)> {
    let k = p.stiffness();
    let w2 = omega * omega;
    let delta = determinant(p, omega);
    if delta == 0.0 {
        return None;
    }
    let d = w2 * ((k.k33 - p.a_minus_c() * w2) * s - k.k14 * i) / delta;
    let e = Complex64::i() * w2 * ((k.k11 - p.mass * w2) * i - k.k14 * s) / delta;
    Some((d, e))
}

/// The criterion's functional ω² JᵀKJ / Δ(ω) (eqs 27–29) for total static
/// unbalance S = Σ s_j e^{iφ_j} and moment unbalance I = Σ s_j z_j e^{iφ_j}:
/// auto-balancing occurs where it is negative for every admissible (S, I).
pub fn functional(p: &TwoSupportParams, omega: f64, s: Complex64, i: Complex64) -> f64 {
    let k = p.stiffness();
    let w2 = omega * omega;
    let quad = (k.k33 - p.a_minus_c() * w2) * s.norm_sqr()
        - 2.0 * k.k14 * (i.re * s.re + i.im * s.im)
        + (k.k11 - p.mass * w2) * i.norm_sqr();
    w2 * quad / determinant(p, omega)
}

/// The functional for a unit unbalance in one correction plane at z (I = zS, eq 32).
pub fn static_functional(p: &TwoSupportParams, z: f64, omega: f64) -> f64 {
    functional(p, omega, Complex64::new(1.0, 0.0), Complex64::new(z, 0.0))
}
