//! Weight files: burnpack records of a network's parameters. Training writes them in f32.
//! The page's models ship smaller: every float rounded to f16, and with [`Bits`] the large
//! tensors (matrices, convolution kernels, embeddings, codebooks) quantized in blocks
//! ([`crate::quant`]). Computing is f32 either way: loading widens everything.
//!
//! A quantized tensor `name` is stored as two:
//!
//! | tensor | dtype | shape | content |
//! |---|---|---|---|
//! | `name` | I8 (8 bits) or U8 (4 bits) | `[bytes]` | the integers, packed as [`Bits`] says, in the parameter's row-major order |
//! | `name#scales` | F16 | `[blocks]` | one scale per block ([`Bits::block`]) |
//!
//! and the file's metadata holds its shape: `name#shape` = the dimensions joined by commas.

use crate::quant::{Bits, Blocks};
use burn::store::burn_pack::{Reader as PackReader, Tensor as PackTensor, Writer as PackWriter};
use burn::store::{bridge, ModuleSnapshot};
use burn::tensor::{f16, Bytes, DType, TensorData};
use std::collections::BTreeMap;

/// Name suffix of a quantized tensor's block scales.
pub const SCALES_SUFFIX: &str = "#scales";
/// Suffix of the metadata key of a quantized tensor's shape.
pub const SHAPE_SUFFIX: &str = "#shape";

/// Parameters smaller than this stay f16: biases, norms, and tensors whose scales would cost
/// more than they save.
const SMALLEST_QUANTIZED: usize = 512;

/// Whether a float parameter of `shape` is quantized: a matrix or more, and not tiny.
pub fn quantizable(shape: &[usize]) -> bool {
    shape.len() >= 2 && shape.iter().product::<usize>() >= SMALLEST_QUANTIZED
}

/// The burnpack of `module` for shipping: floats in f16, and the [`quantizable`] ones to
/// which `bits` gives bits (by parameter name) quantized (see the module docs). No parameter
/// ids, so the same weights always give the same bytes; `metadata` is written as given.
pub fn shipped_bytes<M: ModuleSnapshot>(
    module: &M,
    bits: &dyn Fn(&str) -> Option<Bits>,
    metadata: &[(&str, &str)],
) -> anyhow::Result<Vec<u8>> {
    let mut tensors = Vec::new();
    let mut shapes = Vec::new();
    for tensor in module.collect(None, None, false) {
        let name = tensor.name.clone();
        let data = bridge::into_data(tensor).map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
        let shape = data.shape().to_vec();
        match bits(&name) {
            Some(bits) if data.dtype().is_float() && quantizable(&shape) => {
                let values = data
                    .convert::<f32>()
                    .try_into_vec::<f32>()
                    .map_err(|e| anyhow::anyhow!("{name}: {e:?}"))?;
                let blocks =
                    Blocks::quantize(&values, bits).map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
                let scales = TensorData::new(blocks.scales().to_vec(), [blocks.scales().len()]);
                let bytes = [blocks.packed().len()];
                let packed = match bits {
                    Bits::Eight => TensorData::new(
                        blocks.packed().iter().map(|&b| b as i8).collect::<Vec<_>>(),
                        bytes,
                    ),
                    Bits::Four => TensorData::new(blocks.packed().to_vec(), bytes),
                };
                let dims: Vec<String> = shape.iter().map(usize::to_string).collect();
                shapes.push((format!("{name}{SHAPE_SUFFIX}"), dims.join(",")));
                tensors.push(bridge::from_data(
                    scales,
                    format!("{name}{SCALES_SUFFIX}"),
                    None,
                ));
                tensors.push(bridge::from_data(packed, name, None));
            }
            _ if data.dtype().is_float() => tensors.push(bridge::from_data(
                data.convert_dtype(DType::F16),
                name,
                None,
            )),
            _ => tensors.push(bridge::from_data(data, name, None)),
        }
    }
    let mut writer = PackWriter::new(tensors);
    for (key, value) in metadata {
        writer = writer.with_metadata(key, value);
    }
    for (key, value) in &shapes {
        writer = writer.with_metadata(key, value);
    }
    Ok(writer
        .into_bytes()
        .map_err(|e| anyhow::anyhow!("{e}"))?
        .to_vec())
}

/// [`shipped_bytes`] without quantization: every float rounded to f16.
pub fn f16_bytes<M: ModuleSnapshot>(module: &M) -> anyhow::Result<Vec<u8>> {
    shipped_bytes(module, &|_| None, &[])
}

/// The tensors of a burnpack's bytes with every float widened to f32 (quantized ones
/// dequantized), and its metadata. Damaged bytes give an error naming the tensor.
pub fn read_widened(bytes: &[u8]) -> Result<(Vec<PackTensor>, BTreeMap<String, String>), String> {
    let pack = |e: burn::store::burn_pack::Error| e.to_string();
    let reader = PackReader::from_bytes(Bytes::from_bytes_vec(bytes.to_vec())).map_err(pack)?;
    let metadata: BTreeMap<String, String> = reader
        .metadata()
        .iter()
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect();
    let mut tensors: BTreeMap<String, PackTensor> = reader
        .into_tensors()
        .map_err(pack)?
        .into_iter()
        .map(|t| (t.name.clone(), t))
        .collect();
    let mut scales = take_suffixed(&mut tensors, SCALES_SUFFIX);
    let mut widened = Vec::with_capacity(tensors.len());
    for (name, tensor) in tensors {
        let data = bridge::into_data(tensor).map_err(pack)?;
        let bits = match data.dtype() {
            DType::I8 => Some(Bits::Eight),
            DType::U8 => Some(Bits::Four),
            _ => None,
        };
        let data = match (bits, scales.remove(&format!("{name}{SCALES_SUFFIX}"))) {
            (Some(bits), Some(scale)) => {
                let key = format!("{name}{SHAPE_SUFFIX}");
                let shape: Vec<usize> = metadata
                    .get(&key)
                    .ok_or(format!("{name}: quantized without its shape ({key})"))?
                    .split(',')
                    .map(|d| d.trim().parse::<usize>())
                    .collect::<Result<_, _>>()
                    .map_err(|e| format!("{key}: {e}"))?;
                let scale = bridge::into_data(scale).map_err(pack)?;
                let scale: Vec<f16> = scale
                    .try_into_vec::<f16>()
                    .map_err(|e| format!("{name}{SCALES_SUFFIX}: {e:?}"))?;
                let packed: Vec<u8> = match bits {
                    Bits::Eight => data.iter::<i8>().map(|q| q as u8).collect(),
                    Bits::Four => data.iter::<u8>().collect(),
                };
                let len = shape.iter().product();
                let blocks = Blocks::from_parts(bits, len, scale, packed)
                    .map_err(|e| format!("{name}: {e}"))?;
                TensorData::new(blocks.dequantize(), shape)
            }
            // Integer parameters of a module stay as they are; quantized ones have scales.
            (Some(_), None) => data,
            (None, Some(_)) => {
                return Err(format!("{name}{SCALES_SUFFIX} scales no quantized tensor"))
            }
            _ if data.dtype().is_float() => data.convert::<f32>(),
            _ => data,
        };
        widened.push(bridge::from_data(data, name, None));
    }
    if let Some(name) = scales.keys().next() {
        return Err(format!("{name} scales no tensor"));
    }
    Ok((widened, metadata))
}

/// Takes out of `tensors` those whose names end with `suffix` (the scales stored beside
/// quantized tensors), by name.
pub(crate) fn take_suffixed(
    tensors: &mut BTreeMap<String, PackTensor>,
    suffix: &str,
) -> BTreeMap<String, PackTensor> {
    let names: Vec<String> = tensors
        .keys()
        .filter(|name| name.ends_with(suffix))
        .cloned()
        .collect();
    names
        .into_iter()
        .filter_map(|name| tensors.remove_entry(&name))
        .collect()
}

/// `module` with the parameters of a burnpack's bytes (f32, f16 or quantized, widened to
/// the module's f32); the message says what does not fit.
pub fn load_into<M: ModuleSnapshot>(mut module: M, bytes: &[u8]) -> Result<M, String> {
    let (tensors, _) = read_widened(bytes)?;
    let result = module.apply(tensors, None, None, false);
    if !(result.errors.is_empty() && result.missing.is_empty() && result.unused.is_empty()) {
        return Err(result.to_string());
    }
    Ok(module)
}

/// [`load_into`] from a file; the error names the file.
pub fn load_file<M: ModuleSnapshot>(module: M, path: &std::path::Path) -> anyhow::Result<M> {
    let bytes = std::fs::read(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    load_into(module, &bytes).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use burn::nn::{Linear, LinearConfig};
    use burn::tensor::Device;

    fn weights(linear: &Linear) -> Vec<f32> {
        linear.weight.val().into_data().iter::<f32>().collect()
    }

    #[test]
    fn shipped_weights_load_back_within_their_precision() {
        let device = Device::flex();
        let linear: Linear = LinearConfig::new(64, 48).init(&device);
        let fresh = || LinearConfig::new(64, 48).init(&device);
        let mut sizes = Vec::new();
        for (bits, step) in [
            (None, 1e-3),
            (Some(Bits::Eight), 1.0 / 127.0),
            (Some(Bits::Four), 1.0 / 7.0),
        ] {
            let bytes = shipped_bytes(&linear, &|_| bits, &[("format", "test")]).unwrap();
            assert_eq!(
                bytes,
                shipped_bytes(&linear, &|_| bits, &[("format", "test")]).unwrap()
            );
            let back: Linear = load_into(fresh(), &bytes).unwrap();
            let max = weights(&linear).iter().fold(0f32, |m, v| m.max(v.abs()));
            for (a, b) in weights(&linear).iter().zip(weights(&back)) {
                assert!(
                    (a - b).abs() <= max * step / 2.0 + 1e-6,
                    "{bits:?}: {a} vs {b}"
                );
            }
            let bias = |l: &Linear| {
                l.bias
                    .as_ref()
                    .unwrap()
                    .val()
                    .into_data()
                    .iter::<f32>()
                    .collect::<Vec<_>>()
            };
            for (a, b) in bias(&linear).iter().zip(bias(&back)) {
                assert!((a - b).abs() <= a.abs() * 1e-3, "biases stay f16");
            }
            assert_eq!(read_widened(&bytes).unwrap().1["format"], "test");
            sizes.push(bytes.len());
        }
        assert!(sizes[2] < sizes[1] && sizes[1] < sizes[0], "{sizes:?}");
    }

    #[test]
    fn damaged_quantized_files_are_errors() {
        let device = Device::flex();
        let linear: Linear = LinearConfig::new(64, 48).init(&device);
        let bytes = shipped_bytes(&linear, &|_| Some(Bits::Four), &[]).unwrap();
        let (tensors, _) = read_widened(&bytes).unwrap();
        assert_eq!(tensors.len(), 2, "the scales are folded into their tensor");
        let repack_with = |keep: &dyn Fn(&str) -> bool, shapes: bool| {
            let reader = PackReader::from_bytes(Bytes::from_bytes_vec(bytes.clone())).unwrap();
            let metadata = reader.metadata().clone();
            let kept: Vec<PackTensor> = reader
                .into_tensors()
                .unwrap()
                .into_iter()
                .filter(|t| keep(&t.name))
                .collect();
            let mut writer = PackWriter::new(kept);
            for (key, value) in metadata.iter().filter(|_| shapes) {
                writer = writer.with_metadata(key, value);
            }
            writer.into_bytes().unwrap().to_vec()
        };
        let repack = |keep: &dyn Fn(&str) -> bool| repack_with(keep, true);
        let shapeless = repack_with(&|_| true, false);
        assert!(read_widened(&shapeless)
            .unwrap_err()
            .contains("weight: quantized without its shape (weight#shape)"));
        let no_weight = repack(&|name| name != "weight");
        assert!(read_widened(&no_weight)
            .unwrap_err()
            .contains("weight#scales scales no tensor"));
        let no_bias = repack(&|name| name != "bias");
        let err = load_into(LinearConfig::new(64, 48).init(&device), &no_bias).unwrap_err();
        assert!(err.contains("bias"), "{err}");
        let wrong: Result<Linear, _> = load_into(LinearConfig::new(64, 40).init(&device), &bytes);
        assert!(wrong.is_err());
        assert!(load_into(LinearConfig::new(64, 48).init(&device), b"not weights").is_err());
    }
}
