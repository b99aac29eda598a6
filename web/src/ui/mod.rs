//! The page's components, one concept each.

pub mod about;
pub mod prompt;
pub mod status;
pub mod timeline;
pub mod toolbar;
pub mod viewer;
