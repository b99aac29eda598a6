//! CoMA in the browser: the core library.
//!
//! Motions are 22-joint SMPL skeletons at 20 fps ([`timing`]), Y up, metres, starting at the
//! origin facing +Z (HumanML3D conventions); see [`skeleton`] and [`features`].
//!
//! The modules in layers; each imports only from its own layer or the layers below it (a
//! test, `tests/module_graph.rs`, fails on an import that goes up a layer and on any cycle):
//!
//! ```text
//!  export                         assembling the shipped files from trained runs
//!  eval  train  bench             the lab: the evaluation protocol (it runs the engine), training
//!  session                        the engine: typed commands in, progress and outcomes out
//!  agents                         LLM client, planner, reviewer, the loop (pipeline)
//!  share  plan                    share links; what the planner hands to the generator
//!  model  text  trajectory        SPAM, the evaluator, tokens; MiniLM; paths on the ground
//!  feet  posture                  planted feet of every motion; key postures
//!  gltf  dataset  posecodes  render  bvh  mocap  features  metrics  figure  skeleton  timing  geom  rng  npy  …
//! ```
//!
//! One prompt, from the text box to the canvas: the page's prompt box sends a
//! `Command::Run` to the worker (`web/src/messages.rs`, JSON), which hands it to
//! [`session::Session::execute`]; the engine plans ([`session::planning`]: LLM or built-in
//! planner, fallbacks, the length asked for), runs the loop ([`agents::pipeline`]: SPAM
//! generates and edits [`model::tokens::MotionTokens`], the reviewer judges, segments blend),
//! lays the paths and decodes the joints, reporting [`session::Progress`] on the way; the
//! worker posts the [`session::Outcome`] back and the page shows it. Every type is checked
//! once where it enters (a `Plan` and `MotionTokens` as they are deserialised, a share link
//! as it is decoded) and crosses the later hops as is. `coma run` and `coma eval` call the
//! same engine.

pub mod agents;
// Times training steps too, and the CLI is its only caller: native only.
#[cfg(feature = "native")]
pub mod bench;
pub mod bvh;
pub mod dataset;
pub mod eval;
pub mod executor;
// Assembles trained runs into a model folder: native only (files, training configs).
#[cfg(feature = "native")]
pub mod export;
pub mod features;
pub mod feet;
pub mod figure;
pub mod geom;
pub mod gltf;
pub mod limb;
pub mod metrics;
pub mod mocap;
pub mod model;
pub mod motion_file;
pub mod npy;
pub mod plan;
pub mod posecodes;
pub mod posture;
pub mod quant;
pub mod render;
pub mod rng;
pub mod session;
pub mod share;
pub mod skeleton;
pub mod text;
pub mod timing;
// Training loops need burn's autodiff and optimizers, which the page leaves out.
#[cfg(feature = "train")]
pub mod train;
pub mod trajectory;
pub mod weights;
