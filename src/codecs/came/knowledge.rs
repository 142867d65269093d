//! What the decoder of one meta-node knows of a node: only what its own unit and its ancestors
//! coded, whatever else happens to be decoded — so that every unit decodes alike alone or in a
//! full stream, and the encoder, which knows everything, asks the same question.
//!
//! A unit's ancestors are exactly the units whose roots are ancestors of its root, so the test
//! is a prefix test on node identifiers.

use crate::hierarchy::came::NodeId;

/// A node as the decoder of a unit sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// A leaf (its parent's split is known).
    Leaf,
    /// An inner node whose split is known: its children's positions are there.
    Inner,
    /// An inner node whose split is not known (the root of a unit further down).
    Open,
    /// Nothing known beyond its existence.
    Unknown,
}

/// Per node: the root of the unit coding its split (inner nodes), and the root of the unit
/// coding the split that creates it (the root: the first unit).
#[derive(Clone, Debug, Default)]
pub struct Knowledge {
    /// Root of the unit that codes the node's split.
    pub split_unit: Vec<Option<NodeId>>,
    /// Root of the unit that codes the split creating the node.
    pub created_unit: Vec<NodeId>,
}

/// The status of a node seen from the unit rooted at `unit`, given whether it is a leaf and
/// which units coded its split and its creation.
pub fn status(leaf: bool, split: Option<NodeId>, created: NodeId, unit: NodeId) -> Status {
    if split.is_some_and(|r| r.is_ancestor_of(unit)) {
        Status::Inner
    } else if !created.is_ancestor_of(unit) {
        Status::Unknown
    } else if leaf {
        Status::Leaf
    } else {
        Status::Open
    }
}

impl Knowledge {
    /// The status of node `x` (`leaf`: whether it is one) from the unit rooted at `unit`.
    pub fn status(&self, x: u32, leaf: bool, unit: NodeId) -> Status {
        status(
            leaf,
            self.split_unit[x as usize],
            self.created_unit[x as usize],
            unit,
        )
    }
}
