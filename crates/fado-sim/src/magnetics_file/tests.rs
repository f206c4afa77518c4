//! The flux-map CSV format and the `[motor] flux_map` key: every refusal at its line, paths
//! relative to the TOML file, the map written and read back bit for bit.

use std::path::Path;

use fado_core::Dq;
use fado_core::magnetics::MagneticModel;

use super::*;
use crate::config::SimConfig;

#[test]
fn a_flux_map_file_is_read_in_any_row_order_and_bad_ones_are_refused_at_their_line() {
    let text = "# a 2 x 3 map\ni_d,i_q,psi_d,psi_q\n0,1,0.60,0.05\n-5,-1,0.40,-0.05\n0,0,0.60,0.0\n# note\n-5,0,0.40,0.0\n-5,1,0.40,0.05\n0,-1,0.60,-0.05\n";
    let data = parse_flux_map(text, "m.csv").unwrap();
    let map = data.map();
    assert_eq!(map.i_d(), &[-5.0, 0.0]);
    assert_eq!(map.i_q(), &[-1.0, 0.0, 1.0]);
    let psi = fado_core::MagneticModel::flux(&map, Dq::new(-2.5, 0.5));
    assert!((psi.d - 0.5).abs() < 1e-12 && (psi.q - 0.025).abs() < 1e-12);
    let err = |t: &str| parse_flux_map(t, "m.csv").unwrap_err().to_string();
    // Ragged: the node (0, 1) missing.
    let ragged = text.replace("0,1,0.60,0.05\n", "");
    assert!(err(&ragged).contains("ragged"), "{}", err(&ragged));
    // NaN, at its line.
    let nan = text.replace("-5,0,0.40,0.0", "-5,0,NaN,0.0");
    assert!(err(&nan).starts_with("m.csv:7:1:"), "{}", err(&nan));
    // Not monotonic in its own current: ψd falls from i_d = −5 to 0 at i_q = 1 (line 3).
    let flat = text.replace("0,1,0.60,0.05", "0,1,0.30,0.05");
    assert!(
        err(&flat).starts_with("m.csv:3:1:") && err(&flat).contains("increase"),
        "{}",
        err(&flat)
    );
    // A node twice, a bad header, a word.
    let twice = format!("{text}0,1,0.6,0.05\n");
    assert!(err(&twice).contains("twice"), "{}", err(&twice));
    assert!(err("id,iq,psi_d,psi_q\n").contains("header"));
    let word = text.replace("0,0,0.60,0.0", "0,0,big,0.0");
    assert!(err(&word).starts_with("m.csv:5:1:"), "{}", err(&word));
    // A file that does not exist names itself.
    let e = read_flux_map(Path::new("/nonexistent/map.csv"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("/nonexistent/map.csv"), "{e}");
}

#[test]
fn a_header_in_another_order_a_trailing_comma_a_bom_and_exponents_read_the_same_map() {
    let text =
        "i_d,i_q,psi_d,psi_q\n-5,-1,0.40,-0.05\n-5,1,0.40,0.05\n0,-1,0.60,-0.05\n0,1,0.60,0.05\n";
    let want = parse_flux_map(text, "m.csv").unwrap();
    // The columns by name: i_q first, ψq before ψd (each row in its header's order).
    let swapped =
        "i_q,i_d,psi_q,psi_d\n-1,-5,-0.05,0.40\n1,-5,0.05,0.40\n-1,0,-0.05,0.60\n1,0,0.05,0.60\n";
    // A spreadsheet's trailing comma on every line, a UTF-8 BOM, exponents and spaces.
    let trailing = text.replace('\n', ",\n");
    let bom = format!("\u{feff}{text}");
    let sci = "i_d,i_q,psi_d,psi_q\n-5e0, -1E0, 4.0e-1, -5e-2\n-5,1,0.40,0.05\n0,-1,6E-1,-0.05\n0,1,0.60,0.05\n";
    for variant in [swapped, trailing.as_str(), bom.as_str(), sci] {
        let got = parse_flux_map(variant, "m.csv").unwrap_or_else(|e| panic!("{e}\n{variant}"));
        assert_eq!(got.map().i_d(), want.map().i_d(), "{variant}");
        assert_eq!(got.map().i_q(), want.map().i_q(), "{variant}");
        let at = Dq::new(-2.5, 0.5);
        assert_eq!(
            MagneticModel::flux(&got.map(), at),
            MagneticModel::flux(&want.map(), at),
            "{variant}"
        );
    }
    let err = |t: &str| parse_flux_map(t, "m.csv").unwrap_err().to_string();
    // A value in the trailing comma's empty column, a name twice, units in the names.
    let fifth = trailing.replacen("0.05,\n", "0.05,7\n", 1);
    assert!(err(&fifth).contains("fifth value"), "{}", err(&fifth));
    let twice = text.replacen("psi_q", "psi_d", 1);
    assert!(err(&twice).contains("any order"), "{}", err(&twice));
    let units = text.replacen("psi_d,", "psi_d [Wb],", 1);
    assert!(err(&units).contains("no units"), "{}", err(&units));
}

#[test]
fn a_crlf_file_with_comments_and_blank_lines_is_refused_at_its_own_line() {
    // A lab's export: CRLF line ends, comments and a blank line before the header, a blank
    // line inside; the bad value is on line 8 whatever the line ends.
    let lf = "# lab map\n# 2 x 2\n\ni_d,i_q,psi_d,psi_q\n-5,-1,0.40,-0.05\n\n-5,1,0.40,0.05\n0,-1,x,-0.05\n0,1,0.60,0.05\n";
    let crlf = lf.replace('\n', "\r\n");
    for text in [lf, crlf.as_str()] {
        let e = parse_flux_map(text, "m.csv").unwrap_err().to_string();
        assert!(e.starts_with("m.csv:8:1:"), "{e}");
        let good = text.replace(",x,", ",0.60,");
        assert_eq!(
            parse_flux_map(&good, "m.csv").unwrap().map().i_d(),
            &[-5.0, 0.0]
        );
        let header = text
            .replace("psi_q\r", "psi_qq\r")
            .replace("psi_q\n", "psi_qq\n");
        let e = parse_flux_map(&header, "m.csv").unwrap_err().to_string();
        assert!(e.starts_with("m.csv:4:1:"), "{e}");
    }
}

#[test]
fn a_falling_map_is_told_apart_as_noise_or_swapped_axes() {
    // ψq along i_q at i_d = 0: one dip among rising steps (a measured map's noise), then the
    // whole line falling (the axes or signs swapped).
    let map = |q: [f64; 5]| {
        let mut t = String::from("i_d,i_q,psi_d,psi_q\n");
        for (m, iq) in [-2.0, -1.0, 0.0, 1.0, 2.0].iter().enumerate() {
            t += &format!("-1,{iq},0.5,{}\n0,{iq},0.6,{}\n", 0.02 * iq, q[m]);
        }
        parse_flux_map(&t, "m.csv").unwrap_err().to_string()
    };
    let noisy = map([-0.04, -0.02, 0.0, -0.001, 0.04]);
    assert!(
        noisy.starts_with("m.csv:9:1:") && noisy.contains("noise"),
        "{noisy}"
    );
    assert!(noisy.contains("-0.001000 Wb at i_q = 1 A"), "{noisy}");
    let swapped = map([0.04, 0.02, 0.0, -0.02, -0.04]);
    assert!(swapped.contains("axes and signs"), "{swapped}");
}

/// A scratch directory of this test process.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("fado-magfile-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// ipmsm-2k2's machine with q self- and cross-saturation, tabulated on a 9 × 11 grid.
fn tabulated() -> FluxMapData {
    tabulated_from(-12.0)
}

/// The same machine on 9 nodes of i_d from `i_d0` A in steps of 1.5 A.
fn tabulated_from(i_d0: f64) -> FluxMapData {
    let s = crate::magnetics::tests::saturated_ipm();
    let i_d: Vec<f64> = (0..9).map(|k| i_d0 + 1.5 * k as f64).collect();
    let i_q: Vec<f64> = (0..11).map(|m| -10.0 + 2.0 * m as f64).collect();
    let (mut psi_d, mut psi_q) = (Vec::new(), Vec::new());
    for &id in &i_d {
        for &iq in &i_q {
            let psi = s.flux(Dq::new(id, iq));
            psi_d.push(psi.d);
            psi_q.push(psi.q);
        }
    }
    FluxMapData::new(i_d, i_q, psi_d, psi_q).unwrap()
}

/// ipmsm-2k2's file with `extra` lines at the end of its `[motor]` table.
fn preset_with(extra: &str) -> String {
    let text = include_str!("../../../../motors/ipmsm-2k2.toml");
    let at = text.find("[motor]\n").unwrap() + "[motor]\n".len();
    format!("{}{extra}{}", &text[..at], &text[at..])
}

#[test]
fn a_written_map_reads_back_bit_for_bit() {
    let data = tabulated();
    let text = flux_map_csv(&data, "ipmsm-2k2 with saturation\nsecond line");
    assert!(text.starts_with("# ipmsm-2k2 with saturation\n# second line\ni_d,i_q,psi_d,psi_q\n"));
    assert_eq!(parse_flux_map(&text, "w.csv").unwrap(), data);
}

#[test]
fn a_configuration_names_its_map_relative_to_its_own_directory() {
    let dir = scratch("relative");
    std::fs::write(dir.join("map.csv"), flux_map_csv(&tabulated(), "test")).unwrap();
    set_config_dir(Some(&dir));
    let cfg = SimConfig::from_toml(&preset_with("flux_map = \"map.csv\"\n"));
    set_config_dir(None);
    let cfg = cfg.unwrap();
    let map = cfg.motor_flux_map.as_ref().unwrap();
    assert_eq!(map.path, Some(dir.join("map.csv")));
    assert_eq!(*map.data, tabulated());
    assert!(matches!(
        cfg.plant().magnetics.as_deref(),
        Some(PlantMagnetics::Map(m)) if *m == tabulated()
    ));
    // Written back with the resolved path: the dump reads anywhere.
    let again = SimConfig::from_toml(&cfg.to_toml()).unwrap();
    assert_eq!(again.motor_flux_map, cfg.motor_flux_map);
    // A document over it that gives no magnetics keeps the map; one that gives the algebraic
    // model replaces it.
    let over = SimConfig::from_toml_over(&cfg, "[motor]\nrs = 3.0\n").unwrap();
    assert_eq!(over.motor_flux_map, cfg.motor_flux_map);
    let sat = "[motor.saturation]\na_d0 = 27.8\na_q0 = 19.6\npsi_f = 0.545\n";
    let over = SimConfig::from_toml_over(&cfg, sat).unwrap();
    assert!(over.motor_flux_map.is_none() && over.motor_saturation.is_some());
}

#[test]
fn a_missing_file_a_bad_value_and_two_models_are_refused_at_the_key() {
    let text = preset_with("flux_map = \"/nonexistent/map.csv\"\n");
    let e = SimConfig::from_toml(&text).unwrap_err();
    assert_eq!(e.key, FLUX_MAP_KEY, "{e}");
    assert!(e.message.contains("/nonexistent/map.csv"), "{e}");
    let line = text
        .lines()
        .position(|l| l.starts_with("flux_map"))
        .unwrap()
        + 1;
    assert_eq!(e.location.as_ref().map(|l| l.line), Some(line), "{e}");
    let e = SimConfig::from_toml(&preset_with("flux_map = 3\n")).unwrap_err();
    assert!(e.key == FLUX_MAP_KEY && e.message.contains("string"), "{e}");
    let dir = scratch("both");
    let path = dir.join("m.csv");
    std::fs::write(&path, flux_map_csv(&tabulated(), "")).unwrap();
    let both = format!(
        "{}\n[motor.saturation]\na_d0 = 27.8\na_q0 = 19.6\n",
        preset_with(&format!("flux_map = \"{}\"\n", path.display()))
    );
    let e = SimConfig::from_toml(&both).unwrap_err();
    assert!(e.key == FLUX_MAP_KEY && e.message.contains("both"), "{e}");
}

#[test]
fn an_error_inside_the_map_names_the_csv_file_and_line() {
    let dir = scratch("inside");
    let path = dir.join("bad.csv");
    let good = flux_map_csv(&tabulated(), "");
    // Line 1 is the header; line 5 the fourth node.
    let mut lines: Vec<String> = good.lines().map(str::to_owned).collect();
    let cells: Vec<&str> = lines[4].split(',').collect();
    lines[4] = format!("{},{},NaN,{}", cells[0], cells[1], cells[3]);
    std::fs::write(&path, lines.join("\n")).unwrap();
    let text = preset_with(&format!("flux_map = \"{}\"\n", path.display()));
    let e = SimConfig::from_toml(&text)
        .unwrap_err()
        .in_file("motor.toml");
    let s = e.to_string();
    assert!(s.starts_with(&format!("{}:5:1:", path.display())), "{s}");
}

#[test]
fn the_drive_model_takes_its_own_map_under_model() {
    use fado_core::magnetics::MachineMagnetics;
    let dir = scratch("model");
    std::fs::write(dir.join("model.csv"), flux_map_csv(&tabulated(), "model")).unwrap();
    set_config_dir(Some(&dir));
    let text = format!("{}\n[model]\nflux_map = \"model.csv\"\n", preset_with(""));
    let cfg = SimConfig::from_toml(&text);
    set_config_dir(None);
    let cfg = cfg.unwrap();
    // The plant stays linear; the drive's model is the map, in f64 and rounded to f32.
    assert!(cfg.plant().magnetics.is_none());
    let machine = cfg.drive_config().machine;
    assert!(
        matches!(machine.magnetics, MachineMagnetics::Map(m) if m.i_d() == tabulated().map().i_d())
    );
    assert!(cfg.build_drive_f32().is_ok());
    let e = SimConfig::from_toml(&format!(
        "{}\n[model]\nflux_map = \"/nonexistent.csv\"\n",
        preset_with("")
    ))
    .unwrap_err();
    assert_eq!(e.key, "model.flux_map", "{e}");
    assert!(e.message.contains("/nonexistent.csv"), "{e}");
}

#[test]
fn a_map_in_other_units_or_on_other_axes_than_the_motor_is_refused() {
    // ipmsm-2k2's saturated map against its own [motor] values: accepted. The same map in
    // mVs, and in SyR-e's frame (d on the high-permeance axis, the magnet along −q): refused
    // at `motor.flux_map`, naming the key it disagrees with.
    let dir = scratch("agreement");
    let good = tabulated();
    let m = good.map();
    let write = |name: &str, data: &FluxMapData| {
        std::fs::write(dir.join(name), flux_map_csv(data, "test")).unwrap();
        set_config_dir(Some(&dir));
        let cfg = SimConfig::from_toml(&preset_with(&format!("flux_map = \"{name}\"\n")));
        set_config_dir(None);
        cfg
    };
    assert!(write("good.csv", &good).is_ok());
    let scaled = |x: &[f64]| x.iter().map(|v| v * 1000.0).collect::<Vec<_>>();
    let mvs = FluxMapData::new(
        m.i_d().to_vec(),
        m.i_q().to_vec(),
        scaled(m.psi_d()),
        scaled(m.psi_q()),
    )
    .unwrap();
    let e = write("mvs.csv", &mvs).unwrap_err();
    assert_eq!(e.key, FLUX_MAP_KEY);
    assert!(e.message.contains("`motor.flux_linkage`"), "{e}");
    // SyR-e's frame: i_d' = i_q, i_q' = −i_d, ψd' = ψq, ψq' = −ψd (a map reaching both
    // signs of i_d, so that the rotated one reaches both of i_q).
    let whole = tabulated_from(-6.0);
    let m = whole.map();
    let rows: Vec<([f64; 4], usize)> = (0..m.i_d().len())
        .flat_map(|k| (0..m.i_q().len()).map(move |j| (k, j)))
        .enumerate()
        .map(|(n, (k, j))| {
            let at = k * m.i_q().len() + j;
            let v = [m.i_q()[j], -m.i_d()[k], m.psi_q()[at], -m.psi_d()[at]];
            (v, n + 2)
        })
        .collect();
    let syre = flux_map_from_rows(&rows, "syre.csv", 1).unwrap();
    let e = write("syre.csv", &syre).unwrap_err();
    assert!(e.message.contains("SyR-e"), "{e}");
}

#[test]
fn a_path_relative_to_a_relative_configuration_resolves_to_an_absolute_one() {
    // `fado-sim commission --config dir/motor.toml` writes identified.toml into its output
    // directory: the plant's map must be named there by a path that does not depend on it.
    set_config_dir(Some(Path::new("some/dir")));
    let p = resolve("map.csv");
    set_config_dir(None);
    assert!(p.is_absolute(), "{}", p.display());
    assert!(p.ends_with("some/dir/map.csv"), "{}", p.display());
    assert!(resolve("m.csv").is_absolute());
}
