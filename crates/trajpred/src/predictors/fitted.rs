//! Writing and strictly reading the fitted parameters of the predictors
//! ([`Predictor::fitted_params`](trajpred_core::Predictor::fitted_params)): exact numbers,
//! and a reader that names the JSON path of every bad field.
//!
//! Numbers are written as strings holding Rust's shortest round-trip form (`"0.1"`,
//! `"1.2345678901234567e-7"`), which `str::parse` reads back to the same bits; serde_json's
//! default number parser is not correctly rounded (its `float_roundtrip` feature would be, but
//! it is unified into every crate that parses JSON, burn included). Plain JSON numbers are
//! accepted too, for hand-written files (`docs/evaluation.md`, "Saved parameters").

use nalgebra::{DMatrix, DVector};
use serde_json::Value;
use trajpred_core::{Error, Result};

/// A number written exactly (see the module documentation).
pub(crate) fn exact(v: f64) -> Value {
    Value::String(format!("{v:?}"))
}

/// A vector written exactly.
pub(crate) fn exact_vec<'a>(v: impl IntoIterator<Item = &'a f64>) -> Value {
    Value::Array(v.into_iter().map(|&x| exact(x)).collect())
}

/// A matrix written exactly, row by row.
pub(crate) fn exact_matrix(m: &DMatrix<f64>) -> Value {
    Value::Array(m.row_iter().map(|r| exact_vec(r.iter())).collect())
}

/// A field of fitted parameters being read: the value, its JSON path and the method, so that
/// every error names where it is.
pub(crate) struct At<'a> {
    value: &'a Value,
    path: String,
    method: &'a str,
}

impl<'a> At<'a> {
    /// The root of `method`'s parameters.
    pub(crate) fn root(method: &'a str, value: &'a Value) -> Self {
        At {
            value,
            path: String::new(),
            method,
        }
    }

    /// An [`Error::InvalidFitted`] at this field.
    pub(crate) fn error(&self, reason: impl Into<String>) -> Error {
        Error::InvalidFitted {
            method: self.method.to_string(),
            path: self.path.clone(),
            reason: reason.into(),
        }
    }

    /// The object's fields, refusing any field not in `keys` and any of them missing.
    pub(crate) fn fields<const N: usize>(&self, keys: [&str; N]) -> Result<[At<'a>; N]> {
        self.fields_and(keys, &[])
    }

    /// As [`fields`](Self::fields), also allowing the fields `optional` (not returned: read
    /// them with [`value`](Self::value)).
    pub(crate) fn fields_and<const N: usize>(
        &self,
        keys: [&str; N],
        optional: &[&str],
    ) -> Result<[At<'a>; N]> {
        let obj = self
            .value
            .as_object()
            .ok_or_else(|| self.error(format!("expected an object with {keys:?}")))?;
        if let Some(k) = obj
            .keys()
            .find(|k| !keys.contains(&k.as_str()) && !optional.contains(&k.as_str()))
        {
            return Err(self.error(format!("unknown field `{k}`; expected {keys:?}")));
        }
        let mut out = Vec::with_capacity(N);
        for k in keys {
            let value = obj
                .get(k)
                .ok_or_else(|| self.error(format!("missing field `{k}`")))?;
            out.push(At {
                value,
                path: self.child(k),
                method: self.method,
            });
        }
        out.try_into()
            .map_err(|_| self.error("internal: field count"))
    }

    /// The field `key` when the object has it (allow it with
    /// [`fields_and`](Self::fields_and)'s `optional`).
    pub(crate) fn optional(&self, key: &str) -> Option<At<'a>> {
        self.value.get(key).map(|value| At {
            value,
            path: self.child(key),
            method: self.method,
        })
    }

    fn child(&self, key: &str) -> String {
        if self.path.is_empty() {
            key.to_string()
        } else {
            format!("{}.{key}", self.path)
        }
    }

    /// The array's items; exactly `len` of them when given, else between 1 and `max`.
    pub(crate) fn items(&self, len: Option<usize>, max: usize) -> Result<Vec<At<'a>>> {
        let arr = self
            .value
            .as_array()
            .ok_or_else(|| self.error("expected an array"))?;
        match len {
            Some(n) if arr.len() != n => {
                return Err(self.error(format!("expected {n} entries, got {}", arr.len())));
            }
            None if arr.is_empty() || arr.len() > max => {
                return Err(self.error(format!("expected 1 to {max} entries, got {}", arr.len())));
            }
            _ => {}
        }
        Ok(arr
            .iter()
            .enumerate()
            .map(|(i, value)| At {
                value,
                path: format!("{}[{i}]", self.path),
                method: self.method,
            })
            .collect())
    }

    /// This field's JSON path (`""` at the root).
    pub(crate) fn path(&self) -> &str {
        &self.path
    }

    /// The JSON value itself.
    pub(crate) fn value(&self) -> &'a Value {
        self.value
    }

    /// A string.
    pub(crate) fn str(&self) -> Result<&'a str> {
        self.value
            .as_str()
            .ok_or_else(|| self.error("expected a string"))
    }

    /// A boolean.
    pub(crate) fn bool(&self) -> Result<bool> {
        self.value
            .as_bool()
            .ok_or_else(|| self.error("expected true or false"))
    }

    /// A finite number (an exact string or a JSON number).
    pub(crate) fn f64(&self) -> Result<f64> {
        let v = match self.value {
            Value::String(s) => s
                .parse::<f64>()
                .map_err(|_| self.error(format!("`{s}` is not a number")))?,
            Value::Number(n) => n
                .as_f64()
                .ok_or_else(|| self.error(format!("{n} is not a number")))?,
            _ => return Err(self.error("expected a number")),
        };
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.error(format!("{v} is not finite")))
        }
    }

    /// A finite number that is at least `min` (exclusive when `strict`).
    pub(crate) fn f64_min(&self, min: f64, strict: bool) -> Result<f64> {
        let v = self.f64()?;
        if v > min || (!strict && v == min) {
            Ok(v)
        } else {
            let rel = if strict { ">" } else { ">=" };
            Err(self.error(format!("must be {rel} {min}, got {v}")))
        }
    }

    /// A vector of `len` finite numbers, each checked by `check`.
    pub(crate) fn vector(
        &self,
        len: usize,
        check: impl Fn(&At<'a>) -> Result<f64>,
    ) -> Result<DVector<f64>> {
        let items = self.items(Some(len), len)?;
        let v: Vec<f64> = items.iter().map(check).collect::<Result<_>>()?;
        Ok(DVector::from_vec(v))
    }

    /// A `rows x cols` matrix of finite numbers, written row by row.
    pub(crate) fn matrix(&self, rows: usize, cols: usize) -> Result<DMatrix<f64>> {
        let mut m = DMatrix::zeros(rows, cols);
        for (i, row) in self.items(Some(rows), rows)?.iter().enumerate() {
            for (j, x) in row.items(Some(cols), cols)?.iter().enumerate() {
                m[(i, j)] = x.f64()?;
            }
        }
        Ok(m)
    }
}
