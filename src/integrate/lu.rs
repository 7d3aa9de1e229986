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
        self.factor()
    }

    /// Factor the matrix that `fill` writes (row-major, n×n); false if
    /// singular or not finite.
    pub(crate) fn factor_from(&mut self, fill: impl FnOnce(&mut [f64])) -> bool {
        fill(&mut self.a);
        self.a.iter().all(|v| v.is_finite()) && self.factor()
    }

    /// Factor the buffer in place.
    fn factor(&mut self) -> bool {
        let n = self.n;
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
            let (upper, lower) = a.split_at_mut((k + 1) * n);
            let pivot_row = &upper[k * n..];
            let pivot = pivot_row[k];
            for row in lower.chunks_exact_mut(n) {
                let l = row[k] / pivot;
                row[k] = l;
                if l != 0.0 {
                    for (x, u) in row[k + 1..].iter_mut().zip(&pivot_row[k + 1..]) {
                        *x -= l * u;
                    }
                }
            }
        }
        true
    }

    /// Overwrite b with the solution x of (s·I − J)·x = b (or of the matrix
    /// given to [`RealLu::factor_from`]).
    pub(crate) fn solve(&self, b: &mut [f64]) {
        // The few-weight sizes with the size known to the compiler: loops
        // unrolled, the same operations in the same order (the same bits).
        match self.n {
            3 => self.solve_sized::<3>(b),
            4 => self.solve_sized::<4>(b),
            5 => self.solve_sized::<5>(b),
            6 => self.solve_sized::<6>(b),
            7 => self.solve_sized::<7>(b),
            8 => self.solve_sized::<8>(b),
            _ => self.solve_any(b),
        }
    }

    /// [`Self::solve`] for n = N.
    fn solve_sized<const N: usize>(&self, b: &mut [f64]) {
        let b: &mut [f64; N] = (&mut b[..N]).try_into().expect("n = N");
        let a = &self.a[..N * N];
        for (k, &p) in self.piv[..N].iter().enumerate() {
            b.swap(k, p);
        }
        for i in 0..N {
            let mut s = b[i];
            for k in 0..i {
                s -= a[i * N + k] * b[k];
            }
            b[i] = s;
        }
        for i in (0..N).rev() {
            let mut s = b[i];
            for k in i + 1..N {
                s -= a[i * N + k] * b[k];
            }
            b[i] = s / a[i * N + i];
        }
    }

    /// [`Self::solve`] for any n.
    fn solve_any(&self, b: &mut [f64]) {
        let n = self.n;
        let b = &mut b[..n];
        for (k, &p) in self.piv.iter().enumerate() {
            b.swap(k, p);
        }
        // Slices rather than indices: no bounds checks in the inner loops,
        // the same operations in the same order.
        for (i, row) in self.a.chunks_exact(n).enumerate() {
            let (done, rest) = b.split_at_mut(i);
            let mut s = rest[0];
            for (l, x) in row[..i].iter().zip(done.iter()) {
                s -= l * x;
            }
            rest[0] = s;
        }
        for (i, row) in self.a.chunks_exact(n).enumerate().rev() {
            let (head, done) = b.split_at_mut(i + 1);
            let mut s = head[i];
            for (u, x) in row[i + 1..].iter().zip(done.iter()) {
                s -= u * x;
            }
            head[i] = s / row[i];
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
        self.factor()
    }

    /// Factor the matrix whose real and imaginary parts `fill` writes
    /// (row-major, n×n); false if singular or not finite.
    pub(crate) fn factor_from(&mut self, fill: impl FnOnce(&mut [f64], &mut [f64])) -> bool {
        fill(&mut self.re, &mut self.im);
        self.re.iter().chain(&self.im).all(|v| v.is_finite()) && self.factor()
    }

    /// Factor the buffers in place.
    fn factor(&mut self) -> bool {
        let n = self.n;
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
            let (re_upper, re_lower) = re.split_at_mut((k + 1) * n);
            let (im_upper, im_lower) = im.split_at_mut((k + 1) * n);
            let (ur_row, ui_row) = (&re_upper[k * n..], &im_upper[k * n..]);
            let (pr, pi) = (ur_row[k], ui_row[k]);
            let den = pr * pr + pi * pi;
            for (row_r, row_i) in re_lower
                .chunks_exact_mut(n)
                .zip(im_lower.chunks_exact_mut(n))
            {
                let (ar, ai) = (row_r[k], row_i[k]);
                // l = a / pivot
                let lr = (ar * pr + ai * pi) / den;
                let li = (ai * pr - ar * pi) / den;
                row_r[k] = lr;
                row_i[k] = li;
                if lr != 0.0 || li != 0.0 {
                    let pivot_part = ur_row[k + 1..].iter().zip(&ui_row[k + 1..]);
                    let row_part = row_r[k + 1..].iter_mut().zip(row_i[k + 1..].iter_mut());
                    for ((xr, xi), (ur, ui)) in row_part.zip(pivot_part) {
                        *xr -= lr * ur - li * ui;
                        *xi -= lr * ui + li * ur;
                    }
                }
            }
        }
        true
    }

    /// Overwrite (br, bi) with the solution of ((α + iβ)·I − J)·x = br + i·bi
    /// (or of the matrix given to [`ComplexLu::factor_from`]).
    pub(crate) fn solve(&self, br: &mut [f64], bi: &mut [f64]) {
        // As [`RealLu::solve`]: the few-weight sizes known to the compiler.
        match self.n {
            3 => self.solve_sized::<3>(br, bi),
            4 => self.solve_sized::<4>(br, bi),
            5 => self.solve_sized::<5>(br, bi),
            6 => self.solve_sized::<6>(br, bi),
            7 => self.solve_sized::<7>(br, bi),
            8 => self.solve_sized::<8>(br, bi),
            _ => self.solve_any(br, bi),
        }
    }

    /// [`Self::solve`] for n = N.
    fn solve_sized<const N: usize>(&self, br: &mut [f64], bi: &mut [f64]) {
        let br: &mut [f64; N] = (&mut br[..N]).try_into().expect("n = N");
        let bi: &mut [f64; N] = (&mut bi[..N]).try_into().expect("n = N");
        let (re, im) = (&self.re[..N * N], &self.im[..N * N]);
        for (k, &p) in self.piv[..N].iter().enumerate() {
            br.swap(k, p);
            bi.swap(k, p);
        }
        for i in 0..N {
            let (mut sr, mut si) = (br[i], bi[i]);
            for k in 0..i {
                let (lr, li) = (re[i * N + k], im[i * N + k]);
                sr -= lr * br[k] - li * bi[k];
                si -= lr * bi[k] + li * br[k];
            }
            br[i] = sr;
            bi[i] = si;
        }
        for i in (0..N).rev() {
            let (mut sr, mut si) = (br[i], bi[i]);
            for k in i + 1..N {
                let (ur, ui) = (re[i * N + k], im[i * N + k]);
                sr -= ur * br[k] - ui * bi[k];
                si -= ur * bi[k] + ui * br[k];
            }
            let (dr, di) = (re[i * N + i], im[i * N + i]);
            let den = dr * dr + di * di;
            br[i] = (sr * dr + si * di) / den;
            bi[i] = (si * dr - sr * di) / den;
        }
    }

    /// [`Self::solve`] for any n.
    fn solve_any(&self, br: &mut [f64], bi: &mut [f64]) {
        let n = self.n;
        let (br, bi) = (&mut br[..n], &mut bi[..n]);
        for (k, &p) in self.piv.iter().enumerate() {
            br.swap(k, p);
            bi.swap(k, p);
        }
        let rows = || self.re.chunks_exact(n).zip(self.im.chunks_exact(n));
        // Slices rather than indices: no bounds checks in the inner loops,
        // the same operations in the same order.
        for (i, (row_r, row_i)) in rows().enumerate() {
            let (done_r, rest_r) = br.split_at_mut(i);
            let (done_i, rest_i) = bi.split_at_mut(i);
            let (mut sr, mut si) = (rest_r[0], rest_i[0]);
            let factors = row_r[..i].iter().zip(&row_i[..i]);
            for ((lr, li), (xr, xi)) in factors.zip(done_r.iter().zip(done_i.iter())) {
                sr -= lr * xr - li * xi;
                si -= lr * xi + li * xr;
            }
            rest_r[0] = sr;
            rest_i[0] = si;
        }
        for (i, (row_r, row_i)) in rows().enumerate().rev() {
            let (head_r, done_r) = br.split_at_mut(i + 1);
            let (head_i, done_i) = bi.split_at_mut(i + 1);
            let (mut sr, mut si) = (head_r[i], head_i[i]);
            let factors = row_r[i + 1..].iter().zip(&row_i[i + 1..]);
            for ((ur, ui), (xr, xi)) in factors.zip(done_r.iter().zip(done_i.iter())) {
                sr -= ur * xr - ui * xi;
                si -= ur * xi + ui * xr;
            }
            let (dr, di) = (row_r[i], row_i[i]);
            let den = dr * dr + di * di;
            head_r[i] = (sr * dr + si * di) / den;
            head_i[i] = (si * dr - sr * di) / den;
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
            real.solve_any(&mut y);
            assert_eq!(
                x.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                y.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                "real n = {n}"
            );
            let mut complex = ComplexLu::new(n);
            assert!(complex.factor_shifted(0.7, -1.3, &jac));
            let (mut xr, mut xi, mut yr, mut yi) = (b.clone(), bi.clone(), b.clone(), bi.clone());
            complex.solve(&mut xr, &mut xi);
            complex.solve_any(&mut yr, &mut yi);
            assert!(
                xr.iter()
                    .chain(&xi)
                    .zip(yr.iter().chain(&yi))
                    .all(|(p, q)| p.to_bits() == q.to_bits()),
                "complex n = {n}"
            );
        }
    }
}
