//! Garland–Heckbert quadric error simplification by edge collapses, and the progressive mesh it
//! defines (Hoppe: base mesh M⁰ plus the vertex splits that undo the collapses in reverse).
//!
//! Collapses are taken cheapest first from an indexed 8-ary heap of edges (each edge's key is
//! updated in place when a collapse changes it, so the heap never holds stale entries), and
//! simplification is O(f log f). Each vertex keeps its faces and its edges, so a check reads
//! only the two endpoints' lists. A collapse must keep the mesh a manifold
//! (link condition; no interior edge between two boundary vertices; no two faces on the same
//! three vertices), must not flip a face's normal, and keeps boundaries through constraint
//! quadrics on boundary edges. When the heap runs dry, every edge is queued again, until a
//! whole pass collapses nothing: the base mesh is then as small as these rules allow.
//!
//! Meshes of 200,000 faces or more are first simplified in parallel: a k-d split of the vertices
//! makes regions of 16k-32k faces, each collapses its own edges greedily on a compact copy (small
//! enough to stay in cache) up to a common cost (a high quantile of the initial costs) with the
//! vertices it shares with another region frozen, and the regions' collapses are interleaved
//! cheapest first. No two regions touch the same face, so any interleaving is a valid sequence.
//! A second round cuts what remains along diagonal planes, across the first round's seams, up to
//! the same cost; the single greedy loop does the rest.
//!
//! The progressive mesh needs no replay of the splits: each collapse records the face its split
//! is located from and which corners hold vs, and once the face ids a decoder will assign are
//! known (one pass in split order), every Vsplit record follows from its collapse alone.

use smallvec::SmallVec;

pub(in crate::hierarchy) mod engine;
pub mod quadric;
mod records;
mod regions;
mod reorder;

pub use records::{progressive_mesh, ProgressiveMesh};
pub use reorder::reordered_progressive_mesh;

use engine::{topology, State};
use quadric::{add_seam_planes, initial_quadrics};
use regions::{simplify_in_regions, REGION_MIN_FACES};

/// Where a collapse puts the remaining vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placement {
    /// Where the summed quadric is smallest (rounded to a cell), else the best endpoint or
    /// midpoint.
    Optimal,
    /// One of the endpoints or their midpoint (Hoppe §6: vad_s = 0).
    EndpointOrMidpoint,
}

/// One edge collapse, recorded with what its inverse split needs.
#[derive(Clone, Debug)]
pub struct Collapse {
    /// Remaining vertex.
    pub vs: u32,
    /// Removed vertex.
    pub vt: u32,
    /// Positions of vs and vt before the collapse.
    pub before: [[i32; 3]; 2],
    /// Position of vs after it.
    pub after: [i32; 3],
    /// Removed faces: fl holds directed edge vt → vs, fr (or NIL) vs → vt.
    pub fl: u32,
    /// See `fl`.
    pub fr: u32,
    /// Third corners of fl and fr (vr NIL when fr is).
    pub vl: u32,
    /// See `vl`.
    pub vr: u32,
    /// Faces of vt other than fl and fr, which now hold vs.
    pub moved: SmallVec<[u32; 6]>,
    /// Faces across (vs, vl) from fl and across (vs, vr) from fr (NIL where none): the split
    /// re-links them.
    pub beside: [u32; 2],
    /// The face the split is located from (Hoppe's flclw): the moved face on edge (vt, vl), or
    /// `beside[0]` when none moves.
    pub flclw: u32,
    /// Corner of flclw that holds vs after the collapse.
    pub flclw_corner: u8,
    /// Corners of fl and fr that hold vs (fr's is 0 when there is no fr).
    pub vs_corners: [u8; 2],
}

/// The result of simplification: collapses in order, and what remains.
pub struct Simplified {
    /// Collapses, first to last.
    pub collapses: Vec<Collapse>,
    /// Which vertices remain.
    pub vertex_alive: Vec<bool>,
    /// Which faces remain.
    pub face_alive: Vec<bool>,
    /// Positions after simplification.
    pub positions: Vec<[i32; 3]>,
    /// Faces (remaining ones valid) after simplification.
    pub faces: Vec<[u32; 3]>,
}

/// Grid step of a split's small delta vad_s: positions between a collapse and its split need
/// not be finer than 1/32 of the split's length, so the optimal placement is snapped to
/// multiples of this step from an endpoint (the full mesh stays exact: vad_l is not snapped).
pub fn vad_s_step(vad_l: [i32; 3]) -> i32 {
    let m = vad_l.iter().map(|x| x.unsigned_abs()).max().unwrap_or(0);
    let bits = 32 - m.leading_zeros();
    1 << bits.saturating_sub(5)
}

/// Simplifies the oriented manifold mesh (`cells`, `faces`) as far as the rules allow.
pub fn simplify(cells: &[[i32; 3]], faces: &[[u32; 3]], placement: Placement) -> Simplified {
    let regions = faces.len() >= REGION_MIN_FACES && rayon::current_num_threads() > 1;
    simplify_with_regions(cells, faces, placement, regions)
}

/// [`simplify`], with or without the parallel phase.
fn simplify_with_regions(
    cells: &[[i32; 3]],
    faces: &[[u32; 3]],
    placement: Placement,
    regions: bool,
) -> Simplified {
    let bounds = bounds_of(cells);
    if regions {
        return simplify_in_regions(cells, faces, placement, bounds);
    }
    simplify_whole(cells, faces, placement, bounds, Constraints::default())
}

/// What a simplification keeps besides the rules every collapse obeys.
#[derive(Clone, Copy, Debug, Default)]
pub struct Constraints<'a> {
    /// Seams to keep (edges as sorted vertex pairs, the list sorted): a seam edge gets
    /// constraint planes as a boundary does, and a collapse may neither move a seam nor join
    /// two (Hoppe 1996 §4.3, on discontinuity curves): its removed vertex lies on no seam, or
    /// on exactly two with the collapsed edge one of them. Seams are attribute discontinuities
    /// — uv charts, normal creases, material boundaries — which collapses across would smear.
    pub seams: &'a [[u32; 2]],
    /// Vertices that never vanish and, when they survive a collapse, stay where they are
    /// (empty: none). A mesh cut to a manifold (`mesh::manifold`) pins every vertex that was
    /// copied and its copies: they start in one cell and so stay at every level, and the cut
    /// never opens into a crack.
    pub pinned: &'a [bool],
}

/// [`simplify`] under `constraints`. The single greedy loop only: constrained meshes are
/// simplified without the parallel phase.
pub fn simplify_constrained(
    cells: &[[i32; 3]],
    faces: &[[u32; 3]],
    placement: Placement,
    constraints: Constraints,
) -> Simplified {
    let bounds = bounds_of(cells);
    simplify_whole(cells, faces, placement, bounds, constraints)
}

/// The box of `cells`.
fn bounds_of(cells: &[[i32; 3]]) -> ([i32; 3], [i32; 3]) {
    cells
        .iter()
        .fold(([i32::MAX; 3], [i32::MIN; 3]), |(lo, hi), c| {
            (
                [0, 1, 2].map(|a| lo[a].min(c[a])),
                [0, 1, 2].map(|a| hi[a].max(c[a])),
            )
        })
}

/// The single greedy loop over the whole mesh, under `constraints`.
fn simplify_whole(
    cells: &[[i32; 3]],
    faces: &[[u32; 3]],
    placement: Placement,
    bounds: ([i32; 3], [i32; 3]),
    constraints: Constraints,
) -> Simplified {
    let seams = constraints.seams;
    let n = cells.len();
    let t = topology(n, faces, &vec![true; faces.len()]);
    let seam: Vec<bool> = if seams.is_empty() {
        Vec::new()
    } else {
        t.edges
            .iter()
            .map(|e| seams.binary_search(e).is_ok())
            .collect()
    };
    let mut quadrics = initial_quadrics(cells, faces, &t);
    if !seam.is_empty() {
        add_seam_planes(&mut quadrics, cells, faces, &t, &seam);
    }
    let mut state = State::new(
        cells.to_vec(),
        faces.to_vec(),
        quadrics,
        vec![false; n],
        placement,
        bounds,
        t,
    );
    state.seam = seam;
    state.pinned = constraints.pinned.to_vec();
    // When a pass runs dry, every remaining edge is queued again, until a pass collapses nothing.
    let (mut collapses, mut costs) = (Vec::new(), Vec::new());
    while state.collapse_greedily(f32::INFINITY, &mut collapses, &mut costs) > 0 {}
    Simplified {
        collapses,
        vertex_alive: state.vertex_alive,
        face_alive: state.face_alive,
        positions: state.cells,
        faces: state.faces,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    fn cells_of(mesh: &crate::mesh::TriMesh) -> Vec<[i32; 3]> {
        mesh.positions
            .iter()
            .map(|p| {
                [
                    (p.x * 1000.0) as i32,
                    (p.y * 1000.0) as i32,
                    (p.z * 1000.0) as i32,
                ]
            })
            .collect()
    }

    fn check_round_trip(mesh: &crate::mesh::TriMesh, placement: Placement) {
        check_round_trip_with(mesh, placement, false);
    }

    fn check_round_trip_with(mesh: &crate::mesh::TriMesh, placement: Placement, regions: bool) {
        let cells = cells_of(mesh);
        let s = simplify_with_regions(&cells, &mesh.faces, placement, regions);
        let pm = progressive_mesh(&mesh.faces, &s);
        let mut m = pm.base.clone();
        m.check_invariants().unwrap();
        for (i, split) in pm.vsplits.iter().enumerate() {
            m.vsplit(split).unwrap();
            if i % 7 == 0 {
                m.check_invariants().unwrap();
            }
        }
        m.check_invariants().unwrap();
        // Same faces and positions as the original, through the vertex order.
        let mut got: Vec<[u32; 3]> = m
            .triangles()
            .iter()
            .map(|t| {
                crate::mesh::canonical::rotate_to_smallest(t.map(|v| pm.vertex_origin[v as usize]))
            })
            .collect();
        let mut want: Vec<[u32; 3]> = mesh
            .faces
            .iter()
            .map(|t| crate::mesh::canonical::rotate_to_smallest(*t))
            .collect();
        got.sort_unstable();
        want.sort_unstable();
        assert_eq!(got, want);
        for (v, &o) in pm.vertex_origin.iter().enumerate() {
            assert_eq!(m.positions[v], cells[o as usize]);
        }
        for split in pm.vsplits.iter().rev() {
            m.ecol(split);
        }
        assert_eq!(m, pm.base);
    }

    #[test]
    fn closed_and_open_meshes_simplify_and_rebuild_exactly() {
        for placement in [Placement::Optimal, Placement::EndpointOrMidpoint] {
            check_round_trip(&generate::icosphere(3), placement);
            check_round_trip(&generate::torus(2.0, 0.6, 24, 12), placement);
            check_round_trip(&generate::terrain(400, 5), placement);
        }
        // The parallel phase (regions with frozen seams, interleaved by cost) on small meshes.
        for placement in [Placement::Optimal, Placement::EndpointOrMidpoint] {
            check_round_trip_with(&generate::icosphere(3), placement, true);
            check_round_trip_with(&generate::torus(2.0, 0.6, 32, 16), placement, true);
            check_round_trip_with(&generate::terrain(800, 7), placement, true);
        }
        let sphere = generate::icosphere(3);
        let s = simplify(&cells_of(&sphere), &sphere.faces, Placement::Optimal);
        assert_eq!(
            s.vertex_alive.iter().filter(|&&a| a).count(),
            4,
            "a sphere ends as a tetrahedron"
        );
    }
}
