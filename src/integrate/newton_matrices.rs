//! The two shifted Newton matrices of a Radau IIA step, γ·I − J (real) and
//! (α + iβ)·I − J (complex), factored whole or — for a second-order system
//! written in first order — reduced to its velocity half.
//!
//! When y = (q, p) with q̇ = p exactly, J = [[0, I], [A, B]] and
//! (γ·I − J)·(x, y) = (f, g) splits into
//!   (γ·I − B − A/γ)·y = g + A·(f/γ),   x = (f + y)/γ,
//! an m×m system for m = dim/2 (Hairer's RADAU5 with M1 = M2). The LU costs
//! an eighth and each solve about 3/8 of the full one; the answer is the same
//! up to rounding.

use super::lu::{ComplexLu, RealLu};
use super::structured_newton::StructuredNewton;
use super::{OdeSystem, SolverOptions, Stats};

/// Factored Newton matrices of one Jacobian and step size.
pub(crate) enum NewtonMatrices {
    /// The full dim×dim matrices.
    Full { real: RealLu, complex: ComplexLu },
    /// The m×m matrices of the velocity half, with the Jacobian's lower-left
    /// block A (row-major m×m) and the shifts they were built with.
    Reduced {
        m: usize,
        real: RealLu,
        complex: ComplexLu,
        lower_left: Vec<f64>,
        gamma: f64,
        /// 1/(α + iβ) as (re, −im): α/|·|², β/|·|².
        inv_shift: (f64, f64),
    },
    /// The reduced matrices as tridiagonal plus low rank, from the system's
    /// coupling structure ([`super::structured_newton`]).
    Structured(Box<StructuredNewton>),
}

impl NewtonMatrices {
    /// Buffers for a system of dimension `dim`; `second_order` as
    /// [`super::OdeSystem::second_order_split`] reports it.
    pub(crate) fn new(dim: usize, second_order: Option<usize>) -> Self {
        match second_order {
            Some(m) if 2 * m == dim && m > 0 => NewtonMatrices::Reduced {
                m,
                real: RealLu::new(m),
                complex: ComplexLu::new(m),
                lower_left: vec![0.0; m * m],
                gamma: 0.0,
                inv_shift: (0.0, 0.0),
            },
            _ => NewtonMatrices::Full {
                real: RealLu::new(dim),
                complex: ComplexLu::new(dim),
            },
        }
    }

    /// The matrices `options` allow for `system` from (t0, y0): structured
    /// when it has enough ring coordinates, else as [`Self::new`].
    pub(crate) fn for_system<S: OdeSystem + ?Sized>(
        system: &S,
        t0: f64,
        y0: &[f64],
        options: &SolverOptions,
    ) -> Self {
        let split = system
            .second_order_split()
            .filter(|_| options.reduce_second_order);
        match split {
            Some(m)
                if options.structured_newton
                    && 2 * m == y0.len()
                    && StructuredNewton::pays(system, t0, y0) =>
            {
                NewtonMatrices::Structured(Box::new(StructuredNewton::new(m)))
            }
            _ => NewtonMatrices::new(y0.len(), split),
        }
    }

    /// Factor γ·I − J and (α + iβ)·I − J for the row-major Jacobian `jac`
    /// (the structured matrices use their own local Jacobian instead);
    /// false if either is singular or not finite.
    pub(crate) fn factor<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        gamma: f64,
        alpha: f64,
        beta: f64,
        jac: &[f64],
        stats: &mut Stats,
    ) -> bool {
        match self {
            NewtonMatrices::Structured(s) => s.factor(system, gamma, alpha, beta, stats),
            NewtonMatrices::Full { real, complex } => {
                real.factor_shifted(gamma, jac) && complex.factor_shifted(alpha, beta, jac)
            }
            NewtonMatrices::Reduced {
                m,
                real,
                complex,
                lower_left,
                gamma: g,
                inv_shift,
            } => {
                let m = *m;
                let n = 2 * m;
                let abs2 = alpha * alpha + beta * beta;
                let (alp, bet) = (alpha / abs2, beta / abs2);
                if !(gamma.is_finite() && alp.is_finite() && bet.is_finite()) {
                    return false;
                }
                *g = gamma;
                *inv_shift = (alp, bet);
                // Rows m..2m of J: [A | B].
                let lower = &jac[m * n..];
                for (dst, row) in lower_left.chunks_exact_mut(m).zip(lower.chunks_exact(n)) {
                    dst.copy_from_slice(&row[..m]);
                }
                let real_ok = real.factor_from(|e| {
                    for (i, (e_row, row)) in
                        e.chunks_exact_mut(m).zip(lower.chunks_exact(n)).enumerate()
                    {
                        let (a, b) = row.split_at(m);
                        for (j, v) in e_row.iter_mut().enumerate() {
                            *v = -b[j] - a[j] / gamma;
                        }
                        e_row[i] += gamma;
                    }
                });
                // (α + iβ) − B − A·(α − iβ)/|α + iβ|².
                real_ok
                    && complex.factor_from(|er, ei| {
                        let rows = er.chunks_exact_mut(m).zip(ei.chunks_exact_mut(m));
                        for (i, ((er_row, ei_row), row)) in
                            rows.zip(lower.chunks_exact(n)).enumerate()
                        {
                            let (a, b) = row.split_at(m);
                            for j in 0..m {
                                er_row[j] = -b[j] - a[j] * alp;
                                ei_row[j] = a[j] * bet;
                            }
                            er_row[i] += alpha;
                            ei_row[i] += beta;
                        }
                    })
            }
        }
    }

    /// Overwrite b with the solution of (γ·I − J)·x = b.
    pub(crate) fn solve_real<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        b: &mut [f64],
        stats: &mut Stats,
    ) {
        let dense = match self {
            NewtonMatrices::Structured(s) => return s.solve_real(system, b, stats),
            dense => &*dense,
        };
        match dense {
            NewtonMatrices::Structured(_) => unreachable!("returned above"),
            NewtonMatrices::Full { real, .. } => real.solve(b),
            NewtonMatrices::Reduced {
                m,
                real,
                lower_left,
                gamma,
                ..
            } => {
                let (f, g) = b.split_at_mut(*m);
                for x in f.iter_mut() {
                    *x /= gamma;
                }
                for (gi, row) in g.iter_mut().zip(lower_left.chunks_exact(*m)) {
                    *gi += row.iter().zip(f.iter()).map(|(a, x)| a * x).sum::<f64>();
                }
                real.solve(g);
                for (x, y) in f.iter_mut().zip(g.iter()) {
                    // x = (f + y)/γ with f already divided by γ.
                    *x += y / gamma;
                }
            }
        }
    }

    /// Overwrite (br, bi) with the solution of ((α + iβ)·I − J)·x = br + i·bi.
    pub(crate) fn solve_complex<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        br: &mut [f64],
        bi: &mut [f64],
        stats: &mut Stats,
    ) {
        let dense = match self {
            NewtonMatrices::Structured(s) => return s.solve_complex(system, br, bi, stats),
            dense => dense,
        };
        match dense {
            NewtonMatrices::Structured(_) => unreachable!("returned above"),
            NewtonMatrices::Full { complex, .. } => complex.solve(br, bi),
            NewtonMatrices::Reduced {
                m,
                complex,
                lower_left,
                inv_shift,
                ..
            } => {
                let (alp, bet) = *inv_shift;
                let (fr, gr) = br.split_at_mut(*m);
                let (fi, gi) = bi.split_at_mut(*m);
                // f ← f/(α + iβ) = f·(alp − i·bet).
                for (xr, xi) in fr.iter_mut().zip(fi.iter_mut()) {
                    let (r, i) = (*xr, *xi);
                    *xr = r * alp + i * bet;
                    *xi = i * alp - r * bet;
                }
                for ((yr, yi), row) in gr
                    .iter_mut()
                    .zip(gi.iter_mut())
                    .zip(lower_left.chunks_exact(*m))
                {
                    let (mut sr, mut si) = (0.0, 0.0);
                    for ((a, xr), xi) in row.iter().zip(fr.iter()).zip(fi.iter()) {
                        sr += a * xr;
                        si += a * xi;
                    }
                    *yr += sr;
                    *yi += si;
                }
                complex.solve(gr, gi);
                for ((xr, xi), (yr, yi)) in fr
                    .iter_mut()
                    .zip(fi.iter_mut())
                    .zip(gr.iter().zip(gi.iter()))
                {
                    // x = (f + y)/(α + iβ) with f already divided.
                    *xr += yr * alp + yi * bet;
                    *xi += yi * alp - yr * bet;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The dense matrices never call the system.
    struct NoSystem;

    impl OdeSystem for NoSystem {
        fn dim(&self) -> usize {
            0
        }
        fn rhs(&self, _t: f64, _y: &[f64], _dydt: &mut [f64]) {
            unreachable!("dense Newton matrices evaluate nothing")
        }
    }

    /// A second-order 6×6 Jacobian [[0, I], [A, B]] whose reduced matrices
    /// need pivoting.
    fn jacobian() -> Vec<f64> {
        let a = [[0.0, 2.0, -1.0], [-4.0, 0.5, 0.0], [1.0, 0.0, -3.0]];
        let b = [[-0.2, 1.0, 0.0], [0.0, -5.0, 2.0], [0.3, 0.0, 0.0]];
        let mut j = vec![0.0; 36];
        for i in 0..3 {
            j[i * 6 + 3 + i] = 1.0;
            for k in 0..3 {
                j[(3 + i) * 6 + k] = a[i][k];
                j[(3 + i) * 6 + 3 + k] = b[i][k];
            }
        }
        j
    }

    #[test]
    fn reduced_solves_agree_with_full_ones() {
        let jac = jacobian();
        let (gamma, alpha, beta) = (3.6, 2.7, -1.9);
        let mut full = NewtonMatrices::new(6, None);
        let mut reduced = NewtonMatrices::new(6, Some(3));
        assert!(matches!(reduced, NewtonMatrices::Reduced { .. }));
        assert!(full.factor(&NoSystem, gamma, alpha, beta, &jac, &mut Stats::default()));
        assert!(reduced.factor(&NoSystem, gamma, alpha, beta, &jac, &mut Stats::default()));
        let b = [1.0, -2.0, 0.5, 3.0, 0.25, -1.0];
        let (mut x_full, mut x_red) = (b, b);
        full.solve_real(&NoSystem, &mut x_full, &mut Stats::default());
        reduced.solve_real(&NoSystem, &mut x_red, &mut Stats::default());
        for (p, q) in x_full.iter().zip(&x_red) {
            assert!((p - q).abs() < 1e-13, "{x_full:?} {x_red:?}");
        }
        // The solution really solves (γ·I − J)·x = b.
        for i in 0..6 {
            let jx: f64 = (0..6).map(|k| jac[i * 6 + k] * x_red[k]).sum();
            assert!((gamma * x_red[i] - jx - b[i]).abs() < 1e-12);
        }
        let bi = [0.5, 0.0, -1.0, 2.0, 1.5, -0.75];
        let (mut fr, mut fi) = (b, bi);
        let (mut rr, mut ri) = (b, bi);
        full.solve_complex(&NoSystem, &mut fr, &mut fi, &mut Stats::default());
        reduced.solve_complex(&NoSystem, &mut rr, &mut ri, &mut Stats::default());
        for k in 0..6 {
            assert!((fr[k] - rr[k]).abs() < 1e-13 && (fi[k] - ri[k]).abs() < 1e-13);
        }
    }

    #[test]
    fn an_odd_or_mismatched_split_falls_back_to_full_matrices() {
        assert!(matches!(
            NewtonMatrices::new(6, Some(2)),
            NewtonMatrices::Full { .. }
        ));
        assert!(matches!(
            NewtonMatrices::new(5, None),
            NewtonMatrices::Full { .. }
        ));
    }

    #[test]
    fn a_singular_or_non_finite_reduced_matrix_is_refused() {
        let mut reduced = NewtonMatrices::new(6, Some(3));
        let mut jac = jacobian();
        assert!(!reduced.factor(&NoSystem, 0.0, 1.0, 1.0, &jac, &mut Stats::default()));
        jac[30] = f64::NAN;
        assert!(!reduced.factor(&NoSystem, 3.6, 2.7, -1.9, &jac, &mut Stats::default()));
    }
}
