//! CoMA in the browser: the core library.
//!
//! Motions are 22-joint SMPL skeletons at 20 fps, Y up, metres, starting at the origin facing
//! +Z (HumanML3D conventions); see [`skeleton`] and [`features`].

pub mod agents;
#[cfg(not(target_arch = "wasm32"))]
pub mod bench;
pub mod bvh;
pub mod dataset;
pub mod eval;
pub mod executor;
// Assembles trained runs into a model folder: native only (files, training configs).
#[cfg(not(target_arch = "wasm32"))]
pub mod export;
pub mod features;
pub mod geom;
pub mod model;
pub mod motion_file;
pub mod npy;
pub mod plan;
pub mod posecodes;
pub mod render;
pub mod rng;
pub mod serve;
pub mod session;
pub mod share;
pub mod skeleton;
pub mod text;
pub mod timing;
pub mod train;
pub mod trajectory;
pub mod weights;
