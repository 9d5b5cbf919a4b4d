//! Procedural textures, the same algorithms as Blender's, reproduced bit for bit against
//! Cycles 5.0's x86 kernel (including where it fuses multiply-adds), so that a procedural
//! looks as in Cycles.

pub mod brick;
pub mod checker;
pub mod gabor;
pub mod gradient;
pub mod hash;
pub mod magic;
pub mod noise;
pub mod voronoi;
pub mod wave;
pub mod white_noise;
