//! The 3D skeleton viewer: what to draw ([`scene`], plain data) and the WebGPU renderer that
//! draws it on the page's canvas ([`gpu`]).

#[cfg(target_arch = "wasm32")]
pub mod gpu;
pub mod scene;
