//! OBJ specifics: polygon triangulation, normals, MTL mapping.
