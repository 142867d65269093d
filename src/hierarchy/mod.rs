//! Mesh hierarchies without bits: CAME's binary vertex hierarchy, the octree of EMC's vertex merges and splits, and the
//! reconstruction of triangles from an edge graph that EMC's decoder performs.

pub mod came;
pub mod cliques;
pub mod octree;
pub mod pmesh;
pub mod simplify;
