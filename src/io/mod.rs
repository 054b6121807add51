//! Reading and writing meshes: OBJ, PLY, glTF 2.0 (`.gltf`/`.glb`), chosen by extension.
