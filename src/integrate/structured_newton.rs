//! Newton matrices of a second-order system with a [`CouplingStructure`]: a
//! weight's acceleration a_i depends on its ring neighbours directly and on
//! every other weight only through the few head accelerations z. With J_loc
//! the Jacobian with z held fixed and P = [0; U],
//!
//!   J = J_loc + P·∂z/∂(q, q̇),   c₀·I − J = S − P·∂z/∂(q, q̇),   S = c₀·I − J_loc
//!
//! for the shifts c₀ = γ (real) and α + iβ (complex), c₁ = 1/c₀. Two
//! Woodbury identities solve it:
//!
//! - S reduces as every second-order matrix does ([`super::newton_matrices`])
//!   to T = c₀·I − L_q̇ − c₁·L_q: tridiagonal along the rings (LAPACK's
//!   gttrf/gttrs, partial pivoting) plus the head columns and each ring's
//!   closing corners, whose rows of Qᵀ are unit vectors: exact.
//! - The outer correction has `head` columns. Its rows ∂z/∂(q, q̇) are
//!   formed from L when the system states its head equation
//!   ([`HeadEquation`]); otherwise they act on a vector as one directional
//!   difference of z (two for a complex vector).
//!
//! Costs for m coordinates, all O(m) where the dense matrices take O(m²) per
//! Jacobian and O(m³) per factorisation: a Jacobian (L by forward
//! differences over colour groups, columns no row sees twice) takes
//! 2·(head + 3 or 4) RHS calls whatever m (5 for a ring of five), against
//! 2m. Without a head equation a factorisation of both matrices takes
//! 3·head RHS calls more, a real solve one and a complex solve two.
//!
//! Written by hand: no Rust crate offers a tridiagonal-plus-low-rank solve,
//! and the matrix-free correction is specific to this structure.

use super::lu::{Scalar, factor_in_place, solve_in_place};
use super::{CouplingStructure, HeadEquation, OdeSystem, Stats};
use num_complex::Complex64;

/// Radau5's unit roundoff for difference increments.
const UROUND: f64 = 1e-16;

/// Most head coordinates (Δz lives on the stack).
const MAX_HEAD: usize = 8;

/// Fewest ring coordinates for which the structured matrices pay: measured
/// on packed balls (docs/benchmarks.md), the dense ones are 10 % faster at
/// 16 weights and 7 % slower at 24. The shipped studies (n ≤ 8) keep their
/// bits.
pub(crate) const MIN_RING_COORDINATES: usize = 20;

/// One half (∂/∂q or ∂/∂q̇) of the local Jacobian L, per ring position.
#[derive(Default)]
struct LocalHalf {
    /// To the position's own coordinate.
    diag: Vec<f64>,
    /// To the ring predecessor (cyclic).
    left: Vec<f64>,
    /// To the ring successor (cyclic).
    right: Vec<f64>,
    /// To the head coordinates, `head` per position.
    head: Vec<f64>,
}

impl LocalHalf {
    /// Zeros for `positions` ring positions and `head` head coordinates.
    fn reset(&mut self, positions: usize, head: usize) {
        for v in [&mut self.diag, &mut self.left, &mut self.right] {
            v.clear();
            v.resize(positions, 0.0);
        }
        self.head.clear();
        self.head.resize(positions * head, 0.0);
    }
}

/// The structure and the local Jacobian at the Jacobian's point.
#[derive(Default)]
struct Local {
    m: usize,
    structure: CouplingStructure,
    /// Ring [start, end) of each position.
    ring: Vec<(usize, usize)>,
    colour: Vec<usize>,
    colours: usize,
    dq: LocalHalf,
    dqd: LocalHalf,
    /// The system's head equation, when it gives one.
    head_eq: HeadEquation,
    /// Whether `head_rows` holds ∂z/∂(q, q̇) in full (from the head
    /// equation); else only its head columns, and the ring columns act by
    /// directional differences.
    explicit: bool,
    /// ∂z/∂(q, q̇), row-major, `head` rows of 2m in coordinate order.
    head_rows: Vec<f64>,
    /// Row interchanges of the head's eliminated matrix (scratch).
    head_piv: Vec<usize>,
}

impl Local {
    fn head(&self) -> usize {
        self.structure.head
    }
    fn positions(&self) -> usize {
        self.m - self.head()
    }
    /// The coordinate at T's index `pos` (head first, then ring positions).
    fn coordinate(&self, pos: usize) -> usize {
        let h = self.head();
        if pos < h {
            pos
        } else {
            self.structure.order[pos - h]
        }
    }
    /// U's row for ring position p.
    fn coupling(&self, p: usize) -> &[f64] {
        let h = self.head();
        let row = self.structure.order[p] - h;
        &self.structure.coupling[row * h..(row + 1) * h]
    }
    /// The ring predecessor of position p, if its coupling is held at p's
    /// left (a pair holds its one coupling once: at the second's left and
    /// the first's right).
    fn left(&self, p: usize) -> Option<usize> {
        let (s, e) = self.ring[p];
        match e - s {
            0 | 1 => None,
            2 => (p == s + 1).then_some(s),
            _ => Some(if p == s { e - 1 } else { p - 1 }),
        }
    }
    /// The ring successor of position p, as [`Self::left`].
    fn right(&self, p: usize) -> Option<usize> {
        let (s, e) = self.ring[p];
        match e - s {
            0 | 1 => None,
            2 => (p == s).then_some(s + 1),
            _ => Some(if p == e - 1 { s } else { p + 1 }),
        }
    }

    /// Ring bounds and a colouring in which positions within two of each
    /// other along a ring differ, so that no row sees two columns of a group.
    fn colour_rings(&mut self) -> bool {
        let st = &self.structure;
        let (head, m) = (st.head, self.m);
        let n = m.saturating_sub(head);
        if head > MAX_HEAD || head > m || st.order.len() != n || st.coupling.len() != n * head {
            return false;
        }
        // The order must name every ring coordinate once (`colour` is
        // scratch for the check).
        self.colour.clear();
        self.colour.resize(n, 0);
        for &i in &st.order {
            if !(head..m).contains(&i) || self.colour[i - head] != 0 {
                return false;
            }
            self.colour[i - head] = 1;
        }
        self.ring.clear();
        self.colour.clear();
        self.colours = 0;
        let mut s = 0;
        for &e in &st.ring_ends {
            if e <= s || e > n {
                return false;
            }
            let len = e - s;
            for i in 0..len {
                self.ring.push((s, e));
                let c = ring_colour(i, len);
                self.colour.push(c);
                self.colours = self.colours.max(c + 1);
            }
            s = e;
        }
        s == n
    }

    /// The ring columns of ∂z/∂(q, q̇) from the head equation and L: with
    /// A = M_h + Σ e_i·U_iᵀ (the head's matrix once the weights are
    /// eliminated), A·∂z/∂y_j = own_j − Σ_i e_i·L_ij over the rows i that
    /// see column j. False if the equation is malformed or A singular.
    fn form_head_rows(&mut self) -> bool {
        let (m, h, n) = (self.m, self.head(), self.positions());
        let eq = &self.head_eq;
        if eq.mass.len() != h * h || eq.reaction.len() != n * h || eq.own.len() != 2 * n * h {
            return false;
        }
        let mut a = [0.0; MAX_HEAD * MAX_HEAD];
        let a = &mut a[..h * h];
        a.copy_from_slice(&eq.mass);
        let u = &self.structure.coupling;
        for (e, u) in eq.reaction.chunks_exact(h).zip(u.chunks_exact(h)) {
            for r in 0..h {
                for c in 0..h {
                    a[r * h + c] += e[r] * u[c];
                }
            }
        }
        let mut piv = std::mem::take(&mut self.head_piv);
        let factored = small_lu(a, &mut piv, h);
        self.head_piv = piv;
        if !factored {
            return false;
        }
        let piv = &self.head_piv;
        let mut rows = std::mem::take(&mut self.head_rows);
        for (half, l) in [(0, &self.dq), (1, &self.dqd)] {
            let off = half * m;
            for i in h..m {
                for r in 0..h {
                    rows[r * 2 * m + off + i] = eq.own[(i - h) * 2 * h + half * h + r];
                }
            }
            for p in 0..n {
                let i = self.structure.order[p];
                let e = &eq.reaction[(i - h) * h..(i - h + 1) * h];
                let seen = [
                    Some((p, l.diag[p])),
                    self.left(p).map(|q| (q, l.left[p])),
                    self.right(p).map(|q| (q, l.right[p])),
                ];
                for (q, lij) in seen.into_iter().flatten() {
                    let j = off + self.structure.order[q];
                    for (r, &er) in e.iter().enumerate() {
                        rows[r * 2 * m + j] -= er * lij;
                    }
                }
            }
            let mut col = [0.0; MAX_HEAD];
            for i in h..m {
                for r in 0..h {
                    col[r] = rows[r * 2 * m + off + i];
                }
                solve_in_place(a, piv, h, &mut col[..h]);
                for r in 0..h {
                    rows[r * 2 * m + off + i] = col[r];
                }
            }
        }
        let finite = rows.iter().all(|v| v.is_finite());
        self.head_rows = rows;
        finite
    }
}

/// Colour of place i in a ring of `len` such that places within two of
/// each other along the ring differ, with the fewest colours: 3 when len is
/// a multiple of 3; else blocks of 4 (one or two) then blocks of 3, 4
/// colours; 5 for a ring of 5 (every place sees every other); below 4
/// places, one colour each.
fn ring_colour(i: usize, len: usize) -> usize {
    let fours = match len % 3 {
        _ if len < 4 || len == 5 => return i,
        0 => 0,
        1 => 1,
        _ => 2,
    };
    if i < 4 * fours {
        i % 4
    } else {
        (i - 4 * fours) % 3
    }
}

/// Directional differences of z around the Jacobian's point.
#[derive(Default)]
struct Probe {
    t: f64,
    y0: Vec<f64>,
    f0: Vec<f64>,
    /// Forward-difference increment of each component (Radau5's).
    delta: Vec<f64>,
    y: Vec<f64>,
    f: Vec<f64>,
    dir: Vec<f64>,
    parts: [Vec<f64>; 2],
}

impl Probe {
    fn at(&mut self, t: f64, y: &[f64], f0: &[f64]) {
        self.t = t;
        self.y0.clear();
        self.y0.extend_from_slice(y);
        self.f0.clear();
        self.f0.extend_from_slice(f0);
        self.delta.clear();
        self.delta
            .extend(y.iter().map(|v| (UROUND * v.abs().max(1e-5)).sqrt()));
        self.y.resize(y.len(), 0.0);
        self.f.resize(y.len(), 0.0);
        self.dir.resize(y.len(), 0.0);
    }

    /// f at `self.y` into `self.f`, and Δz against the point into `dz`.
    fn eval<S: OdeSystem + ?Sized>(&mut self, system: &S, stats: &mut Stats) {
        system.rhs(self.t, &self.y, &mut self.f);
        stats.rhs_calls += 1;
    }

    /// Δz of the last evaluation (head accelerations from index m on).
    fn head_change(&self, m: usize, dz: &mut [f64]) {
        for (r, d) in dz.iter_mut().enumerate() {
            *d = self.f[m + r] - self.f0[m + r];
        }
    }

    /// ∂z/∂y·dir into `parts[k]`, with the step scaled so that the
    /// components move by their column increments in the RMS sense.
    fn derivative<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        stats: &mut Stats,
        m: usize,
        head: usize,
        k: usize,
    ) {
        let sum: f64 = self
            .dir
            .iter()
            .zip(&self.delta)
            .map(|(d, e)| (d / e) * (d / e))
            .sum();
        let scale = (sum / self.dir.len() as f64).sqrt();
        self.parts[k].clear();
        if scale == 0.0 || !scale.is_finite() {
            self.parts[k].resize(head, if scale == 0.0 { 0.0 } else { f64::NAN });
            return;
        }
        let eps = 1.0 / scale;
        for ((y, y0), d) in self.y.iter_mut().zip(&self.y0).zip(&self.dir) {
            *y = y0 + eps * d;
        }
        self.eval(system, stats);
        let (f, f0) = (&self.f[m..m + head], &self.f0[m..m + head]);
        self.parts[k].extend(f.iter().zip(f0).map(|(a, b)| (a - b) / eps));
    }
}

/// The two matrices of one shift c₀ (γ, or α + iβ; c₁ = 1/c₀), factored.
///
/// With J_loc the Jacobian with z held fixed ([[0, I], [L_q, L_q̇]]) and
/// P = [0; U], the full Newton matrix is E = S − P·Qᵀ, S = c₀·I − J_loc and
/// Qᵀ = ∂z/∂(q, q̇). S reduces as a second-order matrix does
/// ([`super::newton_matrices`]) to T = c₀·I − L_q̇ − c₁·L_q, which is
/// tridiagonal along the rings plus the head columns and the rings' corners
/// (unit rows of its own low-rank part, so exact); Qᵀ acts on a vector as a
/// directional difference of z.
struct Shifted<S> {
    c1: S,
    dl: Vec<S>,
    d: Vec<S>,
    du: Vec<S>,
    du2: Vec<S>,
    pivoted: Vec<bool>,
    /// T's index of each unit row of T's low-rank part.
    units: Vec<usize>,
    /// (tridiagonal part)⁻¹·(T's low-rank columns), column-major, T's order.
    z_in: Vec<S>,
    k_in: Vec<S>,
    k_in_piv: Vec<usize>,
    /// S⁻¹·P, column-major, 2m each in coordinate order.
    z_out: Vec<S>,
    k_out: Vec<S>,
    k_out_piv: Vec<usize>,
    /// The vector being solved (2m, coordinate order) and scratch.
    x: Vec<S>,
    v: Vec<S>,
    s: Vec<S>,
}

impl<S: Scalar> Shifted<S> {
    fn new() -> Self {
        Shifted {
            c1: S::from(0.0),
            dl: Vec::new(),
            d: Vec::new(),
            du: Vec::new(),
            du2: Vec::new(),
            pivoted: Vec::new(),
            units: Vec::new(),
            z_in: Vec::new(),
            k_in: Vec::new(),
            k_in_piv: Vec::new(),
            z_out: Vec::new(),
            k_out: Vec::new(),
            k_out_piv: Vec::new(),
            x: Vec::new(),
            v: Vec::new(),
            s: Vec::new(),
        }
    }

    /// Form and factor c₀·I − J; false if singular or not finite.
    fn factor<Sys: OdeSystem + ?Sized>(
        &mut self,
        local: &Local,
        probe: &mut Probe,
        system: &Sys,
        stats: &mut Stats,
        c0: S,
        c1: S,
    ) -> bool {
        self.c1 = c1;
        self.factor_t(local, c0) && self.factor_outer(local, probe, system, stats)
    }

    /// T: its tridiagonal part by gttrf, its low-rank part into `z_in`, `k_in`.
    fn factor_t(&mut self, local: &Local, c0: S) -> bool {
        let (m, h, c1) = (local.m, local.head(), self.c1);
        let zero = S::from(0.0);
        let entry = |of_q: f64, of_qd: f64| -(S::from(of_qd) + c1 * S::from(of_q));
        for v in [&mut self.dl, &mut self.du, &mut self.du2] {
            v.clear();
            v.resize(m.saturating_sub(1), zero);
        }
        self.d.clear();
        self.d.resize(m, c0);
        let (a, b) = (&local.dq, &local.dqd);
        for p in 0..local.positions() {
            let pos = h + p;
            self.d[pos] = c0 + entry(a.diag[p], b.diag[p]);
            if local.left(p) == Some(p.wrapping_sub(1)) {
                self.dl[pos - 1] = entry(a.left[p], b.left[p]);
            }
            if local.right(p) == Some(p + 1) {
                self.du[pos] = entry(a.right[p], b.right[p]);
            }
        }
        // The head columns and the rings' closing corners.
        self.units.clear();
        self.z_in.clear();
        for c in 0..h {
            self.units.push(c);
            let start = self.z_in.len();
            self.z_in.resize(start + m, zero);
            for p in 0..local.positions() {
                self.z_in[start + h + p] = entry(a.head[p * h + c], b.head[p * h + c]);
            }
        }
        let mut s = 0;
        for &e in &local.structure.ring_ends {
            if e - s >= 3 {
                for (row, col, value) in [
                    (s, e - 1, entry(a.left[s], b.left[s])),
                    (e - 1, s, entry(a.right[e - 1], b.right[e - 1])),
                ] {
                    self.units.push(h + col);
                    let start = self.z_in.len();
                    self.z_in.resize(start + m, zero);
                    self.z_in[start + h + row] = value;
                }
            }
            s = e;
        }
        if !gttrf(
            &mut self.dl,
            &mut self.d,
            &mut self.du,
            &mut self.du2,
            &mut self.pivoted,
        ) {
            return false;
        }
        let r = self.units.len();
        for col in self.z_in.chunks_exact_mut(m) {
            gttrs(&self.dl, &self.d, &self.du, &self.du2, &self.pivoted, col);
        }
        self.k_in.clear();
        self.k_in.resize(r * r, zero);
        for (j, col) in self.z_in.chunks_exact(m).enumerate() {
            for (i, &unit) in self.units.iter().enumerate() {
                self.k_in[i * r + j] = col[unit];
            }
            self.k_in[j * r + j] = self.k_in[j * r + j] + S::from(1.0);
        }
        small_lu(&mut self.k_in, &mut self.k_in_piv, r)
    }

    /// S⁻¹·P into `z_out` and K = I − Qᵀ·S⁻¹·P factored: `head` directional
    /// differences per real part.
    fn factor_outer<Sys: OdeSystem + ?Sized>(
        &mut self,
        local: &Local,
        probe: &mut Probe,
        system: &Sys,
        stats: &mut Stats,
    ) -> bool {
        let (m, h) = (local.m, local.head());
        let zero = S::from(0.0);
        self.z_out.clear();
        self.z_out.resize(h * 2 * m, zero);
        let mut x = std::mem::take(&mut self.x);
        for r in 0..h {
            x.clear();
            x.resize(2 * m, zero);
            x[m + r] = S::from(1.0);
            for p in 0..local.positions() {
                x[m + local.structure.order[p]] = S::from(local.coupling(p)[r]);
            }
            self.solve_s(local, &mut x);
            self.z_out[r * 2 * m..(r + 1) * 2 * m].copy_from_slice(&x);
        }
        self.x = x;
        self.k_out.clear();
        self.k_out.resize(h * h, zero);
        for r in 0..h {
            head_derivative(
                local,
                probe,
                system,
                stats,
                &self.z_out[r * 2 * m..(r + 1) * 2 * m],
            );
            for i in 0..h {
                self.k_out[i * h + r] = -read_head::<S>(probe, i);
            }
            self.k_out[r * h + r] = self.k_out[r * h + r] + S::from(1.0);
        }
        small_lu(&mut self.k_out, &mut self.k_out_piv, h)
    }

    /// x ← S⁻¹·x (2m, coordinate order): the reduction to T, then T's solve.
    fn solve_s(&mut self, local: &Local, x: &mut [S]) {
        let (m, h, c1) = (local.m, local.head(), self.c1);
        let (f, g) = x.split_at_mut(m);
        for v in f.iter_mut() {
            *v = *v * c1;
        }
        // g += L_q·f (f already divided by c₀): local rows only.
        let a = &local.dq;
        for p in 0..local.positions() {
            let i = local.structure.order[p];
            let mut sum = S::from(a.diag[p]) * f[i];
            if let Some(l) = local.left(p) {
                sum = sum + S::from(a.left[p]) * f[local.structure.order[l]];
            }
            if let Some(r) = local.right(p) {
                sum = sum + S::from(a.right[p]) * f[local.structure.order[r]];
            }
            for c in 0..h {
                sum = sum + S::from(a.head[p * h + c]) * f[c];
            }
            g[i] = g[i] + sum;
        }
        let mut v = std::mem::take(&mut self.v);
        v.clear();
        v.extend((0..m).map(|pos| g[local.coordinate(pos)]));
        self.solve_t(&mut v);
        for (pos, &w) in v.iter().enumerate() {
            let i = local.coordinate(pos);
            g[i] = w;
            f[i] = f[i] + c1 * w;
        }
        self.v = v;
    }

    /// v ← T⁻¹·v (T's order).
    fn solve_t(&mut self, v: &mut [S]) {
        let m = v.len();
        let r = self.units.len();
        gttrs(&self.dl, &self.d, &self.du, &self.du2, &self.pivoted, v);
        let mut s = std::mem::take(&mut self.s);
        s.clear();
        s.extend(self.units.iter().map(|&u| v[u]));
        solve_in_place(&self.k_in, &self.k_in_piv, r, &mut s);
        for (col, &t) in self.z_in.chunks_exact(m).zip(&s) {
            for (x, z) in v.iter_mut().zip(col) {
                *x = *x - *z * t;
            }
        }
        self.s = s;
    }

    /// `self.x` ← E⁻¹·`self.x` (2m, coordinate order).
    fn solve<Sys: OdeSystem + ?Sized>(
        &mut self,
        local: &Local,
        probe: &mut Probe,
        system: &Sys,
        stats: &mut Stats,
    ) {
        let (m, h) = (local.m, local.head());
        let mut x = std::mem::take(&mut self.x);
        self.solve_s(local, &mut x);
        head_derivative(local, probe, system, stats, &x);
        let mut t = [S::from(0.0); MAX_HEAD];
        for (i, t) in t.iter_mut().enumerate().take(h) {
            *t = read_head(probe, i);
        }
        solve_in_place(&self.k_out, &self.k_out_piv, h, &mut t[..h]);
        for (col, &t) in self.z_out.chunks_exact(2 * m).zip(&t[..h]) {
            for (v, z) in x.iter_mut().zip(col) {
                *v = *v + *z * t;
            }
        }
        self.x = x;
    }
}

/// ∂z/∂y·x into the probe's parts (one real part per [`Scalar::PARTS`]).
fn head_derivative<S: Scalar, Sys: OdeSystem + ?Sized>(
    local: &Local,
    probe: &mut Probe,
    system: &Sys,
    stats: &mut Stats,
    x: &[S],
) {
    let (m, h) = (local.m, local.head());
    if local.explicit {
        for k in 0..S::PARTS {
            let part = &mut probe.parts[k];
            part.clear();
            part.extend(local.head_rows.chunks_exact(2 * m).map(|row| {
                row.iter()
                    .zip(x)
                    .map(|(q, &v)| q * S::part(v, k))
                    .sum::<f64>()
            }));
        }
        return;
    }
    for k in 0..S::PARTS {
        for (d, &v) in probe.dir.iter_mut().zip(x) {
            *d = S::part(v, k);
        }
        probe.derivative(system, stats, m, h, k);
    }
}

/// Component i of the last [`head_derivative`].
fn read_head<S: Scalar>(probe: &Probe, i: usize) -> S {
    let im = if S::PARTS > 1 { probe.parts[1][i] } else { 0.0 };
    S::assemble(probe.parts[0][i], im)
}

/// Tridiagonal LU with partial pivoting (LAPACK's gttrf): `dl`, `d`, `du`
/// are the sub-, main and super-diagonal; `du2` receives the second
/// super-diagonal of U. False if singular or not finite.
fn gttrf<S: Scalar>(
    dl: &mut [S],
    d: &mut [S],
    du: &mut [S],
    du2: &mut [S],
    pivoted: &mut Vec<bool>,
) -> bool {
    let n = d.len();
    pivoted.clear();
    pivoted.resize(n.saturating_sub(1), false);
    for i in 0..n.saturating_sub(1) {
        if d[i].mag() >= dl[i].mag() {
            if d[i].mag() != 0.0 {
                let f = dl[i] / d[i];
                dl[i] = f;
                d[i + 1] = d[i + 1] - f * du[i];
            }
        } else {
            pivoted[i] = true;
            let f = d[i] / dl[i];
            d[i] = dl[i];
            dl[i] = f;
            let temp = du[i];
            du[i] = d[i + 1];
            d[i + 1] = temp - f * d[i + 1];
            if i + 2 < n {
                du2[i] = du[i + 1];
                du[i + 1] = -(f * du[i + 1]);
            }
        }
    }
    d.iter().all(|v| v.mag() != 0.0 && v.finite())
        && dl
            .iter()
            .chain(du.iter())
            .chain(du2.iter())
            .all(|v| v.finite())
}

/// Solve with gttrf's factors in place (LAPACK's gttrs, no transpose).
fn gttrs<S: Scalar>(dl: &[S], d: &[S], du: &[S], du2: &[S], pivoted: &[bool], b: &mut [S]) {
    let n = d.len();
    for i in 0..n.saturating_sub(1) {
        if pivoted[i] {
            let temp = b[i] - dl[i] * b[i + 1];
            b[i] = b[i + 1];
            b[i + 1] = temp;
        } else {
            b[i + 1] = b[i + 1] - dl[i] * b[i];
        }
    }
    if n == 0 {
        return;
    }
    b[n - 1] = b[n - 1] / d[n - 1];
    if n > 1 {
        b[n - 2] = (b[n - 2] - du[n - 2] * b[n - 1]) / d[n - 2];
    }
    for i in (0..n.saturating_sub(2)).rev() {
        b[i] = (b[i] - du[i] * b[i + 1] - du2[i] * b[i + 2]) / d[i];
    }
}

/// Factor the r×r `a` in place ([`factor_in_place`]), every entry finite.
fn small_lu<S: Scalar>(a: &mut [S], piv: &mut Vec<usize>, r: usize) -> bool {
    piv.clear();
    piv.resize(r, 0);
    factor_in_place(a, piv, r) && a.iter().all(|v| v.finite())
}

/// The structured reduced Newton matrices of one Jacobian and step size.
pub(crate) struct StructuredNewton {
    local: Local,
    probe: Probe,
    real: Shifted<f64>,
    complex: Shifted<Complex64>,
}

impl StructuredNewton {
    /// Buffers for a system of m coordinates (state dimension 2m).
    pub(crate) fn new(m: usize) -> Self {
        StructuredNewton {
            local: Local {
                m,
                ..Local::default()
            },
            probe: Probe::default(),
            real: Shifted::new(),
            complex: Shifted::new(),
        }
    }

    /// Whether `system` offers a structure at (t, y) with enough ring
    /// coordinates for these matrices to pay.
    pub(crate) fn pays<S: OdeSystem + ?Sized>(system: &S, t: f64, y: &[f64]) -> bool {
        // Ring coordinates are fewer than the state's half: most systems
        // need not be asked.
        if y.len() / 2 < MIN_RING_COORDINATES {
            return false;
        }
        let mut structure = CouplingStructure::default();
        system.coupling_structure(t, y, &mut structure)
            && structure.order.len() >= MIN_RING_COORDINATES
    }

    /// The local Jacobian at (t, y), f(t, y) = `f0`, by forward differences
    /// over colour groups; false if the system gives no usable structure.
    pub(crate) fn evaluate<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        t: f64,
        y: &[f64],
        f0: &[f64],
        stats: &mut Stats,
    ) -> bool {
        let local = &mut self.local;
        let m = local.m;
        if y.len() != 2 * m
            || !system.coupling_structure(t, y, &mut local.structure)
            || !local.colour_rings()
        {
            return false;
        }
        let (h, n) = (local.head(), local.positions());
        let probe = &mut self.probe;
        probe.at(t, y, f0);
        local.dq.reset(n, h);
        local.dqd.reset(n, h);
        local.head_rows.clear();
        local.head_rows.resize(h * 2 * m, 0.0);
        // Δz of one evaluation (head ≤ a few coordinates).
        let mut dz = [0.0; MAX_HEAD];
        let dz = &mut dz[..h];
        for half in 0..2 {
            let off = half * m;
            // Head columns, one at a time.
            for c in 0..h {
                probe.y.copy_from_slice(y);
                let delta = probe.delta[off + c];
                probe.y[off + c] += delta;
                probe.eval(system, stats);
                probe.head_change(m, dz);
                for (r, d) in dz.iter().enumerate() {
                    local.head_rows[r * 2 * m + off + c] = d / delta;
                }
                for p in 0..n {
                    let v = local_change(local, probe, dz, p) / delta;
                    let target = if half == 0 {
                        &mut local.dq
                    } else {
                        &mut local.dqd
                    };
                    target.head[p * h + c] = v;
                }
            }
            // Ring columns, a colour group at a time.
            for g in 0..local.colours {
                probe.y.copy_from_slice(y);
                for p in (0..n).filter(|&p| local.colour[p] == g) {
                    let c = off + local.structure.order[p];
                    probe.y[c] += probe.delta[c];
                }
                probe.eval(system, stats);
                probe.head_change(m, dz);
                for p in 0..n {
                    let column = |q: usize| off + local.structure.order[q];
                    let (slot, q) = if local.colour[p] == g {
                        (0, p)
                    } else if let Some(l) = local.left(p).filter(|&l| local.colour[l] == g) {
                        (1, l)
                    } else if let Some(r) = local.right(p).filter(|&r| local.colour[r] == g) {
                        (2, r)
                    } else {
                        continue;
                    };
                    let v = local_change(local, probe, dz, p) / probe.delta[column(q)];
                    let target = if half == 0 {
                        &mut local.dq
                    } else {
                        &mut local.dqd
                    };
                    match slot {
                        0 => target.diag[p] = v,
                        1 => target.left[p] = v,
                        _ => target.right[p] = v,
                    }
                }
            }
        }
        local.explicit =
            system.head_equation(t, y, f0, &mut local.head_eq) && local.form_head_rows();
        true
    }

    /// Factor γ·I − ∂a/∂q̇ − ∂a/∂q/γ and (α + iβ)·I − ∂a/∂q̇ − ∂a/∂q/(α + iβ);
    /// false if either is singular or not finite.
    pub(crate) fn factor<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        gamma: f64,
        alpha: f64,
        beta: f64,
        stats: &mut Stats,
    ) -> bool {
        let shift = Complex64::new(alpha, beta);
        gamma.is_finite()
            && shift.is_finite()
            && self.real.factor(
                &self.local,
                &mut self.probe,
                system,
                stats,
                gamma,
                1.0 / gamma,
            )
            && self.complex.factor(
                &self.local,
                &mut self.probe,
                system,
                stats,
                shift,
                shift.inv(),
            )
    }

    /// Overwrite b (2m) with the solution of (γ·I − J)·x = b.
    pub(crate) fn solve_real<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        b: &mut [f64],
        stats: &mut Stats,
    ) {
        let shifted = &mut self.real;
        shifted.x.clear();
        shifted.x.extend_from_slice(b);
        shifted.solve(&self.local, &mut self.probe, system, stats);
        b.copy_from_slice(&shifted.x);
    }

    /// Overwrite (br, bi) (2m each) with the solution of
    /// ((α + iβ)·I − J)·x = br + i·bi.
    pub(crate) fn solve_complex<S: OdeSystem + ?Sized>(
        &mut self,
        system: &S,
        br: &mut [f64],
        bi: &mut [f64],
        stats: &mut Stats,
    ) {
        let shifted = &mut self.complex;
        shifted.x.clear();
        shifted.x.extend(
            br.iter()
                .zip(bi.iter())
                .map(|(&r, &i)| Complex64::new(r, i)),
        );
        shifted.solve(&self.local, &mut self.probe, system, stats);
        for ((r, i), v) in br.iter_mut().zip(bi.iter_mut()).zip(&shifted.x) {
            *r = v.re;
            *i = v.im;
        }
    }
}

/// Change of ring position p's acceleration in the probe's last evaluation
/// with the head's share U_p·Δz taken out.
fn local_change(local: &Local, probe: &Probe, dz: &[f64], p: usize) -> f64 {
    let m = local.m;
    let i = local.structure.order[p];
    let through_head: f64 = local
        .coupling(p)
        .iter()
        .zip(dz.iter())
        .map(|(u, d)| u * d)
        .sum();
    probe.f[m + i] - probe.f0[m + i] - through_head
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::test_stream::uniform;

    /// A rotor-like head (x, y) and n weights on rings: each weight feels
    /// its ring neighbours through a nonlinear spring, the head coordinates
    /// directly, and every other weight only through the head accelerations
    /// z, which solve a 2×2 system summed over all weights.
    struct Rings {
        /// Weight indices, ring after ring, and where each ring ends.
        order: Vec<usize>,
        ends: Vec<usize>,
        /// Whether it gives its head equation.
        head_equation: bool,
    }

    impl Rings {
        fn n(&self) -> usize {
            self.order.len()
        }
        /// (predecessor, successor) of weight j in its ring, if any.
        fn neighbours(&self, j: usize) -> (Option<usize>, Option<usize>) {
            let p = self.order.iter().position(|&w| w == j).unwrap();
            let s = self.ends.iter().rev().find(|&&e| e <= p).copied();
            let s = s.unwrap_or(0);
            let e = *self.ends.iter().find(|&&e| e > p).unwrap();
            let len = e - s;
            let at = |q: usize| self.order[s + q];
            match len {
                1 => (None, None),
                2 => (None, Some(at(1 - (p - s)))),
                _ => (
                    Some(at((p - s + len - 1) % len)),
                    Some(at((p - s + 1) % len)),
                ),
            }
        }
        fn coupling(&self, psi: f64) -> [f64; 2] {
            [0.3 * psi.sin(), -0.3 * psi.cos()]
        }
        fn coupling_slope(&self, psi: f64) -> [f64; 2] {
            [0.3 * psi.cos(), 0.3 * psi.sin()]
        }
    }

    impl OdeSystem for Rings {
        fn dim(&self) -> usize {
            2 * (2 + self.n())
        }
        fn second_order_split(&self) -> Option<usize> {
            Some(2 + self.n())
        }
        fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
            let (n, m) = (self.n(), 2 + self.n());
            let (q, qd) = y.split_at(m);
            dydt[..m].copy_from_slice(qd);
            let spring = |a: f64, b: f64| 40.0 * (b - a) + 5.0 * (b - a).powi(3);
            let mut local = vec![0.0; n];
            for j in 0..n {
                let (psi, rate) = (q[2 + j], qd[2 + j]);
                let (prev, next) = self.neighbours(j);
                let mut l = -0.7 * rate + 3.0 * q[0] * psi.cos() - 2.0 * qd[1] * psi.sin();
                for k in [prev, next].into_iter().flatten() {
                    l += spring(psi, q[2 + k]) + 0.5 * (qd[2 + k] - rate);
                }
                local[j] = l;
            }
            // (M + Σ c_j c_jᵀ) z = g, with c_j = U_j's row scaled.
            let mut a = [[5.0, 0.2], [0.2, 4.0]];
            let mut g = [-300.0 * q[0] - 2.0 * qd[0], -250.0 * q[1] - 3.0 * qd[1]];
            for j in 0..n {
                let (psi, rate) = (q[2 + j], qd[2 + j]);
                let c = self.coupling(psi);
                for r in 0..2 {
                    for s in 0..2 {
                        a[r][s] += c[r] * c[s];
                    }
                    g[r] += c[r] * local[j] + 0.1 * rate * rate * c[1 - r];
                }
            }
            let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
            let z = [
                (g[0] * a[1][1] - g[1] * a[0][1]) / det,
                (g[1] * a[0][0] - g[0] * a[1][0]) / det,
            ];
            dydt[m] = z[0];
            dydt[m + 1] = z[1];
            for j in 0..n {
                let c = self.coupling(q[2 + j]);
                dydt[m + 2 + j] = local[j] + c[0] * z[0] + c[1] * z[1];
            }
        }
        fn coupling_structure(&self, _t: f64, y: &[f64], out: &mut CouplingStructure) -> bool {
            out.head = 2;
            out.coupling.clear();
            for j in 0..self.n() {
                out.coupling.extend(self.coupling(y[2 + j]));
            }
            out.order = self.order.iter().map(|j| 2 + j).collect();
            out.ring_ends = self.ends.clone();
            true
        }
        /// With local_j = a_j − c_j·z the head rows read
        /// (M + 2Σ c cᵀ)·z − Σ c_j·a_j = g₀ + Σ 0.1 ψ̇_j² (c_j1, c_j0).
        fn head_equation(&self, _t: f64, y: &[f64], f: &[f64], out: &mut HeadEquation) -> bool {
            if !self.head_equation {
                return false;
            }
            let m = 2 + self.n();
            let z = [f[m], f[m + 1]];
            let mut mass = [5.0, 0.2, 0.2, 4.0];
            out.reaction.clear();
            out.own.clear();
            for j in 0..self.n() {
                let (psi, rate, accel) = (y[2 + j], y[m + 2 + j], f[m + 2 + j]);
                let (c, dc) = (self.coupling(psi), self.coupling_slope(psi));
                for r in 0..2 {
                    for s in 0..2 {
                        mass[r * 2 + s] += 2.0 * c[r] * c[s];
                    }
                }
                out.reaction.extend([-c[0], -c[1]]);
                let (cz, dcz) = (c[0] * z[0] + c[1] * z[1], dc[0] * z[0] + dc[1] * z[1]);
                for r in 0..2 {
                    let swapped = 0.1 * rate * rate * dc[1 - r];
                    out.own
                        .push(swapped - 2.0 * (dc[r] * cz + c[r] * dcz) + dc[r] * accel);
                }
                out.own.extend([0.2 * rate * c[1], 0.2 * rate * c[0]]);
            }
            out.mass.clear();
            out.mass.extend(mass);
            true
        }
    }

    fn state(n: usize) -> Vec<f64> {
        let mut seed = 7u64;
        (0..2 * (2 + n)).map(|_| uniform(&mut seed) - 0.5).collect()
    }

    /// ∂f/∂y by central differences (truncation O(δ²), far below the
    /// forward differences' O(√ε) that both Newton matrices use).
    fn reference_jacobian(system: &Rings, y: &[f64]) -> Vec<f64> {
        let dim = y.len();
        let mut jac = vec![0.0; dim * dim];
        let (mut yp, mut fp, mut fm) = (y.to_vec(), vec![0.0; dim], vec![0.0; dim]);
        for j in 0..dim {
            let d = 1e-5 * (1.0 + y[j].abs());
            yp[j] = y[j] + d;
            system.rhs(0.0, &yp, &mut fp);
            yp[j] = y[j] - d;
            system.rhs(0.0, &yp, &mut fm);
            yp[j] = y[j];
            for i in 0..dim {
                jac[i * dim + j] = (fp[i] - fm[i]) / (2.0 * d);
            }
        }
        jac
    }

    /// Largest |(c·I − J)·x − b| over the rows, relative to the largest of
    /// |c·x|, |J·x| and |b| in any row, for x = xr + i·xi and c = cr + i·ci.
    fn relative_residual(
        jac: &[f64],
        c: (f64, f64),
        x: (&[f64], &[f64]),
        b: (&[f64], &[f64]),
    ) -> f64 {
        let dim = x.0.len();
        let (mut worst, mut scale) = (0.0f64, 0.0f64);
        for i in 0..dim {
            let jr: f64 = (0..dim).map(|k| jac[i * dim + k] * x.0[k]).sum();
            let ji: f64 = (0..dim).map(|k| jac[i * dim + k] * x.1[k]).sum();
            let (cr, ci) = (c.0 * x.0[i] - c.1 * x.1[i], c.0 * x.1[i] + c.1 * x.0[i]);
            worst = worst
                .max((cr - jr - b.0[i]).abs())
                .max((ci - ji - b.1[i]).abs());
            scale = scale
                .max(cr.hypot(ci))
                .max(jr.hypot(ji))
                .max(b.0[i].hypot(b.1[i]));
        }
        worst / scale
    }

    /// The structured matrices at (γ, α, β) solve the real and the complex
    /// Newton systems of the exact Jacobian to `tol`; returns the RHS calls
    /// of the Jacobian, then of the factorisations and solves.
    fn solves(system: &Rings, shifts: (f64, f64, f64), tol: f64) -> (u64, u64) {
        let y = state(system.n());
        let dim = y.len();
        let mut f0 = vec![0.0; dim];
        system.rhs(0.0, &y, &mut f0);
        let jac = reference_jacobian(system, &y);
        let mut structured = StructuredNewton::new(dim / 2);
        let mut stats = Stats::default();
        assert!(structured.evaluate(system, 0.0, &y, &f0, &mut stats));
        let jacobian_calls = stats.rhs_calls;
        let (g, a, b) = shifts;
        assert!(structured.factor(system, g, a, b, &mut stats));
        let mut seed = 3u64;
        let br: Vec<f64> = (0..dim).map(|_| uniform(&mut seed) - 0.5).collect();
        let bi: Vec<f64> = (0..dim).map(|_| uniform(&mut seed) - 0.5).collect();
        let zeros = vec![0.0; dim];
        let mut x = br.clone();
        structured.solve_real(system, &mut x, &mut stats);
        let real = relative_residual(&jac, (g, 0.0), (&x, &zeros), (&br, &zeros));
        let (mut xr, mut xi) = (br.clone(), bi.clone());
        structured.solve_complex(system, &mut xr, &mut xi, &mut stats);
        let complex = relative_residual(&jac, (a, b), (&xr, &xi), (&br, &bi));
        assert!(
            real < tol && complex < tol,
            "shifts {shifts:?}: residuals {real:e}, {complex:e} (tolerance {tol:e})"
        );
        (jacobian_calls, stats.rhs_calls - jacobian_calls)
    }

    /// Shifts (γ, α, β)/h of a step with h·‖J‖ about 0.05 and about 50 (the
    /// second is where Radau5 works on a stiff problem), and the residual
    /// each must reach: ten times what the structured matrices gave when
    /// written (7e-8, 3e-5). Forward differences limit both: the dense
    /// matrices of Radau5 reach 2e-7 and 1e-5 on the same systems; the
    /// tridiagonal LU or Woodbury's identity going wrong gave 2e-3 and more.
    const SHIFTS: [((f64, f64, f64), f64); 2] =
        [((360.0, 270.0, -190.0), 1e-6), ((0.36, 0.27, -0.19), 3e-4)];

    /// Both ways of applying ∂z/∂(q, q̇) solve the Newton systems of
    /// `order` and `ends`; with the head equation the factorisations and
    /// solves call the right-hand side no more (3·2 + 1 + 2 calls without).
    fn solves_either_way(order: Vec<usize>, ends: Vec<usize>) {
        for head_equation in [false, true] {
            let system = Rings {
                order: order.clone(),
                ends: ends.clone(),
                head_equation,
            };
            for (shifts, tol) in SHIFTS {
                let (_, later) = solves(&system, shifts, tol);
                assert_eq!(later, if head_equation { 0 } else { 9 });
            }
        }
    }

    #[test]
    fn one_ring_in_shuffled_order_solves_the_newton_systems() {
        solves_either_way(vec![3, 0, 7, 5, 1, 9, 2, 8, 4, 6, 10], vec![11]);
    }

    #[test]
    fn two_rings_a_pair_and_single_weights_solve_the_newton_systems() {
        solves_either_way(
            vec![0, 2, 4, 6, 1, 3, 5, 7, 8, 9, 10, 11],
            vec![4, 8, 10, 11, 12],
        );
    }

    #[test]
    fn a_jacobian_costs_the_same_rhs_calls_for_ten_or_two_hundred_weights() {
        let ring = |n: usize| Rings {
            order: (0..n).collect(),
            ends: vec![n],
            head_equation: false,
        };
        // 2·(head + colours): 2·(2 + 4) for rings of 10 and 200, whose
        // lengths are not multiples of 3, and 2·(2 + 3) for one of 201.
        let (shifts, tol) = SHIFTS[0];
        assert_eq!(solves(&ring(10), shifts, tol).0, 12);
        assert_eq!(solves(&ring(200), shifts, tol).0, 12);
        assert_eq!(solves(&ring(201), shifts, tol).0, 10);
    }

    #[test]
    fn ring_colours_differ_within_two_places_and_are_as_few_as_can_be() {
        for len in 1..=60 {
            let colours: Vec<usize> = (0..len).map(|i| ring_colour(i, len)).collect();
            for i in 0..len {
                for d in 1..=2.min(len - 1) {
                    let j = (i + d) % len;
                    assert!(j == i || colours[i] != colours[j], "len {len}: {colours:?}");
                }
            }
            let used = colours.iter().max().map_or(0, |c| c + 1);
            let fewest = match len {
                1..=3 => len,
                5 => 5,
                _ if len % 3 == 0 => 3,
                _ => 4,
            };
            assert_eq!(used, fewest, "len {len}: {colours:?}");
        }
    }

    #[test]
    fn tridiagonal_and_small_solves_solve() {
        let mut seed = 11u64;
        let mut u = || uniform(&mut seed) - 0.5;
        for n in [1usize, 2, 3, 7] {
            // A small diagonal, so that rows are interchanged.
            let dl: Vec<f64> = (1..n).map(|_| u()).collect();
            let d: Vec<f64> = (0..n).map(|_| 0.1 * u()).collect();
            let du: Vec<f64> = (1..n).map(|_| u()).collect();
            let b: Vec<f64> = (0..n).map(|_| u()).collect();
            let (mut fl, mut fd, mut fu) = (dl.clone(), d.clone(), du.clone());
            let (mut f2, mut piv) = (vec![0.0; n.saturating_sub(1)], Vec::new());
            assert!(gttrf(&mut fl, &mut fd, &mut fu, &mut f2, &mut piv));
            let mut x = b.clone();
            gttrs(&fl, &fd, &fu, &f2, &piv, &mut x);
            for i in 0..n {
                let mut r = d[i] * x[i] - b[i];
                if i > 0 {
                    r += dl[i - 1] * x[i - 1];
                }
                if i + 1 < n {
                    r += du[i] * x[i + 1];
                }
                assert!(r.abs() < 1e-12, "tridiagonal n = {n}, row {i}: {r}");
            }
            let a: Vec<f64> = (0..n * n).map(|_| u()).collect();
            let (mut lu, mut p) = (a.clone(), Vec::new());
            assert!(small_lu(&mut lu, &mut p, n));
            let mut x = b.clone();
            solve_in_place(&lu, &p, n, &mut x);
            for i in 0..n {
                let r: f64 = (0..n).map(|k| a[i * n + k] * x[k]).sum::<f64>() - b[i];
                assert!(r.abs() < 1e-12, "dense n = {n}, row {i}: {r}");
            }
        }
    }

    /// A system whose declared structure is malformed in the given way.
    struct Malformed(fn(&mut CouplingStructure));

    impl OdeSystem for Malformed {
        fn dim(&self) -> usize {
            8
        }
        fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
            dydt.copy_from_slice(y);
        }
        fn coupling_structure(&self, _t: f64, _y: &[f64], out: &mut CouplingStructure) -> bool {
            *out = CouplingStructure {
                head: 1,
                coupling: vec![0.0; 3],
                order: vec![1, 2, 3],
                ring_ends: vec![3],
            };
            (self.0)(out);
            true
        }
    }

    #[test]
    fn a_malformed_structure_is_refused_not_used() {
        let cases: [fn(&mut CouplingStructure); 6] = [
            |s| s.order = vec![1, 2, 2],
            |s| s.order = vec![1, 2, 4],
            |s| s.order = vec![0, 1, 2],
            |s| s.ring_ends = vec![2],
            |s| s.ring_ends = vec![2, 2, 3],
            |s| {
                s.coupling.pop();
            },
        ];
        let y = [0.5; 8];
        for (k, case) in cases.into_iter().enumerate() {
            let mut matrices = StructuredNewton::new(4);
            let ok = matrices.evaluate(&Malformed(case), 0.0, &y, &y, &mut Stats::default());
            assert!(!ok, "case {k}");
        }
        let mut matrices = StructuredNewton::new(4);
        assert!(matrices.evaluate(&Malformed(|_| ()), 0.0, &y, &y, &mut Stats::default()));
    }

    #[test]
    fn a_singular_tridiagonal_is_refused() {
        let (mut dl, mut d, mut du, mut du2) = (vec![1.0], vec![1.0, 1.0], vec![1.0], vec![]);
        assert!(!gttrf(&mut dl, &mut d, &mut du, &mut du2, &mut Vec::new()));
    }
}
