//! Mesh hierarchies without bits: CAME's binary vertex hierarchy (`came`), the octree of EMC's
//! vertex merges and splits (`octree`), the reconstruction of triangles from an edge graph that
//! EMC's decoder performs (`cliques`), QEM simplification and the progressive mesh it defines
//! (`simplify`), and Hoppe's vertex splits and edge collapses applied in place (`pmesh`).

pub mod came;
pub mod cliques;
pub mod octree;
pub mod pmesh;
pub mod simplify;
