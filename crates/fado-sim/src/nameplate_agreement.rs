//! What a commissioning told about a motor (its nameplate) against what it measured.
//!
//! The procedure's standstill test measures the stator resistance as it is, phase to neutral
//! (R̂s within 0.05 % on every preset, docs/results/commissioning.md). A nameplate whose `rs`
//! is twice that is the usual slip of a datasheet's terminal resistance, measured between two
//! terminals of a star winding (2·Rs), taken for the phase value; half of it, a value halved
//! once too often. Temperature alone moves a copper winding's resistance by 0.39 %/K, so a
//! datasheet's 20 °C value against a winding at 120 °C is 0.72 ×, and a hot value against a
//! cold winding 1.39 ×: both inside the bands' gap.

/// The range of the nameplate's `rs` over the measured R̂s that names a line-to-line value:
/// 2 ± 15 % (beyond the 1.39 a winding's temperature gives).
pub const LINE_TO_LINE: (f64, f64) = (1.7, 2.35);

/// The range that names a value halved once too often: ½ ± 15 %.
pub const HALVED: (f64, f64) = (0.42, 0.59);

/// A warning naming `key` (the nameplate's `rs`, e.g. `motor.rs`) where `stated` (Ω) is twice
/// or half the `measured` R̂s (Ω); None where they agree as the same winding's can.
pub fn resistance(key: &str, stated: f64, measured: f64) -> Option<String> {
    let ratio = stated / measured;
    let slip = if (LINE_TO_LINE.0..=LINE_TO_LINE.1).contains(&ratio) {
        "line-to-line? A datasheet's terminal resistance is measured between two terminals, \
         2·Rs for a star winding: give half of it"
    } else if (HALVED.0..=HALVED.1).contains(&ratio) {
        "halved twice? The phase value is half the line-to-line one, once"
    } else {
        return None;
    };
    Some(format!(
        "`{key}` = {stated} Ω is {ratio:.2} × the {measured:.4e} Ω the standstill test measured \
         phase to neutral: {slip} (identified.toml holds the measured value)"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn twice_and_half_the_measured_resistance_are_named_and_temperature_is_not() {
        let w = resistance("motor.rs", 2.0 * 0.63, 0.63).expect("line-to-line");
        assert!(
            w.contains("`motor.rs`") && w.contains("line-to-line"),
            "{w}"
        );
        let w = resistance("nameplate.rs", 0.5 * 0.63, 0.63).expect("halved");
        assert!(w.contains("`nameplate.rs`") && w.contains("halved"), "{w}");
        // The same winding 100 K apart, either way, and the measurement's own spread.
        for ratio in [1.0, 1.0005, 1.39, 0.72] {
            assert!(
                resistance("motor.rs", ratio * 0.63, 0.63).is_none(),
                "{ratio}"
            );
        }
    }
}
