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
pub mod features;
pub mod geom;
pub mod model;
pub mod motion_file;
pub mod npy;
pub mod posecodes;
pub mod render;
pub mod rng;
pub mod serve;
pub mod share;
pub mod skeleton;
pub mod text;
pub mod train;
pub mod trajectory;
pub mod weights;
