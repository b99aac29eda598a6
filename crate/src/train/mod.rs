//! Training: the data in memory, run bookkeeping (checkpoints, logs, plots) and the training
//! loops of the motion model.

pub mod motions;
pub mod run;
pub mod tokens;
pub mod transformer;
pub mod vq;
