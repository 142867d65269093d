//! Meta-nodes (Grabner §3.1.3, after El-Sana & Chiang): L levels of the hierarchy form one unit
//! of the stream, decodable once its ancestors are. A meta-node rooted at depth D0 holds the
//! splits of its root's subtree at depths D0..D0+L; the inner nodes at depth D0+L root its child
//! meta-nodes. With [`Tails::Whole`] (`came`), a meta-node whose subtree ends within L + L/2
//! levels holds all of it, so that the last levels do not scatter into units of a few splits each
//! (docs/FORMAT.md §8.1); with [`Tails::Split`] (`came-paper`) every meta-node holds L levels,
//! as published.
//!
//! Units follow in breadth-first order of the meta-node tree (so by D0), each after its parent.
//!
//! `came` from syntax 5 cuts by depth bands instead ([`Shape::Bands`]): a unit holds a few
//! levels of a region, so that a far view reads the coarse levels of the whole surface and
//! nothing of the fine ones.

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

/// How a hierarchy is cut into meta-nodes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// Meta-nodes of `levels` levels, each rooted where its parent ends (the paper's;
    /// `came` before syntax 5).
    Levels { levels: u8, tails: Tails },
    /// Depth bands (`came` syntax 5): the first unit holds depths 0 … `region` + `band` − 1; a
    /// unit rooted at depth d > 0 holds its root's subtree's splits at depths d + `region` …
    /// d + `region` + `band` − 1, and its children are rooted at depth d + `band`, so that each
    /// unit holds one band of depths over a region of about 2^`region` nodes: a view whose
    /// front crosses a region at some depth reads the bands above it there and nothing below.
    /// A unit whose subtree holds at most `whole` splits from its first depth down holds all
    /// of them.
    Bands { region: u8, band: u8, whole: u32 },
}

/// Where a unit's splits lie: depths `start` … `end` − 1 of its root's subtree (all from
/// `start` down when it holds its subtree whole), its child units rooted at depth `child`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Band {
    pub start: u8,
    pub end: u8,
    pub child: u8,
}

impl Shape {
    /// The band of a unit rooted at depth `top` (the first unit: the tree's root, depth 0).
    pub fn band(self, top: u8) -> Band {
        match self {
            Shape::Levels { levels, .. } => Band {
                start: top,
                end: top.saturating_add(levels),
                child: top.saturating_add(levels),
            },
            Shape::Bands { region, band, .. } if top == 0 => Band {
                start: 0,
                end: region + band,
                child: band,
            },
            Shape::Bands { region, band, .. } => Band {
                start: top.saturating_add(region),
                end: top.saturating_add(region).saturating_add(band),
                child: top.saturating_add(band),
            },
        }
    }
}

/// Whether a meta-node rooted at a subtree of `height` levels holds all of it.
pub fn holds_whole(height: u8, levels: u8) -> bool {
    height <= levels + levels / 2
}

/// Partitions `tree` into meta-nodes of `shape`.
pub fn partition(tree: &VertexTree, shape: Shape) -> Partition {
    let n = tree.leaves;
    let total = tree.node_count();
    // Subtree heights and inner nodes; nodes are numbered bottom-up.
    let mut height = vec![0u8; total];
    let mut inner = vec![0u32; total];
    for (i, &[t, u]) in tree.children.iter().enumerate() {
        height[n + i] = height[t as usize].max(height[u as usize]) + 1;
        inner[n + i] = 1 + inner[t as usize] + inner[u as usize];
    }
    let depth = |v: u32| tree.ids[v as usize].len();
    let mut split_unit = vec![None; total];
    let mut created_unit = vec![NodeId::ROOT; total];
    let mut units: Vec<MetaNode> = Vec::new();
    let mut roots = std::collections::VecDeque::new();
    if !tree.is_leaf(tree.root) {
        roots.push_back((tree.root, None));
    }
    while let Some((root, parent)) = roots.pop_front() {
        let index = units.len();
        let band = shape.band(depth(root));
        // Breadth first from the root: the nodes above the band (split by the units above),
        // then the band's splits.
        let mut order = vec![root];
        let mut at = 0;
        let mut nodes = Vec::new();
        let mut whole_count = 0u32;
        while at < order.len() {
            let v = order[at];
            at += 1;
            if depth(v) >= band.start {
                nodes.push(v);
                whole_count += inner[v as usize];
                continue;
            }
            for c in tree.children_of(v).expect("above the band: inner") {
                if !tree.is_leaf(c) {
                    order.push(c);
                }
            }
        }
        let whole = match shape {
            Shape::Levels { levels, tails } => {
                tails == Tails::Whole && holds_whole(height[root as usize], levels)
            }
            Shape::Bands { whole, .. } => whole_count <= whole,
        };
        let unit_id = tree.ids[root as usize];
        // Child units by their root, in the order their first split is met.
        let mut child_of_root: Vec<u32> = Vec::new();
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
                if whole || depth(c) < band.end {
                    nodes.push(c);
                    continue;
                }
                let mut r = c;
                while depth(r) > band.child {
                    r = tree.parent[r as usize];
                }
                if !child_of_root.contains(&r) {
                    child_of_root.push(r);
                    roots.push_back((r, Some(index)));
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::codecs::{came, canonical_for, Codec};
    use crate::hierarchy::came::BuildOptions;
    use crate::mesh::generate;

    #[test]
    fn every_split_lies_in_one_unit_within_its_band_under_its_root() {
        let mesh = generate::icosphere(5);
        let codec = came::modelled::Came;
        let canonical = canonical_for(&mesh, &codec.default_options()).unwrap();
        let tree = came::hierarchy(&canonical, &BuildOptions::QUADRIC_ORDER).unwrap();
        let shape = came::modelled::SHAPE;
        let part = partition(&tree, shape);
        let depth = |v: u32| tree.ids[v as usize].len();
        let mut seen = vec![false; tree.node_count()];
        assert!(part.units.len() > 8, "{} units", part.units.len());
        for (i, unit) in part.units.iter().enumerate() {
            let root = tree.ids[unit.root as usize];
            let band = shape.band(root.len());
            match unit.parent {
                None => assert_eq!(i, 0),
                Some(p) => {
                    assert!(p < i);
                    let parent = part.units[p].root;
                    assert_eq!(shape.band(depth(parent)).child, root.len());
                    assert!(tree.ids[parent as usize].is_ancestor_of(root));
                }
            }
            assert!(!unit.nodes.is_empty());
            for &s in &unit.nodes {
                assert!(!tree.is_leaf(s) && !seen[s as usize]);
                seen[s as usize] = true;
                assert!(root.is_ancestor_of(tree.ids[s as usize]));
                assert!(depth(s) >= band.start);
                assert!(unit.whole || depth(s) < band.end);
                assert_eq!(part.knowledge.split_unit[s as usize], Some(root));
            }
        }
        let inner = (0..tree.node_count() as u32).filter(|&v| !tree.is_leaf(v));
        assert!(inner.clone().all(|v| seen[v as usize]));
        // Bands: more than one unit starts at a depth below the first unit's band.
        let first = shape.band(0).end;
        assert!(part
            .units
            .iter()
            .any(|u| !u.whole && shape.band(depth(u.root)).start > first));
    }
}
