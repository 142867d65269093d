//! Mesh hierarchies without bits: the octree of EMC's vertex merges and splits, and the
//! reconstruction of triangles from an edge graph that EMC's decoder performs.

pub mod cliques;
pub mod octree;
pub mod pmesh;
pub mod simplify;
