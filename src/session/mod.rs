//! `tesela session`: a long-lived renderer for Blender's interactive viewport. It keeps a
//! loaded scene and its BVH, takes commands on stdin and streams progressive images on
//! stdout (docs/session.md).

mod pieces;
pub mod protocol;
mod run;
pub mod schedule;
pub mod state;

pub use run::{SessionOptions, run};
