//! The motor presets of the repository's `motors/` folder, compiled in: one TOML document per
//! motor (`[motor]` with the ratings, `[inverter]` with at least the DC link), each naming its
//! source in its first comment line. `fado-sim motors` lists them; any of them is a valid
//! `--config` file, and [`Preset::machine`] gives its data as the drive's model.

use fado_core::MachineModel;

use crate::config::SimConfig;
use crate::error::SimConfigError;

/// A motor preset: its name (the file stem) and its TOML text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Preset {
    /// Name, as in `motors/<name>.toml`.
    pub name: &'static str,
    /// The TOML document.
    pub toml: &'static str,
}

macro_rules! presets {
    ($($name:literal),* $(,)?) => {
        /// Every preset of `motors/`, in alphabetical order.
        pub const PRESETS: &[Preset] = &[$(Preset {
            name: $name,
            toml: include_str!(concat!("../../../motors/", $name, ".toml")),
        }),*];
    };
}

presets!(
    "hub-hoverboard-48v",
    "ipmsm-2k2",
    "ipmsm-gem-50k",
    "multirotor-mn5006-22v",
    "outrunner-cheetah-24v",
    "paper",
    "pmsyrm-5k",
    "servo-1ft6084",
);

/// The preset called `name`.
pub fn find(name: &str) -> Option<&'static Preset> {
    PRESETS.iter().find(|p| p.name == name)
}

impl Preset {
    /// The one-line description: the file's first comment line without its `# name:` head.
    pub fn description(&self) -> &'static str {
        let first = self.toml.lines().next().unwrap_or("");
        let text = first.trim_start_matches('#').trim();
        text.split_once(": ").map_or(text, |(_, rest)| rest)
    }

    /// The preset as a simulation configuration (over the defaults).
    pub fn config(&self) -> Result<SimConfig, SimConfigError> {
        SimConfig::from_toml(self.toml).map_err(|e| e.in_file(format!("motors/{}.toml", self.name)))
    }

    /// The preset's motor as a drive's model, with the DC link of its inverter.
    pub fn machine(&self) -> Result<MachineModel<f64>, SimConfigError> {
        let c = self.config()?;
        Ok(c.motor.with_dc_voltage(c.inverter.dc_voltage))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_file_of_the_folder_is_a_valid_preset() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../motors");
        let mut files: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .filter_map(|e| {
                let p = e.unwrap().path();
                (p.extension()? == "toml").then(|| p.file_stem().unwrap().to_string_lossy().into())
            })
            .collect();
        files.sort();
        let names: Vec<&str> = PRESETS.iter().map(|p| p.name).collect();
        assert_eq!(files, names, "motors/ and PRESETS disagree");
        for p in PRESETS {
            let m = p.machine().unwrap_or_else(|e| panic!("{}: {e}", p.name));
            m.validate().unwrap();
            assert!(!p.description().is_empty(), "{}", p.name);
        }
        let paper = find("paper").unwrap().machine().unwrap();
        let core = MachineModel::<f64>::paper();
        assert_eq!(paper.with_dc_voltage(core.dc_voltage), core);
        assert!(find("ipmsm-2k2").unwrap().machine().unwrap().is_salient());
        // The interior-magnet motor with Lq/Ld ≥ 1.5.
        let gem = find("ipmsm-gem-50k").unwrap().machine().unwrap();
        assert!(gem.lq / gem.ld >= 1.5, "{gem:?}");
    }
}
