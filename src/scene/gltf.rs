//! glTF 2.0 loader (`.gltf` with external or data-URI buffers, and `.glb`).
//! (Being written: see the loader helper's work.)
