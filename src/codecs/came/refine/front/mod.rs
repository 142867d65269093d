//! The view-dependent mesh: the front of a CAME hierarchy, split and collapsed to a view, with
//! the triangles it holds — over the meta-nodes loaded so far, asking for the others as the
//! view needs them.
//!
//! Invariants ([`ViewMesh::check_invariants`], after every step in the tests):
//! - the active nodes form a cut: the root is split or active, a split node's children are
//!   active or split, an active or below node's children are below;
//! - only nodes whose split is loaded are split (a node whose meta-node is not loaded, or was
//!   refused, stays on the front or under it);
//! - a triangle is present exactly when the node it is born at is split, and its corners are
//!   then the active nodes on its corners' leaf paths (distinct, since two corners part at its
//!   birth node and the third at an ancestor of it);
//! - every split node's dependencies are split, and each node counts the split nodes that
//!   depend on it;
//! - each active node lists exactly the present triangles with a corner at it.
//!
//! Loading everything and refining everything gives the full decode's triangles on the full
//! decode's vertices.
//!
//! No cracks: together, the invariants say that the adapted mesh is the full mesh projected
//! through the front — every triangle of the full mesh with each corner moved to the active
//! node on its leaf path, those keeping three distinct corners (a triangle born at a node that
//! is not split has two corners under one active node) — so every edge of the adapted mesh is
//! used by exactly the faces that use it in that projection, and a seam can open nowhere, not
//! even between a loaded meta-node and one still on its way (tested against the projection
//! computed from the whole stream).
//!
//! No fold-overs in view: every present face that shows in the view — meets its frustum and
//! spans the tolerance on the screen ([`View::shows_triangle`]; a smaller face shows within the
//! tolerance whichever way it turns) — turns the way of the full mesh's triangle it stands for (its *counterpart*: the same triangle with each corner at
//! its leaf), the normals of the two making an angle under 90°. The hierarchy's build does not test Hoppe's fold-over conditions
//! (the stored dependencies make a split's neighbourhood the one the encoder saw, but nothing
//! checked that neighbourhood for flips), and the counterpart's corners are not known where
//! their meta-nodes are not loaded, so the front makes sure of it from what it holds
//! ([`ViewMesh::orientation_certain`]): a face is certain when
//! - its triangle's own normal, coded where the triangle is born (`came` syntax 4,
//!   [`crate::hierarchy::came::face_normals`]), makes with n an angle that, plus the header's
//!   bound on the code's error, is under 90°; or
//! - its corners are leaves (it is its counterpart); or
//! - its corners' error spheres are small beside it: with e₁ = b − a, e₂ = c − a, and each
//!   counterpart corner within r of its node, n·n' ≥ |n|(|n| − |e₁|R₂ − R₁|e₂| − R₁R₂) where
//!   R₁ = r_a + r_b, R₂ = r_a + r_c (for some choice of the corner a); or
//! - its normal n is within 90° − α_v of the axis of a corner v's normal cone (which holds the
//!   counterpart's normal, a face with a corner under v); or
//! - n is within 90° − α of the cone of a loaded node on one of its counterpart's leaf paths
//!   below its corners (the counterpart has a corner under that node too, and the deeper the
//!   node, the narrower its cone); or
//! - the deepest loaded nodes on its counterpart's leaf paths (the leaves themselves once their
//!   meta-nodes are in) make a proxy triangle whose normal is within β of n and whose spheres
//!   bound the counterpart's normal within γ of its own (the sphere test above, as a cosine),
//!   with β + γ < 90°. Coarse faces of a curved region fail the tests on their corners, whose
//!   spheres and cones span the region; these two look at the counterpart's own
//!   neighbourhood wherever the stream has been read (on dragon-50k's far view they took the
//!   guard from 8× to 1.4× the unguarded front's faces).
//!
//! The faces a split or collapse moves or makes are listed and checked at the end of the
//! adaptation. With triangle normals (syntax 4) every face is decided by the triangle's own
//! normal, whatever is loaded: a face in view that is not certain folds over (or nearly), and
//! is split as below, never waiting for data to prove a face — so the guard reads little the
//! view does not (dragon-50k's far view: 71.6% of the stream against 98.5% when it waited;
//! 68.0% unguarded). When no loaded split of a corner alone would turn such a face right, the
//! face waits for its corners' splits that are not loaded before splitting the coarsest
//! corner: with units by depth band, splitting blind took that view from 1,118 to 1,186 faces.
//! Before syntax 4, a face in view that is not certain **first waits for the meta-nodes under the
//! deepest loaded nodes on its counterpart's leaf paths** ([`ViewMesh::ask_for_certificate`]):
//! they decide it, exactly once the leaves are in. Only a face that is not certain from its
//! counterpart itself (it folds over) or whose meta-nodes cannot come (refused) has a corner
//! split (with its dependencies) — the coarsest whose split alone would make it certain, else
//! the coarsest that can be split — in turn until it is, at worst down to the leaves.
//! Splitting for want of data chased each counterpart down the hierarchy, face after face, and
//! cost the million-triangle mesh's far view 13× the unguarded front's faces (1.05× now, for 17
//! points more of its stream read: BENCHMARKS.md). The passes collapse without checking the
//! faces a collapse moves: those it leaves in view and not certain are split as above after the
//! passes, like any other listed face. A node the guard split collapses again only when a retry
//! finds every face in view it would move certain (retries come after the guard, when a face
//! the collapse would move moves, and in each new view). Faces out of view that
//! are not certain stay listed, to be made certain when a view sees them (certainty out of
//! view would refine the whole surface: 7× the faces close up, in the fly-through). A face
//! waiting for a meta-node is also kept listed (the front is not settled meanwhile), and so
//! is one whose split would take the front past a face budget (the budget comes first). The
//! invariant checked: every present face is certain or listed, and after an adaptation that
//! settled, every listed face in view waits for nothing (it could not be split: a refused
//! meta-node).

mod loading;
mod orientation;
mod output;
mod parts;
mod passes;
#[cfg(test)]
mod tests;
mod topology;

use super::loader::{ByteSource, Fetch, Loader, Reads, SeekSource};
use super::view::View;
use crate::error::{Error, Result};
use glam::DVec3;
pub use output::PresentTriangle;
use parts::{Faces, Front, Guard, Loading, Nodes, Scratch};
use std::ops::Range;
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    /// Under the front.
    Below,
    /// On the front.
    Active,
    /// Above the front.
    Split,
}

/// Where a meta-node stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum UnitState {
    /// Not asked for.
    Idle,
    /// Asked for, not arrived.
    Requested,
    /// Its bytes handed over by the caller ([`Fetch::External`]), not yet taken in.
    Supplied,
    Loaded,
    /// Corrupt or cut: its branch stays as coarse as its parent unit leaves it.
    Refused,
}

/// Whether a triangle's orientation is to be checked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Suspicion {
    /// Not listed: certain, or not present.
    None,
    /// Listed: its corners moved since it was last checked.
    Moved,
    /// Listed: found not certain (out of view, or its split waits for a meta-node or a budget).
    Uncertain,
}

/// Whether an active node can be split.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ready {
    Now,
    /// Its meta-node is on its way.
    Waiting,
    /// A leaf, or a split the stream cannot make (a refused meta-node, a dependency on a
    /// vertex or a cycle of dependencies).
    Never,
}

/// Limits of one [`ViewMesh::adapt`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Budget {
    /// Splits and collapses at most (the pass resumes where it stopped at the next call).
    pub operations: usize,
    /// Faces to hold the front to, by scaling the tolerance from call to call.
    pub faces: Option<usize>,
}

impl Budget {
    /// No limit.
    pub const UNLIMITED: Budget = Budget {
        operations: usize::MAX,
        faces: None,
    };
}

/// What one [`ViewMesh::adapt`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Adapted {
    pub splits: usize,
    pub collapses: usize,
    /// Passes over the active nodes.
    pub passes: usize,
    /// Meta-nodes that arrived and were taken in at the start of the call.
    pub loaded: usize,
    /// Splits the view wanted, and faces in view not yet certain of their orientation, that
    /// wait for a meta-node (asked for; a later call makes or decides them).
    pub waiting: usize,
    /// Splits the view wanted that the stream cannot make (a refused meta-node's branch).
    pub blocked: usize,
    /// Whether the face budget held back a split the view wanted (the tolerance is raised for
    /// the next call).
    pub capped: bool,
    /// Whether the front is settled for this view: a pass found nothing more to do, nothing
    /// was held back and nothing waits for a meta-node.
    pub settled: bool,
    /// Faces in view left not certain of their orientation (module docs): waiting for a
    /// meta-node, held back by a budget, or on a branch the stream cannot refine.
    pub unsure: usize,
}

impl Adapted {
    /// `self` followed by `next`.
    fn then(self, next: Adapted) -> Adapted {
        Adapted {
            splits: self.splits + next.splits,
            collapses: self.collapses + next.collapses,
            passes: self.passes + next.passes,
            loaded: self.loaded + next.loaded,
            waiting: next.waiting,
            blocked: next.blocked,
            capped: next.capped,
            settled: next.settled,
            unsure: next.unsure,
        }
    }
}

/// What has been fetched of the stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fetched {
    /// Meta-nodes decoded and taken in.
    pub units_loaded: usize,
    /// Meta-nodes refused (corrupt or cut).
    pub units_refused: usize,
    /// Meta-nodes of the stream.
    pub units: usize,
    /// Bytes read from the source (header and index included).
    pub bytes_read: u64,
    /// The stream's bytes, as its header and index give them.
    pub stream_bytes: u64,
}

/// A hit of [`ViewMesh::pick`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pick {
    /// The triangle, as numbered in the decoded tree.
    pub triangle: u32,
    /// Distance along the ray (in ray-direction lengths).
    pub distance: f64,
    /// The point hit.
    pub point: DVec3,
}

/// The front of a hierarchy and the triangles it holds, in parts that each keep their own
/// lists (front/parts.rs): the decoded tree's records, the front over them, the triangles it holds,
/// the orientation guard's lists, the scratch lists of passes and forced splits, and the
/// meta-nodes' loading.
pub struct ViewMesh {
    nodes: Nodes,
    front: Front,
    faces: Faces,
    guard: Guard,
    scratch: Scratch,
    loading: Loading,
    /// κ's scale, regulated to a face budget.
    scale: f64,
}

impl ViewMesh {
    /// The front at the root of the stream in `source`, having read its header, its index and
    /// its first meta-node only; the others are fetched as views need them.
    pub fn open(source: impl ByteSource + 'static, fetch: Fetch) -> Result<ViewMesh> {
        ViewMesh::open_reading(source, fetch, Reads::DEFAULT)
    }

    /// [`ViewMesh::open`], reading the stream's header and index `reads` at a time (a
    /// `Fetch::External` source holds the whole index: it is read at once).
    pub fn open_reading(
        source: impl ByteSource + 'static,
        fetch: Fetch,
        reads: Reads,
    ) -> Result<ViewMesh> {
        let (loader, opened) = Loader::open(Box::new(source), fetch, reads)?;
        let mut units = vec![UnitState::Idle; opened.units];
        units[0] = UnitState::Requested;
        let mut vm = ViewMesh {
            nodes: Nodes::default(),
            front: Front::default(),
            faces: Faces::default(),
            guard: Guard::default(),
            scratch: Scratch::default(),
            loading: Loading {
                loader,
                opened: vec![Vec::new(); units.len()],
                units,
                outstanding: 1,
                view_now: View::nothing(),
                refusals: Vec::new(),
                bytes_read: opened.head_bytes,
                stream_bytes: opened.stream_bytes,
                waited_for: None,
                waiting_nodes: Vec::new(),
                waited_now: Vec::new(),
            },
            scale: 1.0,
        };
        let root = opened.root;
        if let Err(e) = &root.outcome {
            return Err(Error::malformed(1, 0, format!("the root meta-node: {e}")));
        }
        vm.take_in(root);
        vm.activate(0);
        Ok(vm)
    }

    /// The front of the stream in file `path`, its meta-nodes read by a loader thread.
    pub fn open_file(path: &Path) -> Result<ViewMesh> {
        let file = std::fs::File::open(path)?;
        ViewMesh::open(SeekSource(std::io::BufReader::new(file)), Fetch::Background)
    }

    /// The front of a stream (or prefix) in memory, meta-nodes decoded inline as they are
    /// needed.
    pub fn from_stream(bytes: &[u8]) -> Result<ViewMesh> {
        ViewMesh::open(bytes.to_vec(), Fetch::Inline)
    }

    /// The meta-nodes asked for since the last call, with their byte ranges in the stream, in
    /// the order the adaptations asked for them, when the stream was opened with
    /// [`Fetch::External`] (none otherwise): fetch them and hand their bytes to
    /// [`ViewMesh::supply`].
    pub fn wanted(&mut self) -> Vec<(usize, Range<u64>)> {
        self.loading.loader.take_wanted()
    }

    /// Hands over the bytes of meta-node `unit`, fetched as [`ViewMesh::wanted`] asked: the
    /// unit is decoded now and taken in at the next adaptation (refused there, its branch left
    /// coarse, if the bytes are cut or corrupt). An error if the unit was not asked for or was
    /// handed over already.
    pub fn supply(&mut self, unit: usize, bytes: &[u8]) -> Result<()> {
        match self.loading.units.get(unit) {
            None => {
                return Err(Error::Unsupported(format!(
                    "unit {unit} supplied; the stream has {} units",
                    self.loading.units.len()
                )))
            }
            Some(UnitState::Requested) => {}
            Some(_) => {
                return Err(Error::Unsupported(format!(
                    "unit {unit} supplied, but it is not waited for"
                )))
            }
        }
        self.loading.units[unit] = UnitState::Supplied;
        self.loading.loader.supply(unit, bytes);
        Ok(())
    }

    /// Faces present.
    pub fn face_count(&self) -> usize {
        self.faces.count
    }

    /// Active nodes (the vertices of the adapted mesh).
    pub fn vertex_count(&self) -> usize {
        self.front.active.len()
    }

    /// κ's scale now (1 unless a face budget raised it).
    pub fn tolerance_scale(&self) -> f64 {
        self.scale
    }

    /// What has been fetched so far.
    pub fn fetched(&self) -> Fetched {
        Fetched {
            units_loaded: self
                .loading
                .units
                .iter()
                .filter(|&&u| u == UnitState::Loaded)
                .count(),
            units_refused: self.loading.refusals.len(),
            units: self.loading.units.len(),
            bytes_read: self.loading.bytes_read,
            stream_bytes: self.loading.stream_bytes,
        }
    }

    /// Whether a node loaded so far has a normal cone (a `came` stream with cones), so that
    /// back faces can be culled.
    pub fn has_normal_cones(&self) -> bool {
        self.nodes.bounds.iter().any(|b| b.cone.is_some())
    }

    /// The meta-nodes refused, and why.
    pub fn refusals(&self) -> &[(usize, String)] {
        &self.loading.refusals
    }

    /// Waits until every meta-node asked for has arrived, and takes them in.
    pub fn wait_for_units(&mut self) -> usize {
        self.take_arrivals(true)
    }

    /// Adapts the front to `view` with the meta-nodes at hand: takes in those that have
    /// arrived, then passes over the active nodes, refining each the view wants refined down
    /// its subtree (dependencies first) and collapsing the parents of the others up the tree
    /// while the view does not want them, until a pass changes nothing or the budget is spent.
    /// Splits that need a meta-node not loaded ask for it and wait.
    pub fn adapt(&mut self, view: &View, budget: Budget) -> Adapted {
        if self.loading.view_now != *view {
            self.loading.view_now = view.clone();
        }
        let mut done = Adapted {
            loaded: self.take_arrivals(false),
            ..Adapted::default()
        };
        let mut pass = std::mem::take(&mut self.scratch.pass);
        let new_view = self.adapt_passes(view, budget, &mut done, &mut pass);
        self.settle_orientation(view, budget, &mut done, &mut pass, new_view);
        self.scratch.pass = pass;
        self.regulate(budget.faces, done.capped);
        done
    }

    /// Adapts to `view` until the front settles, waiting for the meta-nodes it asks for
    /// (at most `calls` adaptations: a face budget may take several to regulate).
    pub fn settle(&mut self, view: &View, budget: Budget, calls: usize) -> Adapted {
        let mut total = Adapted::default();
        for _ in 0..calls {
            let done = self.adapt(view, budget);
            total = total.then(done);
            if done.settled {
                break;
            }
            if done.waiting > 0 {
                total.loaded += self.wait_for_units();
            }
        }
        total
    }
}
