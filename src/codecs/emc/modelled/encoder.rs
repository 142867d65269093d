//! The modelled coder's encoder: the walker's questions answered from the key trie and the
//! mesh's edges ([`Clusters`]), each answer arithmetic-coded under the walker's context.

use super::walk::{Question, Side, Stop, Walker};
use crate::codecs::emc::clusters::{Clusters, SplitPlan};
use crate::codecs::emc::state::{face_corrections, EdgeCode, EmcState};
use crate::codecs::emc::EmcParams;
use crate::codecs::{Encoded, Stats};
use crate::coding::arith::{ArithEncoder, BitContext, UintContext};
use crate::coding::SyntaxClass;
use crate::container::{Header, LevelCost, StreamWriter};
use crate::hierarchy::octree::KeyTrie;
use crate::mesh::CanonicalMesh;

struct EncoderSide {
    coder: ArithEncoder,
    clusters: Clusters,
    plan: SplitPlan,
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
    ) -> Result<[bool; 3], Stop> {
        let answers = [0, 1, 2].map(|k| self.clusters.bit(v, first + k) == 1);
        let question = Question::Half;
        self.coder.bits3(
            contexts,
            index,
            [0, 1, 2].map(|k| answers[k] ^ flips[k]),
            question.class(),
            question.field(),
        );
        Ok(answers)
    }

    fn begin_split(&mut self, state: &EmcState, v: usize, step: usize) {
        self.clusters.plan(state, v, step, &mut self.plan);
    }

    fn end_split(&mut self, v: usize, _r: usize) {
        self.clusters.commit(v, &self.plan);
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

pub fn encode(mesh: &CanonicalMesh, params: &EmcParams, header: Header) -> crate::Result<Encoded> {
    let order = params.order;
    let n = mesh.vertex_count() as u64;
    let mut walker = Walker::new(order, n);
    walker.state.reserve(mesh.vertex_count());
    let mut side = EncoderSide {
        coder: ArithEncoder::default(),
        clusters: Clusters::new(mesh, KeyTrie::new(order, &mesh.cells)),
        plan: SplitPlan::default(),
    };
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
            side.clusters.release_edges();
            if last {
                walker.release_caches();
            }
            let corrections = face_corrections(
                mesh,
                &walker.state,
                &side.clusters.ranges,
                &side.clusters.trie,
            )?;
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
        for (field, bits) in &coder.field_bits {
            stats.add_named(&format!("{field}_bits"), *bits);
        }
        let (payload, level_ledger) = coder.finish();
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
