//! Shared pieces of the test fixtures.

/// The rotor of the shipped SI studies: 10 kg on supports of 1e5 N/m with 5 %
/// of critical damping (ω_n = 100 rad/s), spinning at 300 rad/s.
pub const SI_SCENE: &str = r#"[scene.rotor]
mass = 10.0
kx = 1.0e5
ky = 1.0e5
bx = 100.0
by = 100.0
[scene.speed]
mode = "constant"
omega = 300.0
"#;
