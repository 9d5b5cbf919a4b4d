//! Procedural textures, the same algorithms as Blender's (so a procedural looks as in Cycles).
