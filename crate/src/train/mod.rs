//! Training: data in memory and (next) the training loops of the motion model.

pub mod motions;
