//! Borrowed numeric arrays handed to the writers: positions and per-point or per-cell fields in
//! `f32`, `f64` or `i32`, without copying.

mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
    impl Sealed for i32 {}
}

/// A borrowed, flat array of numbers of one type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Values<'a> {
    /// 32-bit floats.
    F32(&'a [f32]),
    /// 64-bit floats.
    F64(&'a [f64]),
    /// 32-bit signed integers (labels, region ids).
    I32(&'a [i32]),
}

impl Values<'_> {
    /// Number of values.
    pub fn len(&self) -> usize {
        match self {
            Values::F32(v) => v.len(),
            Values::F64(v) => v.len(),
            Values::I32(v) => v.len(),
        }
    }

    /// True when there are no values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Value `i` as `f64` (exact for every variant), or `None` past the end.
    pub fn get(&self, i: usize) -> Option<f64> {
        match self {
            Values::F32(v) => v.get(i).map(|&x| f64::from(x)),
            Values::F64(v) => v.get(i).copied(),
            Values::I32(v) => v.get(i).map(|&x| f64::from(x)),
        }
    }

    /// Bytes per value.
    pub(crate) fn size(&self) -> usize {
        match self {
            Values::F32(_) | Values::I32(_) => 4,
            Values::F64(_) => 8,
        }
    }

    /// Appends values `range` little-endian.
    pub(crate) fn extend_le(&self, range: std::ops::Range<usize>, out: &mut Vec<u8>) {
        match self {
            Values::F32(v) => v[range].iter().for_each(|x| out.extend_from_slice(&x.to_le_bytes())),
            Values::F64(v) => v[range].iter().for_each(|x| out.extend_from_slice(&x.to_le_bytes())),
            Values::I32(v) => v[range].iter().for_each(|x| out.extend_from_slice(&x.to_le_bytes())),
        }
    }

    /// Writes value `i` as shortest round-trip decimal text.
    pub(crate) fn write_text(&self, i: usize, out: &mut String) {
        use std::fmt::Write;
        // Writing to a String cannot fail.
        let _ = match self {
            Values::F32(v) => write!(out, "{}", v[i]),
            Values::F64(v) => write!(out, "{}", v[i]),
            Values::I32(v) => write!(out, "{}", v[i]),
        };
    }
}

impl<'a> From<&'a [f32]> for Values<'a> {
    fn from(v: &'a [f32]) -> Self {
        Values::F32(v)
    }
}

impl<'a> From<&'a [f64]> for Values<'a> {
    fn from(v: &'a [f64]) -> Self {
        Values::F64(v)
    }
}

impl<'a> From<&'a [i32]> for Values<'a> {
    fn from(v: &'a [i32]) -> Self {
        Values::I32(v)
    }
}

/// A number type positions and fields may come in: `f32`, `f64` or (fields only) `i32`.
pub trait Element: sealed::Sealed + Copy + 'static {
    /// The slice as [`Values`].
    fn values(s: &[Self]) -> Values<'_>;
}

impl Element for f32 {
    fn values(s: &[Self]) -> Values<'_> {
        Values::F32(s)
    }
}

impl Element for f64 {
    fn values(s: &[Self]) -> Values<'_> {
        Values::F64(s)
    }
}

impl Element for i32 {
    fn values(s: &[Self]) -> Values<'_> {
        Values::I32(s)
    }
}

/// A floating-point type positions come in: `f32` (MPM particles, glam `Vec3`) or `f64`.
pub trait Real: Element {
    /// The value as `f64` (exact).
    fn to_f64(self) -> f64;
}

impl Real for f32 {
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
}

impl Real for f64 {
    fn to_f64(self) -> f64 {
        self
    }
}

/// A named field: `components` numbers per point or per cell, stored flat (tuple `i` is
/// `values[i * components..(i + 1) * components]`).
#[derive(Debug, Clone, PartialEq)]
pub struct DataArray<'a> {
    /// The field's name as tools show it (e.g. `velocity`).
    pub name: String,
    /// Numbers per tuple: 1 for scalars, 3 for vectors.
    pub components: usize,
    /// The numbers.
    pub values: Values<'a>,
}

impl<'a> DataArray<'a> {
    /// A scalar field: one number per point or cell.
    pub fn scalars<T: Element>(name: impl Into<String>, values: &'a [T]) -> Self {
        DataArray { name: name.into(), components: 1, values: T::values(values) }
    }

    /// A 3-vector field: one `[x, y, z]` per point or cell.
    pub fn vectors<T: Element>(name: impl Into<String>, values: &'a [[T; 3]]) -> Self {
        DataArray { name: name.into(), components: 3, values: T::values(values.as_flattened()) }
    }

    /// A field of `components` numbers per tuple, stored flat.
    pub fn new(name: impl Into<String>, components: usize, values: impl Into<Values<'a>>) -> Self {
        DataArray { name: name.into(), components, values: values.into() }
    }

    /// Number of tuples, or an error message when the length is not a multiple of the components.
    pub(crate) fn tuples(&self) -> Result<usize, String> {
        if self.components == 0 {
            return Err(format!("field `{}` has 0 components", self.name));
        }
        if !self.values.len().is_multiple_of(self.components) {
            return Err(format!(
                "field `{}` has {} values, not a multiple of its {} components",
                self.name,
                self.values.len(),
                self.components
            ));
        }
        Ok(self.values.len() / self.components)
    }

    /// Checks that the field has `expected` tuples.
    pub(crate) fn check(&self, expected: usize, per: &str) -> Result<(), String> {
        let n = self.tuples()?;
        if self.name.is_empty() {
            return Err("a field has an empty name".into());
        }
        if n != expected {
            return Err(format!("field `{}` has {n} tuples but there are {expected} {per}", self.name));
        }
        Ok(())
    }
}
