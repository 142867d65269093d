//! Meta-nodes (Grabner §3.1.3, after El-Sana & Chiang): L levels of the hierarchy form one unit
//! of the stream, decodable once its ancestors are. A meta-node rooted at depth D0 holds the
//! splits of its root's subtree at depths D0..D0+L; the inner nodes at depth D0+L root its child
//! meta-nodes. With [`Tails::Whole`] (`came`), a meta-node whose subtree ends within L + L/2
//! levels holds all of it, so that the last levels do not scatter into units of a few splits each
//! (docs/FORMAT.md §8.1); with [`Tails::Split`] (`came-paper`) every meta-node holds L levels,
//! as published.
//!
//! Units follow in breadth-first order of the meta-node tree (so by D0), each after its parent.

use super::knowledge::Knowledge;
use crate::hierarchy::came::{NodeId, VertexTree};

/// One meta-node of the encoder's partition.
#[derive(Clone, Debug)]
pub struct MetaNode {
    /// The hierarchy node it is rooted at.
    pub root: u32,
    /// The unit it depends on.
    pub parent: Option<usize>,
    /// Whether it holds its root's whole subtree.
    pub whole: bool,
    /// Its inner nodes, breadth first from the root: the splits it codes, in order.
    pub nodes: Vec<u32>,
}

/// The partition of a hierarchy into meta-nodes, with what a decoder knows in each.
pub struct Partition {
    /// Meta-nodes in stream order.
    pub units: Vec<MetaNode>,
    /// Per node: the root of the unit that codes its split (inner nodes), and of the unit that
    /// codes the split creating it.
    pub knowledge: Knowledge,
}

/// Whether a meta-node near the leaves holds the rest of its subtree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tails {
    /// A subtree ending within L + L/2 levels is one meta-node.
    Whole,
    /// Every meta-node holds L levels (the paper).
    Split,
}

/// Whether a meta-node rooted at a subtree of `height` levels holds all of it.
pub fn holds_whole(height: u8, levels: u8) -> bool {
    height <= levels + levels / 2
}

/// Partitions `tree` into meta-nodes of `levels` levels.
pub fn partition(tree: &VertexTree, levels: u8, tails: Tails) -> Partition {
    let n = tree.leaves;
    let total = tree.node_count();
    // Subtree heights; nodes are numbered bottom-up.
    let mut height = vec![0u8; total];
    for (i, &[t, u]) in tree.children.iter().enumerate() {
        height[n + i] = height[t as usize].max(height[u as usize]) + 1;
    }
    let mut split_unit = vec![None; total];
    let mut created_unit = vec![NodeId::ROOT; total];
    let mut units: Vec<MetaNode> = Vec::new();
    let mut roots = std::collections::VecDeque::new();
    if !tree.is_leaf(tree.root) {
        roots.push_back((tree.root, None));
    }
    while let Some((root, parent)) = roots.pop_front() {
        let index = units.len();
        let whole = tails == Tails::Whole && holds_whole(height[root as usize], levels);
        let top = tree.ids[root as usize].len();
        let unit_id = tree.ids[root as usize];
        let mut nodes = vec![root];
        let mut at = 0;
        while at < nodes.len() {
            let s = nodes[at];
            at += 1;
            split_unit[s as usize] = Some(unit_id);
            for c in tree.children_of(s).expect("queued nodes are inner") {
                created_unit[c as usize] = unit_id;
                if tree.is_leaf(c) {
                    continue;
                }
                if whole || tree.ids[c as usize].len() < top + levels {
                    nodes.push(c);
                } else {
                    roots.push_back((c, Some(index)));
                }
            }
        }
        units.push(MetaNode {
            root,
            parent,
            whole,
            nodes,
        });
    }
    Partition {
        units,
        knowledge: Knowledge {
            split_unit,
            created_unit,
        },
    }
}
