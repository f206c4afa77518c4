//! Where the trace goes: memory, columns or a CSV file, decimated.

use super::{Probe, Sample, TraceRow};

/// Where the rows of a trace go as they are produced: memory ([`Vec`], [`TraceColumns`]) or
/// a file ([`CsvTraceWriter`]), so that a run's memory need not grow with its duration.
pub trait TraceSink {
    /// Takes one row.
    fn push(&mut self, row: &TraceRow);
}

impl TraceSink for Vec<TraceRow> {
    fn push(&mut self, row: &TraceRow) {
        Vec::push(self, *row);
    }
}

/// The trace as one `Vec<f64>` per column of [`TraceRow::COLUMNS`] (struct of arrays, flags
/// as 0.0/1.0): what the Python bindings hand to numpy without another copy.
#[derive(Clone, Debug, PartialEq)]
pub struct TraceColumns {
    /// One vector per column, in [`TraceRow::COLUMNS`] order.
    pub columns: Vec<Vec<f64>>,
}

impl TraceColumns {
    /// Empty columns with room for `rows` rows.
    pub fn with_capacity(rows: usize) -> Self {
        Self {
            columns: vec![Vec::with_capacity(rows); TraceRow::COLUMNS.len()],
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.columns.first().map_or(0, Vec::len)
    }

    /// True without rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl TraceSink for TraceColumns {
    fn push(&mut self, row: &TraceRow) {
        for (column, value) in self.columns.iter_mut().zip(row.values()) {
            column.push(value);
        }
    }
}

/// Writes rows as CSV (header first) as they come. A write error is kept, the following rows
/// are dropped, and [`finish`](Self::finish) reports it.
///
/// The bytes are those of the `csv` crate serializing [`TraceRow`] (header line, `,` between
/// fields, `\n` after each row, no field needing quotes): floats in the shortest form that
/// reads back to the same value (`zmij`, printed as `ryu` prints them, which `csv` uses),
/// flags and status words as integers. A row is formatted into one line buffer and written
/// whole; `tests` compare the bytes with `csv`'s on rows with every kind of value.
pub struct CsvTraceWriter<W: std::io::Write> {
    writer: W,
    line: Vec<u8>,
    error: Option<csv::Error>,
    rows: u64,
}

impl<W: std::io::Write> CsvTraceWriter<W> {
    /// A writer onto `w` (buffer `w` yourself if it is a file: each row is one `write_all`).
    pub fn new(w: W) -> Self {
        Self {
            writer: w,
            line: Vec::with_capacity(1024),
            error: None,
            rows: 0,
        }
    }

    /// Rows written.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// A write failed (the rest of the rows are dropped; [`finish`](Self::finish) says why).
    pub fn failed(&self) -> bool {
        self.error.is_some()
    }

    /// Flushes and returns the inner writer, or the first error.
    pub fn finish(mut self) -> Result<W, csv::Error> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        if self.rows == 0 {
            // The header alone, as `Trace::write_csv` writes for an empty trace.
            self.write_header()?;
        }
        self.writer.flush()?;
        Ok(self.writer)
    }

    fn write_header(&mut self) -> std::io::Result<()> {
        self.line.clear();
        self.line
            .extend_from_slice(TraceRow::COLUMNS.join(",").as_bytes());
        self.line.push(b'\n');
        self.writer.write_all(&self.line)
    }

    fn write_row(&mut self, row: &TraceRow) -> std::io::Result<()> {
        if self.rows == 0 {
            self.write_header()?;
        }
        self.line.clear();
        row.write_csv_line(&mut self.line);
        self.writer.write_all(&self.line)
    }
}

impl<W: std::io::Write> TraceSink for CsvTraceWriter<W> {
    fn push(&mut self, row: &TraceRow) {
        if self.error.is_none() {
            match self.write_row(row) {
                Ok(()) => self.rows += 1,
                Err(e) => self.error = Some(e.into()),
            }
        }
    }
}

/// Hands every `decimation`-th sample to a [`TraceSink`] as a [`TraceRow`].
pub struct Decimated<'a> {
    decimation: u64,
    count: u64,
    sink: &'a mut dyn TraceSink,
}

impl<'a> Decimated<'a> {
    /// Keeps one sample in `decimation` (at least 1), starting with the first.
    pub fn new(decimation: u32, sink: &'a mut dyn TraceSink) -> Self {
        Self {
            decimation: decimation.max(1) as u64,
            count: 0,
            sink,
        }
    }
}

impl Probe for Decimated<'_> {
    fn observe(&mut self, s: &Sample) {
        if self.count.is_multiple_of(self.decimation) {
            self.sink.push(&TraceRow::from(s));
        }
        self.count += 1;
    }
}

/// Keeps every `decimation`-th sample as a [`TraceRow`] in memory.
#[derive(Clone, Debug, Default)]
pub struct Trace {
    /// Keep one sample in this many (≥ 1).
    pub decimation: u32,
    /// The rows kept.
    pub rows: Vec<TraceRow>,
    count: u64,
}

impl Trace {
    /// An empty trace keeping one sample in `decimation`.
    pub fn new(decimation: u32) -> Self {
        Self {
            decimation: decimation.max(1),
            rows: Vec::new(),
            count: 0,
        }
    }

    /// One column of the trace by name (see [`TraceRow::COLUMNS`]).
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let k = TraceRow::COLUMNS.iter().position(|c| *c == name)?;
        Some(self.rows.iter().map(|r| r.values()[k]).collect())
    }

    /// Writes the rows as CSV with a header.
    pub fn write_csv<W: std::io::Write>(&self, w: W) -> Result<(), csv::Error> {
        let mut wr = CsvTraceWriter::new(w);
        for r in &self.rows {
            wr.push(r);
        }
        wr.finish()?.flush()?;
        Ok(())
    }
}

impl Probe for Trace {
    fn observe(&mut self, s: &Sample) {
        if self.count.is_multiple_of(self.decimation as u64) {
            self.rows.push(TraceRow::from(s));
        }
        self.count += 1;
    }
}
