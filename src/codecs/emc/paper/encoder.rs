//! EMC encoder. The paper builds a list of merges bottom-up and writes it reversed; the same
//! splits fall out directly of the key trie (`hierarchy::octree`): a cluster is a range of
//! key-sorted vertices and splits where its first and last keys differ. So the encoder runs the
//! decoder's top-down passes, reading each decision off the trie and the original edges, and
//! updates the shared [`EmcState`] exactly as the decoder will.

use super::super::clusters::{Clusters, SplitPlan};
use super::super::state::{face_corrections, EmcState, NO_SPLIT};
use super::super::EmcParams;
use super::syntax::{self, EdgeCode};
use crate::codecs::{Encoded, Stat, Stats};
use crate::coding::{BitSink, SyntaxClass};
use crate::container::{Header, LevelCost, StreamWriter};
use crate::hierarchy::octree::KeyTrie;
use crate::mesh::CanonicalMesh;

/// Bits and counts per syntax element, for the paper's table. The per-operation counters are
/// plain fields (the encoder's inner loop touches them); the rest are named once.
#[derive(Default)]
struct Tally {
    counts: Stats,
    refinement_bits: u64,
    connecting_flag_bits: u64,
    edge_code_bits: u64,
    edge_codes: [u64; 3],
    split_distance_bits: u64,
    distances: Vec<u64>,
    splits: u64,
}

impl Tally {
    fn add(&mut self, stat: Stat, value: f64) {
        self.counts.add(stat, value);
    }

    fn into_counts(mut self) -> Stats {
        let fields = [
            (Stat::RefinementBits, self.refinement_bits),
            (Stat::ConnectingFlagBits, self.connecting_flag_bits),
            (Stat::EdgeCodeBits, self.edge_code_bits),
            (Stat::SplitDistanceBits, self.split_distance_bits),
        ];
        for (stat, value) in fields {
            self.add(stat, value as f64);
        }
        let named = [
            ("splits", self.splits),
            ("edge_stay", self.edge_codes[EdgeCode::Stay as usize]),
            ("edge_move", self.edge_codes[EdgeCode::Move as usize]),
            (
                "edge_duplicate",
                self.edge_codes[EdgeCode::Duplicate as usize],
            ),
        ];
        for (key, value) in named {
            self.counts.add_named(key, value as f64);
        }
        let distances = std::mem::take(&mut self.distances);
        for (d, &n) in distances.iter().enumerate().filter(|(_, &n)| n > 0) {
            let key = if d == 0 {
                "distance_none".to_string()
            } else {
                format!("distance_{d}")
            };
            self.counts.add_named(&key, n as f64);
        }
        self.counts
    }
}

pub fn encode(mesh: &CanonicalMesh, params: &EmcParams, header: Header) -> crate::Result<Encoded> {
    let order = params.order;
    let n = mesh.vertex_count();
    let mut clusters = Clusters::new(mesh, KeyTrie::new(order, &mesh.cells));
    let mut plan = SplitPlan::default();
    let mut state = EmcState::new(order, n as u64);
    state.reserve(n);
    let mut tally = Tally {
        distances: vec![0; syntax::MAX_DISTANCE + 1],
        ..Tally::default()
    };
    let mut writer = StreamWriter::new(&header);
    // The paper leaves its header out of its byte counts; ours is the container's header
    // without the index (which, like the paper's lack of one, is framing: docs/FORMAT.md §2).
    let mut header_bytes = Vec::new();
    header.write(&mut header_bytes);
    tally.add(Stat::HeaderBytes, header_bytes.len() as f64);
    let final_triangles = mesh.face_count();

    for level in 1..=order.levels as usize {
        let mut sink = BitSink::default();
        for step in 3 * (level - 1)..3 * level {
            let present = state.len();
            for v in 0..present {
                if state.next_split[v] as usize != step {
                    let bit = clusters.bit(v, step);
                    sink.put(SyntaxClass::Geometry, 1, bit);
                    tally.refinement_bits += 1;
                    state.refine(v, step, bit);
                    continue;
                }
                let r = state.len();
                clusters.plan(&state.adjacency[v], v, r, step, r + 1, &mut plan);
                sink.put(SyntaxClass::Connectivity, 1, plan.connecting as u32);
                tally.connecting_flag_bits += 1;
                for &code in &plan.codes {
                    syntax::put_edge(&mut sink, code);
                    tally.edge_code_bits += syntax::edge_bits(code);
                    tally.edge_codes[code as usize] += 1;
                }
                let next = [
                    clusters.trie.next_split(plan.lower.clone()),
                    clusters.trie.next_split(plan.upper.clone()),
                ];
                for next_step in next {
                    let bits = syntax::put_distance(&mut sink, step, next_step);
                    tally.split_distance_bits += bits;
                    tally.distances[next_step.map_or(0, |s| s - step)] += 1;
                }
                tally.splits += 1;
                let next = next.map(|s| s.map_or(NO_SPLIT, |s| s as u16));
                state.split(v, step, plan.connecting, &plan.codes, next);
                clusters.commit(v, r, &plan);
            }
        }
        if level == order.levels as usize {
            clusters.release_edges();
            let corrections = face_corrections(mesh, &state, &clusters.ranges, &clusters.trie)?;
            let cliques = mesh.face_count() - corrections.double_sided.len()
                + corrections.false_triangles.len();
            tally.add(Stat::Cliques, cliques as f64);
            tally.add(
                Stat::FalseTriangles,
                corrections.false_triangles.len() as f64,
            );
            tally.add(
                Stat::DoubleSidedFaces,
                corrections.double_sided.len() as f64,
            );
            tally.add(
                Stat::OrientationExceptions,
                corrections.orientation_exceptions.len() as f64,
            );
            let before = sink_total(&sink);
            syntax::put_list(&mut sink, &corrections.false_triangles);
            syntax::put_list(&mut sink, &corrections.double_sided);
            syntax::put_list(&mut sink, &corrections.orientation_exceptions);
            tally.add(
                Stat::FaceCorrectionBits,
                (sink_total(&sink) - before) as f64,
            );
        }
        let (payload, ledger) = sink.finish();
        writer.push_level(
            &payload,
            LevelCost {
                connectivity_bits: ledger.connectivity,
                geometry_bits: ledger.geometry,
                vertices: state.len(),
                // The paper's decoder knows its triangles only once the last level is read.
                triangles: if level == order.levels as usize {
                    final_triangles
                } else {
                    0
                },
            },
        );
    }
    let (bytes, levels) = writer.finish();
    Ok(Encoded {
        bytes,
        levels,
        stats: tally.into_counts(),
    })
}

fn sink_total(sink: &BitSink) -> u64 {
    sink.ledger().total()
}
