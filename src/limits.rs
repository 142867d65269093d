//! Every bound the decoders and readers enforce, in one place. A stream or file past one of these
//! is refused with [`crate::Error::Limit`] before anything is allocated for it.

/// Most vertices a stream may declare (2^28: 6 GiB of double positions).
pub const MAX_VERTICES: u64 = 1 << 28;
/// Most triangles a stream may declare.
pub const MAX_TRIANGLES: u64 = 1 << 29;
/// Most units (levels, meta-nodes) a stream's index may list.
pub const MAX_UNITS: u64 = 1 << 20;
/// Most bytes of codec parameters in a header.
pub const MAX_PARAM_BYTES: u64 = 1 << 12;
/// Most material names a stream may declare.
pub const MAX_MATERIALS: u64 = 1 << 16;
/// Most bytes of one material name (or of the material library's name).
pub const MAX_NAME_BYTES: u64 = 1 << 12;

/// Most triangles an EMC level may show, for a stream whose full mesh has `triangles`: every
/// level's graph is the full graph with vertices merged, and on real meshes its 3-cliques stay
/// within 0.4% of the full count (results/emc). Four times the count plus room for tiny meshes'
/// coarse levels leaves a wide margin and still bounds what a hostile stream can make the
/// decoder list. The encoder refuses a mesh whose own graph has more.
pub fn level_triangles(triangles: u64) -> usize {
    triangles.saturating_mul(4).saturating_add(4096) as usize
}

/// Most edges an EMC graph may have for a full mesh of `triangles`: every edge of a triangle
/// mesh lies on a face, and every level's graph is the full one with vertices merged.
pub fn graph_edges(triangles: u64) -> u64 {
    triangles.saturating_mul(3)
}

/// Most bytes a decoder allocates at once beyond the stream it reads, as a multiple of the
/// decoded mesh's own size (24 bytes a position, 12 a triangle): the coder's state and contexts,
/// the decoder's graph or face adjacency, and the mesh it hands out. Checked by tests/limits.rs on a 3,301-vertex mesh,
/// where the decoders measure 2.1 (raw), 4.5 (pm), 4.2 (emc-paper), 5.5 (emc), 9.0 (came-paper)
/// and 8.8 (came, which keeps its whole hierarchy for view-dependent refinement: two nodes a
/// vertex with their positions, spheres and paths, every triangle's corner paths and, while
/// units are missing, the corners waiting for them (12 bytes each); its priors add about 10 kB
/// whatever the mesh).
pub const DECODE_MEMORY_MULTIPLE: usize = 9;
