//! The exact nonlinear equations of the plane rotor written in the frame that
//! turns with the rotor (the `rotating` fidelity).
//!
//! With isotropic supports (k_x = k_y = k, b_x = b_y = b), constant speed ω and
//! no gravity in the plane, these equations are autonomous: the balanced state
//! is a fixed point and, once the transient has died, the integrator's step is
//! no longer tied to the revolution. With w = u + i v = (x + i y) e^{−iωt}:
//!
//!   M_Σ (ẅ + 2iωẇ − ω²w) + b (ẇ + iωw) + k w + Σ̂'' + 2iωΣ̂' − ω²Σ̂ = 0,
//!   κ_j m_j l_j² ψ̈_j + β_j l_j² ψ̇_j + m_j l_j Im[(ẅ + 2iωẇ − ω²w) e^{−iψ_j}] = 0,
//!
//! where Σ̂ = M e e^{iψ₀} + Σ m_j l_j e^{iψ_j} is the total unbalance seen from
//! the rotor. These are the inertial equations of [`super::system`] with
//! z̈ = e^{iωt}(ẅ + 2iωẇ − ω²w): the same arrowhead, the same O(n) elimination.
//! r = |w| and ε are frame-independent, so metrics compare directly.

use super::cargo::Cargo;
use super::effect::{Effect, EffectContext, Forces};
use super::rigid_contact::{self, Clustered, RigidContact};
use super::scene::Scene;
use super::speed::SpeedLaw;
use super::validate::SceneError;
use crate::integrate::{CouplingStructure, Events, HeadEquation, OdeSystem};
use std::cell::RefCell;

/// Why a scene cannot use the rotating frame.
pub fn rotating_frame_obstacle(scene: &Scene) -> Option<&'static str> {
    if let Err(why) = scene.rotor.as_rotor().isotropic_plane() {
        return Some(why);
    }
    if !matches!(scene.speed, SpeedLaw::Constant { .. }) {
        return Some("the speed is not constant");
    }
    scene.effects.rotating_frame_obstacle()
}

/// The plane rotor with cargoes in the rotor-fixed frame, as an [`OdeSystem`].
///
/// State: [u, v, ψ_1..ψ_n, u̇, v̇, ψ̇_1..ψ̇_n], the same layout as the inertial
/// constant-speed system with (x, y) replaced by (u, v).
#[derive(Debug)]
pub struct RotatingSystem {
    omega: f64,
    m_total: f64,
    k: f64,
    b: f64,
    /// M e ω² e^{iψ₀}: the rotor's centrifugal force, constant in this frame.
    unbalance_force: (f64, f64),
    cargo: Vec<Cargo>,
    inertia: Vec<f64>,
    /// 1/I of each cargo: the elimination multiplies by it (the same value
    /// it computed per call before), the back-substitution still divides.
    inv_inertia: Vec<f64>,
    /// m·l of each cargo (constant per run).
    mass_track: Vec<f64>,
    /// (sin ψ, cos ψ) of each cargo, evaluated once per call: the trig is a
    /// third of a run's time and both loops of the right-hand side need it.
    /// A field, not a local, so that a call allocates nothing.
    trig: RefCell<Vec<(f64, f64)>>,
    effects: Vec<Box<dyn Effect>>,
    rotor_unbalance: (f64, f64),
    /// Rigid contact between the weights, when the scene asks for it.
    rigid: Option<RigidContact>,
    /// (1/I, w, Q) of each cluster in a clustered right-hand side (a field,
    /// not a local, so that a call allocates nothing).
    cluster_sums: RefCell<Vec<[f64; 4]>>,
}

impl RotatingSystem {
    /// Build from a scene; errors when the scene cannot use this frame.
    pub fn new(scene: &Scene) -> Result<Self, SceneError> {
        scene.validate()?;
        if let Some(why) = rotating_frame_obstacle(scene) {
            return Err(SceneError::Invalid {
                field: "solver.fidelity".into(),
                value: "rotating".into(),
                reason: why.into(),
            });
        }
        let SpeedLaw::Constant { omega } = scene.speed else {
            unreachable!("checked above")
        };
        let cargo = scene.cargoes()?;
        let cargo_count = cargo.len();
        let Ok(r) = scene.rotor.as_rotor().isotropic_plane() else {
            unreachable!("checked above")
        };
        let me = r.unbalance;
        let (s, c) = super::trig::sin_cos(r.unbalance_angle);
        let rigid = scene
            .effects
            .contact
            .as_ref()
            .and_then(|c| c.rigid(&cargo, omega));
        let effects = scene.effects.build(&super::effect::BuildSetup {
            rigid_contact: rigid.is_some(),
            ..super::effect::BuildSetup::plane(&cargo, omega)
        });
        Ok(RotatingSystem {
            omega,
            m_total: r.mass + cargo.iter().map(|c| c.mass).sum::<f64>(),
            k: r.stiffness,
            b: r.damping,
            unbalance_force: (me * omega * omega * c, me * omega * omega * s),
            inertia: cargo.iter().map(Cargo::inertia).collect(),
            inv_inertia: cargo.iter().map(|c| 1.0 / c.inertia()).collect(),
            mass_track: cargo.iter().map(|c| c.mass * c.track_radius).collect(),
            trig: RefCell::new(vec![(0.0, 0.0); cargo.len()]),
            cargo,
            effects,
            rotor_unbalance: (me, r.unbalance_angle),
            rigid,
            cluster_sums: RefCell::new(Vec::with_capacity(cargo_count)),
        })
    }

    /// The same system with one more effect, applied after the built ones
    /// (as [`super::system::RotorSystem::with_effect`]).
    pub fn with_effect(mut self, effect: Box<dyn Effect>) -> Self {
        self.effects.push(effect);
        self
    }

    /// How contact between the weights is modelled: "rigid" (held here as
    /// constraints), "penalty" (a force among the effects) or none.
    pub fn contact_model(&self) -> Option<&'static str> {
        let penalty = self.effects.iter().any(|e| e.name() == "contact");
        RigidContact::model_name(self.rigid.is_some(), penalty)
    }

    /// The constant spin speed ω.
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// Rotating-frame state (u, u̇, v, v̇) from the inertial (x, ẋ, y, ẏ) at time t.
    pub fn from_inertial(&self, t: f64, x: f64, xd: f64, y: f64, yd: f64) -> [f64; 4] {
        let (s, c) = super::trig::sin_cos(self.omega * t);
        // ẇ = (ż − iω z) e^{−iωt}
        let (zr, zi) = (xd + self.omega * y, yd - self.omega * x);
        [
            x * c + y * s,
            zr * c + zi * s,
            -x * s + y * c,
            -zr * s + zi * c,
        ]
    }
}

impl OdeSystem for RotatingSystem {
    fn dim(&self) -> usize {
        2 * (2 + self.cargo.len())
    }

    fn second_order_split(&self) -> Option<usize> {
        // `rhs` copies (u̇, v̇, ψ̇) into the first half as it is.
        Some(2 + self.cargo.len())
    }

    fn coupling_structure(&self, _t: f64, y: &[f64], out: &mut CouplingStructure) -> bool {
        // A cluster couples all its members: dense Newton matrices.
        if self.rigid.is_some() {
            return false;
        }
        let n = self.cargo.len();
        let psi = &y[2..2 + n];
        out.head = 2;
        out.coupling.clear();
        // ψ̈_j = (Q_j − m l (cos ψ_j · v̈ − sin ψ_j · ü))/I_j, as `rhs` back-substitutes.
        for ((&p, &ml), &inertia) in psi.iter().zip(&self.mass_track).zip(&self.inertia) {
            let (s, co) = super::trig::sin_cos(p);
            out.coupling.extend([ml * s / inertia, -ml * co / inertia]);
        }
        super::coupling::cargo_rings(&self.cargo, psi, 2, out)
    }

    fn head_equation(&self, _t: f64, y: &[f64], f: &[f64], out: &mut HeadEquation) -> bool {
        if self.rigid.is_some() || self.effects.iter().any(|e| e.rotor_forces_from_weights()) {
            return false;
        }
        let n = self.cargo.len();
        let nq = 2 + n;
        // M_Σ·a + Σ w_j ψ̈_j = G, w_j = m l (−sin ψ_j, cos ψ_j); weight j's
        // own terms in G − Σ w ψ̈: m l (ω + ψ̇_j)² (cos ψ_j, sin ψ_j) − w_j ψ̈_j.
        out.mass.clear();
        out.mass.extend([self.m_total, 0.0, 0.0, self.m_total]);
        out.reaction.clear();
        out.own.clear();
        let (psi, psi_rate, psi_accel) = (&y[2..nq], &y[nq + 2..], &f[nq + 2..]);
        let per_cargo = psi.iter().zip(psi_rate).zip(psi_accel);
        for (((&p, &p_rate), &accel), &ml) in per_cargo.zip(&self.mass_track) {
            let (s, co) = super::trig::sin_cos(p);
            let rate = self.omega + p_rate;
            let centrifugal = ml * rate * rate;
            out.reaction.extend([-ml * s, ml * co]);
            out.own.extend([
                -centrifugal * s + ml * accel * co,
                centrifugal * co + ml * accel * s,
                2.0 * ml * rate * co,
                2.0 * ml * rate * s,
            ]);
        }
        true
    }

    fn rhs(&self, t: f64, y: &[f64], dydt: &mut [f64]) {
        if let Some(rigid) = &self.rigid
            && rigid.mode().any_linked()
        {
            return self.rhs_clustered(rigid, t, y, dydt);
        }
        let n = self.cargo.len();
        let nq = 2 + n;
        let ((gr, gi), (fr, fi)) = self.head_and_weight_forces(t, y, dydt);
        let (mut gr, mut gi) = (gr, gi);
        let w = self.omega;
        let (psi, psi_rate) = (&y[2..nq], &y[nq + 2..]);
        let cargo_f = &mut dydt[nq + 2..];
        let (mut a11, mut a12, mut a22) = (self.m_total, 0.0, self.m_total);
        let mut trig = self.trig.borrow_mut();
        // Zipped slices: no bounds checks in the loop.
        let per_cargo = psi.iter().zip(psi_rate).zip(cargo_f.iter_mut());
        let constants = self.mass_track.iter().zip(&self.inv_inertia);
        for (((&p, &p_rate), f), ((&ml, &inv), tr)) in per_cargo.zip(constants.zip(trig.iter_mut()))
        {
            let (s, co) = super::trig::sin_cos(p);
            *tr = (s, co);
            let rate = w + p_rate;
            gr += ml * rate * rate * co;
            gi += ml * rate * rate * s;
            // Cargo row: I ψ̈ + (−ml s, ml co)·a = Q − ml Im[(fr + i fi) e^{−iψ}].
            let q = *f - ml * (fi * co - fr * s);
            *f = q;
            let (wr, wi) = (-ml * s, ml * co);
            a11 -= wr * wr * inv;
            a12 -= wr * wi * inv;
            a22 -= wi * wi * inv;
            gr -= wr * q * inv;
            gi -= wi * q * inv;
        }
        let det = a11 * a22 - a12 * a12;
        let ar = (gr * a22 - gi * a12) / det;
        let ai = (gi * a11 - gr * a12) / det;
        let constants = self.mass_track.iter().zip(&self.inertia);
        for ((f, &(s, co)), (&ml, &inertia)) in cargo_f.iter_mut().zip(trig.iter()).zip(constants) {
            *f = (*f - ml * (co * ai - s * ar)) / inertia;
        }
        dydt[nq] = ar;
        dydt[nq + 1] = ai;
    }

    fn events(&self) -> Option<&dyn Events> {
        self.rigid.as_ref().map(|_| self as &dyn Events)
    }
}

impl RotatingSystem {
    /// Copy q̇ into dydt's first half, fill its weight slots with the
    /// effects' forces on the weights, and return the head's right-hand side
    /// G before the weights' terms and the frame acceleration 2iωẇ − ω²w
    /// (see the module docs): what both eliminations start from.
    #[inline]
    fn head_and_weight_forces(
        &self,
        t: f64,
        y: &[f64],
        dydt: &mut [f64],
    ) -> ((f64, f64), (f64, f64)) {
        let n = self.cargo.len();
        let nq = 2 + n;
        let (q, qd) = y.split_at(nq);
        dydt[..nq].copy_from_slice(qd);
        let (u, v, ud, vd) = (q[0], q[1], qd[0], qd[1]);
        let w = self.omega;
        // Frame acceleration of the plane without ẅ: 2iωẇ − ω²w.
        let (fr, fi) = (-2.0 * w * vd - w * w * u, 2.0 * w * ud - w * w * v);
        // Head right-hand side G (see the module docs).
        let mut gr =
            -self.m_total * fr - self.b * (ud - w * v) - self.k * u + self.unbalance_force.0;
        let mut gi =
            -self.m_total * fi - self.b * (vd + w * u) - self.k * v + self.unbalance_force.1;
        let psi = &q[2..];
        let psi_rate = &qd[2..];
        let cargo_f = &mut dydt[nq + 2..];
        // −0.0 is the exact additive identity: the effects' terms (drag's
        // first) land bit for bit as when drag assigned them directly.
        cargo_f.fill(-0.0);
        if !self.effects.is_empty() {
            let ctx = EffectContext {
                t,
                phi: 0.0,
                spin_rate: w,
                spin_accel: 0.0,
                spin_free: false,
                cargo: &self.cargo,
                psi,
                psi_rate,
                rotor_unbalance: self.rotor_unbalance,
            };
            // −0.0 again: adding an untouched rotor force leaves G exactly as it was.
            let (mut rotor_f, mut spin_f) = ([-0.0; super::rotor::MAX_DOF], 0.0);
            let mut forces = Forces {
                rotor: &mut rotor_f,
                spin: &mut spin_f,
                cargo: cargo_f,
            };
            for e in &self.effects {
                e.apply(&ctx, &mut forces);
            }
            gr += rotor_f[0];
            gi += rotor_f[1];
        }
        ((gr, gi), (fr, fi))
    }

    /// The right-hand side with weights linked by rigid contact: each
    /// cluster's rows summed (the contact torques cancel) and eliminated as
    /// one weight of inertia Σ I and reaction Σ w; every member gets the
    /// cluster's acceleration, and the links' torques are recorded for the
    /// events.
    fn rhs_clustered(&self, rigid: &RigidContact, t: f64, y: &[f64], dydt: &mut [f64]) {
        let n = self.cargo.len();
        let nq = 2 + n;
        let ((mut gr, mut gi), (fr, fi)) = self.head_and_weight_forces(t, y, dydt);
        let w = self.omega;
        let (psi, psi_rate) = (&y[2..nq], &y[nq + 2..]);
        let mut mode = rigid.mode();
        let (clusters, torque) = mode.clusters_and_torques();
        let mut trig = self.trig.borrow_mut();
        // Each weight's force Q (kept in its slot of dydt for the torques)
        // and the head's centrifugal terms.
        let cargo_f = &mut dydt[nq + 2..];
        for j in 0..n {
            let (s, co) = super::trig::sin_cos(psi[j]);
            trig[j] = (s, co);
            let ml = self.mass_track[j];
            let rate = w + psi_rate[j];
            gr += ml * rate * rate * co;
            gi += ml * rate * rate * s;
            cargo_f[j] -= ml * (fi * co - fr * s);
        }
        let (ar, ai) = self.eliminate_clusters(clusters, &trig, cargo_f, (gr, gi));
        // Each member's acceleration is its cluster's; the torque of the
        // link after member i is what members up to i owe their own rows,
        // Σ (Q − I a − w·z).
        for (c, &[inv, wr, wi, q]) in self.cluster_sums.borrow().iter().enumerate() {
            let a = (q - (wr * ar + wi * ai)) * inv;
            let links = clusters.links(c);
            let mut carried = 0.0;
            for (i, &j) in clusters.members(c).iter().enumerate() {
                if let Some(&link) = links.get(i) {
                    let (s, co) = trig[j];
                    carried +=
                        cargo_f[j] - self.inertia[j] * a - self.mass_track[j] * (co * ai - s * ar);
                    torque[link] = carried;
                }
                cargo_f[j] = a;
            }
        }
        dydt[nq] = ar;
        dydt[nq + 1] = ai;
        mode.recorded_at(t, y);
    }

    /// Eliminate the clusters from M·(ü, v̈, ψ̈) = (g, forces), each as one
    /// weight of inertia Σ I, reaction Σ w and force Σ Q, and solve the head:
    /// returns (ü, v̈) and leaves each cluster's (1/I, w, Q) in
    /// `cluster_sums` for its acceleration (Q − w·z)/I. `trig` holds (sin ψ,
    /// cos ψ) of each weight.
    fn eliminate_clusters(
        &self,
        clusters: &rigid_contact::Clusters,
        trig: &[(f64, f64)],
        forces: &[f64],
        (mut gr, mut gi): (f64, f64),
    ) -> (f64, f64) {
        let (mut a11, mut a12, mut a22) = (self.m_total, 0.0, self.m_total);
        let mut sums = self.cluster_sums.borrow_mut();
        sums.clear();
        for c in 0..clusters.len() {
            let (mut inertia, mut wr, mut wi, mut q) = (0.0, 0.0, 0.0, 0.0);
            for &j in clusters.members(c) {
                let (s, co) = trig[j];
                let ml = self.mass_track[j];
                inertia += self.inertia[j];
                wr -= ml * s;
                wi += ml * co;
                q += forces[j];
            }
            let inv = 1.0 / inertia;
            a11 -= wr * wr * inv;
            a12 -= wr * wi * inv;
            a22 -= wi * wi * inv;
            gr -= wr * q * inv;
            gi -= wi * q * inv;
            sums.push([inv, wr, wi, q]);
        }
        let det = a11 * a22 - a12 * a12;
        ((gr * a22 - gi * a12) / det, (gi * a11 - gr * a12) / det)
    }
}

impl Clustered for RotatingSystem {
    fn rigid(&self) -> &RigidContact {
        self.rigid
            .as_ref()
            .expect("asked only of a system with rigid contact")
    }

    fn first_weight(&self) -> usize {
        2
    }

    fn coordinates(&self) -> usize {
        2 + self.cargo.len()
    }

    fn impulse_response(&self, _t: f64, y: &[f64], impulse: &[f64], response: &mut [f64]) {
        let n = self.cargo.len();
        let mut trig = self.trig.borrow_mut();
        for (tr, &p) in trig.iter_mut().zip(&y[2..2 + n]) {
            *tr = super::trig::sin_cos(p);
        }
        let mode = self.rigid().mode();
        let clusters = mode.clusters();
        let (ar, ai) = self.eliminate_clusters(clusters, &trig, impulse, (0.0, 0.0));
        for (c, &[inv, wr, wi, q]) in self.cluster_sums.borrow().iter().enumerate() {
            let a = (q - (wr * ar + wi * ai)) * inv;
            for &j in clusters.members(c) {
                response[2 + j] = a;
            }
        }
        response[0] = ar;
        response[1] = ai;
    }
}

crate::rigid_contact_events!(RotatingSystem);
