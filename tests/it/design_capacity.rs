//! Capacity theory of seed 000 against the paper's Table 1 and closed forms.

use autobal::design::capacity::{
    capacity, capacity_scale, dimensionless_capacity, hemisphere_capacity,
    semicylinder_sector_capacity, weight_mass,
};
use autobal::design::geometry::{excess_weights, rho_half_race, rho_max, sector_angle};
use autobal::design::optimum::optimal_rho;
use autobal::design::table::optimal_row;
use autobal::design::{DesignError, Shape};

/// A Table 1 entry as printed: ρ (a fraction where the paper prints one), sector in degrees, s.
struct Printed {
    n: u32,
    rho: f64,
    rho_is_fraction: bool,
    sector: Option<f64>,
    s: f64,
}

const fn p(n: u32, rho: f64, frac: bool, sector: Option<f64>, s: f64) -> Printed {
    Printed {
        n,
        rho,
        rho_is_fraction: frac,
        sector,
        s,
    }
}

const BALLS: [Printed; 8] = [
    p(1, 3.0 / 4.0, true, None, 0.105),
    p(2, 3.0 / 7.0, true, Some(194.0), 0.060),
    p(3, 0.364, false, Some(209.0), 0.051),
    p(4, 0.315, false, Some(219.0), 0.044),
    p(5, 0.278, false, Some(226.0), 0.037),
    p(6, 0.248, false, Some(231.0), 0.031),
    p(7, 0.224, false, Some(235.0), 0.027),
    p(8, 0.204, false, Some(238.0), 0.023),
];

const ROLLERS: [Printed; 8] = [
    p(1, 2.0 / 3.0, true, None, 0.148),
    p(2, 2.0 / 5.0, true, Some(167.0), 0.143),
    p(3, 1.0 / 3.0, true, Some(180.0), 0.148),
    p(4, 0.286, false, Some(189.0), 0.145),
    p(5, 0.251, false, Some(195.0), 0.140),
    p(6, 0.223, false, Some(201.0), 0.133),
    p(7, 0.201, false, Some(205.0), 0.126),
    p(8, 0.183, false, Some(208.0), 0.119),
];

fn round3(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

fn check_table(shape: Shape, printed: &[Printed]) {
    for row in printed {
        let got = optimal_row(shape, row.n).unwrap();
        if row.rho_is_fraction {
            assert!(
                (got.rho_opt - row.rho).abs() < 1e-12,
                "{shape} n={}: ρ_opt {} ≠ {}",
                row.n,
                got.rho_opt,
                row.rho
            );
        } else {
            assert_eq!(
                round3(got.rho_opt),
                row.rho,
                "{shape} n={}: ρ_opt {}",
                row.n,
                got.rho_opt
            );
        }
        // The paper's s column is not rounded consistently (balls n = 3: 0.0518
        // printed 0.051; rollers n = 5: 0.1395 printed 0.140): it must agree
        // within one unit of its last printed digit.
        assert!(
            (got.s - row.s).abs() < 1e-3,
            "{shape} n={}: s = {} does not print as {}",
            row.n,
            got.s,
            row.s
        );
        // The sector column is an integer the paper rounds inconsistently
        // (195.8 → 195 but 204.5 → 205): it must be the floor or the ceiling.
        match (row.sector, got.sector_deg) {
            (None, None) => {}
            (Some(want), Some(have)) => assert!(
                (have - want).abs() < 1.0,
                "{shape} n={}: sector {have}° vs printed {want}°",
                row.n
            ),
            (want, have) => panic!("{shape} n={}: sector {have:?} vs {want:?}", row.n),
        }
    }
}

#[test]
fn table1_balls_reproduced_to_printed_digits() {
    check_table(Shape::Ball, &BALLS);
}

#[test]
fn table1_rollers_reproduced_to_printed_digits() {
    check_table(Shape::Roller, &ROLLERS);
}

#[test]
fn optimum_is_a_maximum_of_capacity() {
    for shape in Shape::ALL {
        for n in 1..=16 {
            let opt = optimal_rho(shape, n).unwrap();
            let upper = rho_max(n).unwrap().min(0.999);
            for i in 1..200 {
                let rho = upper * f64::from(i) / 200.0;
                let s = dimensionless_capacity(shape, n, rho).unwrap();
                assert!(
                    s <= opt.s * (1.0 + 1e-12),
                    "{shape} n={n}: s({rho}) = {s} > {}",
                    opt.s
                );
            }
        }
    }
}

#[test]
fn single_weight_capacity_is_m_times_track_radius_for_any_rho() {
    for &rho in &[0.1, 0.5, 0.75, 0.95] {
        let (gamma, r_race, h) = (7800.0, 0.05, 0.01);
        let m = weight_mass(Shape::Roller, gamma, r_race, rho, h).unwrap();
        let s = capacity(Shape::Roller, 1, rho, gamma, r_race, h).unwrap();
        assert!((s - m * r_race * (1.0 - rho)).abs() < 1e-15 * s.max(1.0));
    }
}

#[test]
fn dimensional_capacity_matches_dimensionless_times_scale() {
    let (gamma, r_race, h) = (7800.0, 0.08, 0.012);
    for shape in Shape::ALL {
        for n in 1..=8 {
            let rho = 0.9 * rho_max(n).unwrap().min(0.9);
            let dim = capacity(shape, n, rho, gamma, r_race, h).unwrap();
            let scale = capacity_scale(shape, gamma, r_race, h).unwrap();
            let s = dimensionless_capacity(shape, n, rho).unwrap();
            assert!((dim - scale * s).abs() <= 1e-12 * dim, "{shape} n={n}");
        }
    }
}

#[test]
fn rollers_carry_one_and_a_half_times_balls_at_height_two_r() {
    let (gamma, r_race) = (7800.0, 0.1);
    for n in 1..=8 {
        let rho = rho_half_race(n).unwrap();
        let h = 2.0 * rho * r_race;
        let balls = capacity(Shape::Ball, n, rho, gamma, r_race, h).unwrap();
        let rollers = capacity(Shape::Roller, n, rho, gamma, r_race, h).unwrap();
        assert!(
            (rollers / balls - 1.5).abs() < 1e-12,
            "n={n}: {}",
            rollers / balls
        );
    }
}

#[test]
fn hemisphere_and_sector_beat_single_weights_by_published_ratios() {
    let (gamma, r_race, h) = (7800.0, 0.1, 0.02);
    let ball = capacity(Shape::Ball, 1, 0.75, gamma, r_race, h).unwrap();
    let hemi = hemisphere_capacity(gamma, r_race).unwrap();
    assert!((hemi / ball - 16.0 / 9.0).abs() < 1e-12);
    let roller = capacity(Shape::Roller, 1, 2.0 / 3.0, gamma, r_race, h).unwrap();
    let sector = semicylinder_sector_capacity(gamma, r_race, h).unwrap();
    assert!((sector / roller - 9.0 / (2.0 * std::f64::consts::PI)).abs() < 1e-12);
}

#[test]
fn half_race_rho_fills_180_degrees() {
    for n in 2..=20 {
        let rho = rho_half_race(n).unwrap();
        let sector = sector_angle(n, rho).unwrap().to_degrees();
        assert!((sector - 180.0).abs() < 1e-9, "n={n}: {sector}");
    }
}

#[test]
fn rho_max_packs_the_whole_race() {
    for n in 2..=64 {
        let rho = rho_max(n).unwrap();
        let sector = sector_angle(n, rho).unwrap().to_degrees();
        assert!((sector - 360.0).abs() < 1e-6, "n={n}: {sector}");
        // At the fit limit the outermost weights touch diametrically opposite.
        let s = dimensionless_capacity(Shape::Roller, n, rho).unwrap();
        assert!(
            s.abs() < 1e-12,
            "n={n}: a full ring has no capacity, got {s}"
        );
    }
}

#[test]
fn capacity_grows_with_density_radius_and_height() {
    let base = capacity(Shape::Roller, 3, 0.3, 7800.0, 0.05, 0.01).unwrap();
    assert!(capacity(Shape::Roller, 3, 0.3, 7900.0, 0.05, 0.01).unwrap() > base);
    assert!(capacity(Shape::Roller, 3, 0.3, 7800.0, 0.06, 0.01).unwrap() > base);
    assert!(capacity(Shape::Roller, 3, 0.3, 7800.0, 0.05, 0.02).unwrap() > base);
}

#[test]
fn excess_weights_appear_where_the_paper_says() {
    // Seed 000: Fig. 7 "is correct" (no excess weights) for n = 2..4 balls and
    // n = 2..7 rollers; excess weights exist for balls from n = 5 and rollers from n = 8.
    for n in 1..=4 {
        assert_eq!(
            optimal_row(Shape::Ball, n).unwrap().excess,
            0,
            "balls n={n}"
        );
    }
    for n in 1..=7 {
        assert_eq!(
            optimal_row(Shape::Roller, n).unwrap().excess,
            0,
            "rollers n={n}"
        );
    }
    for n in 5..=8 {
        assert!(
            optimal_row(Shape::Ball, n).unwrap().excess > 0,
            "balls n={n}"
        );
    }
    for n in 8..=12 {
        assert!(
            optimal_row(Shape::Roller, n).unwrap().excess > 0,
            "rollers n={n}"
        );
    }
    // Pressed symmetrically, excess weights come in pairs and are never all of them.
    for n in 1..=30 {
        let e = excess_weights(n, optimal_rho(Shape::Ball, n).unwrap().rho).unwrap();
        assert_eq!(e % 2, 0);
        assert!(e < n);
    }
}

#[test]
fn out_of_domain_inputs_are_typed_errors_naming_the_value() {
    assert_eq!(
        dimensionless_capacity(Shape::Ball, 0, 0.3),
        Err(DesignError::ZeroWeights)
    );
    for rho in [0.0, -0.1, 1.0, 1.5, f64::NAN] {
        let err = dimensionless_capacity(Shape::Ball, 1, rho).unwrap_err();
        assert!(
            matches!(err, DesignError::RhoOutOfRange { .. }),
            "{rho}: {err}"
        );
    }
    let err = dimensionless_capacity(Shape::Roller, 5, 0.9).unwrap_err();
    assert!(matches!(err, DesignError::DoesNotFit { n: 5, .. }));
    let msg = err.to_string();
    assert!(
        msg.contains("0.9") && msg.contains("ρ_max(5)") && msg.contains("0.370"),
        "{msg}"
    );
    let err = capacity(Shape::Ball, 3, 0.3, -1.0, 0.1, 0.0).unwrap_err();
    assert!(err.to_string().contains("density"), "{err}");
}
