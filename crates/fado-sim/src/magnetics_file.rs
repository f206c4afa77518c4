//! The plant's magnetics in a configuration file: `[motor.saturation]` (the algebraic model)
//! and `[motor] flux_map = "FILE.csv"` (a flux map), and the flux-map CSV format read and
//! written.
//!
//! **The CSV format.** The header `i_d,i_q,psi_d,psi_q` (the four names in any order, each
//! row's values in the header's order; a trailing comma on every line is read as an empty
//! last column), then one row per node of a rectangular grid in any order: SI peak values in the rotor frame (d on the magnet, ψd = λf
//! at zero current). Lines starting with `#` and blank lines are ignored. A row that does not
//! parse, a non-finite value, a node given twice or missing (a ragged grid) and a map not
//! strictly increasing in its own current (it has no inverse i(ψ)) are refused as
//! `FILE:LINE:1: `flux_map`: …`.
//!
//! **Paths.** A relative `flux_map` path is relative to the directory of the TOML file that
//! names it: the command-line tool records that directory when it reads a `--config` file
//! ([`set_config_dir`]); a TOML text given without a file (a Python `config_toml` string)
//! resolves it against the working directory. The resolved path is absolute ([`resolve`]).

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use fado_core::magnetics::{FluxMapError, Saturation};
use serde::Deserialize;

use crate::error::SimConfigError;
use crate::magnetics::{FluxMapData, PlantMagnetics};
use crate::source::SourceLocation;

/// The configuration key of a flux map, as errors name it.
pub const FLUX_MAP_KEY: &str = "motor.flux_map";

/// The CSV header, column by column.
const HEADER: [&str; 4] = ["i_d", "i_q", "psi_d", "psi_q"];

thread_local! {
    /// The directory relative `flux_map` paths resolve against (None: the working directory).
    static CONFIG_DIR: RefCell<Option<PathBuf>> = const { RefCell::new(None) };
}

/// Makes relative `flux_map` paths in the TOML texts this thread parses from now on resolve
/// against `dir` (the directory of the configuration file read; None: the working
/// directory). The command-line tool calls it as it reads its `--config` file.
pub fn set_config_dir(dir: Option<&Path>) {
    CONFIG_DIR.with(|d| *d.borrow_mut() = dir.map(Path::to_path_buf));
}

/// `written` resolved as a `flux_map` path (see [`set_config_dir`]), made absolute: a
/// configuration written back elsewhere (a `--dump-config`, the `identified.toml` that
/// `commission` writes into its output directory) still names the same file, also when the
/// configuration was read by a relative path.
pub fn resolve(written: &str) -> PathBuf {
    let p = Path::new(written);
    if p.is_absolute() {
        return p.to_path_buf();
    }
    let joined = CONFIG_DIR.with(|d| match &*d.borrow() {
        Some(dir) => dir.join(p),
        None => p.to_path_buf(),
    });
    std::path::absolute(&joined).unwrap_or(joined)
}

/// A flux map named by a configuration: the file it came from and its data.
#[derive(Clone, Debug, PartialEq)]
pub struct FluxMapFile {
    /// The file, resolved (what `--dump-config` writes back); None for a map given as data
    /// (Python's `flux_map=(i_d, i_q, psi_d, psi_q)`), which a dump names but cannot hold.
    pub path: Option<PathBuf>,
    /// The checked map, shared by every plant built from the configuration.
    pub data: Arc<FluxMapData>,
}

impl FluxMapFile {
    /// Reads the map at `written` (resolved by [`resolve`]).
    pub fn read(written: &str) -> Result<Self, SimConfigError> {
        let path = resolve(written);
        let data = read_flux_map(&path)?;
        Ok(Self {
            path: Some(path),
            data: Arc::new(data),
        })
    }

    /// A map given as data, not read from a file.
    pub fn in_memory(data: FluxMapData) -> Self {
        Self {
            path: None,
            data: Arc::new(data),
        }
    }

    /// The `flux_map` value a dump writes: the resolved path, or for a map held in memory a
    /// description that reading it back refuses as a missing file.
    pub fn written(&self) -> String {
        match &self.path {
            Some(p) => p.display().to_string(),
            None => {
                let m = self.data.map();
                format!(
                    "({}x{} map given as arrays: write it with fado_sim::magnetics_file::flux_map_csv)",
                    m.i_d().len(),
                    m.i_q().len()
                )
            }
        }
    }
}

/// The plant's saturating magnetics of a configuration: the flux map if one is given, else
/// the algebraic model, else None (constant inductances).
pub fn plant_magnetics(
    saturation: Option<&Saturation<f64>>,
    flux_map: Option<&FluxMapFile>,
) -> Option<Arc<PlantMagnetics>> {
    match (flux_map, saturation) {
        (Some(m), _) => Some(Arc::new(PlantMagnetics::Map(*m.data))),
        (None, Some(s)) => Some(Arc::new(PlantMagnetics::Saturation(*s))),
        (None, None) => None,
    }
}

/// Refuses a motor given both magnetic models (one place per parameter).
pub fn check_one_model(
    saturation: Option<&Saturation<f64>>,
    flux_map: Option<&FluxMapFile>,
) -> Result<(), SimConfigError> {
    if saturation.is_some() && flux_map.is_some() {
        return Err(SimConfigError::new(
            FLUX_MAP_KEY,
            "the motor has both `[motor.saturation]` and `flux_map`: give one magnetic model",
        ));
    }
    Ok(())
}

/// Takes `[motor.saturation]` and `[motor] flux_map` out of the user's document (`[motor]`
/// itself is the linear machine's record), parsed; the map's file read and checked.
/// A `[model] flux_map` path is resolved here too (its file is read with the drive's model).
pub fn take_magnetics(
    user: &mut toml::Table,
) -> Result<(Option<Saturation<f64>>, Option<FluxMapFile>), SimConfigError> {
    crate::model_magnetics::resolve_model_paths(user);
    let Some(toml::Value::Table(motor)) = user.get_mut("motor") else {
        return Ok((None, None));
    };
    let saturation = match motor.remove("saturation") {
        Some(table) => Some(
            Saturation::<f64>::deserialize(table)
                .map_err(|e| crate::config::key_error(e).in_section("motor.saturation"))?,
        ),
        None => None,
    };
    let flux_map = match motor.remove("flux_map") {
        Some(toml::Value::String(written)) => Some(FluxMapFile::read(&written)?),
        Some(other) => {
            return Err(SimConfigError::new(
                FLUX_MAP_KEY,
                format!(
                    "must be the path of a CSV file (a string), got a {}",
                    other.type_str()
                ),
            ));
        }
        None => None,
    };
    Ok((saturation, flux_map))
}

/// Writes the magnetics back into a serialised configuration's `[motor]` table.
pub fn insert_magnetics(
    table: &mut toml::Table,
    saturation: Option<&Saturation<f64>>,
    flux_map: Option<&FluxMapFile>,
) {
    let Some(toml::Value::Table(motor)) = table.get_mut("motor") else {
        return;
    };
    if let Some(m) = flux_map {
        motor.insert("flux_map".into(), toml::Value::String(m.written()));
    }
    if let Some(s) = saturation {
        let sat = toml::Table::try_from(s).expect("Saturation is a TOML table");
        motor.insert("saturation".into(), toml::Value::Table(sat));
    }
}

/// Where a flux-map file went wrong: `FILE:LINE:1: `motor.flux_map`: …`.
fn map_error(file: &str, line: usize, message: impl Into<String>) -> SimConfigError {
    let mut e = SimConfigError::new(FLUX_MAP_KEY, message);
    e.location = Some(SourceLocation {
        file: Some(file.to_owned()),
        line,
        column: 1,
    });
    e
}

/// Reads a flux map from a CSV file (see [`parse_flux_map`]); a file that cannot be read is
/// refused naming it.
pub fn read_flux_map(path: &Path) -> Result<FluxMapData, SimConfigError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| {
        SimConfigError::new(
            FLUX_MAP_KEY,
            format!("cannot read `{name}`: {e} (a path in a TOML file is relative to that file)"),
        )
    })?;
    parse_flux_map(&text, &name)
}

/// The physical 1-based line numbers of a text's records: the CSV reader's own line count
/// skips comment lines, and a record's byte offset is where the reader resumed (before any
/// comment or blank lines preceding it).
struct Lines<'a> {
    text: &'a str,
    lines: Vec<&'a str>,
    /// The byte offsets of the text's `\n`s, ascending.
    newlines: Vec<usize>,
}

impl<'a> Lines<'a> {
    fn new(text: &'a str) -> Self {
        Self {
            text,
            lines: text.lines().collect(),
            newlines: text
                .bytes()
                .enumerate()
                .filter_map(|(at, b)| (b == b'\n').then_some(at))
                .collect(),
        }
    }

    /// The line of the first record starting at or after byte `byte`.
    fn at(&self, byte: u64) -> usize {
        let mut start = (byte as usize).min(self.text.len());
        // In a CRLF file the reader resumes after the `\r`: the `\n` there still ends the
        // line before the record.
        if start > 0 && self.text.as_bytes().get(start - 1..=start) == Some(b"\r\n") {
            start += 1;
        }
        // The `\n`s before `start` (a search: a map's records are read in one pass).
        let mut line = self.newlines.partition_point(|&at| at < start);
        while self
            .lines
            .get(line)
            .is_some_and(|l| l.trim().is_empty() || l.trim_start().starts_with('#'))
        {
            line += 1;
        }
        line + 1
    }

    fn of(&self, pos: Option<&csv::Position>) -> usize {
        pos.map_or(0, |p| self.at(p.byte()))
    }
}

/// One data row: the four values and the line they are on.
type Row = ([f64; 4], usize);

/// Where each of [`HEADER`]'s four columns is in the file, and whether every record ends
/// with an empty field (a trailing comma, as some spreadsheets export).
#[derive(Clone, Copy)]
struct Columns {
    at: [usize; 4],
    trailing_comma: bool,
}

/// The columns of a header: its names are [`HEADER`]'s in any order (a tool that writes i_q
/// first), optionally followed by one empty name (a trailing comma).
fn columns(got: &[&str]) -> Option<Columns> {
    let trailing_comma = got.len() == HEADER.len() + 1 && got.last() == Some(&"");
    let names = if trailing_comma {
        &got[..HEADER.len()]
    } else {
        got
    };
    if names.len() != HEADER.len() {
        return None;
    }
    let mut at = [0; 4];
    for (slot, name) in at.iter_mut().zip(HEADER) {
        *slot = names.iter().position(|&n| n == name)?;
    }
    Some(Columns { at, trailing_comma })
}

/// Checks the header; returns its line and where each column is.
fn read_header(
    reader: &mut csv::Reader<&[u8]>,
    lines: &Lines,
    file: &str,
) -> Result<(usize, Columns), SimConfigError> {
    let headers = reader
        .headers()
        .map_err(|e| map_error(file, 1, e.to_string()))?
        .clone();
    let line = headers.position().map_or(1, |p| lines.at(p.byte()));
    let got: Vec<&str> = headers.iter().collect();
    if let Some(columns) = columns(&got) {
        return Ok((line, columns));
    }
    let joined = got.join(",");
    let hint = if joined.contains(';') || joined.contains('\t') {
        ": the file is separated by semicolons or tabs (a spreadsheet's export, often with \
         decimal commas); the map is comma-separated with decimal points"
    } else if joined.to_ascii_lowercase() == HEADER.join(",") {
        ": the names are lower case"
    } else if joined.contains('[') || joined.contains('(') {
        ": the names carry no units (A and Wb peak, SI)"
    } else {
        ""
    };
    Err(map_error(
        file,
        line,
        format!(
            "the header must name the columns `i_d`, `i_q`, `psi_d` and `psi_q` (in any \
             order), got `{joined}`{hint}"
        ),
    ))
}

/// The data rows, every value a finite number, in [`HEADER`]'s order.
fn read_rows(
    reader: &mut csv::Reader<&[u8]>,
    lines: &Lines,
    file: &str,
    columns: Columns,
) -> Result<Vec<Row>, SimConfigError> {
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| map_error(file, lines.of(e.position()), e.to_string()))?;
        let line = lines.of(record.position());
        if columns.trailing_comma && record.get(HEADER.len()).is_some_and(|c| !c.is_empty()) {
            let msg = "a fifth value where the header's trailing comma leaves the column empty";
            return Err(map_error(file, line, msg.to_string()));
        }
        let mut v = [0.0; 4];
        for ((x, name), at) in v.iter_mut().zip(HEADER).zip(columns.at) {
            let cell = record.get(at).unwrap_or("");
            *x = cell.parse::<f64>().map_err(|_| {
                map_error(file, line, format!("`{name}` = `{cell}` is not a number"))
            })?;
            if !x.is_finite() {
                let msg = format!("`{name}` = {cell} is not finite");
                return Err(map_error(file, line, msg));
            }
        }
        rows.push((v, line));
    }
    Ok(rows)
}

/// The distinct values of column `k`, increasing.
fn axis(rows: &[Row], k: usize) -> Vec<f64> {
    let mut a: Vec<f64> = rows.iter().map(|r| r.0[k]).collect();
    a.sort_by(f64::total_cmp);
    a.dedup();
    a
}

/// ψd and ψq on the grid (row-major) and the line each node came from.
type Placed = (Vec<f64>, Vec<f64>, Vec<usize>);

/// The rows placed on the grid `i_d` × `i_q`: ψd, ψq and the line of each node (row-major).
fn place_rows(
    rows: &[Row],
    (i_d, i_q): (&[f64], &[f64]),
    file: &str,
    header_line: usize,
) -> Result<Placed, SimConfigError> {
    let (nd, nq) = (i_d.len(), i_q.len());
    let mut psi_d = vec![f64::NAN; nd * nq];
    let mut psi_q = vec![f64::NAN; nd * nq];
    let mut line_of = vec![0usize; nd * nq];
    for (v, line) in rows {
        let k = i_d.partition_point(|&x| x < v[0]);
        let m = i_q.partition_point(|&x| x < v[1]);
        let at = k * nq + m;
        if line_of[at] != 0 {
            let msg = format!(
                "the node (i_d, i_q) = ({}, {}) is given twice (line {} too)",
                v[0], v[1], line_of[at]
            );
            return Err(map_error(file, *line, msg));
        }
        (psi_d[at], psi_q[at], line_of[at]) = (v[2], v[3], *line);
    }
    if let Some(at) = line_of.iter().position(|&l| l == 0) {
        let last = rows.last().map_or(header_line, |r| r.1);
        let msg = format!(
            "the grid is ragged: no row for (i_d, i_q) = ({}, {}); a map needs every pair of its \
             {nd} i_d and {nq} i_q values",
            i_d[at / nq],
            i_q[at % nq]
        );
        return Err(map_error(file, last, msg));
    }
    Ok((psi_d, psi_q, line_of))
}

/// Parses a flux map in the CSV format of this module; `file` names the source in messages.
pub fn parse_flux_map(text: &str, file: &str) -> Result<FluxMapData, SimConfigError> {
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let lines = Lines::new(text);
    let (header_line, columns) = read_header(&mut reader, &lines, file)?;
    let rows = read_rows(&mut reader, &lines, file, columns)?;
    flux_map_from_rows(&rows, file, header_line)
}

/// A flux map from its nodes, one row (i_d, i_q, ψd, ψq) each in any order, with the line
/// (or row number) each came from: the refusals of [`parse_flux_map`] after the parsing.
/// `file` names the source and `header_line` the line of errors about the whole grid.
pub fn flux_map_from_rows(
    rows: &[([f64; 4], usize)],
    file: &str,
    header_line: usize,
) -> Result<FluxMapData, SimConfigError> {
    if let Some((v, line)) = rows.iter().find(|r| r.0.iter().any(|x| !x.is_finite())) {
        let k = v.iter().position(|x| !x.is_finite()).unwrap_or(0);
        let msg = format!("`{}` = {} is not finite", HEADER[k], v[k]);
        return Err(map_error(file, *line, msg));
    }
    let (i_d, i_q) = (axis(rows, 0), axis(rows, 1));
    let (nq, shape) = (i_q.len(), i_d.len().min(i_q.len()));
    if shape < 2 {
        let msg = "the grid needs at least two values of i_d and of i_q";
        return Err(map_error(file, header_line, msg));
    }
    let (psi_d, psi_q, line_of) = place_rows(rows, (&i_d, &i_q), file, header_line)?;
    let grid = Grid {
        i_d: &i_d,
        i_q: &i_q,
        psi_d: &psi_d,
        psi_q: &psi_q,
    };
    let falls = |table: &str, k: usize, m: usize| grid.falls(table, k, m);
    let checked = FluxMapData::new(i_d.clone(), i_q.clone(), psi_d.clone(), psi_q.clone());
    checked.map_err(|e| match e {
        FluxMapError::NotMonotonic { table, k, m } => {
            map_error(file, line_of[k * nq + m], falls(table, k, m))
        }
        FluxMapError::NotFinite { k, m, .. } => map_error(file, line_of[k * nq + m], e.to_string()),
        _ => map_error(file, header_line, e.to_string()),
    })
}

/// A map's nodes before its checks (row-major ψ), for the messages of its refusals.
struct Grid<'a> {
    i_d: &'a [f64],
    i_q: &'a [f64],
    psi_d: &'a [f64],
    psi_q: &'a [f64],
}

impl Grid<'_> {
    /// Why `table` (ψd along i_d, ψq along i_q) falls into node (k, m): the values, and the
    /// likely cause by how much of the node's line falls. A map falling along most of its
    /// axis has its axes or signs swapped (SyR-e's maps put d on the high-permeance axis); a
    /// few falling steps among rising ones are noise of a measured map.
    fn falls(&self, table: &str, k: usize, m: usize) -> String {
        let nq = self.i_q.len();
        let d_axis = table == "psi_d";
        let (axis, name, other, at) = if d_axis {
            (self.i_d, "i_d", ("i_q", self.i_q[m]), k)
        } else {
            (self.i_q, "i_q", ("i_d", self.i_d[k]), m)
        };
        let value = |n: usize| match d_axis {
            true => self.psi_d[n * nq + m],
            false => self.psi_q[k * nq + n],
        };
        let steps = axis.len() - 1;
        let falling = (1..axis.len())
            .filter(|&n| value(n) <= value(n - 1))
            .count();
        let (psi_d0, psi_q0) = self.at_zero_current();
        let cause = if psi_q0.abs() > 2.0 * psi_d0.abs() {
            format!(
                "the columns psi_d and psi_q look swapped: nearest zero current ψd = \
                 {psi_d0:.6} Wb and ψq = {psi_q0:.6} Wb, where a magnet machine has ψd = λf \
                 and ψq = 0 (the header is i_d,i_q,psi_d,psi_q)"
            )
        } else if 2 * falling > steps {
            "the map falls along most of this axis: check its axes and signs (d on the magnet, \
             ψd = λf at i = 0, SI peak values; SyR-e's maps put d on the high-permeance axis)"
                .to_owned()
        } else {
            "a local dip (noise in a measured map?): smooth the map or thin its grid".to_owned()
        };
        format!(
            "{table} does not increase with its own current: {:.6} Wb at {name} = {} A, \
             {:.6} Wb at {name} = {} A ({} = {} A); {falling} of the line's {steps} steps fall, \
             and a map with no inverse i(ψ) cannot be run: {cause}",
            value(at - 1),
            axis[at - 1],
            value(at),
            axis[at],
            other.0,
            other.1,
        )
    }
}

impl Grid<'_> {
    /// (ψd, ψq) at the node nearest zero current.
    fn at_zero_current(&self) -> (f64, f64) {
        let nearest = |axis: &[f64]| {
            (0..axis.len())
                .min_by(|&a, &b| axis[a].abs().total_cmp(&axis[b].abs()))
                .unwrap_or(0)
        };
        let (k, m) = (nearest(self.i_d), nearest(self.i_q));
        let n = k * self.i_q.len() + m;
        (self.psi_d[n], self.psi_q[n])
    }
}

/// The map as CSV text in this module's format (every node, i_d-major; values in Rust's
/// shortest round-trip form, so that reading it back gives the same map bit for bit).
pub fn flux_map_csv(data: &FluxMapData, comment: &str) -> String {
    let map = data.map();
    let mut out = String::new();
    for line in comment.lines() {
        out.push_str(&format!("# {line}\n"));
    }
    out.push_str("i_d,i_q,psi_d,psi_q\n");
    let nq = map.i_q().len();
    for (k, id) in map.i_d().iter().enumerate() {
        for (m, iq) in map.i_q().iter().enumerate() {
            let at = k * nq + m;
            let (pd, pq) = (map.psi_d()[at], map.psi_q()[at]);
            out.push_str(&format!("{id:?},{iq:?},{pd:?},{pq:?}\n"));
        }
    }
    out
}

#[cfg(test)]
mod tests;
