//! The planner: a prompt becomes a [`Plan`](crate::plan::Plan) of consecutive
//! segments, each with a base motion, body-part edits and an optional path.
//!
//! With an LLM configured, three steps each ask it one question with a JSON schema (rewrite,
//! segment, decompose); without one, or whenever the LLM fails, the deterministic rules of
//! [`offline`] make the plan.

pub mod lexicon;
pub mod llm;
pub mod meaning;
pub mod offline;
pub mod postures;
pub mod prompt_set;
pub mod sided;
pub mod timeline_set;
