//! What the tests of datasheet machines (`unseen_datasheets.rs`, `unseen_motor_tables.rs`)
//! share: the scenarios every machine runs and the machines' files.

/// The scenarios every machine runs.
pub const SCENARIOS: [&str; 6] = [
    "reversal",
    "stops",
    "rated-reversal",
    "loaded-start",
    "fullrange",
    "regen-stop",
];

/// The text of `tests/data/unseen/<name>.toml`.
pub fn file(name: &str) -> String {
    let path = format!(
        "{}/tests/data/unseen/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    std::fs::read_to_string(path).unwrap()
}
