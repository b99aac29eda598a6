//! Weight files: burnpack records of a network's parameters. Training writes them in f32;
//! the page's default models ship rounded to f16 (half the download) and compute in f32,
//! widened on load.

use burn::module::Module;
use burn::store::{bridge, burn_pack, ModuleRecord, ModuleSnapshot};

/// The burnpack of `module` with every float parameter rounded to f16: the same tensor
/// names and shapes as training's f32 file, without parameter ids, so the same weights
/// always give the same bytes.
pub fn f16_bytes<M: ModuleSnapshot>(module: &M) -> anyhow::Result<Vec<u8>> {
    let mut tensors = Vec::new();
    for tensor in module.collect(None, None, false) {
        let name = tensor.name.clone();
        let data = bridge::into_data(tensor).map_err(|e| anyhow::anyhow!("{name}: {e}"))?;
        let data = if data.dtype().is_float() {
            data.convert_dtype(burn::tensor::DType::F16)
        } else {
            data
        };
        tensors.push(bridge::from_data(data, name, None));
    }
    let bytes = burn_pack::Writer::new(tensors)
        .into_bytes()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(bytes.to_vec())
}

/// `module` with the parameters of a burnpack's bytes (f32, or f16 widened to the module's
/// f32); the message says what does not fit.
pub fn load_into<M: Module>(module: M, bytes: &[u8]) -> Result<M, String> {
    let record = ModuleRecord::from_bytes(burn::tensor::Bytes::from_bytes_vec(bytes.to_vec()))
        .map_err(|e| format!("{e:?}"))?;
    module
        .try_load_record(record.cast_to_module_dtype())
        .map_err(|e| format!("{e:?}"))
}

/// [`load_into`] from a file; the error names the file.
pub fn load_file<M: Module>(module: M, path: &std::path::Path) -> anyhow::Result<M> {
    let bytes = std::fs::read(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    load_into(module, &bytes).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}
