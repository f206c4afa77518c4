//! The slips of a datasheet's values (a winding line-to-line, a DC link given as the mains'
//! rms voltage, a flux linkage from Kt per A rms taken as peak), each on real machines.

use super::tests::{first, ipmsm, paper, servo_400w};
use super::*;
use std::string::ToString;

/// `motors/servo-1ft6084.toml` (Siemens 1FT6084, 14 N·m at 19 A peak, 4500 r/min, 565 V).
fn servo_1ft6084() -> MachineModel<f64> {
    MachineModel {
        rs: 0.268,
        ld: 2.2e-3,
        lq: 2.2e-3,
        flux_linkage: 0.12258,
        pole_pairs: 4,
        inertia: 0.0146,
        viscous_friction: 0.0,
        rated_current: 19.0,
        rated_speed_rpm: 4500.0,
        rated_torque: 14.0,
        dc_voltage: 565.0,
        magnetics: Default::default(),
    }
}

/// `rs`, `ld` and `lq` entered line-to-line (2 × the phase's, as datasheets give them
/// between two terminals) on the 2.2 kW IPMSM: the rated point then needs 379 V phase peak,
/// 1.22 × its 540 V link's 312 V (0.965 with the phase values); the warning names the link
/// and the line-to-line winding with the phase values that fit the link.
#[test]
fn a_winding_given_line_to_line_is_named_with_its_phase_values_where_the_link_shows_it() {
    let phase = ipmsm();
    assert!(check(&phase, None).is_empty(), "{}", first(&phase, None));
    let ll = MachineModel {
        rs: 2.0 * phase.rs,
        ld: 2.0 * phase.ld,
        lq: 2.0 * phase.lq,
        ..phase
    };
    let f = first(&ll, None);
    assert!(matches!(f, Finding::DcLinkShort { .. }), "{f}");
    let text = f.to_string();
    assert!(
        text.contains("1.22 ×")
            && text.contains("line-to-line")
            && text.contains("rs = 3.6e0 Ω, ld = 3.6e-2 H, lq = 5.1e-2 H"),
        "{text}"
    );
    for key in ["rs", "ld", "lq", "dc_voltage"] {
        assert!(f.keys().contains(&key), "{key}: {:?}", f.keys());
    }
    // The paper's motor needs 0.40 of its link: a line-to-line winding (0.44) does not show.
    let paper_ll = MachineModel {
        rs: 2.0 * paper().rs,
        ld: 2.0 * paper().ld,
        lq: 2.0 * paper().lq,
        ..paper()
    };
    assert!(
        check(&paper_ll, None).is_empty(),
        "{}",
        first(&paper_ll, None)
    );
}

/// The GBM5208 gimbal motor (8.5 Ω per phase, drop 1.876 × its back-EMF, warned) with its
/// 17 Ω line-to-line resistance: 3.75, refused, naming the phase value 8.5 Ω.
#[test]
fn a_resistance_given_line_to_line_is_named_with_its_phase_value() {
    let gimbal = MachineModel::<f64> {
        rs: 17.0,
        ld: 5.4e-3,
        lq: 5.4e-3,
        flux_linkage: 30.9e-3,
        pole_pairs: 7,
        inertia: 1e-4,
        viscous_friction: 0.0,
        rated_current: 0.5,
        rated_speed_rpm: 100.0,
        rated_torque: 0.16,
        dc_voltage: 14.8,
        magnetics: Default::default(),
    };
    let f = first(&gimbal, None);
    assert_eq!((f.key(), f.severity()), ("rs", Severity::Error), "{f}");
    let text = f.to_string();
    assert!(
        text.contains("3.75") && text.contains("line-to-line") && text.contains("rs = 8.5e0 Ω"),
        "{text}"
    );
    // A drop beyond the bound even halved (mΩ for Ω, 1000 ×) names no line-to-line value.
    let milli = MachineModel {
        rs: 8.5e3,
        ..gimbal
    };
    assert!(!first(&milli, None).to_string().contains("line-to-line"));
}

/// A DC link entered as the mains' rms voltage: the 1FT6084 servo (565 V link, rated point
/// 0.76 of it) on "400 V", the 400 W servo (310 V, 0.52) on "230 V", the 2.2 kW IPMSM
/// (540 V, 0.965) on "400 V" (1.30: beyond the link, the short-link warning names √2 × 400).
/// A real 400 V battery link whose rated point needs 0.63 of it (a 50 kW traction machine),
/// and the same machines on a link that is no mains' voltage, are not named.
#[test]
fn a_dc_link_given_as_the_mains_rms_voltage_is_named_with_the_rectified_link() {
    let servo = servo_1ft6084();
    let link =
        |m: &MachineModel<f64>| ratings::rated_point_voltage(m) / (m.dc_voltage / 3f64.sqrt());
    assert!(check(&servo, None).is_empty(), "{}", first(&servo, None));
    let mains = MachineModel {
        dc_voltage: 400.0,
        ..servo
    };
    let f = first(&mains, None);
    assert!(
        matches!(f, Finding::DcLinkMains { .. }),
        "{f} ({:.3})",
        link(&mains)
    );
    assert_eq!((f.key(), f.severity()), ("dc_voltage", Severity::Warning));
    assert!(f.to_string().contains("dc_voltage = 566?"), "{f}");
    // The 400 W servo on 230 V needs 0.70 of it: below the bound, unnamed.
    let small = MachineModel {
        dc_voltage: 230.0,
        ..servo_400w()
    };
    assert!(link(&small) < MAINS_LINK_RATIO, "{:.3}", link(&small));
    assert!(check(&small, None).is_empty(), "{}", first(&small, None));
    // Beyond the link: the short-link warning with the rectified value.
    let ipm = MachineModel {
        dc_voltage: 400.0,
        ..ipmsm()
    };
    let f = first(&ipm, None);
    assert!(matches!(f, Finding::DcLinkShort { .. }), "{f}");
    assert!(f.to_string().contains("√2 × it, 566 V"), "{f}");
    // The 50 kW traction machine of fado-sim's `tests/data/classes/` on its real 400 V battery
    // (0.63 of it), and the servo on a 420 V link (no mains' voltage): no finding.
    let traction = MachineModel::<f64> {
        rs: 0.01,
        ld: 0.2e-3,
        lq: 0.5e-3,
        flux_linkage: 0.08,
        pole_pairs: 4,
        inertia: 0.05,
        viscous_friction: 0.0,
        rated_current: 300.0,
        rated_speed_rpm: 2500.0,
        rated_torque: 190.0,
        dc_voltage: 400.0,
        magnetics: Default::default(),
    };
    let v = link(&traction);
    assert!(
        check(&traction, None).is_empty(),
        "{} ({v:.3})",
        first(&traction, None)
    );
    let odd = MachineModel {
        dc_voltage: 420.0,
        ..servo
    };
    assert!(check(&odd, None).is_empty(), "{}", first(&odd, None));
}

/// A torque constant per A rms converted as per A peak (λf = Kt/(1.5·p), √2 too large): the
/// 1FT6084 servo (Kt 0.7355 N·m/A peak) and the 400 W servo then have a rated torque 0.71 ×
/// the model's, inside the wide band; the warning names `flux_linkage` with the value
/// undone. A line-to-line λf (0.58) stays named as such.
#[test]
fn a_flux_linkage_from_a_kt_per_ampere_rms_taken_as_peak_is_named_with_its_value() {
    let servo = servo_1ft6084();
    for m in [servo, servo_400w()] {
        let kt = MachineModel {
            flux_linkage: m.flux_linkage * 2f64.sqrt(),
            ..m
        };
        let f = first(&kt, None);
        let slip = match f {
            Finding::Torque { slip, .. } => Some(slip),
            _ => None,
        };
        assert_eq!(slip, Some(TorqueSlip::KtRms), "{f}");
        assert_eq!((f.key(), f.severity()), ("flux_linkage", Severity::Warning));
        let text = f.to_string();
        assert!(
            text.contains(" × the torque") && text.contains("kt_nm_per_arms"),
            "{text}"
        );
        assert!(
            text.contains(&std::format!("flux_linkage = {:e} Wb", m.flux_linkage)),
            "{text}"
        );
    }
    let ll = MachineModel {
        flux_linkage: servo.flux_linkage * 3f64.sqrt(),
        ..servo
    };
    let f = first(&ll, None);
    assert!(matches!(f, Finding::Torque { .. }), "{f}");
    assert!(f.to_string().contains("line-to-line constant"), "{f}");
}

/// A line-to-line rms back-EMF constant taken as the phase peak (λf = E_LL,rms/ω where
/// √2·E_LL,rms/(√3·ω) is meant: √(3/2) = 1.22 too large) puts the rated torque at 0.80–0.82 ×
/// the model's, inside the wide band: on the 1FT6084 and the 400 W servo the warning names
/// `flux_linkage` with the value undone; the other λf slips keep their own names.
#[test]
fn a_flux_linkage_from_a_line_to_line_rms_constant_taken_as_peak_is_named_with_its_value() {
    for m in [servo_1ft6084(), servo_400w()] {
        assert!(check(&m, None).is_empty(), "{}", first(&m, None));
        let slip = MachineModel {
            flux_linkage: m.flux_linkage * 1.5f64.sqrt(),
            ..m
        };
        let f = first(&slip, None);
        assert!(
            matches!(
                f,
                Finding::Torque {
                    slip: TorqueSlip::LineRmsAsPhasePeak,
                    ..
                }
            ),
            "{f}"
        );
        assert_eq!((f.key(), f.severity()), ("flux_linkage", Severity::Warning));
        let text = f.to_string();
        assert!(
            text.contains("line-to-line rms back-EMF taken as the phase peak"),
            "{text}"
        );
        let given: f64 = text
            .split("flux_linkage = ")
            .nth(1)
            .and_then(|s| s.split(' ').next())
            .and_then(|v| v.parse().ok())
            .expect("the value undone");
        assert!((given / m.flux_linkage - 1.0).abs() < 1e-12, "{text}");
    }
    let kt = MachineModel {
        flux_linkage: servo_400w().flux_linkage * 2f64.sqrt(),
        ..servo_400w()
    };
    let f = first(&kt, None);
    assert!(
        matches!(
            f,
            Finding::Torque {
                slip: TorqueSlip::KtRms,
                ..
            }
        ),
        "{f}"
    );
}

/// A rated speed in rad/s where r/min is meant (× π/30): the 400 W servo's rated point then
/// needs 8 % of its 310 V link (an error), the 1FT6084's 11 %; the finding blames
/// `rated_speed_rpm` and gives the speed undone, not a line-to-line `rs`. Ratings divided by
/// 10 (which the speed undone can fit too) stay named.
#[test]
fn a_rated_speed_in_rad_per_s_is_named_with_the_speed_it_means() {
    for m in [servo_400w(), servo_1ft6084()] {
        let slip = MachineModel {
            rated_speed_rpm: m.rated_speed_rpm * core::f64::consts::PI / 30.0,
            ..m
        };
        let findings = check(&slip, None);
        let dc = findings
            .iter()
            .find(|f| matches!(f, Finding::DcLinkOversized { .. }))
            .expect("the DC link's finding");
        assert_eq!(dc.key(), "rated_speed_rpm");
        let text = dc.to_string();
        assert!(
            text.contains(&std::format!("rated_speed_rpm = {:.0}", m.rated_speed_rpm)),
            "{text}"
        );
        for f in findings.iter() {
            if let Finding::Resistance { line_to_line, .. } = f {
                assert_eq!(*line_to_line, None, "{f}");
                assert_eq!(f.key(), "rated_speed_rpm", "{f}");
            }
        }
    }
    let mut tenth = servo_400w();
    tenth.rated_current /= 10.0;
    tenth.rated_speed_rpm /= 10.0;
    tenth.rated_torque /= 10.0;
    let f = first(&tenth, None);
    assert!(f.to_string().contains("divided by 10"), "{f}");
}
