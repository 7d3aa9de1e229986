//! Dense LU factorisation with partial pivoting, in place, one kernel for
//! real and complex matrices: the Newton matrices of the implicit stepper
//! and the small reduced systems of the structured ones.
//!
//! Hand-written rather than nalgebra's: the matrices are small (a rotor with
//! a few balancers has tens of states), the buffers are allocated once per
//! solve and reused for every factorisation (nalgebra's `LU` takes its matrix
//! by value and allocates its permutation each time), and in the test
//! profile only this crate is optimised, so a dependency's generic code
//! would run at opt-level 0.

use num_complex::Complex64;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// The arithmetic a factorisation needs, for real and complex entries.
pub(crate) trait Scalar:
    Copy
    + PartialEq
    + From<f64>
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Real parts a vector splits into (1 or 2).
    const PARTS: usize;
    /// Size for pivoting (|x|, or |re| + |im|).
    fn mag(self) -> f64;
    /// Neither NaN nor infinite.
    fn finite(self) -> bool;
    /// Real part `k` (0: real, 1: imaginary).
    fn part(x: Self, k: usize) -> f64;
    /// The value from its parts.
    fn assemble(re: f64, im: f64) -> Self;
}

impl Scalar for f64 {
    const PARTS: usize = 1;
    fn mag(self) -> f64 {
        self.abs()
    }
    fn finite(self) -> bool {
        self.is_finite()
    }
    fn part(x: Self, _k: usize) -> f64 {
        x
    }
    fn assemble(re: f64, _im: f64) -> Self {
        re
    }
}

impl Scalar for Complex64 {
    const PARTS: usize = 2;
    fn mag(self) -> f64 {
        self.l1_norm()
    }
    fn finite(self) -> bool {
        self.is_finite()
    }
    fn part(x: Self, k: usize) -> f64 {
        if k == 0 { x.re } else { x.im }
    }
    fn assemble(re: f64, im: f64) -> Self {
        Complex64::new(re, im)
    }
}

/// Factor the n×n row-major `a` in place (L's multipliers below the
/// diagonal, U on and above), the row interchanges into `piv`; false if a
/// pivot is zero or not finite. Ties for the pivot go to the first row.
pub(crate) fn factor_in_place<S: Scalar>(a: &mut [S], piv: &mut [usize], n: usize) -> bool {
    let a = &mut a[..n * n];
    for k in 0..n {
        let mut p = k;
        let mut amax = a[k * n + k].mag();
        for i in k + 1..n {
            let v = a[i * n + k].mag();
            if v > amax {
                amax = v;
                p = i;
            }
        }
        piv[k] = p;
        if amax == 0.0 || !amax.is_finite() {
            return false;
        }
        if p != k {
            for j in 0..n {
                a.swap(k * n + j, p * n + j);
            }
        }
        let (upper, lower) = a.split_at_mut((k + 1) * n);
        let pivot_row = &upper[k * n..];
        let pivot = pivot_row[k];
        let zero = S::from(0.0);
        for row in lower.chunks_exact_mut(n) {
            let l = row[k] / pivot;
            row[k] = l;
            if l != zero {
                for (x, &u) in row[k + 1..].iter_mut().zip(&pivot_row[k + 1..]) {
                    *x = *x - l * u;
                }
            }
        }
    }
    true
}

/// Overwrite b with the solution of A·x = b, A factored by
/// [`factor_in_place`].
pub(crate) fn solve_in_place<S: Scalar>(a: &[S], piv: &[usize], n: usize, b: &mut [S]) {
    // The few-weight sizes with the size known to the compiler: loops
    // unrolled, the same operations in the same order (the same bits).
    match n {
        3 => solve_sized::<S, 3>(a, piv, b),
        4 => solve_sized::<S, 4>(a, piv, b),
        5 => solve_sized::<S, 5>(a, piv, b),
        6 => solve_sized::<S, 6>(a, piv, b),
        7 => solve_sized::<S, 7>(a, piv, b),
        8 => solve_sized::<S, 8>(a, piv, b),
        _ => solve_any(a, piv, n, b),
    }
}

/// [`solve_in_place`] for n = N.
fn solve_sized<S: Scalar, const N: usize>(a: &[S], piv: &[usize], b: &mut [S]) {
    let b: &mut [S; N] = (&mut b[..N]).try_into().expect("n = N");
    let a = &a[..N * N];
    for (k, &p) in piv[..N].iter().enumerate() {
        b.swap(k, p);
    }
    for i in 0..N {
        let mut s = b[i];
        for k in 0..i {
            s = s - a[i * N + k] * b[k];
        }
        b[i] = s;
    }
    for i in (0..N).rev() {
        let mut s = b[i];
        for k in i + 1..N {
            s = s - a[i * N + k] * b[k];
        }
        b[i] = s / a[i * N + i];
    }
}

/// [`solve_in_place`] for any n.
fn solve_any<S: Scalar>(a: &[S], piv: &[usize], n: usize, b: &mut [S]) {
    let b = &mut b[..n];
    // Every interchange first: the factorisation swapped whole rows, its
    // multipliers included.
    for (k, &p) in piv[..n].iter().enumerate() {
        b.swap(k, p);
    }
    // Slices rather than indices: no bounds checks in the inner loops,
    // the same operations in the same order.
    for (i, row) in a[..n * n].chunks_exact(n).enumerate() {
        let (done, rest) = b.split_at_mut(i);
        let mut s = rest[0];
        for (&l, &x) in row[..i].iter().zip(done.iter()) {
            s = s - l * x;
        }
        rest[0] = s;
    }
    for (i, row) in a[..n * n].chunks_exact(n).enumerate().rev() {
        let (head, done) = b.split_at_mut(i + 1);
        let mut s = head[i];
        for (&u, &x) in row[i + 1..].iter().zip(done.iter()) {
            s = s - u * x;
        }
        head[i] = s / row[i];
    }
}

/// LU factors of an n×n matrix and its interchanges, with its buffers.
pub(crate) struct DenseLu<S> {
    n: usize,
    a: Vec<S>,
    piv: Vec<usize>,
}

impl<S: Scalar> DenseLu<S> {
    /// Buffers for an n×n matrix.
    pub(crate) fn new(n: usize) -> Self {
        DenseLu {
            n,
            a: vec![S::from(0.0); n * n],
            piv: vec![0; n],
        }
    }

    /// Factor c·I − J (J real, row-major); false if singular or not finite.
    fn factor_shifted_by(&mut self, c: S, jac: &[f64]) -> bool {
        let n = self.n;
        if !c.finite() || jac.iter().any(|v| !v.is_finite()) {
            return false;
        }
        for (a, &j) in self.a.iter_mut().zip(jac) {
            *a = S::from(-j);
        }
        for i in 0..n {
            self.a[i * n + i] = self.a[i * n + i] + c;
        }
        factor_in_place(&mut self.a, &mut self.piv, n)
    }

    /// Overwrite b with the solution of the factored system.
    fn solve_scalars(&self, b: &mut [S]) {
        solve_in_place(&self.a, &self.piv, self.n, b);
    }
}

/// LU factors of s·I − J with row pivoting.
pub(crate) type RealLu = DenseLu<f64>;

impl DenseLu<f64> {
    /// Factor s·I − J (J row-major); false if singular or not finite.
    pub(crate) fn factor_shifted(&mut self, s: f64, jac: &[f64]) -> bool {
        self.factor_shifted_by(s, jac)
    }

    /// Factor the matrix that `fill` writes (row-major, n×n); false if
    /// singular or not finite.
    pub(crate) fn factor_from(&mut self, fill: impl FnOnce(&mut [f64])) -> bool {
        fill(&mut self.a);
        self.a.iter().all(|v| v.is_finite()) && factor_in_place(&mut self.a, &mut self.piv, self.n)
    }

    /// Overwrite b with the solution x of (s·I − J)·x = b (or of the matrix
    /// given to [`RealLu::factor_from`]).
    pub(crate) fn solve(&self, b: &mut [f64]) {
        self.solve_scalars(b);
    }
}

/// LU factors of (α + iβ)·I − J with row pivoting; right-hand sides and
/// solutions as real and imaginary parts, as the implicit stepper keeps them.
pub(crate) struct ComplexLu {
    lu: DenseLu<Complex64>,
    /// The parts a caller fills, and the packed right-hand side.
    re: Vec<f64>,
    im: Vec<f64>,
    packed: Vec<Complex64>,
}

impl ComplexLu {
    /// Buffers for an n×n matrix.
    pub(crate) fn new(n: usize) -> Self {
        ComplexLu {
            lu: DenseLu::new(n),
            re: vec![0.0; n * n],
            im: vec![0.0; n * n],
            packed: vec![Complex64::new(0.0, 0.0); n],
        }
    }

    /// Factor (α + iβ)·I − J (J row-major); false if singular or not finite.
    pub(crate) fn factor_shifted(&mut self, alpha: f64, beta: f64, jac: &[f64]) -> bool {
        self.lu.factor_shifted_by(Complex64::new(alpha, beta), jac)
    }

    /// Factor the matrix whose real and imaginary parts `fill` writes
    /// (row-major, n×n); false if singular or not finite.
    pub(crate) fn factor_from(&mut self, fill: impl FnOnce(&mut [f64], &mut [f64])) -> bool {
        fill(&mut self.re, &mut self.im);
        for ((a, &r), &i) in self.lu.a.iter_mut().zip(&self.re).zip(&self.im) {
            *a = Complex64::new(r, i);
        }
        self.lu.a.iter().all(|v| v.is_finite())
            && factor_in_place(&mut self.lu.a, &mut self.lu.piv, self.lu.n)
    }

    /// Overwrite (br, bi) with the solution of ((α + iβ)·I − J)·x = br + i·bi
    /// (or of the matrix given to [`ComplexLu::factor_from`]).
    pub(crate) fn solve(&mut self, br: &mut [f64], bi: &mut [f64]) {
        let n = self.lu.n;
        for ((p, &r), &i) in self.packed.iter_mut().zip(&br[..n]).zip(&bi[..n]) {
            *p = Complex64::new(r, i);
        }
        self.lu.solve_scalars(&mut self.packed);
        for ((p, r), i) in self.packed.iter().zip(&mut br[..n]).zip(&mut bi[..n]) {
            *r = p.re;
            *i = p.im;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4×4 Jacobian whose shifted matrices need pivoting (zero diagonal).
    const J: [f64; 16] = [
        0.0, 1.0, 0.0, 2.0, //
        -3.0, 0.0, 1.0, 0.0, //
        0.5, -1.0, 0.0, 4.0, //
        1.0, 0.0, -2.0, 0.0,
    ];

    #[test]
    fn real_lu_solves_a_shifted_system() {
        let (n, s) = (4, 0.0);
        let mut lu = RealLu::new(n);
        assert!(lu.factor_shifted(s, &J));
        let x = [1.0, -2.0, 3.0, 0.5];
        let mut b = [0.0; 4];
        for i in 0..n {
            b[i] = s * x[i] - (0..n).map(|j| J[i * n + j] * x[j]).sum::<f64>();
        }
        lu.solve(&mut b);
        for i in 0..n {
            assert!((b[i] - x[i]).abs() < 1e-13, "{b:?}");
        }
        assert!(!lu.factor_shifted(0.0, &[0.0; 16]));
        assert!(!lu.factor_shifted(1.0, &[f64::NAN; 16]));
    }

    #[test]
    fn complex_lu_solves_a_shifted_system() {
        let (n, a, bt) = (4, 0.3, -1.7);
        let mut lu = ComplexLu::new(n);
        assert!(lu.factor_shifted(a, bt, &J));
        let (xr, xi) = ([1.0, -2.0, 3.0, 0.5], [0.25, 1.0, -1.0, 2.0]);
        let (mut br, mut bi) = ([0.0; 4], [0.0; 4]);
        for i in 0..n {
            let jr: f64 = (0..n).map(|j| J[i * n + j] * xr[j]).sum();
            let ji: f64 = (0..n).map(|j| J[i * n + j] * xi[j]).sum();
            br[i] = a * xr[i] - bt * xi[i] - jr;
            bi[i] = a * xi[i] + bt * xr[i] - ji;
        }
        lu.solve(&mut br, &mut bi);
        for i in 0..n {
            assert!((br[i] - xr[i]).abs() < 1e-13 && (bi[i] - xi[i]).abs() < 1e-13);
        }
    }

    #[test]
    fn sized_solves_give_the_bits_of_the_general_ones() {
        for n in 3..=8 {
            let jac: Vec<f64> = (0..n * n)
                .map(|k| ((k * 7919 % 97) as f64 - 48.0) / 13.0)
                .collect();
            let b: Vec<f64> = (0..n).map(|k| (k as f64 - 2.5) / 3.0).collect();
            let bi: Vec<f64> = b.iter().map(|v| v * v - 0.5).collect();
            let mut real = RealLu::new(n);
            assert!(real.factor_shifted(0.7, &jac));
            let (mut x, mut y) = (b.clone(), b.clone());
            real.solve(&mut x);
            solve_any(&real.a, &real.piv, n, &mut y);
            assert_eq!(
                x.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                y.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                "real n = {n}"
            );
            let mut complex = DenseLu::<Complex64>::new(n);
            assert!(complex.factor_shifted_by(Complex64::new(0.7, -1.3), &jac));
            let mut x: Vec<Complex64> = b
                .iter()
                .zip(&bi)
                .map(|(&r, &i)| Complex64::new(r, i))
                .collect();
            let mut y = x.clone();
            complex.solve_scalars(&mut x);
            solve_any(&complex.a, &complex.piv, n, &mut y);
            assert!(
                x.iter()
                    .zip(&y)
                    .all(|(p, q)| p.re.to_bits() == q.re.to_bits()
                        && p.im.to_bits() == q.im.to_bits()),
                "complex n = {n}"
            );
        }
    }
}
