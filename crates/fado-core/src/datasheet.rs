//! Motor data as datasheets state them: the alternative `[motor]` keys (and `fado.Machine`
//! fields) a user may give instead of fado's per-phase, peak, SI values, and the one
//! conversion of each. Datasheets give the resistance and inductance between two terminals
//! (twice the phase's of a star-connected winding), the back-EMF constant as a line-to-line
//! voltage per 1000 r/min — rms (Kollmorgen, Siemens and most servo makers: "effective
//! sinusoidal value between two terminals") or peak (maxon, BLDC makers: the DC voltage of
//! block commutation) — the torque constant per ampere rms and the currents rms. Each
//! alternative replaces one fado key (`l_line_to_line` both inductances); giving an
//! alternative and its fado key, or two alternatives of one key, is refused naming both.
//!
//! | key | unit | fado key | conversion |
//! |---|---|---|---|
//! | `rs_line_to_line` | Ω | `rs` | R_LL/2 |
//! | `l_line_to_line` | H | `ld`, `lq` | L_LL/2 (the average over the rotor's position on a salient rotor: give `ld` and `lq` for an IPM) |
//! | `ke_vll_rms_per_krpm` | V rms per 1000 r/min | `flux_linkage` | Ke·√2/√3 / (p·1000·2π/60) |
//! | `ke_vll_peak_per_krpm` | V peak per 1000 r/min | `flux_linkage` | Ke/√3 / (p·1000·2π/60) |
//! | `kt_nm_per_arms` | N·m per A rms | `flux_linkage` | Kt/(1.5·√2·p) (the magnet torque per ampere) |
//! | `rated_current_arms` | A rms | `rated_current` | √2·I |
//! | `kv_rpm_per_volt` | r/min per V (peak line-to-line) | `flux_linkage` | 60/(2π·√3·p·Kv) = 5.513/(p·Kv) |
//! | `inertia_kg_cm2` | kg·cm² | `inertia` | J·10⁻⁴ |
//!
//! Kv (hobby and robotics motors) is the no-load speed per volt of the supply, which a
//! sinusoidally driven motor reaches when its peak line-to-line back-EMF equals it: a
//! 100 r/min/V, 7-pole-pair outrunner has λf = 7.88 mWb (`examples/motors/my-outrunner.toml`).
//! Servo datasheets give the rotor inertia in kg·cm² (10⁻⁴ kg·m²).

use crate::Real;

/// One alternative key.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Alternative {
    /// The datasheet key.
    pub key: &'static str,
    /// The fado keys it gives.
    pub targets: &'static [&'static str],
    /// Its unit.
    pub unit: &'static str,
    /// The conversion, in words (what `--dump-config` prints beside the value).
    pub rule: &'static str,
    /// True when the conversion needs the pole pairs.
    pub needs_pole_pairs: bool,
}

/// Every alternative key.
pub const ALTERNATIVES: [Alternative; 8] = [
    Alternative {
        key: "rs_line_to_line",
        targets: &["rs"],
        unit: "Ω",
        rule: "from rs_line_to_line (Ω between two terminals): rs = R_LL/2",
        needs_pole_pairs: false,
    },
    Alternative {
        key: "l_line_to_line",
        targets: &["ld", "lq"],
        unit: "H",
        rule: "from l_line_to_line (H between two terminals): ld = lq = L_LL/2",
        needs_pole_pairs: false,
    },
    Alternative {
        key: "ke_vll_rms_per_krpm",
        targets: &["flux_linkage"],
        unit: "V rms line-to-line per 1000 r/min",
        rule: "from ke_vll_rms_per_krpm (V rms line-to-line per 1000 r/min): λf = Ke·√2/√3/(p·1000·2π/60)",
        needs_pole_pairs: true,
    },
    Alternative {
        key: "ke_vll_peak_per_krpm",
        targets: &["flux_linkage"],
        unit: "V peak line-to-line per 1000 r/min",
        rule: "from ke_vll_peak_per_krpm (V peak line-to-line per 1000 r/min): λf = Ke/√3/(p·1000·2π/60)",
        needs_pole_pairs: true,
    },
    Alternative {
        key: "kt_nm_per_arms",
        targets: &["flux_linkage"],
        unit: "N·m per A rms",
        rule: "from kt_nm_per_arms (N·m per A rms): λf = Kt/(1.5·√2·p)",
        needs_pole_pairs: true,
    },
    Alternative {
        key: "rated_current_arms",
        targets: &["rated_current"],
        unit: "A rms",
        rule: "from rated_current_arms (A rms): rated_current = √2·I_rms",
        needs_pole_pairs: false,
    },
    Alternative {
        key: "kv_rpm_per_volt",
        targets: &["flux_linkage"],
        unit: "r/min per V, peak line-to-line back-EMF",
        rule: "from kv_rpm_per_volt (r/min per V, peak line-to-line): λf = 60/(2π·√3·p·Kv)",
        needs_pole_pairs: true,
    },
    Alternative {
        key: "inertia_kg_cm2",
        targets: &["inertia"],
        unit: "kg·cm²",
        rule: "from inertia_kg_cm2 (kg·cm²): inertia = J·1e-4",
        needs_pole_pairs: false,
    },
];

/// The alternative called `key`, if it is one.
pub fn alternative(key: &str) -> Option<&'static Alternative> {
    ALTERNATIVES.iter().find(|a| a.key == key)
}

/// The value of `alt`'s fado keys for the datasheet value `value` on a motor with
/// `pole_pairs` (used only where the conversion needs it).
pub fn convert(alt: &Alternative, value: f64, pole_pairs: f64) -> f64 {
    let sqrt2 = 2f64.step_sqrt();
    let sqrt3 = 3f64.step_sqrt();
    let per_krpm = |ke: f64| ke / (pole_pairs * 1000.0 * core::f64::consts::PI / 30.0);
    match alt.key {
        "rs_line_to_line" | "l_line_to_line" => value / 2.0,
        "ke_vll_rms_per_krpm" => per_krpm(value * sqrt2 / sqrt3),
        "ke_vll_peak_per_krpm" => per_krpm(value / sqrt3),
        "kt_nm_per_arms" => value / (1.5 * sqrt2 * pole_pairs),
        "kv_rpm_per_volt" => 30.0 / (core::f64::consts::PI * sqrt3 * pole_pairs * value),
        "inertia_kg_cm2" => value * 1e-4,
        _ => value * sqrt2,
    }
}

/// Why the keys `given` (a motor's keys) cannot be converted: `(key, message)` naming the
/// first alternative given with its fado key or with another alternative of the same key.
pub fn conflict<'a>(
    given: impl Iterator<Item = &'a str> + Clone,
) -> Option<(&'a str, &'static str, &'static str)> {
    for a in given.clone().filter_map(alternative) {
        for other in given.clone() {
            if other == a.key {
                continue;
            }
            let clash = a.targets.contains(&other)
                || alternative(other)
                    .is_some_and(|b| b.targets.iter().any(|t| a.targets.contains(t)));
            if clash {
                return Some((other, a.key, a.targets[0]));
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversions_match_the_datasheets_own_consistency() {
        // A 4-pole servo (Ke 51 V peak/krpm, Kt 0.49 N·m per DC ampere): λf 0.1406 Wb.
        let ke = convert(alternative("ke_vll_peak_per_krpm").unwrap(), 51.0, 2.0);
        assert!((ke - 0.1406).abs() < 1e-4, "{ke}");
        // Kt per A rms and Ke rms of one sinusoidal motor agree: Kt = √3·Ke_rms/(1000·2π/60)
        // (SI), so both give one λf.
        let ke_rms = 60.0;
        let kt = 3f64.step_sqrt() * ke_rms / (1000.0 * core::f64::consts::PI / 30.0);
        let a = convert(alternative("ke_vll_rms_per_krpm").unwrap(), ke_rms, 3.0);
        let b = convert(alternative("kt_nm_per_arms").unwrap(), kt, 3.0);
        assert!((a / b - 1.0).abs() < 1e-12, "{a} {b}");
        assert_eq!(
            convert(alternative("rs_line_to_line").unwrap(), 0.641, 1.0),
            0.3205
        );
        // Kv 100 r/min/V on 7 pole pairs: 5.513/(7·100) = 7.88 mWb, and Kv is Ke peak
        // line-to-line per 1000 r/min inverted (1000/Kv V per 1000 r/min).
        let kv = convert(alternative("kv_rpm_per_volt").unwrap(), 100.0, 7.0);
        assert!((kv - 7.876e-3).abs() < 1e-6, "{kv}");
        let ke = convert(alternative("ke_vll_peak_per_krpm").unwrap(), 10.0, 7.0);
        assert!((kv / ke - 1.0).abs() < 1e-12, "{kv} {ke}");
        let j = convert(alternative("inertia_kg_cm2").unwrap(), 2.5, 1.0);
        assert!((j - 2.5e-4).abs() < 1e-18, "{j}");
    }

    #[test]
    fn an_alternative_with_its_fado_key_or_a_twin_is_a_conflict() {
        let keys = ["rs", "rs_line_to_line"];
        assert_eq!(
            conflict(keys.iter().copied()),
            Some(("rs", "rs_line_to_line", "rs"))
        );
        let keys = ["kt_nm_per_arms", "ke_vll_rms_per_krpm"];
        assert!(conflict(keys.iter().copied()).is_some());
        let keys = ["l_line_to_line", "lq"];
        assert!(conflict(keys.iter().copied()).is_some());
        let keys = [
            "rs_line_to_line",
            "l_line_to_line",
            "kt_nm_per_arms",
            "rated_current_arms",
        ];
        assert_eq!(conflict(keys.iter().copied()), None);
    }
}
