//! Dense LU factorisation with partial pivoting, real and complex, in place,
//! for the Newton matrices of the implicit stepper.
//!
//! Hand-written rather than nalgebra's: the matrices are small (a rotor with
//! a few balancers has tens of states), the buffers are allocated once per
//! solve and reused for every factorisation (nalgebra's `LU` takes its matrix
//! by value and allocates its permutation each time), the complex matrix
//! (α + iβ)·I − J is kept as two real arrays without a complex-number crate,
//! and in the test profile only this crate is optimised, so a dependency's
//! generic code would run at opt-level 0.

/// LU factors of s·I − J with row pivoting.
pub(crate) struct RealLu {
    n: usize,
    a: Vec<f64>,
    piv: Vec<usize>,
}

impl RealLu {
    /// Buffers for an n×n matrix.
    pub(crate) fn new(n: usize) -> Self {
        RealLu {
            n,
            a: vec![0.0; n * n],
            piv: vec![0; n],
        }
    }

    /// Factor s·I − J (J row-major); false if singular or not finite.
    pub(crate) fn factor_shifted(&mut self, s: f64, jac: &[f64]) -> bool {
        let n = self.n;
        if !s.is_finite() || jac.iter().any(|v| !v.is_finite()) {
            return false;
        }
        for (a, j) in self.a.iter_mut().zip(jac) {
            *a = -j;
        }
        for i in 0..n {
            self.a[i * n + i] += s;
        }
        let a = &mut self.a;
        for k in 0..n {
            let mut p = k;
            let mut amax = a[k * n + k].abs();
            for i in k + 1..n {
                let v = a[i * n + k].abs();
                if v > amax {
                    amax = v;
                    p = i;
                }
            }
            self.piv[k] = p;
            if amax == 0.0 || !amax.is_finite() {
                return false;
            }
            if p != k {
                for j in 0..n {
                    a.swap(k * n + j, p * n + j);
                }
            }
            let pivot = a[k * n + k];
            for i in k + 1..n {
                let l = a[i * n + k] / pivot;
                a[i * n + k] = l;
                if l != 0.0 {
                    for j in k + 1..n {
                        a[i * n + j] -= l * a[k * n + j];
                    }
                }
            }
        }
        true
    }

    /// Overwrite b with the solution x of (s·I − J)·x = b.
    pub(crate) fn solve(&self, b: &mut [f64]) {
        let (n, a) = (self.n, &self.a);
        for k in 0..n {
            b.swap(k, self.piv[k]);
        }
        for i in 0..n {
            let mut s = b[i];
            for j in 0..i {
                s -= a[i * n + j] * b[j];
            }
            b[i] = s;
        }
        for i in (0..n).rev() {
            let mut s = b[i];
            for j in i + 1..n {
                s -= a[i * n + j] * b[j];
            }
            b[i] = s / a[i * n + i];
        }
    }
}

/// LU factors of (α + iβ)·I − J with row pivoting, as real and imaginary parts.
pub(crate) struct ComplexLu {
    n: usize,
    re: Vec<f64>,
    im: Vec<f64>,
    piv: Vec<usize>,
}

impl ComplexLu {
    /// Buffers for an n×n matrix.
    pub(crate) fn new(n: usize) -> Self {
        ComplexLu {
            n,
            re: vec![0.0; n * n],
            im: vec![0.0; n * n],
            piv: vec![0; n],
        }
    }

    /// Factor (α + iβ)·I − J (J row-major); false if singular or not finite.
    pub(crate) fn factor_shifted(&mut self, alpha: f64, beta: f64, jac: &[f64]) -> bool {
        let n = self.n;
        if !(alpha.is_finite() && beta.is_finite()) || jac.iter().any(|v| !v.is_finite()) {
            return false;
        }
        for (a, j) in self.re.iter_mut().zip(jac) {
            *a = -j;
        }
        self.im.fill(0.0);
        for i in 0..n {
            self.re[i * n + i] += alpha;
            self.im[i * n + i] = beta;
        }
        let (re, im) = (&mut self.re, &mut self.im);
        for k in 0..n {
            let mut p = k;
            let mut amax = re[k * n + k].abs() + im[k * n + k].abs();
            for i in k + 1..n {
                let v = re[i * n + k].abs() + im[i * n + k].abs();
                if v > amax {
                    amax = v;
                    p = i;
                }
            }
            self.piv[k] = p;
            if amax == 0.0 || !amax.is_finite() {
                return false;
            }
            if p != k {
                for j in 0..n {
                    re.swap(k * n + j, p * n + j);
                    im.swap(k * n + j, p * n + j);
                }
            }
            let (pr, pi) = (re[k * n + k], im[k * n + k]);
            let den = pr * pr + pi * pi;
            for i in k + 1..n {
                let (ar, ai) = (re[i * n + k], im[i * n + k]);
                // l = a / pivot
                let lr = (ar * pr + ai * pi) / den;
                let li = (ai * pr - ar * pi) / den;
                re[i * n + k] = lr;
                im[i * n + k] = li;
                if lr != 0.0 || li != 0.0 {
                    for j in k + 1..n {
                        let (ur, ui) = (re[k * n + j], im[k * n + j]);
                        re[i * n + j] -= lr * ur - li * ui;
                        im[i * n + j] -= lr * ui + li * ur;
                    }
                }
            }
        }
        true
    }

    /// Overwrite (br, bi) with the solution of ((α + iβ)·I − J)·x = br + i·bi.
    pub(crate) fn solve(&self, br: &mut [f64], bi: &mut [f64]) {
        let (n, re, im) = (self.n, &self.re, &self.im);
        for k in 0..n {
            br.swap(k, self.piv[k]);
            bi.swap(k, self.piv[k]);
        }
        for i in 0..n {
            let (mut sr, mut si) = (br[i], bi[i]);
            for j in 0..i {
                let (lr, li) = (re[i * n + j], im[i * n + j]);
                sr -= lr * br[j] - li * bi[j];
                si -= lr * bi[j] + li * br[j];
            }
            br[i] = sr;
            bi[i] = si;
        }
        for i in (0..n).rev() {
            let (mut sr, mut si) = (br[i], bi[i]);
            for j in i + 1..n {
                let (ur, ui) = (re[i * n + j], im[i * n + j]);
                sr -= ur * br[j] - ui * bi[j];
                si -= ur * bi[j] + ui * br[j];
            }
            let (dr, di) = (re[i * n + i], im[i * n + i]);
            let den = dr * dr + di * di;
            br[i] = (sr * dr + si * di) / den;
            bi[i] = (si * dr - sr * di) / den;
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
}
