//! Tesela: a physically based renderer for glTF scenes and Blender.

pub mod scene;
