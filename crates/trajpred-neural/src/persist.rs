//! The model file: one file holding a JSON header (configuration, standardisation, training
//! reports) followed by the networks' weights in burn's record format (burnpack bytes).
//!
//! Layout: the magic line `trajpred-neural 1\n`, then little-endian `u64` lengths each
//! followed by that many bytes: first the JSON header, then one record per network.

use crate::error::{NeuralError, Result};
use crate::train::Standardizer;
use burn::module::{Module, ModuleVisitor, Param};
use burn::store::ModuleRecord;
use burn::tensor::{Bytes, DType, Tensor};
use std::path::Path;

const MAGIC: &[u8] = b"trajpred-neural 1\n";

fn perr(path: &Path, reason: impl ToString) -> NeuralError {
    NeuralError::Persistence {
        path: path.display().to_string(),
        reason: reason.to_string(),
    }
}

/// Writes the header and the modules' records to `path`.
pub(crate) fn write<N: Module>(path: &Path, header: &str, nets: &[N]) -> Result<()> {
    let mut out = Vec::from(MAGIC);
    let mut push = |bytes: &[u8]| {
        out.extend_from_slice(&(bytes.len() as u64).to_le_bytes());
        out.extend_from_slice(bytes);
    };
    push(header.as_bytes());
    for n in nets {
        let bytes = n
            .clone()
            .into_record()
            .into_bytes()
            .map_err(|e| perr(path, format!("{e:?}")))?;
        push(&bytes[..]);
    }
    // whole or not at all: a killed save leaves the previous model file
    trajpred_core::io::write_atomic(path, &out).map_err(|e| perr(path, e))
}

/// Reads a file written by [`write`]: the header and the raw records.
pub(crate) fn read(path: &Path) -> Result<(String, Vec<Vec<u8>>)> {
    let data = std::fs::read(path).map_err(|e| perr(path, e))?;
    parse(path, &data)
}

/// Splits the bytes of a model file (named `path` in errors) into header and records.
pub(crate) fn parse(path: &Path, data: &[u8]) -> Result<(String, Vec<Vec<u8>>)> {
    let rest = data
        .strip_prefix(MAGIC)
        .ok_or_else(|| perr(path, "not a trajpred-neural model file"))?;
    let mut chunks = Vec::new();
    let mut pos = 0usize;
    while pos < rest.len() {
        let len_bytes: [u8; 8] = rest
            .get(pos..pos + 8)
            .and_then(|s| s.try_into().ok())
            .ok_or_else(|| perr(path, "truncated length field"))?;
        let len = usize::try_from(u64::from_le_bytes(len_bytes))
            .map_err(|_| perr(path, "length field too large"))?;
        pos += 8;
        let end = pos
            .checked_add(len)
            .filter(|&e| e <= rest.len())
            .ok_or_else(|| perr(path, "truncated chunk"))?;
        chunks.push(rest[pos..end].to_vec());
        pos = end;
    }
    if chunks.is_empty() {
        return Err(perr(path, "no header"));
    }
    let header = String::from_utf8(chunks.remove(0)).map_err(|e| perr(path, e))?;
    Ok((header, chunks))
}

/// The element type and shape of every float parameter of a module, in visiting order.
#[derive(Default, PartialEq)]
struct Shapes(Vec<(DType, Vec<usize>)>);

impl ModuleVisitor for Shapes {
    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        let t = param.val();
        self.0.push((t.dtype(), t.dims().to_vec()));
    }
}

fn shapes<N: Module>(net: &N) -> Shapes {
    let mut s = Shapes::default();
    net.visit(&mut s);
    s
}

/// Loads raw record bytes into a freshly built module. The loaded parameters must have the
/// fresh module's shapes and be `f32`.
pub(crate) fn load_into<N: Module>(path: &Path, net: N, bytes: Vec<u8>) -> Result<N> {
    // cast to the network's f32 on load: a record of another element type (a damaged file)
    // would otherwise be taken as it is and make burn panic (fixtures/fuzz-models)
    let record = ModuleRecord::from_bytes(Bytes::from_bytes_vec(bytes))
        .map_err(|e| perr(path, format!("{e:?}")))?
        .cast_to_module_dtype();
    let expected = shapes(&net);
    let loaded = net
        .try_load_record(record)
        .map_err(|e| perr(path, format!("{e:?}")))?;
    let got = shapes(&loaded);
    if got != expected || got.0.iter().any(|(dtype, _)| *dtype != DType::F32) {
        return Err(perr(
            path,
            "the weights' element types or shapes do not match the network the header describes",
        ));
    }
    Ok(loaded)
}

/// Checks what a header says about the data before any network is built from it: the
/// number of axes (1 to [`trajpred_core::MAX_AXES`]) and a standardisation of that many
/// axes with finite means and finite positive deviations.
pub(crate) fn check_header(path: &Path, dim: usize, scaler: &Standardizer) -> Result<()> {
    if dim == 0 || dim > trajpred_core::MAX_AXES {
        return Err(perr(
            path,
            format!("{dim} axes (1 to {} expected)", trajpred_core::MAX_AXES),
        ));
    }
    if scaler.mean.len() != dim || scaler.std.len() != dim {
        return Err(perr(
            path,
            format!(
                "standardisation of {} / {} axes for {dim} axes",
                scaler.mean.len(),
                scaler.std.len()
            ),
        ));
    }
    if !scaler.mean.iter().all(|m| m.is_finite())
        || !scaler.std.iter().all(|s| s.is_finite() && *s > 0.0)
    {
        return Err(perr(
            path,
            "standardisation with a non-finite mean or a deviation that is not finite and positive",
        ));
    }
    Ok(())
}

/// Serialises a header.
pub(crate) fn to_json<T: serde::Serialize>(path: &Path, v: &T) -> Result<String> {
    serde_json::to_string(v).map_err(|e| perr(path, e))
}

/// Parses a header.
pub(crate) fn from_json<T: serde::de::DeserializeOwned>(path: &Path, s: &str) -> Result<T> {
    serde_json::from_str(s).map_err(|e| perr(path, e))
}
