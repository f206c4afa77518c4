//! Checking the signal arrays handed to `estimate` and `Estimator.run`.
//!
//! An input must be a 1-D, contiguous, aligned numpy array of float64 or float32 in native
//! byte order; all four must have the same length. Anything else raises `fado.InputError`
//! naming the argument and saying how to fix it. Nothing is copied silently: a strided view
//! (e.g. a column of a 2-D array) is refused rather than copied behind the user's back.

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::errors::input_error;

/// One borrowed input column, in the dtype it came in.
pub enum Column<'py> {
    /// A float64 array.
    F64(PyReadonlyArray1<'py, f64>),
    /// A float32 array.
    F32(PyReadonlyArray1<'py, f32>),
}

/// The data of a [`Column`], which may cross into code running without the GIL.
#[derive(Clone, Copy, Debug)]
pub enum ColumnSlice<'a> {
    /// float64 samples.
    F64(&'a [f64]),
    /// float32 samples.
    F32(&'a [f32]),
}

impl ColumnSlice<'_> {
    /// Number of samples.
    pub fn len(&self) -> usize {
        match self {
            ColumnSlice::F64(x) => x.len(),
            ColumnSlice::F32(x) => x.len(),
        }
    }

    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl Column<'_> {
    /// The samples ([`column()`] made sure that they form one slice).
    pub fn slice(&self) -> ColumnSlice<'_> {
        match self {
            Column::F64(a) => ColumnSlice::F64(a.as_slice().unwrap_or(&[])),
            Column::F32(a) => ColumnSlice::F32(a.as_slice().unwrap_or(&[])),
        }
    }
}

fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .fully_qualified_name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".to_owned())
}

/// Checks one argument and borrows it read-only.
pub fn column<'py>(argument: &str, obj: &Bound<'py, PyAny>) -> PyResult<Column<'py>> {
    let array = one_d_array(argument, obj)?;
    let py = obj.py();
    let column = if let Ok(a) = array.cast::<PyArray1<f64>>() {
        a.try_readonly().map(Column::F64)
    } else if let Ok(a) = array.cast::<PyArray1<f32>>() {
        a.try_readonly().map(Column::F32)
    } else {
        let dtype = array
            .dtype()
            .str()
            .map(|s| s.to_string())
            .unwrap_or_else(|_| "?".to_owned());
        return Err(input_error(
            py,
            argument,
            format!(
                "expected dtype float64 or float32 (native byte order), got {dtype}; convert \
                 with x.astype(numpy.float64)"
            ),
        ));
    };
    let column = column.map_err(|e| {
        input_error(
            py,
            argument,
            format!("the array cannot be borrowed for reading: {e}"),
        )
    })?;
    check_layout(argument, array)?;
    // The checks above are exactly what `as_slice` needs; refuse rather than assume.
    let readable = match &column {
        Column::F64(a) => a.as_slice().is_ok(),
        Column::F32(a) => a.as_slice().is_ok(),
    };
    if !readable {
        return Err(input_error(
            py,
            argument,
            "the array's memory cannot be read as one slice; pass numpy.ascontiguousarray(x)"
                .to_owned(),
        ));
    }
    Ok(column)
}

/// `obj` as a numpy array of one dimension, or an error naming `argument` and how to convert it.
fn one_d_array<'a, 'py>(
    argument: &str,
    obj: &'a Bound<'py, PyAny>,
) -> PyResult<&'a Bound<'py, PyUntypedArray>> {
    let py = obj.py();
    let Ok(array) = obj.cast::<PyUntypedArray>() else {
        return Err(input_error(
            py,
            argument,
            format!(
                "expected a 1-D numpy.ndarray of float64 or float32, got {}; convert it with \
                 numpy.asarray(x, dtype=numpy.float64)",
                type_name(obj)
            ),
        ));
    };
    if array.ndim() != 1 {
        return Err(input_error(
            py,
            argument,
            format!(
                "expected a 1-D array, got {} dimensions (shape ({})); pass one signal per \
                 argument, e.g. numpy.ascontiguousarray(x[:, 0])",
                array.ndim(),
                array
                    .shape()
                    .iter()
                    .map(|d| d.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    }
    Ok(array)
}

/// Refuses a non-empty array that is not contiguous or not aligned.
fn check_layout(argument: &str, array: &Bound<'_, PyUntypedArray>) -> PyResult<()> {
    let py = array.py();
    if !array.is_empty() && !array.is_contiguous() {
        return Err(input_error(
            py,
            argument,
            format!(
                "the array is not contiguous (strides {:?} bytes); pass \
                 numpy.ascontiguousarray(x)",
                array.strides()
            ),
        ));
    }
    if !array.is_empty() && !array.is_aligned() {
        return Err(input_error(
            py,
            argument,
            "the array's data are not aligned; pass numpy.require(x, requirements='CA')".to_owned(),
        ));
    }
    Ok(())
}

/// The signal whose length differs, and a signal to compare it with: the one whose length
/// the other three share (v_α's length differing from three equal ones names v_α), else the
/// first that differs from v_α's. `None` when all four are equal.
fn odd_length(lengths: &[usize; 4]) -> Option<(usize, usize)> {
    let shared = |k: usize| lengths.iter().filter(|&&n| n == lengths[k]).count();
    let differs = (1..4).find(|&k| lengths[k] != lengths[0])?;
    match (0..4).find(|&k| shared(k) == 1) {
        Some(odd) if (0..4).any(|k| shared(k) == 3) => {
            let reference = (0..4).find(|&k| k != odd).unwrap_or(0);
            Some((odd, reference))
        }
        _ => Some((differs, 0)),
    }
}

/// The four signals of a recording, checked to have equal lengths.
pub struct Signals<'py> {
    columns: [Column<'py>; 4],
}

/// Argument names, in order.
pub const SIGNAL_NAMES: [&str; 4] = ["v_alpha", "v_beta", "i_alpha", "i_beta"];

impl<'py> Signals<'py> {
    /// Checks and borrows v_α, v_β, i_α, i_β.
    pub fn new(
        v_alpha: &Bound<'py, PyAny>,
        v_beta: &Bound<'py, PyAny>,
        i_alpha: &Bound<'py, PyAny>,
        i_beta: &Bound<'py, PyAny>,
    ) -> PyResult<Self> {
        let py = v_alpha.py();
        let columns = [
            column(SIGNAL_NAMES[0], v_alpha)?,
            column(SIGNAL_NAMES[1], v_beta)?,
            column(SIGNAL_NAMES[2], i_alpha)?,
            column(SIGNAL_NAMES[3], i_beta)?,
        ];
        let lengths = [0, 1, 2, 3].map(|k| columns[k].slice().len());
        if let Some((odd, reference)) = odd_length(&lengths) {
            let single = if lengths[odd] == 1 {
                format!(
                    "; a single value where a series is meant? A constant signal is \
                     numpy.full({}, x)",
                    lengths[reference]
                )
            } else {
                String::new()
            };
            return Err(input_error(
                py,
                SIGNAL_NAMES[odd],
                format!(
                    "length {} differs from {}'s length {}; all four signals must have one \
                     sample per sampling period{single}",
                    lengths[odd], SIGNAL_NAMES[reference], lengths[reference]
                ),
            ));
        }
        Ok(Self { columns })
    }

    /// The four columns' data.
    pub fn slices(&self) -> [ColumnSlice<'_>; 4] {
        [
            self.columns[0].slice(),
            self.columns[1].slice(),
            self.columns[2].slice(),
            self.columns[3].slice(),
        ]
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.columns[0].slice().len()
    }

    /// True for an empty recording.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}
