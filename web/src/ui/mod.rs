//! The page's components, one concept each.

pub mod about;
pub mod clips;
pub mod path_draw;
pub mod postures;
pub mod prompt;
pub mod segments;
pub mod settings;
pub mod status;
pub mod steps;
pub mod timeline;
pub mod toolbar;
pub mod viewer;
