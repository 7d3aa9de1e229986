//! The assembled equations of motion of a rotor with auto-balancers in the
//! inertial frame (seed 004, eqs 3, 15–20), as an [`OdeSystem`].
//!
//! State layout: q = [rotor coordinates (k), φ (only when the speed is free),
//! ψ_1..ψ_n], then q̇ in the same order. Cargo angles are integrated relative
//! to the rotor, ψ_j = φ_j − φ: inertial angles grow to thousands of radians
//! and would ruin relative error control.
//!
//! The mass matrix is an arrowhead: every cargo row couples only to the small
//! head block (rotor coordinates and φ). Each right-hand side eliminates the
//! cargo rows (a Schur complement onto the head block), solves the head block
//! of size ≤ 5 by Gaussian elimination and back-substitutes: O(n) work and no
//! heap allocation per call.

use super::cargo::Cargo;
use super::effect::{Effect, EffectContext, Forces};
use super::rigid_contact::{Clustered, RigidContact};
use super::rotor::{DofVec, MAX_DOF, Rotor};
use super::speed::SpeedLaw;
use super::tilt_inertia::TiltTerms;
use crate::integrate::{CouplingStructure, Events, HeadEquation, OdeSystem};

/// Largest head block: rotor coordinates plus the spin angle.
const MAX_HEAD: usize = MAX_DOF + 1;

/// Where each coordinate lives in the state vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    /// Number of rotor coordinates k.
    pub rotor_dof: usize,
    /// True when φ is a state variable (variable speed).
    pub spin_free: bool,
    /// Number of cargoes n.
    pub cargoes: usize,
}

impl Layout {
    /// Number of generalised coordinates.
    pub fn nq(&self) -> usize {
        self.head() + self.cargoes
    }
    /// Size of the head block (rotor coordinates plus φ when free).
    pub fn head(&self) -> usize {
        self.rotor_dof + usize::from(self.spin_free)
    }
    /// State dimension 2·nq.
    pub fn dim(&self) -> usize {
        2 * self.nq()
    }
    /// Index of φ in q (meaningful only when the spin is free).
    pub fn phi(&self) -> usize {
        self.rotor_dof
    }
    /// Index of ψ_j in q.
    pub fn psi(&self, j: usize) -> usize {
        self.head() + j
    }
}

/// Rotor, cargoes, speed law and enabled effects, ready to integrate.
#[derive(Debug)]
pub struct RotorSystem {
    rotor: Box<dyn Rotor>,
    cargo: Vec<Cargo>,
    /// κ m l² per cargo (cached: used twice per cargo per call).
    inertia: Vec<f64>,
    plane_maps: Vec<[DofVec; 2]>,
    /// Where vibration counts ([`Rotor::watch_maps`]), once per system.
    watch_maps: Vec<[DofVec; 2]>,
    /// Tilt maps of the planes whose weights' tilt inertia is modelled.
    tilt_maps: Vec<Option<[DofVec; 2]>>,
    speed: SpeedLaw,
    effects: Vec<Box<dyn Effect>>,
    layout: Layout,
    /// Rotor mass matrix plus Σ m Gᵀ G of the cargoes (constant).
    head_mass: [DofVec; MAX_DOF],
    /// J_P plus the rolling inertia of balls and rollers.
    spin_inertia: f64,
    /// The rotor's static unbalance, cached for the effects (constant).
    rotor_unbalance: (f64, f64),
    /// (sin, cos) of each cargo's absolute angle φ + ψ_j, evaluated once per
    /// call for the elimination and reused by the back-substitution. A field,
    /// not a local, so that a call allocates nothing.
    trig: std::cell::RefCell<Vec<(f64, f64)>>,
    /// Rigid contact between the weights, when the scene asks for it.
    rigid: Option<RigidContact>,
    /// Each weight's (w, Q) in a clustered right-hand side, and each
    /// cluster's summed row (fields, not locals: a call allocates nothing).
    rows: std::cell::RefCell<Vec<(DofVec, f64)>>,
    cluster_sums: std::cell::RefCell<Vec<ClusterRow>>,
}

impl RotorSystem {
    /// Assemble the system; `effects` are the already-built enabled effects.
    pub fn new(
        rotor: Box<dyn Rotor>,
        cargo: Vec<Cargo>,
        speed: SpeedLaw,
        effects: Vec<Box<dyn Effect>>,
    ) -> Self {
        let k = rotor.dof();
        let plane_maps: Vec<_> = (0..rotor.planes()).map(|p| rotor.plane_map(p)).collect();
        let tilt_maps: Vec<_> = (0..rotor.planes()).map(|p| rotor.tilt_map(p)).collect();
        let mut head_mass = rotor.mass_matrix();
        for c in &cargo {
            let [gu, gv] = plane_maps[c.plane];
            for a in 0..k {
                for b in 0..k {
                    head_mass[a][b] += c.mass * (gu[a] * gu[b] + gv[a] * gv[b]);
                }
            }
        }
        let spin_inertia =
            rotor.spin_inertia() + cargo.iter().map(|c| c.rolling_inertia).sum::<f64>();
        let layout = Layout {
            rotor_dof: k,
            spin_free: !speed.is_prescribed(),
            cargoes: cargo.len(),
        };
        let rotor_watch = rotor.watch_maps();
        RotorSystem {
            inertia: cargo.iter().map(Cargo::inertia).collect(),
            trig: std::cell::RefCell::new(vec![(0.0, 0.0); cargo.len()]),
            rigid: None,
            rows: std::cell::RefCell::new(vec![([0.0; MAX_DOF], 0.0); cargo.len()]),
            cluster_sums: std::cell::RefCell::new(Vec::with_capacity(cargo.len())),
            rotor_unbalance: rotor.static_unbalance(),
            rotor,
            cargo,
            plane_maps,
            watch_maps: rotor_watch,
            tilt_maps,
            speed,
            effects,
            layout,
            head_mass,
            spin_inertia,
        }
    }

    /// The same system with `rigid` contact between its weights, held as
    /// constraints instead of a force (the effects must then leave contact out).
    pub fn with_rigid_contact(mut self, rigid: Option<RigidContact>) -> Self {
        self.rigid = rigid;
        self
    }

    /// How contact between the weights is modelled: "rigid" (held here as
    /// constraints), "penalty" (a force among the effects) or none.
    pub fn contact_model(&self) -> Option<&'static str> {
        let penalty = self.effects.iter().any(|e| e.name() == "contact");
        RigidContact::model_name(self.rigid.is_some(), penalty)
    }

    /// The same system with one more effect, applied after the built ones:
    /// how code outside the scene format (a test, an experiment) adds physics.
    pub fn with_effect(mut self, effect: Box<dyn Effect>) -> Self {
        self.effects.push(effect);
        self
    }

    /// Where each coordinate lives in the state.
    pub fn layout(&self) -> Layout {
        self.layout
    }

    /// The rotor model.
    pub fn rotor(&self) -> &dyn Rotor {
        self.rotor.as_ref()
    }

    /// The cargoes.
    pub fn cargo(&self) -> &[Cargo] {
        &self.cargo
    }

    /// Mass matrix of the rotor coordinates with the cargoes' masses (constant).
    pub fn head_mass(&self) -> &[DofVec; MAX_DOF] {
        &self.head_mass
    }

    /// Maps (G_u, G_v) of the places whose vibration counts in r and A_ref.
    pub fn watch_maps(&self) -> &[[DofVec; 2]] {
        &self.watch_maps
    }

    /// Map (G_u, G_v) of the plane cargo j runs in.
    pub fn cargo_plane_map(&self, j: usize) -> [DofVec; 2] {
        self.plane_maps[self.cargo[j].plane]
    }

    /// The speed law.
    pub fn speed(&self) -> &SpeedLaw {
        &self.speed
    }

    /// The rotating force per φ̇² (cos φ and sin φ parts, generalised on the
    /// rotor coordinates) the enabled effects add with the weights locked
    /// (the race's mass carried off the axis), added into both.
    pub fn effects_locked_forcing(&self, cos_part: &mut DofVec, sin_part: &mut DofVec) {
        for e in &self.effects {
            e.locked_forcing(cos_part, sin_part);
        }
    }

    /// Names of the enabled effects.
    pub fn effect_names(&self) -> Vec<&'static str> {
        self.effects.iter().map(|e| e.name()).collect()
    }

    /// The tilt-inertia terms of cargo `c` at angle (sin, cos) φ_j and rate
    /// φ̇_j, when its plane models them.
    fn tilt_terms(
        &self,
        c: &Cargo,
        angle: (f64, f64),
        rate: f64,
        q: &[f64],
        qd: &[f64],
    ) -> Option<TiltTerms> {
        let tilt = self.tilt_maps[c.plane].as_ref()?;
        let k = self.layout.rotor_dof;
        Some(TiltTerms::at(
            tilt,
            k,
            c.mass,
            c.track_radius,
            angle,
            rate,
            q,
            qd,
        ))
    }

    /// Spin angle and rate at time t in state y.
    pub fn spin(&self, t: f64, y: &[f64]) -> (f64, f64) {
        if self.layout.spin_free {
            let nq = self.layout.nq();
            (y[self.layout.phi()], y[nq + self.layout.phi()])
        } else {
            let (phi, rate, _) = self.speed.prescribed(t);
            (phi, rate)
        }
    }
}

impl OdeSystem for RotorSystem {
    fn dim(&self) -> usize {
        self.layout.dim()
    }

    fn second_order_split(&self) -> Option<usize> {
        // `rhs` copies q̇ into the first half as it is.
        Some(self.layout.nq())
    }

    fn coupling_structure(&self, t: f64, y: &[f64], out: &mut CouplingStructure) -> bool {
        // A cluster couples all its members: dense Newton matrices.
        if self.rigid.is_some() {
            return false;
        }
        let lay = self.layout;
        let (k, nq, head) = (lay.rotor_dof, lay.nq(), lay.head());
        let (q, qd) = y.split_at(nq);
        let (phi, spin_rate) = self.spin(t, y);
        out.head = head;
        out.coupling.clear();
        // ψ̈_j = (Q_j − w_j·z_rotor − (I_j − J_j) φ̈)/I_j, as `rhs` back-substitutes.
        for (j, c) in self.cargo.iter().enumerate() {
            let (s, co) = super::trig::sin_cos(phi + q[head + j]);
            let ml = c.mass * c.track_radius;
            let [gu, gv] = &self.plane_maps[c.plane];
            let inv = 1.0 / self.inertia[j];
            let mut w: DofVec = [0.0; MAX_DOF];
            for i in 0..k {
                w[i] = ml * (co * gv[i] - s * gu[i]);
            }
            let rate = spin_rate + qd[head + j];
            if let Some(t) = self.tilt_terms(c, (s, co), rate, &q[..k], &qd[..k]) {
                for i in 0..k {
                    w[i] += t.coupling[i];
                }
            }
            out.coupling.extend(w[..k].iter().map(|wi| -wi * inv));
            if lay.spin_free {
                out.coupling
                    .push(-(self.inertia[j] - c.rolling_coupling) * inv);
            }
        }
        super::coupling::cargo_rings(&self.cargo, &q[head..], head, out)
    }

    fn head_equation(&self, t: f64, y: &[f64], f: &[f64], out: &mut HeadEquation) -> bool {
        // A free spin and the tilt terms add head terms of their own, and
        // so does an effect that loads the rotor from the weights: those
        // scenes keep the directional differences.
        let lay = self.layout;
        if lay.spin_free
            || self.rigid.is_some()
            || self.tilt_maps.iter().any(Option::is_some)
            || self.effects.iter().any(|e| e.rotor_forces_from_weights())
        {
            return false;
        }
        let (k, nq) = (lay.rotor_dof, lay.nq());
        let (phi, spin_rate, spin_accel) = self.speed.prescribed(t);
        // head_mass·z + Σ w_j ψ̈_j = F with w_j = m l (cos φ_j G_v − sin φ_j G_u);
        // weight j's own terms in F − Σ w ψ̈: m l φ̇_j² (cos φ_j G_u + sin φ_j G_v)
        // − w_j (φ̈ + ψ̈_j), φ_j = φ + ψ_j.
        out.mass.clear();
        for row in &self.head_mass[..k] {
            out.mass.extend_from_slice(&row[..k]);
        }
        out.reaction.clear();
        out.own.clear();
        for (j, c) in self.cargo.iter().enumerate() {
            let (s, co) = super::trig::sin_cos(phi + y[k + j]);
            let ml = c.mass * c.track_radius;
            let [gu, gv] = &self.plane_maps[c.plane];
            let rate = spin_rate + y[nq + k + j];
            let accel = spin_accel + f[nq + k + j];
            out.reaction
                .extend((0..k).map(|i| ml * (co * gv[i] - s * gu[i])));
            out.own.extend((0..k).map(|i| {
                ml * rate * rate * (co * gv[i] - s * gu[i]) + ml * accel * (co * gu[i] + s * gv[i])
            }));
            out.own
                .extend((0..k).map(|i| 2.0 * ml * rate * (co * gu[i] + s * gv[i])));
        }
        true
    }

    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        if let Some(rigid) = &self.rigid
            && rigid.mode().any_linked()
        {
            return self.rhs_clustered(rigid, t, y, dydt);
        }
        let lay = self.layout;
        let (k, nq, head) = (lay.rotor_dof, lay.nq(), lay.head());
        let (kin, mut h) = self.begin(t, y, dydt);
        let cargo_f = &mut dydt[nq + head..];

        // Eliminate the cargo rows. Cargo row j reads
        //   I_j ψ̈_j + c_j·z = Q_j,  c_j = (w_j, I_j − J_j),
        // and contributes e_j·ψ̈_j to the head rows, e_j = (w_j, −J_j), with
        // w_j = m l (−sin φ_j G_u + cos φ_j G_v) and J_j the rolling coupling.
        let mut trig = self.trig.borrow_mut();
        for j in 0..self.cargo.len() {
            let (w, qj) = self.weight_row::<true>(j, &kin, &mut h, &mut trig, cargo_f);
            let c = &self.cargo[j];
            self.eliminate(&mut h, self.inertia[j], c.rolling_coupling, &w, qj);
        }
        let z = self.finish_head(&kin, &mut h);

        // Back-substitute the cargo accelerations.
        let q = &y[..nq];
        let qd = &y[nq..];
        let z_spin = if lay.spin_free { z[k] } else { 0.0 };
        for (j, c) in self.cargo.iter().enumerate() {
            let (s, co) = trig[j];
            let ml = c.mass * c.track_radius;
            let [gu, gv] = &self.plane_maps[c.plane];
            let mut wz = 0.0;
            for i in 0..k {
                wz += ml * (co * gv[i] - s * gu[i]) * z[i];
            }
            let rate = kin.spin_rate + qd[head + j];
            if let Some(t) = self.tilt_terms(c, (s, co), rate, &q[..k], &qd[..k]) {
                wz += (0..k).map(|i| t.coupling[i] * z[i]).sum::<f64>();
            }
            let spin_term = (self.inertia[j] - c.rolling_coupling) * z_spin;
            cargo_f[j] = (cargo_f[j] - wz - spin_term) / self.inertia[j];
        }
        dydt[nq..nq + head].copy_from_slice(&z[..head]);
    }

    fn events(&self) -> Option<&dyn Events> {
        self.rigid.as_ref().map(|_| self as &dyn Events)
    }
}

/// The head block of the elimination as it is assembled: the matrix, the
/// right-hand side, and the column and diagonal of φ̈.
struct Head {
    a: [[f64; MAX_HEAD]; MAX_HEAD],
    g: [f64; MAX_HEAD],
    spin_col: DofVec,
    spin_diag: f64,
    /// The rotor's own column of φ̈ (its unbalance), kept for the spin row.
    coupling: DofVec,
    spin_f: f64,
}

/// The spin and the state a right-hand side reads, once per call.
struct Kinematics<'y> {
    phi: f64,
    spin_rate: f64,
    spin_accel: f64,
    q: &'y [f64],
    qd: &'y [f64],
}

impl RotorSystem {
    /// Copy q̇ into dydt's first half, put the effects' forces on the
    /// weights into its weight slots, and start the head block: the rotor's
    /// and the effects' forces, the rotor's mass matrix and its φ̈ column.
    #[inline(always)]
    fn begin<'y>(&self, t: f64, y: &'y [f64], dydt: &mut [f64]) -> (Kinematics<'y>, Head) {
        let lay = self.layout;
        let (k, nq, head) = (lay.rotor_dof, lay.nq(), lay.head());
        let (q, qd) = y.split_at(nq);
        dydt[..nq].copy_from_slice(qd);
        let (phi, spin_rate, spin_accel) = if lay.spin_free {
            (q[lay.phi()], qd[lay.phi()], 0.0)
        } else {
            self.speed.prescribed(t)
        };
        let psi = &q[head..];
        let psi_rate = &qd[head..];

        // Generalised forces: rotor g[..k], spin g[k]; cargo forces live in
        // the acceleration slots of dydt until they are replaced by ψ̈.
        let mut g: [f64; MAX_HEAD] = [0.0; MAX_HEAD];
        let mut rotor_f: DofVec = [0.0; MAX_DOF];
        self.rotor
            .forces(&q[..k], &qd[..k], spin_rate, &mut rotor_f);
        self.rotor.unbalance_forces(phi, spin_rate, &mut rotor_f);
        let mut spin_f = self.speed.torque(spin_rate);
        let cargo_f = &mut dydt[nq + head..];
        // −0.0, not 0.0: it is the exact additive identity (−0.0 − x is −x
        // bit for bit, sign of zero included), so the first effect's terms
        // land unchanged, as when drag used to assign them directly.
        cargo_f.fill(-0.0);
        if !self.effects.is_empty() {
            let ctx = EffectContext {
                t,
                phi,
                spin_rate,
                spin_accel,
                spin_free: lay.spin_free,
                cargo: &self.cargo,
                psi,
                psi_rate,
                rotor_unbalance: self.rotor_unbalance,
            };
            let mut forces = Forces {
                rotor: &mut rotor_f,
                spin: &mut spin_f,
                cargo: cargo_f,
            };
            for effect in &self.effects {
                effect.apply(&ctx, &mut forces);
            }
        }
        g[..k].copy_from_slice(&rotor_f[..k]);

        // Head block before elimination.
        let coupling = self.rotor.spin_coupling(phi, &q[..k]);
        let mut a = [[0.0; MAX_HEAD]; MAX_HEAD];
        for r in 0..k {
            a[r][..k].copy_from_slice(&self.head_mass[r][..k]);
        }
        let kin = Kinematics {
            phi,
            spin_rate,
            spin_accel,
            q,
            qd,
        };
        // Column of φ̈ in the rotor rows (rotor unbalance plus every cargo's).
        let h = Head {
            a,
            g,
            spin_col: coupling,
            spin_diag: self.spin_inertia,
            coupling,
            spin_f,
        };
        (kin, h)
    }

    /// Weight j's share of the head block (its centrifugal force, its φ̈
    /// column, its tilt terms) and its row: the reaction w_j on the rotor
    /// coordinates (tilt coupling included) and its generalised force Q_j
    /// (also written back into its slot of `cargo_f`). Without `FORCES`
    /// only the mass matrix is assembled (an impulse's response).
    #[inline(always)]
    fn weight_row<const FORCES: bool>(
        &self,
        j: usize,
        kin: &Kinematics<'_>,
        h: &mut Head,
        trig: &mut [(f64, f64)],
        cargo_f: &mut [f64],
    ) -> (DofVec, f64) {
        let lay = self.layout;
        let (k, head) = (lay.rotor_dof, lay.head());
        let c = &self.cargo[j];
        let (s, co) = super::trig::sin_cos(kin.phi + kin.q[head + j]);
        trig[j] = (s, co);
        let ml = c.mass * c.track_radius;
        let [gu, gv] = &self.plane_maps[c.plane];
        let rate = kin.spin_rate + kin.qd[head + j];
        let mut w: DofVec = [0.0; MAX_DOF];
        for i in 0..k {
            w[i] = ml * (co * gv[i] - s * gu[i]);
            if FORCES {
                h.g[i] += ml * rate * rate * (co * gu[i] + s * gv[i]);
            }
            h.spin_col[i] += w[i];
        }
        let inertia = self.inertia[j];
        let jc = c.rolling_coupling;
        h.spin_diag -= jc;
        let mut qj = cargo_f[j];
        if FORCES && !lay.spin_free {
            qj -= (inertia - jc) * kin.spin_accel;
            cargo_f[j] = qj;
        }
        // The m R² terms (src/model/tilt_inertia.rs); the scene
        // guarantees a prescribed speed.
        if let Some(t) = self.tilt_terms(c, (s, co), rate, &kin.q[..k], &kin.qd[..k]) {
            for r in 0..k {
                for col in 0..k {
                    h.a[r][col] += t.mu * t.jac[r] * t.jac[col];
                }
                if FORCES {
                    h.g[r] -= t.rotor_force * t.jac[r] + t.coupling[r] * kin.spin_accel;
                }
                w[r] += t.coupling[r];
            }
            if FORCES {
                qj += t.cargo_force;
                cargo_f[j] = qj;
            }
        }
        (w, qj)
    }

    /// Eliminate one row I ψ̈ + w·z + (I − J) φ̈ = Q (a weight's, or a
    /// cluster's sum) from the head block.
    #[inline(always)]
    fn eliminate(&self, h: &mut Head, inertia: f64, jc: f64, w: &DofVec, qj: f64) {
        let lay = self.layout;
        let k = lay.rotor_dof;
        let inv = 1.0 / inertia;
        for r in 0..k {
            let er = w[r] * inv;
            for col in 0..k {
                h.a[r][col] -= er * w[col];
            }
            h.g[r] -= er * qj;
        }
        if lay.spin_free {
            for r in 0..k {
                // e_r · c_φ and e_φ · c_r terms.
                h.a[r][k] -= w[r] * inv * (inertia - jc);
                h.a[k][r] += jc * inv * w[r];
            }
            h.a[k][k] += jc * inv * (inertia - jc);
            h.g[k] += jc * inv * qj;
        }
    }

    /// Close the head block (the spin row, or the prescribed φ̈'s share)
    /// and solve it for z = (rotor accelerations, φ̈).
    #[inline(always)]
    fn finish_head(&self, kin: &Kinematics<'_>, h: &mut Head) -> [f64; MAX_HEAD] {
        let lay = self.layout;
        let k = lay.rotor_dof;
        if lay.spin_free {
            for r in 0..k {
                h.a[r][k] += h.spin_col[r];
                h.a[k][r] += h.coupling[r];
            }
            h.a[k][k] += h.spin_diag;
            h.g[k] += h.spin_f;
        } else {
            for r in 0..k {
                h.g[r] -= h.spin_col[r] * kin.spin_accel;
            }
        }
        solve_small(&mut h.a, &mut h.g, lay.head())
    }

    /// The right-hand side with weights linked by rigid contact: each
    /// cluster's rows summed (the contact torques cancel) and eliminated as
    /// one row, I_C = Σ I, w_C = Σ w, J_C = Σ J, Q_C = Σ Q; every member gets
    /// the cluster's acceleration, and the links' torques are recorded for
    /// the events (docs/model.md, "Rigid contact").
    fn rhs_clustered(&self, rigid: &RigidContact, t: f64, y: &[f64], dydt: &mut [f64]) {
        let lay = self.layout;
        let (k, nq, head) = (lay.rotor_dof, lay.nq(), lay.head());
        let (kin, mut h) = self.begin(t, y, dydt);
        let cargo_f = &mut dydt[nq + head..];
        let mut mode = rigid.mode();
        let (clusters, torque) = mode.clusters_and_torques();
        let mut trig = self.trig.borrow_mut();
        let mut rows = self.rows.borrow_mut();
        let mut sums = self.cluster_sums.borrow_mut();
        sums.clear();
        for c in 0..clusters.len() {
            let mut sum = ClusterRow::default();
            for &j in clusters.members(c) {
                let (w, qj) = self.weight_row::<true>(j, &kin, &mut h, &mut trig, cargo_f);
                rows[j] = (w, qj);
                sum.add(self.inertia[j], self.cargo[j].rolling_coupling, &w, qj, k);
            }
            self.eliminate(&mut h, sum.inertia, sum.coupling, &sum.w, sum.q);
            sums.push(sum);
        }
        let z = self.finish_head(&kin, &mut h);
        let z_spin = if lay.spin_free { z[k] } else { 0.0 };
        let reaction = |w: &DofVec, i: f64, jc: f64| {
            (0..k).map(|r| w[r] * z[r]).sum::<f64>() + (i - jc) * z_spin
        };
        for (c, sum) in sums.iter().enumerate() {
            let a = (sum.q - reaction(&sum.w, sum.inertia, sum.coupling)) / sum.inertia;
            let links = clusters.links(c);
            let mut carried = 0.0;
            for (i, &j) in clusters.members(c).iter().enumerate() {
                if let Some(&link) = links.get(i) {
                    let (w, qj) = &rows[j];
                    let (inertia, jc) = (self.inertia[j], self.cargo[j].rolling_coupling);
                    carried += qj - inertia * a - reaction(w, inertia, jc);
                    torque[link] = carried;
                }
                cargo_f[j] = a;
            }
        }
        dydt[nq..nq + head].copy_from_slice(&z[..head]);
        mode.recorded_at(t, y);
    }
}

/// A cluster's summed row: I_C, J_C, w_C and Q_C.
#[derive(Debug, Clone, Copy, Default)]
struct ClusterRow {
    inertia: f64,
    coupling: f64,
    w: DofVec,
    q: f64,
}

impl ClusterRow {
    fn add(&mut self, inertia: f64, coupling: f64, w: &DofVec, q: f64, k: usize) {
        self.inertia += inertia;
        self.coupling += coupling;
        for r in 0..k {
            self.w[r] += w[r];
        }
        self.q += q;
    }
}

impl Clustered for RotorSystem {
    fn rigid(&self) -> &RigidContact {
        self.rigid
            .as_ref()
            .expect("asked only of a system with rigid contact")
    }

    fn first_weight(&self) -> usize {
        self.layout.head()
    }

    fn coordinates(&self) -> usize {
        self.layout.nq()
    }

    fn impulse_response(&self, t: f64, y: &[f64], impulse: &[f64], response: &mut [f64]) {
        let lay = self.layout;
        let (k, nq, head) = (lay.rotor_dof, lay.nq(), lay.head());
        let (q, qd) = y.split_at(nq);
        let (phi, spin_rate, _) = if lay.spin_free {
            (q[lay.phi()], qd[lay.phi()], 0.0)
        } else {
            self.speed.prescribed(t)
        };
        let kin = Kinematics {
            phi,
            spin_rate,
            spin_accel: 0.0,
            q,
            qd,
        };
        let coupling = self.rotor.spin_coupling(phi, &q[..k]);
        let mut h = Head {
            a: [[0.0; MAX_HEAD]; MAX_HEAD],
            g: [0.0; MAX_HEAD],
            spin_col: coupling,
            spin_diag: self.spin_inertia,
            coupling,
            spin_f: 0.0,
        };
        for r in 0..k {
            h.a[r][..k].copy_from_slice(&self.head_mass[r][..k]);
        }
        let mode = self.rigid().mode();
        let clusters = mode.clusters();
        let mut trig = self.trig.borrow_mut();
        let mut forces = impulse.to_vec();
        let mut sums = Vec::with_capacity(clusters.len());
        for c in 0..clusters.len() {
            let mut sum = ClusterRow::default();
            for &j in clusters.members(c) {
                let (w, qj) = self.weight_row::<false>(j, &kin, &mut h, &mut trig, &mut forces);
                sum.add(self.inertia[j], self.cargo[j].rolling_coupling, &w, qj, k);
            }
            self.eliminate(&mut h, sum.inertia, sum.coupling, &sum.w, sum.q);
            sums.push(sum);
        }
        // The mass matrix only: the spin row's entries, no forces.
        h.spin_f = 0.0;
        let z = if lay.spin_free {
            self.finish_head(&kin, &mut h)
        } else {
            solve_small(&mut h.a, &mut h.g, head)
        };
        let z_spin = if lay.spin_free { z[k] } else { 0.0 };
        for (c, sum) in sums.iter().enumerate() {
            let reaction = (0..k).map(|r| sum.w[r] * z[r]).sum::<f64>()
                + (sum.inertia - sum.coupling) * z_spin;
            let a = (sum.q - reaction) / sum.inertia;
            for &j in clusters.members(c) {
                response[head + j] = a;
            }
        }
        response[..head].copy_from_slice(&z[..head]);
    }
}

crate::rigid_contact_events!(RotorSystem);

/// Solve the dense system a·z = g of size `size` ≤ 5 by Gaussian elimination
/// with partial pivoting (a library call would cost more than the solve).
fn solve_small(
    a: &mut [[f64; MAX_HEAD]; MAX_HEAD],
    g: &mut [f64; MAX_HEAD],
    size: usize,
) -> [f64; MAX_HEAD] {
    for col in 0..size {
        let pivot = (col..size)
            .max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))
            .unwrap_or(col);
        a.swap(col, pivot);
        g.swap(col, pivot);
        let inv = 1.0 / a[col][col];
        for row in col + 1..size {
            let f = a[row][col] * inv;
            if f != 0.0 {
                for c in col..size {
                    a[row][c] -= f * a[col][c];
                }
                g[row] -= f * g[col];
            }
        }
    }
    let mut z = [0.0; MAX_HEAD];
    for row in (0..size).rev() {
        let mut sum = g[row];
        for c in row + 1..size {
            sum -= a[row][c] * z[c];
        }
        z[row] = sum / a[row][row];
    }
    z
}
