//! Key postures (PRO-Motion's plan–posture–go, design §4.5): poses and actions the motion model
//! never saw in its data (a T-pose, a squat, kneeling, a superhero landing, crawling), built
//! from closed-vocabulary posture scripts instead of learned from motion capture.
//!
//! - [`script`]: a key pose as constraints in the describer's vocabulary, parsed and checked.
//! - [`solver`]: a script → a pose of the 22-joint skeleton (joint limits, floor, balance, a
//!   rest prior), deterministic and bounded.
//! - [`library`]: named postures and movements of key poses, read from `static/postures/`.
//! - [`go`]: key poses placed in time — eased transitions, planted feet, flight for jumps,
//!   turns and cycles — into a motion at 20 fps.
//! - [`track`]: the key poses of a plan segment, laid over the generated motion and reviewed.
//! - [`check`]: the solver's round trip through the describer, and a fuzz of scripts.
//! - [`measure`]: foot skating, the lowest joint and joint speeds outside flight, against the
//!   real test motions (`coma posture motions`).

pub mod check;
pub mod go;
pub mod library;
pub mod measure;
pub mod script;
pub mod solver;
pub mod track;

#[cfg(test)]
mod tests;
