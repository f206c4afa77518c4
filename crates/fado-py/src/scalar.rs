//! The two arithmetic types a recording can be replayed in: f64 (analysis) and f32 (what
//! firmware runs).

use std::borrow::Cow;

use fado_core::Real;
use numpy::Element;

use crate::inputs::ColumnSlice;

/// The scalar an estimator runs on, as seen by the bindings.
pub trait Scalar: Real + Element + Send + Sync + 'static {
    /// The numpy name of the type.
    const DTYPE: Dtype;

    /// The column in this type: borrowed when it already is, converted (rounded to nearest
    /// for f64 → f32, exact for f32 → f64) otherwise.
    fn column(slice: ColumnSlice<'_>) -> Cow<'_, [Self]>;
}

impl Scalar for f64 {
    const DTYPE: Dtype = Dtype::Float64;

    fn column(slice: ColumnSlice<'_>) -> Cow<'_, [f64]> {
        match slice {
            ColumnSlice::F64(x) => Cow::Borrowed(x),
            ColumnSlice::F32(x) => Cow::Owned(x.iter().map(|&v| f64::from(v)).collect()),
        }
    }
}

impl Scalar for f32 {
    const DTYPE: Dtype = Dtype::Float32;

    fn column(slice: ColumnSlice<'_>) -> Cow<'_, [f32]> {
        match slice {
            ColumnSlice::F32(x) => Cow::Borrowed(x),
            ColumnSlice::F64(x) => Cow::Owned(x.iter().map(|&v| v as f32).collect()),
        }
    }
}

/// Which arithmetic an estimator runs in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dtype {
    /// Double precision (the default; analysis).
    Float64,
    /// Single precision, as on a microcontroller with a single-precision FPU.
    Float32,
}

impl Dtype {
    /// The numpy name: "float64" or "float32".
    pub fn name(self) -> &'static str {
        match self {
            Dtype::Float64 => "float64",
            Dtype::Float32 => "float32",
        }
    }
}
