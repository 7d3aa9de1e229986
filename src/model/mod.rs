//! What is simulated: rotors carrying auto-balancers, their cargoes, the
//! speed law and optional effects, assembled into an ODE system.
//!
//! - [`scene::Scene`]: a plain, serialisable description of one simulation.
//! - [`rotor`]: rotor models (one file each) behind the [`rotor::Rotor`] trait.
//! - [`balancer`]: ball, roller and pendulum kinds (one file each).
//! - [`effect`]: drag, gravity, contact … (one file each, one registry line).
//! - [`system::RotorSystem`]: the assembled equations (O(n) per call).
//! - [`forced`]: steady forced response with the cargoes locked.
//! - [`critical_speeds`]: undamped natural frequencies and critical speeds.
//! - [`start`]: initial states (locked steady state, rest, step, run-up).
//! - [`invariants`]: energy and angular momentum, for validation.
//! - [`balanced_family`]: linear stability over the family of balanced states.
//! - [`linear`]: linear stability of the balanced state (rotating frame).
//! - [`validate`]: why a scene is rejected (a leaf every layer may use).
//! - [`sommerfeld`]: the whirl's load on a limited drive (passage through resonance).
//! - [`zero_approx`]: seed 003's empirical criterion for any rotor model.

pub mod balanced_family;
pub mod balancer;
pub mod cargo;
pub mod coupling;
pub mod critical_speeds;
pub mod effect;
pub mod forced;
pub mod frame;
pub mod gap;
pub mod invariants;
pub mod linear;
pub mod quasi_static;
pub mod race_ring;
pub mod rigid_contact;
pub mod rotor;
pub mod scene;
pub mod sommerfeld;
pub mod speed;
pub mod start;
pub mod system;
pub mod tilt_inertia;
pub mod trig;
pub mod unbalance;
pub mod validate;
pub mod zero_approx;
