//! The parallel region phase for large meshes: a k-d split into regions of 16k-32k faces, each
//! simplified greedily on a compact copy with its shared vertices frozen, the regions'
//! collapses interleaved cheapest first; then a second round across the seams.

use super::engine::{topology, State};
use super::quadric::{initial_quadrics, Quadric};
use super::{Collapse, Placement, Simplified};
use crate::hierarchy::pmesh::NIL;
use rayon::prelude::*;

/// Meshes below this many faces are simplified by one greedy loop; larger ones first in
/// regions, in parallel.
pub(super) const REGION_MIN_FACES: usize = 200_000;
/// Faces per region in the first round. Small regions keep a greedy loop's data in cache: on
/// bunny-closed-35k ×16, regions of 140k faces collapse at 3.2 µs per collapse, of 35k at
/// 2.0 µs; 17k made the whole 7% faster than 35k.
pub(super) const REGION_FACES: usize = 1 << 14;
/// At most this many regions (region ids are bytes).
pub(super) const MAX_REGIONS: usize = 128;
/// Regions of the second round, which cuts across the first round's seams.
pub(super) const SECOND_ROUND_REGIONS: usize = 8;
/// The first round makes the collapses cheaper than this quantile of its initial edge costs;
/// the seams go to the second round, which stops at the same cost, and the costlier collapses
/// to the last greedy loop. Measured with one round of 8 regions on bunny-closed-35k ×16: 0.5
/// leaves 50% of the collapses to the global loop, 0.97 leaves 7%. With both rounds, on
/// bunny-closed-35k ×4 (278k faces), the RMS error of every level stays within 2% of one
/// greedy loop (most of them better) and the stream grows 0.06%.
pub(super) const REGION_COST_QUANTILE: f64 = 0.985;
/// About this many evenly spaced edges are placed to estimate that quantile.
pub(super) const REGION_COST_SAMPLES: usize = 1 << 16;

/// The faces `face_ids` in `count` regions (a power of two): each face goes where its first
/// corner is in a k-d split of their vertices into sets of equal size, each set halved across
/// the one of `directions` along which it is longest.
pub(super) fn split_into_regions(
    cells: &[[i32; 3]],
    faces: &[[u32; 3]],
    face_ids: &[u32],
    directions: &[[i64; 3]],
    count: usize,
) -> Vec<Vec<u32>> {
    let along = |d: &[i64; 3], v: u32| -> i64 {
        let c = cells[v as usize];
        (0..3).map(|a| d[a] * i64::from(c[a])).sum()
    };
    let split = |ids: &mut [u32]| {
        if ids.len() < 2 {
            return 0;
        }
        let extent = |d: &[i64; 3]| {
            let (lo, hi) = ids.par_iter().map(|&v| (along(d, v), along(d, v))).reduce(
                || (i64::MAX, i64::MIN),
                |(lo, hi), (l, h)| (lo.min(l), hi.max(h)),
            );
            hi.saturating_sub(lo)
        };
        let d = directions
            .iter()
            .max_by_key(|d| extent(d))
            .expect("a direction");
        let middle = ids.len() / 2;
        ids.select_nth_unstable_by_key(middle, |&v| (along(d, v), v));
        middle
    };
    let mut ids: Vec<u32> = face_ids.iter().map(|&f| faces[f as usize][0]).collect();
    ids.sort_unstable();
    ids.dedup();
    // Halve every set until there are `count`.
    let mut sets: Vec<&mut [u32]> = vec![&mut ids];
    while sets.len() < count {
        sets = sets
            .into_par_iter()
            .flat_map_iter(|set| {
                let middle = split(set);
                let (low, high) = set.split_at_mut(middle);
                [low, high]
            })
            .collect();
    }
    let mut vertex_region = vec![0u8; cells.len()];
    for (r, set) in sets.iter().enumerate() {
        for &v in set.iter() {
            vertex_region[v as usize] = r as u8;
        }
    }
    let mut regions = vec![Vec::new(); count];
    for &f in face_ids {
        regions[vertex_region[faces[f as usize][0] as usize] as usize].push(f);
    }
    regions
}

/// The mesh as the region phase keeps it: parts of it are simplified on compact copies and
/// written back.
pub(super) struct Whole {
    pub(super) cells: Vec<[i32; 3]>,
    pub(super) faces: Vec<[u32; 3]>,
    pub(super) quadrics: Vec<Quadric>,
    pub(super) vertex_alive: Vec<bool>,
    pub(super) face_alive: Vec<bool>,
    pub(super) placement: Placement,
    pub(super) bounds: ([i32; 3], [i32; 3]),
}

impl Whole {
    pub(super) fn live_faces(&self) -> Vec<u32> {
        (0..self.faces.len() as u32)
            .filter(|&f| self.face_alive[f as usize])
            .collect()
    }
}

/// The vertices of some faces (sorted) and the faces in their indices.
pub(super) fn compact(faces: &[[u32; 3]], face_ids: &[u32]) -> (Vec<u32>, Vec<[u32; 3]>) {
    let mut vertices: Vec<u32> = face_ids.iter().flat_map(|&f| faces[f as usize]).collect();
    vertices.sort_unstable();
    vertices.dedup();
    let local = |v: u32| vertices.binary_search(&v).expect("a corner") as u32;
    let local_faces = face_ids
        .iter()
        .map(|&f| faces[f as usize].map(local))
        .collect();
    (vertices, local_faces)
}

/// Some faces of the whole mesh, on a compact copy that keeps what a greedy loop touches in
/// cache.
pub(super) struct Part {
    pub(super) state: State,
    /// Whole-mesh id of each vertex and face of the part.
    pub(super) vertices: Vec<u32>,
    pub(super) face_ids: Vec<u32>,
}

/// What a part's simplification made, in whole-mesh ids.
pub(super) struct RegionRun {
    pub(super) collapses: Vec<Collapse>,
    pub(super) costs: Vec<f32>,
    /// Whole-mesh id of each vertex of the part, and its final state.
    pub(super) vertices: Vec<u32>,
    pub(super) cells: Vec<[i32; 3]>,
    pub(super) quadrics: Vec<Quadric>,
    pub(super) vertex_alive: Vec<bool>,
    /// Whole-mesh id of each face of the part, and its final corners (whole-mesh ids) and state.
    pub(super) face_ids: Vec<u32>,
    pub(super) faces: Vec<[u32; 3]>,
    pub(super) face_alive: Vec<bool>,
}

impl Part {
    /// The faces `face_ids` of `whole`, with the `frozen` vertices left where they are. With
    /// `own_quadrics` the part sums its vertices' quadrics itself, which is exact for every
    /// vertex whose faces all lie in the part; otherwise it takes them from `whole`.
    pub(super) fn new(
        whole: &Whole,
        face_ids: Vec<u32>,
        frozen: &[bool],
        own_quadrics: bool,
    ) -> Part {
        let (vertices, faces) = compact(&whole.faces, &face_ids);
        let topology = topology(vertices.len(), &faces, &vec![true; faces.len()]);
        let cells: Vec<[i32; 3]> = vertices.iter().map(|&v| whole.cells[v as usize]).collect();
        let quadrics = if own_quadrics {
            initial_quadrics(&cells, &faces, &topology)
        } else {
            vertices
                .iter()
                .map(|&v| whole.quadrics[v as usize])
                .collect()
        };
        let state = State::new(
            cells,
            faces,
            quadrics,
            vertices.iter().map(|&v| frozen[v as usize]).collect(),
            whole.placement,
            whole.bounds,
            topology,
        );
        Part {
            state,
            vertices,
            face_ids,
        }
    }

    /// Collapse costs of every `stride`-th edge that may collapse.
    pub(super) fn sample_costs(&self, stride: usize) -> Vec<f32> {
        let state = &self.state;
        state
            .edges
            .iter()
            .filter(|&&[a, b]| !state.frozen[a as usize] && !state.frozen[b as usize])
            .step_by(stride)
            .map(|&[a, b]| state.place(a, b).1 as f32)
            .collect()
    }

    /// Simplifies the part greedily up to `max_cost`: one pass, or with `until_dry` passes until
    /// one collapses nothing.
    pub(super) fn simplify(self, max_cost: f32, until_dry: bool) -> RegionRun {
        let Part {
            state: mut region,
            vertices,
            face_ids,
        } = self;
        let (mut local_collapses, mut costs) = (Vec::new(), Vec::new());
        loop {
            let made = region.collapse_greedily(max_cost, &mut local_collapses, &mut costs);
            if made == 0 || !until_dry {
                break;
            }
        }
        let global_vertex = |v: u32| if v == NIL { NIL } else { vertices[v as usize] };
        let global_face = |f: u32| if f == NIL { NIL } else { face_ids[f as usize] };
        let collapses = local_collapses
            .into_iter()
            .map(|c| Collapse {
                vs: global_vertex(c.vs),
                vt: global_vertex(c.vt),
                vl: global_vertex(c.vl),
                vr: global_vertex(c.vr),
                fl: global_face(c.fl),
                fr: global_face(c.fr),
                moved: c.moved.iter().map(|&f| global_face(f)).collect(),
                beside: c.beside.map(global_face),
                flclw: global_face(c.flclw),
                ..c
            })
            .collect();
        RegionRun {
            collapses,
            costs,
            faces: region.faces.iter().map(|t| t.map(global_vertex)).collect(),
            cells: region.cells,
            quadrics: region.quadrics,
            vertex_alive: region.vertex_alive,
            face_alive: region.face_alive,
            vertices,
            face_ids,
        }
    }
}

impl RegionRun {
    /// Copies the run's faces and its vertices but the `frozen` ones back into `whole`.
    pub(super) fn write_back(&self, whole: &mut Whole, frozen: &[bool]) {
        for (i, &v) in self.vertices.iter().enumerate() {
            if !frozen[v as usize] {
                whole.cells[v as usize] = self.cells[i];
                whole.quadrics[v as usize] = self.quadrics[i];
                whole.vertex_alive[v as usize] = self.vertex_alive[i];
            }
        }
        for (i, &f) in self.face_ids.iter().enumerate() {
            whole.faces[f as usize] = self.faces[i];
            whole.face_alive[f as usize] = self.face_alive[i];
        }
    }
}

/// Simplification in regions, in parallel, then one greedy loop for what remains.
///
/// In a round, each region collapses its own edges, greedily, with the vertices it shares with
/// other regions frozen, so that no two regions touch the same face or vertex and their
/// collapses can be interleaved in any order. The interleaving follows the costs (always the
/// cheapest next collapse of any region), so the sequence stays close to one greedy loop. The
/// first round cuts the mesh along the axes; the second cuts what remains along diagonal
/// planes, so that it collapses across the first round's seams. The last greedy loop does the
/// second round's seams and the costliest collapses.
///
/// No topology of the whole mesh is built: in the first round each region sums its own
/// quadrics (exact for its unshared vertices, all of whose faces it holds) and the shared
/// vertices get theirs from the band of faces around them.
pub(super) fn simplify_in_regions(
    cells: &[[i32; 3]],
    faces: &[[u32; 3]],
    placement: Placement,
    bounds: ([i32; 3], [i32; 3]),
) -> Simplified {
    let n = cells.len();
    let mut whole = Whole {
        cells: cells.to_vec(),
        faces: faces.to_vec(),
        quadrics: vec![Quadric::default(); n],
        vertex_alive: vec![true; n],
        face_alive: vec![true; faces.len()],
        placement,
        bounds,
    };
    let axes = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
    let all: Vec<u32> = (0..faces.len() as u32).collect();
    // Regions of REGION_FACES to twice that many faces (a power of two of them).
    let count = (1usize << (faces.len() / REGION_FACES).max(2).ilog2()).min(MAX_REGIONS);
    let regions = split_into_regions(cells, faces, &all, &axes, count);
    let (first_runs, max_cost) = collapse_round(&mut whole, regions, None);
    // The first round's collapses are put in order while the rest are made.
    let (mut collapses, mut later) = rayon::join(
        || interleave(first_runs),
        || simplify_rest(&mut whole, max_cost),
    );
    collapses.append(&mut later);
    Simplified {
        collapses,
        vertex_alive: whole.vertex_alive,
        face_alive: whole.face_alive,
        positions: whole.cells,
        faces: whole.faces,
    }
}

/// After the first round: the second round, then one greedy loop over what remains.
pub(super) fn simplify_rest(whole: &mut Whole, max_cost: f32) -> Vec<Collapse> {
    let n = whole.cells.len();
    let diagonals = [[1, 1, 1], [1, 1, -1], [1, -1, 1], [-1, 1, 1]];
    let regions = split_into_regions(
        &whole.cells,
        &whole.faces,
        &whole.live_faces(),
        &diagonals,
        SECOND_ROUND_REGIONS,
    );
    let (second_runs, _) = collapse_round(whole, regions, Some(max_cost));
    let mut collapses = interleave(second_runs);
    // What remains; when a pass runs dry, every remaining edge is queued again, until a pass
    // collapses nothing.
    let none_frozen = vec![false; n];
    let live = whole.live_faces();
    let mut rest = Part::new(whole, live, &none_frozen, false).simplify(f32::INFINITY, true);
    collapses.append(&mut rest.collapses);
    rest.write_back(whole, &none_frozen);
    collapses
}

/// Each region's collapses, with their costs.
pub(super) type Streams = Vec<(Vec<Collapse>, Vec<f32>)>;

/// One round of the region phase over `regions` (faces of `whole`): up to `max_cost`, or in
/// the first round (`None`) up to a quantile of the initial costs. Returns each region's
/// collapses and the cost it stopped at. The first round's regions sum the quadrics of the
/// input mesh.
pub(super) fn collapse_round(
    whole: &mut Whole,
    regions: Vec<Vec<u32>>,
    max_cost: Option<f32>,
) -> (Streams, f32) {
    let first = max_cost.is_none();
    let n = whole.cells.len();
    let mut region_of = vec![u32::MAX; n];
    let mut shared = vec![false; n];
    for (r, face_ids) in regions.iter().enumerate() {
        for &f in face_ids {
            for v in whole.faces[f as usize] {
                let slot = &mut region_of[v as usize];
                if *slot == u32::MAX {
                    *slot = r as u32;
                } else if *slot != r as u32 {
                    shared[v as usize] = true;
                }
            }
        }
    }
    if first {
        // Quadrics of the shared vertices, from the band of faces around them.
        let band: Vec<u32> = regions
            .iter()
            .flatten()
            .copied()
            .filter(|&f| whole.faces[f as usize].iter().any(|&v| shared[v as usize]))
            .collect();
        let band = Part::new(whole, band, &shared, true);
        for (&v, q) in band.vertices.iter().zip(&band.state.quadrics) {
            if shared[v as usize] {
                whole.quadrics[v as usize] = *q;
            }
        }
    }
    let parts: Vec<Part> = regions
        .into_par_iter()
        .map(|face_ids| Part::new(whole, face_ids, &shared, first))
        .collect();
    // Every region stops at the same cost, so that the seams, collapsed after, are the only
    // collapses out of cost order. The quantile is estimated from evenly spaced edges.
    let max_cost = max_cost.unwrap_or_else(|| {
        let edge_count: usize = parts.iter().map(|p| p.state.edges.len()).sum();
        let stride = (edge_count / REGION_COST_SAMPLES).max(1);
        let mut sampled: Vec<f32> = parts
            .par_iter()
            .flat_map_iter(|p| p.sample_costs(stride))
            .collect();
        if sampled.is_empty() {
            return f32::NEG_INFINITY;
        }
        let middle =
            ((sampled.len() as f64 * REGION_COST_QUANTILE) as usize).min(sampled.len() - 1);
        *sampled.select_nth_unstable_by(middle, f32::total_cmp).1
    });
    let runs: Vec<RegionRun> = parts
        .into_par_iter()
        .map(|part| part.simplify(max_cost, false))
        .collect();
    let streams = runs
        .into_iter()
        .map(|run| {
            run.write_back(whole, &shared);
            (run.collapses, run.costs)
        })
        .collect();
    (streams, max_cost)
}

/// The collapses of regions that share no face, in one sequence: always the cheapest next
/// collapse of any region (ties: the lower region), so that it stays close to one greedy loop.
pub(super) fn interleave(streams: Streams) -> Vec<Collapse> {
    // Costs are not negative, so their bits order them.
    let mut made: Vec<_> = streams
        .into_iter()
        .map(|(collapses, costs)| collapses.into_iter().zip(costs).peekable())
        .collect();
    let mut heads: std::collections::BinaryHeap<_> = made
        .iter_mut()
        .enumerate()
        .filter_map(|(r, m)| Some(std::cmp::Reverse((m.peek()?.1.to_bits(), r))))
        .collect();
    let mut collapses = Vec::with_capacity(made.iter().map(|m| m.size_hint().0).sum());
    while let Some(std::cmp::Reverse((_, r))) = heads.pop() {
        collapses.extend(made[r].next().map(|(c, _)| c));
        if let Some((_, cost)) = made[r].peek() {
            heads.push(std::cmp::Reverse((cost.to_bits(), r)));
        }
    }
    collapses
}
