//! The parts of a [`ViewMesh`](super::ViewMesh), each with the lists it keeps and what holds of
//! them (`ViewMesh::check_invariants` checks them together): node records, the front, its
//! triangles, the orientation guard, scratch, and the meta-nodes' loading.

use super::super::loader::NONE;
use super::super::loader::{Dependency, Loader};
use super::super::view::View;
use super::orientation::CodedNormal;
use super::{State, Suspicion, UnitState};
use crate::hierarchy::came::cones::NormalCone;
use crate::hierarchy::came::NodeId;
use glam::DVec3;
use smallvec::SmallVec;

/// The decoded tree's records, one entry a node in the loader's decoding order, every list as
/// long as `links`: what a meta-node brought, and each node's place on the front (in its
/// links, beside its place in the tree, as a split or collapse reads both). Of what a
/// meta-node brought, only `children` and `opens` change after, when the meta-node that
/// splits a node is taken in.
#[derive(Default)]
pub(super) struct Nodes {
    /// What a split or collapse reads and writes of a node, in one cache line.
    pub(super) links: Vec<Links>,
    /// The meta-node that splits the node, while it is not loaded (else `NONE`).
    pub(super) opens: Vec<u32>,
    /// What the view test reads of each node (one cache line a node: the test of every
    /// active node and of its parent, every pass, read three arrays before).
    pub(super) bounds: Vec<Bounds>,
    /// Triangles born at the node's split.
    pub(super) born: Vec<SmallVec<[u32; 2]>>,
    /// Nodes whose splits the node's split needs.
    pub(super) depends_on: Vec<SmallVec<[Dependency; 2]>>,
}

/// A node's path, parent, children, state, place on the front and faces: what a split or
/// collapse reads and writes of it, in one cache line (seven lists before: the fly-through's
/// median frame 5% longer, BENCHMARKS.md).
#[derive(Clone, Debug)]
#[repr(C, align(64))]
pub(super) struct Links {
    /// Present triangles with a corner at the node (active nodes only).
    pub(super) faces_at: SmallVec<[u32; 6]>,
    pub(super) id: NodeId,
    /// Children, `[NONE; 2]` for leaves and nodes whose split is not loaded.
    pub(super) children: [u32; 2],
    pub(super) parent: u32,
    /// The node's place among the front's active nodes (`NONE` if it is not active).
    pub(super) active_slot: u32,
    /// Split nodes depending on the node.
    pub(super) split_dependants: u32,
    pub(super) state: State,
}

// One cache line.
const _: () = assert!(std::mem::size_of::<Links>() == 64);

/// A node's position, error sphere, deviation and normal cone: what the view test reads.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Bounds {
    /// Position, in world units.
    pub(super) center: DVec3,
    /// Error-sphere radius, in world units.
    pub(super) radius: f64,
    /// Deviation, in world units: the error the view test projects.
    pub(super) deviation: f64,
    /// Normal cone, for back-face culling.
    pub(super) cone: NormalCone,
}

/// Which nodes are on the front: the active ones listed, and a bit each (each node's state,
/// place in the list and split dependants are in its [`Links`]).
#[derive(Default)]
pub(super) struct Front {
    /// The active nodes (each one's place among them is in its links).
    pub(super) active: Vec<u32>,
    /// The active nodes again, a bit a node (bit v % 64 of word v / 64): a pass lists them
    /// in node order from it.
    pub(super) active_bits: Vec<u64>,
}

/// The triangles: each one's corners (as leaves, and as the active nodes on their paths),
/// whether it is present, and how many are (each active node's present triangles are in its
/// [`Links`]).
#[derive(Default)]
pub(super) struct Faces {
    // Per triangle.
    pub(super) leaf_corners: Vec<[NodeId; 3]>,
    /// What the stream says of the counterpart's normal (`came` syntax 4).
    pub(super) normals: Vec<CodedNormal>,
    /// The active nodes at its corners while present, `[NONE; 3]` while not (so that whether
    /// a face is present is read with its corners, not from a list of its own).
    pub(super) corners: Vec<[u32; 3]>,
    /// Present triangles.
    pub(super) count: usize,
}

/// The orientation guard's lists: faces whose orientation is to be made certain, and the
/// collapses it refused or will try again.
#[derive(Default)]
pub(super) struct Guard {
    /// The face that last kept the node split (a face in view its collapse would leave not
    /// certain of its orientation, or that the guard split it for): checked first.
    pub(super) held_by: Vec<u32>,
    /// Whether the node is in `refused`.
    pub(super) refused_listed: Vec<bool>,
    /// Split nodes whose collapse was refused for a face's orientation: tried again after the
    /// passes of every adaptation (not by the passes themselves, which would check the same
    /// faces again and again while a view lasts).
    pub(super) refused: Vec<u32>,
    /// Split nodes whose collapse to try again after the passes, a face it would move having
    /// moved (`in_retry`: whether listed).
    pub(super) retry: Vec<u32>,
    pub(super) in_retry: Vec<bool>,
    /// Where the triangle stands in `suspects`.
    pub(super) suspected: Vec<Suspicion>,
    /// Present triangles whose orientation is to be made certain: those splits moved or made
    /// since the last adaptation's guard, and those it could not yet make certain.
    pub(super) suspects: Vec<u32>,
}

/// What passes and forced splits work through, kept to save allocating it each time.
#[derive(Default)]
pub(super) struct Scratch {
    /// The active nodes a pass visits.
    pub(super) pass: Vec<u32>,
    /// Split nodes a collapse left with no split dependant: they may collapse now.
    pub(super) freed: Vec<u32>,
    /// Splits planned by a forced split, in order, and each node's mark of being planned;
    /// the nodes it works through.
    pub(super) plan: Vec<u32>,
    pub(super) stack: Vec<u32>,
    pub(super) planned: Vec<bool>,
    /// Where an interrupted pass resumes: the node it stopped at (passes go in node order).
    pub(super) cursor: u32,
}

/// The meta-nodes: the loader, each unit's state, what was read and refused, and the splits
/// waiting for units.
pub(super) struct Loading {
    pub(super) loader: Loader,
    pub(super) units: Vec<UnitState>,
    /// Per unit: the open nodes whose splits it holds (one, its root, in meta-nodes of L
    /// levels; those at the band's first depth under its root in depth bands).
    pub(super) opened: Vec<Vec<u32>>,
    /// Asked for and not arrived.
    pub(super) outstanding: usize,
    /// The view of the adaptation under way: the meta-nodes it asks for go to the loader with
    /// the screen error of the node waiting for them ([`View::screen_error`]).
    pub(super) view_now: View,
    pub(super) refusals: Vec<(usize, String)>,
    pub(super) bytes_read: u64,
    pub(super) stream_bytes: u64,
    /// The view of the last adaptation, if its last pass changed nothing but splits waited
    /// for meta-nodes; the nodes those splits start from (and the list being made).
    pub(super) waited_for: Option<View>,
    pub(super) waiting_nodes: Vec<u32>,
    pub(super) waited_now: Vec<u32>,
}

/// The result of a part's check: what is off, in one line.
pub(super) type Checked = std::result::Result<(), String>;

impl Nodes {
    /// Every list one entry a node; a child's parent is the node it hangs from.
    pub(super) fn check(&self) -> Checked {
        let n = self.links.len();
        let lengths = [
            self.opens.len(),
            self.bounds.len(),
            self.born.len(),
            self.depends_on.len(),
        ];
        if lengths.iter().any(|&len| len != n) {
            return Err(format!("node lists of lengths {lengths:?} for {n} nodes"));
        }
        for (v, links) in self.links.iter().enumerate() {
            for &c in links.children.iter().filter(|&&c| c != NONE) {
                if self.links.get(c as usize).map(|l| l.parent) != Some(v as u32) {
                    return Err(format!("node {c} is a child of {v} but not its parent's"));
                }
            }
        }
        Ok(())
    }
}

impl Front {
    /// The active list, each active node's place in it (in `links`) and its bit agree.
    pub(super) fn check(&self, links: &[Links]) -> Checked {
        let n = links.len();
        if self.active_bits.len() < n.div_ceil(64) {
            return Err("the active bitmap is short".into());
        }
        for (slot, &v) in self.active.iter().enumerate() {
            if links.get(v as usize).map(|l| l.active_slot) != Some(slot as u32) {
                return Err(format!("active node {v} is not at its place {slot}"));
            }
        }
        let listed = links.iter().filter(|l| l.active_slot != NONE).count();
        let bits: u32 = self.active_bits.iter().map(|w| w.count_ones()).sum();
        if listed != self.active.len() || bits as usize != self.active.len() {
            return Err("the active list, places and bits disagree".into());
        }
        Ok(())
    }
}

impl Faces {
    /// Whether triangle `t` is present.
    pub(super) fn present(&self, t: usize) -> bool {
        self.corners[t][0] != NONE
    }

    /// A record a triangle in each list, and the count of those present.
    pub(super) fn check(&self) -> Checked {
        let t = self.leaf_corners.len();
        if self.corners.len() != t || self.normals.len() != t {
            return Err("triangle lists of other lengths".into());
        }
        if let Some(t) = (0..t).find(|&t| {
            let c = self.corners[t];
            c.contains(&NONE) && c != [NONE; 3]
        }) {
            return Err(format!("triangle {t} has some corners and not others"));
        }
        let present = (0..t).filter(|&t| self.present(t)).count();
        if present != self.count {
            return Err(format!(
                "{present} triangles present, {} counted",
                self.count
            ));
        }
        Ok(())
    }
}

impl Guard {
    /// The triangles listed as suspects are those marked, each once.
    pub(super) fn check(&self) -> Checked {
        let marked = self
            .suspected
            .iter()
            .filter(|&&m| m != Suspicion::None)
            .count();
        if marked != self.suspects.len()
            || self.suspects.iter().any(|&t| {
                self.suspected
                    .get(t as usize)
                    .is_none_or(|&m| m == Suspicion::None)
            })
        {
            return Err("the listed triangles and their marks disagree".into());
        }
        Ok(())
    }
}
