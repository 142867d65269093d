//! EMC encoder. The paper builds a list of merges bottom-up and writes it reversed; the same
//! splits fall out directly of the key trie (`hierarchy::octree`): a cluster is a range of
//! key-sorted vertices and splits where its first and last keys differ. So the encoder runs the
//! decoder's top-down passes, reading each decision off the trie and the original edges, and
//! updates the shared [`EmcState`] exactly as the decoder will.

use super::context::{final_faces, EmcState, FaceCorrections, NO_SPLIT};
use super::syntax::{self, EdgeCode};
use super::EmcParams;
use crate::codecs::{Encoded, LevelRecord};
use crate::coding::{BitLedger, BitSink, SyntaxClass};
use crate::container::{Header, StreamWriter};
use crate::hierarchy::cliques::propagate_orientation;
use crate::hierarchy::octree::KeyTrie;
use crate::mesh::canonical::rotate_to_smallest;
use crate::mesh::CanonicalMesh;
use std::collections::{BTreeMap, HashMap};
use std::ops::Range;

/// Bits and counts per syntax element, for the paper's table. The per-operation counters are
/// plain fields (the encoder's inner loop touches them); the rest are named once.
#[derive(Default)]
struct Tally {
    counts: BTreeMap<String, f64>,
    refinement_bits: u64,
    connecting_flag_bits: u64,
    edge_code_bits: u64,
    edge_codes: [u64; 3],
    split_distance_bits: u64,
    distances: Vec<u64>,
    splits: u64,
}

impl Tally {
    fn add(&mut self, key: &str, value: f64) {
        *self.counts.entry(key.to_string()).or_default() += value;
    }

    fn into_counts(mut self) -> BTreeMap<String, f64> {
        let fields = [
            ("refinement_bits", self.refinement_bits),
            ("connecting_flag_bits", self.connecting_flag_bits),
            ("edge_code_bits", self.edge_code_bits),
            ("split_distance_bits", self.split_distance_bits),
            ("splits", self.splits),
            ("edge_stay", self.edge_codes[EdgeCode::Stay as usize]),
            ("edge_move", self.edge_codes[EdgeCode::Move as usize]),
            (
                "edge_duplicate",
                self.edge_codes[EdgeCode::Duplicate as usize],
            ),
        ];
        for (key, value) in fields {
            self.add(key, value as f64);
        }
        let distances = std::mem::take(&mut self.distances);
        for (d, &n) in distances.iter().enumerate().filter(|(_, &n)| n > 0) {
            let key = if d == 0 {
                "distance_none".to_string()
            } else {
                format!("distance_{d}")
            };
            self.add(&key, n as f64);
        }
        self.counts
    }
}

pub fn encode(mesh: &CanonicalMesh, params: &EmcParams, header: Header) -> Encoded {
    let order = params.order;
    let trie = KeyTrie::new(order, &mesh.cells);
    let n = mesh.vertex_count();
    let neighbours = crate::hierarchy::cliques::adjacency(n, &mesh.faces);

    let mut state = EmcState::new(order, n as u64);
    let mut ranges: Vec<Range<usize>> = std::iter::once(0..n).collect();
    // List vertex that each mesh vertex currently belongs to.
    let mut cluster_of = vec![0u32; n];
    let mut stamp_left = vec![0u32; 1];
    let mut stamp_right = vec![0u32; 1];
    let mut stamp = 0u32;
    let mut tally = Tally {
        distances: vec![0; syntax::MAX_DISTANCE + 1],
        ..Tally::default()
    };
    let mut writer = StreamWriter::new(&header);
    let mut header_bytes = Vec::new();
    header.write(&mut header_bytes);
    tally.add("header_bytes", header_bytes.len() as f64);
    let mut levels = Vec::with_capacity(order.levels as usize);
    let mut total = BitLedger::default();

    for level in 1..=order.levels as usize {
        let mut sink = BitSink::default();
        for step in 3 * (level - 1)..3 * level {
            let present = state.len();
            for v in 0..present {
                let range = ranges[v].clone();
                if state.next_split[v] as usize != step {
                    let bit = order.bit(trie.keys[range.start], step);
                    sink.put(SyntaxClass::Geometry, 1, bit);
                    tally.refinement_bits += 1;
                    state.refine(v, step, bit);
                    continue;
                }
                let mid = trie.partition(range.clone(), step);
                let (left, right) = (range.start..mid, mid..range.end);
                let r = state.len() as u32;
                for &u in &trie.vertices[right.clone()] {
                    cluster_of[u as usize] = r;
                }
                // Which clusters each half touches.
                stamp += 1;
                stamp_left.resize(state.len() + 1, 0);
                stamp_right.resize(state.len() + 1, 0);
                let mut connecting = false;
                for (half, stamps) in [(&left, &mut stamp_left), (&right, &mut stamp_right)] {
                    for &u in &trie.vertices[half.clone()] {
                        for &w in &neighbours[u as usize] {
                            let c = cluster_of[w as usize];
                            stamps[c as usize] = stamp;
                            connecting |= half.start == left.start && c == r;
                        }
                    }
                }
                let codes: Vec<EdgeCode> = state.adjacency[v]
                    .iter()
                    .map(|&nb| {
                        let (l, rr) = (
                            stamp_left[nb as usize] == stamp,
                            stamp_right[nb as usize] == stamp,
                        );
                        debug_assert!(l || rr, "neighbour {nb} lost by both halves");
                        match (l, rr) {
                            (true, true) => EdgeCode::Duplicate,
                            (false, true) => EdgeCode::Move,
                            _ => EdgeCode::Stay,
                        }
                    })
                    .collect();
                sink.put(SyntaxClass::Connectivity, 1, connecting as u32);
                tally.connecting_flag_bits += 1;
                for &code in &codes {
                    syntax::put_edge(&mut sink, code);
                    tally.edge_code_bits += syntax::edge_bits(code);
                    tally.edge_codes[code as usize] += 1;
                }
                let next = [
                    trie.next_split(left.clone()),
                    trie.next_split(right.clone()),
                ];
                for next_step in next {
                    let bits = syntax::put_distance(&mut sink, step, next_step);
                    tally.split_distance_bits += bits;
                    tally.distances[next_step.map_or(0, |s| s - step)] += 1;
                }
                tally.splits += 1;
                let next = next.map(|s| s.map_or(NO_SPLIT, |s| s as u16));
                state.split(v, step, connecting, &codes, next);
                ranges[v] = left;
                ranges.push(right);
            }
        }
        if level == order.levels as usize {
            let corrections = face_corrections(mesh, &state, &ranges, &trie, &mut tally);
            let before = sink_total(&sink);
            syntax::put_list(&mut sink, &corrections.false_triangles);
            syntax::put_list(&mut sink, &corrections.double_sided);
            syntax::put_list(&mut sink, &corrections.orientation_exceptions);
            tally.add("face_correction_bits", (sink_total(&sink) - before) as f64);
        }
        let (payload, ledger) = sink.finish();
        writer.push_level(&payload);
        total.connectivity += ledger.connectivity;
        total.geometry += ledger.geometry;
        levels.push((total, state.len(), 0usize));
    }
    let (bytes, ends) = writer.finish();
    let final_triangles = mesh.face_count();
    let levels = levels
        .into_iter()
        .zip(ends)
        .enumerate()
        .map(|(i, ((ledger, vertices, _), end_byte))| LevelRecord {
            end_byte,
            connectivity_bits: ledger.connectivity,
            geometry_bits: ledger.geometry,
            vertices,
            triangles: if i + 1 == order.levels as usize {
                final_triangles
            } else {
                0
            },
        })
        .collect();
    Encoded {
        bytes,
        levels,
        stats: tally.into_counts(),
    }
}

fn sink_total(sink: &BitSink) -> u64 {
    sink.ledger().total()
}

/// Compares the cliques of the final edge graph with the mesh's faces and lists what the decoder
/// must correct: false triangles, faces present in both orientations, and orientations that the
/// propagation predicts wrongly.
fn face_corrections(
    mesh: &CanonicalMesh,
    state: &EmcState,
    ranges: &[Range<usize>],
    trie: &KeyTrie,
    tally: &mut Tally,
) -> FaceCorrections {
    // Every cluster is a single mesh vertex by now.
    let mut list_id = vec![0u32; mesh.vertex_count()];
    for (v, range) in ranges.iter().enumerate() {
        debug_assert_eq!(range.len(), 1);
        list_id[trie.vertices[range.start] as usize] = v as u32;
    }
    // Oriented faces in list ids, keyed by their ascending triple.
    let mut faces: HashMap<[u32; 3], u8> = HashMap::new(); // bit 0: unflipped, bit 1: flipped
    for f in &mesh.faces {
        let f = f.map(|u| list_id[u as usize]);
        let mut sorted = f;
        sorted.sort_unstable();
        let unflipped = rotate_to_smallest(f) == sorted;
        *faces.entry(sorted).or_default() |= if unflipped { 1 } else { 2 };
    }
    let cliques = state.cliques();
    let mut corrections = FaceCorrections::default();
    for (i, t) in cliques.iter().enumerate() {
        match faces.get(t) {
            None => corrections.false_triangles.push(i as u32),
            Some(3) => corrections.double_sided.push(i as u32),
            Some(_) => {}
        }
    }
    debug_assert_eq!(
        cliques.len() - corrections.false_triangles.len(),
        faces.len(),
        "every face is a 3-clique of its own edges"
    );
    let skipped = corrections.skipped(cliques.len());
    let positions: Vec<_> = (0..state.len())
        .map(|v| mesh.grid.dequantize(state.cells[v]))
        .collect();
    // Let the propagation follow the true orientations and note where they were not predicted.
    let is_flipped = |t: usize| faces.get(&cliques[t]).copied() == Some(2);
    let centre = super::context::centroid(&positions);
    propagate_orientation(
        &cliques,
        &skipped,
        &state.adjacency,
        &positions,
        centre,
        |visit, t, predicted| {
            if is_flipped(t) != predicted {
                corrections.orientation_exceptions.push(visit as u32);
            }
            is_flipped(t)
        },
    );
    tally.add("cliques", cliques.len() as f64);
    tally.add("false_triangles", corrections.false_triangles.len() as f64);
    tally.add("double_sided_faces", corrections.double_sided.len() as f64);
    tally.add(
        "orientation_exceptions",
        corrections.orientation_exceptions.len() as f64,
    );
    debug_assert_eq!(
        {
            let mut got: Vec<_> = final_faces(&cliques, &state.adjacency, &positions, &corrections)
                .into_iter()
                .map(rotate_to_smallest)
                .collect();
            got.sort_unstable();
            got
        },
        {
            let mut want: Vec<_> = mesh
                .faces
                .iter()
                .map(|f| rotate_to_smallest(f.map(|u| list_id[u as usize])))
                .collect();
            want.sort_unstable();
            want
        }
    );
    corrections
}
