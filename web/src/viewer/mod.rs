//! The 3D viewer: what to draw ([`scene`], plain data: the figure, its shadows, the ground,
//! the camera), which renderer draws it ([`choice`]), the Canvas 2D renderer's projection and
//! painter's sort ([`flat`]), and the renderers on the page's canvas: WebGPU and WebGL2 through
//! wgpu ([`gpu`]), Canvas 2D ([`canvas2d`]), one [`renderer::Renderer`] over them.

#[cfg(target_arch = "wasm32")]
pub mod canvas2d;
pub mod choice;
pub mod flat;
#[cfg(target_arch = "wasm32")]
pub mod gpu;
#[cfg(target_arch = "wasm32")]
pub mod renderer;
pub mod scene;
