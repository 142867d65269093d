//! The modelled coder's encoder: the walker's questions answered from the key trie and the
//! mesh's edges ([`Clusters`]), each answer arithmetic-coded under the walker's context.

use super::walk::{Question, Side, Stop, Walker};
use crate::codecs::emc::clusters::{ClusterLanes, Clusters, SplitPlan};
use crate::codecs::emc::state::{face_corrections, EdgeCode};
use crate::codecs::emc::EmcParams;
use crate::codecs::on_pool;
use crate::codecs::{Encoded, Stats};
use crate::coding::arith::{ArithEncoder, BitContext, UintContext};
use crate::coding::{varint, BitLedger, SyntaxClass};
use crate::container::{Header, LevelCost, StreamWriter};
use crate::hierarchy::octree::KeyTrie;
use crate::mesh::CanonicalMesh;
use std::collections::BTreeMap;

/// The clusters an encoder side plans its splits on: the encoder's own, or a slab's view of
/// them while the slabs of a sliced pass are coded at once.
enum ClusterAccess {
    Owned(Clusters),
    Slab(ClusterLanes),
}

impl ClusterAccess {
    fn owned(&mut self) -> &mut Clusters {
        match self {
            ClusterAccess::Owned(clusters) => clusters,
            ClusterAccess::Slab(_) => unreachable!("a slab's side is not the encoder's"),
        }
    }

    fn next_split(&self, v: usize) -> Option<usize> {
        match self {
            ClusterAccess::Owned(clusters) => clusters.next_split(v),
            ClusterAccess::Slab(lanes) => lanes.next_split(v),
        }
    }

    fn bit(&self, v: usize, step: usize) -> u32 {
        match self {
            ClusterAccess::Owned(clusters) => clusters.bit(v, step),
            ClusterAccess::Slab(lanes) => lanes.bit(v, step),
        }
    }

    fn ahead(&mut self, v: usize, step: usize, predicted: bool) -> bool {
        match self {
            ClusterAccess::Owned(clusters) => clusters.ahead(v, step, predicted),
            ClusterAccess::Slab(lanes) => lanes.ahead(v, step, predicted),
        }
    }
}

struct EncoderSide {
    coder: ArithEncoder,
    clusters: ClusterAccess,
    plan: SplitPlan,
    /// The current sliced pass's split counts, its slab streams' lengths so far, and the
    /// most visits a slab has.
    counts: Vec<u32>,
    lengths: Vec<usize>,
    visits: usize,
    /// The level's stream while a slab's is coded.
    parked: Option<ArithEncoder>,
    /// The level's slab table and slab streams so far, and what the slab streams cost.
    table: Vec<u8>,
    streams: Vec<u8>,
    slab_bits: BTreeMap<&'static str, f64>,
    slab_ledger: BitLedger,
}

impl EncoderSide {
    /// A side coding into a fresh stream, planning on `clusters`.
    fn over(clusters: ClusterAccess) -> Self {
        EncoderSide {
            coder: ArithEncoder::default(),
            clusters,
            plan: SplitPlan::default(),
            counts: Vec::new(),
            lengths: Vec::new(),
            visits: 0,
            parked: None,
            table: Vec::new(),
            streams: Vec::new(),
            slab_bits: BTreeMap::new(),
            slab_ledger: BitLedger::default(),
        }
    }

    /// The level's payload (docs/FORMAT.md §7) and its cost, from the level's stream `coder`:
    /// in a stream with slabs, the slab table, the level's stream and the slab streams; else
    /// the level's stream. Clears the level's slab table and streams.
    fn payload(&mut self, coder: ArithEncoder, slabs: u8) -> (Vec<u8>, BitLedger) {
        let (main, ledger) = coder.finish();
        if slabs < 2 {
            return (main, ledger);
        }
        let (table, streams) = (
            std::mem::take(&mut self.table),
            std::mem::take(&mut self.streams),
        );
        let slab_ledger = std::mem::take(&mut self.slab_ledger);
        let mut payload = Vec::with_capacity(table.len() + main.len() + streams.len() + 8);
        varint::put(&mut payload, table.len() as u64);
        payload.extend_from_slice(&table);
        varint::put(&mut payload, main.len() as u64);
        payload.extend_from_slice(&main);
        payload.extend_from_slice(&streams);
        // The table and the lengths count as connectivity (they say where splits are coded).
        let coded = (main.len() + streams.len()) as u64 * 8;
        let cost = BitLedger {
            connectivity: ledger.connectivity + slab_ledger.connectivity + payload.len() as u64 * 8
                - coded,
            geometry: ledger.geometry + slab_ledger.geometry,
        };
        (payload, cost)
    }
}

impl Side for EncoderSide {
    fn code(
        &mut self,
        context: &mut BitContext,
        question: Question,
        flip: bool,
        v: usize,
        step: usize,
    ) -> Result<bool, Stop> {
        let answer = match question {
            Question::Split => self.clusters.next_split(v) == Some(step),
            Question::Half => self.clusters.bit(v, step) == 1,
            // 1 ^ flip: the predicted half.
            Question::Ahead => self.clusters.ahead(v, step, !flip),
            Question::Connecting => self.plan.connecting,
            Question::Duplicate(i) => self.plan.codes[i] == EdgeCode::Duplicate,
            Question::Moves(i) => self.plan.codes[i] == EdgeCode::Move,
            Question::Leaf(0) => self.plan.lower.len() == 1,
            Question::Leaf(_) => self.plan.upper.len() == 1,
        };
        self.coder
            .bit(context, answer ^ flip, question.class(), question.field());
        Ok(answer)
    }

    fn code3(
        &mut self,
        contexts: &mut [BitContext],
        index: [usize; 3],
        flips: [bool; 3],
        v: usize,
        first: usize,
        ahead: bool,
    ) -> Result<[bool; 3], Stop> {
        let answers = [0, 1, 2].map(|k| self.clusters.bit(v, first + k) == 1);
        let question = Question::Half;
        self.coder.bits3(
            contexts,
            index,
            [0, 1, 2].map(|k| answers[k] ^ flips[k]),
            question.class(),
            if ahead {
                "leaf_ahead"
            } else {
                question.field()
            },
        );
        Ok(answers)
    }

    fn begin_split(
        &mut self,
        neighbours: &[u32],
        v: usize,
        r: usize,
        step: usize,
        vertices: usize,
    ) {
        match &mut self.clusters {
            ClusterAccess::Owned(clusters) => {
                clusters.plan(neighbours, v, r, step, vertices, &mut self.plan)
            }
            ClusterAccess::Slab(lanes) => lanes.plan(neighbours, v, r, step, &mut self.plan),
        }
    }

    fn end_split(&mut self, v: usize, r: usize) {
        match &mut self.clusters {
            ClusterAccess::Owned(clusters) => clusters.commit(v, r, &self.plan),
            ClusterAccess::Slab(lanes) => lanes.commit(v, r, &self.plan),
        }
    }

    fn begin_sliced_pass(
        &mut self,
        interior: &[Vec<u32>],
        step: Option<usize>,
    ) -> Result<Vec<u32>, Stop> {
        self.counts = interior
            .iter()
            .map(|visits| match step {
                Some(step) => visits
                    .iter()
                    .filter(|&&v| self.clusters.next_split(v as usize) == Some(step))
                    .count() as u32,
                None => 0,
            })
            .collect();
        self.lengths.clear();
        self.visits = interior.iter().map(Vec::len).max().unwrap_or(0);
        // The slabs' splits take their ids now.
        let splits = self.counts.iter().map(|&c| c as usize).sum();
        self.clusters.owned().make_room(splits);
        Ok(self.counts.clone())
    }

    fn slab_sides(&mut self) -> Result<Option<Vec<Self>>, Stop> {
        if rayon::current_num_threads() < 2 {
            return Ok(None);
        }
        let slabs = self.counts.len();
        let Some(lanes) = self.clusters.owned().slab_lanes(slabs, self.visits) else {
            return Ok(None);
        };
        Ok(Some(
            lanes
                .into_iter()
                .map(|lanes| EncoderSide::over(ClusterAccess::Slab(lanes)))
                .collect(),
        ))
    }

    fn join_slab_sides(&mut self, sides: Vec<Self>) {
        let mut lanes = Vec::with_capacity(sides.len());
        for (slab, side) in sides.into_iter().enumerate() {
            // As if coded here between begin_slab and end_slab.
            self.parked = Some(std::mem::replace(&mut self.coder, side.coder));
            self.end_slab(slab);
            if let ClusterAccess::Slab(view) = side.clusters {
                lanes.push(view);
            }
        }
        self.clusters.owned().join_slab_lanes(&lanes);
    }

    fn begin_slab(&mut self, _slab: usize) -> Result<(), Stop> {
        self.parked = Some(std::mem::take(&mut self.coder));
        Ok(())
    }

    fn end_slab(&mut self, _slab: usize) {
        let slab = std::mem::replace(&mut self.coder, self.parked.take().unwrap_or_default());
        for (field, bits) in &slab.field_bits {
            *self.slab_bits.entry(field).or_default() += bits;
        }
        let (bytes, ledger) = slab.finish();
        self.slab_ledger.connectivity += ledger.connectivity;
        self.slab_ledger.geometry += ledger.geometry;
        self.lengths.push(bytes.len());
        self.streams.extend_from_slice(&bytes);
    }

    fn end_sliced_pass(&mut self) {
        for (&count, &len) in self.counts.iter().zip(&self.lengths) {
            varint::put(&mut self.table, count as u64);
            varint::put(&mut self.table, len as u64);
        }
    }
}

/// Writes an ascending list of clique positions: its length, then the gaps.
pub fn put_list(
    coder: &mut ArithEncoder,
    context: &mut UintContext,
    list: &[u32],
    field: &'static str,
) {
    coder.uint(context, list.len() as u64, SyntaxClass::Connectivity, field);
    let mut next = 0u64;
    for &x in list {
        coder.uint(context, x as u64 - next, SyntaxClass::Connectivity, field);
        next = x as u64 + 1;
    }
}

/// Encodes on rayon's pool ([`on_pool`]).
pub fn encode(mesh: &CanonicalMesh, params: &EmcParams, header: Header) -> crate::Result<Encoded> {
    on_pool(|| encode_here(mesh, params, header))
}

fn encode_here(mesh: &CanonicalMesh, params: &EmcParams, header: Header) -> crate::Result<Encoded> {
    let order = params.order;
    let n = mesh.vertex_count() as u64;
    let mut walker = Walker::new(
        order,
        n,
        params.slabs as usize,
        1 << params.sliced_visits_log2,
    );
    walker.state.reserve(mesh.vertex_count());
    walker.ahead_levels = params.ahead_levels as usize;
    let mut side = EncoderSide::over(ClusterAccess::Owned(Clusters::new(
        mesh,
        KeyTrie::new(order, &mesh.cells),
    )));
    let mut writer = StreamWriter::new(&header);
    let mut stats = Stats::default();
    // Whether the face corrections are coded (the edge graph is final from then on).
    let mut settled = false;
    for level in 1..=order.levels as usize {
        walker
            .level(&mut side, level, 3, n, mesh.face_count() as u64)
            .expect("the encoder's answers agree with the header");
        let mut coder = std::mem::take(&mut side.coder);
        let last = level == order.levels as usize;
        if !settled && params.corrections_follow(level, walker.state.len() as u64, n) {
            settled = true;
            debug_assert!(
                walker.leaf.iter().all(|&leaf| leaf),
                "every vertex decoded is a leaf: no split follows"
            );
            // What only splits read goes before the corrections, the encoder's peak of memory.
            let clusters = side.clusters.owned();
            clusters.release_edges();
            if last {
                walker.release_caches();
            }
            let corrections =
                face_corrections(mesh, &walker.state, &clusters.ranges, &clusters.trie)?;
            let lists = [
                (&corrections.false_triangles, "false_triangles"),
                (&corrections.double_sided, "double_sided"),
                (
                    &corrections.orientation_exceptions,
                    "orientation_exceptions",
                ),
            ];
            for (i, (list, field)) in lists.into_iter().enumerate() {
                put_list(&mut coder, &mut walker.contexts.corrections[i], list, field);
                stats.add_named(field, list.len() as f64);
            }
        }
        for (field, bits) in coder.field_bits.iter().chain(&side.slab_bits) {
            stats.add_named(&format!("{field}_bits"), *bits);
        }
        side.slab_bits.clear();
        let (payload, level_ledger) = side.payload(coder, params.slabs);
        writer.push_level(
            &payload,
            LevelCost {
                connectivity_bits: level_ledger.connectivity,
                geometry_bits: level_ledger.geometry,
                vertices: walker.state.len(),
                // Triangles are listed once the corrections make them the mesh's faces.
                triangles: if settled { mesh.face_count() } else { 0 },
            },
        );
    }
    stats.add_named("leaves", walker.leaf.iter().filter(|&&l| l).count() as f64);
    let (bytes, levels) = writer.finish();
    Ok(Encoded {
        bytes,
        levels,
        stats,
    })
}
