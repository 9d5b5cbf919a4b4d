//! Tesela: a physically based renderer for glTF scenes and Blender.
//!
//! Pipeline: [`scene`] (glTF or built-in) → [`render_scene::RenderScene`] (BVH, emitters) →
//! [`render::render`] (tiles, [`integrator`]s, [`bsdf`]s, [`emitter`]s) → [`output`] or the
//! [`protocol`] pipe.

pub mod accel;
pub mod bsdf;
pub mod camera;
pub mod denoise;
pub mod displace;
pub mod emitter;
pub mod film;
pub mod frame;
pub mod instancing;
pub mod integrator;
pub mod medium;
pub mod motion;
pub mod output;
pub mod protocol;
pub mod render;
pub mod render_scene;
pub mod sampler;
pub mod sampling;
pub mod scene;
pub mod session;
pub mod shading;
pub mod study;
pub mod texture;
pub mod trig;
