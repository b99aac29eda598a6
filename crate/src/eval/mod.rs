//! Measuring the model: control probes (and, next, the text–motion evaluator and the field's
//! metrics).

pub mod probes;
