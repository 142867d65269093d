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
//! - its corners are leaves (it is its counterpart); or
//! - its corners' error spheres are small beside it: with e₁ = b − a, e₂ = c − a, and each
//!   counterpart corner within r of its node, n·n' ≥ |n|(|n| − |e₁|R₂ − R₁|e₂| − R₁R₂) where
//!   R₁ = r_a + r_b, R₂ = r_a + r_c (for some choice of the corner a); or
//! - its normal n is within 90° − α_v of the axis of a corner v's normal cone (which holds the
//!   counterpart's normal, a face with a corner under v); or
//! - the deepest loaded nodes on its counterpart's leaf paths (the leaves themselves once their
//!   meta-nodes are in) make a proxy triangle whose normal is within β of n and whose spheres
//!   bound the counterpart's normal within γ of its own (the sphere test above, as a cosine),
//!   with β + γ < 90°. Coarse faces of a curved region fail the first three, whose spheres and
//!   cones span the region; this one looks at the counterpart's own neighbourhood wherever the
//!   stream has been read (on dragon-50k's far view it took the guard from 8× to 1.4× the
//!   unguarded front's faces).
//!
//! The faces a split or collapse moves or makes are listed and checked at the end of the
//! adaptation; a face in view that is not certain has its coarsest corner that can be split
//! split in turn (with its dependencies) until it is — at worst down to the leaves — and a
//! collapse that would leave a face in view not certain is not made. Faces out of view that
//! are not certain stay listed, to be made certain when a view sees them (certainty out of
//! view would refine the whole surface: 7× the faces close up, in the fly-through). A face
//! waiting for a meta-node is also kept listed (the front is not settled meanwhile), and so
//! is one whose split would take the front past a face budget (the budget comes first). The
//! invariant checked: every present face is certain or listed, and after an adaptation that
//! settled, every listed face in view waits for nothing (it could not be split: a refused
//! meta-node).

use super::loader::{ByteSource, Dependency, Fetch, Loaded, Loader, SeekSource, UnitDelta, NONE};
use super::view::View;
use crate::error::{Error, Result};
use crate::hierarchy::came::cones::NormalCone;
use crate::hierarchy::came::NodeId;
use crate::mesh::TriMesh;
use crate::prefetch::prefetch;
use glam::DVec3;
use smallvec::SmallVec;
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
    /// Splits the view wanted that wait for a meta-node (asked for; a later call makes them).
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

/// A margin for the rounding of the orientation tests' products (relative to their size).
const SLACK: f64 = 1.0 + 1e-9;

/// For a triangle on corners `p` whose counterpart's corners lie within `r` of them: a lower
/// bound on the cosine of the angle between the two normals, from the best choice of corner a
/// (with e₁ = b − a, e₂ = c − a, R₁ = r_a + r_b, R₂ = r_a + r_c, the counterpart's normal n'
/// has n·n' ≥ |n|(|n| − |e₁|R₂ − R₁|e₂| − R₁R₂) and |n'| ≤ (|e₁| + R₁)(|e₂| + R₂)); `None`
/// when no choice bounds it above 0.
fn spheres_hold_orientation(p: [DVec3; 3], r: [f64; 3]) -> Option<f64> {
    let area = (p[1] - p[0]).cross(p[2] - p[0]).length();
    if !(area > 0.0 && area.is_finite()) {
        return None;
    }
    (0..3)
        .filter_map(|a| {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            let (e1, e2) = ((p[b] - p[a]).length(), (p[c] - p[a]).length());
            let (r1, r2) = (r[a] + r[b], r[a] + r[c]);
            let slack = (e1 * r2 + r1 * e2 + r1 * r2) * SLACK;
            (area > slack).then(|| (area - slack) / ((e1 + r1) * (e2 + r2)))
        })
        .reduce(f64::max)
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

/// The front of a hierarchy and the triangles it holds.
pub struct ViewMesh {
    // Per node, in the loader's decoding order.
    ids: Vec<NodeId>,
    parent: Vec<u32>,
    /// Children, `[NONE; 2]` for leaves and nodes whose split is not loaded.
    children: Vec<[u32; 2]>,
    /// The meta-node that splits the node, while it is not loaded (else `NONE`).
    opens: Vec<u32>,
    /// Position and error-sphere radius, in world units.
    /// (One array: the view test of every active node, every pass, reads both.)
    spheres: Vec<(DVec3, f64)>,
    /// Deviation, in world units: the error the view test projects.
    deviations: Vec<f64>,
    /// Normal cone, for back-face culling.
    cones: Vec<NormalCone>,
    state: Vec<State>,
    /// Triangles born at the node's split.
    born: Vec<SmallVec<[u32; 2]>>,
    /// Nodes whose splits the node's split needs.
    depends_on: Vec<SmallVec<[Dependency; 2]>>,
    /// Split nodes depending on the node.
    split_dependants: Vec<u32>,
    /// The face that last kept the node split (a face in view its collapse would leave not
    /// certain of its orientation, or that the guard split it for): checked first.
    held_by: Vec<u32>,
    /// Whether the node is in `refused`.
    refused_listed: Vec<bool>,
    /// Split nodes whose collapse was refused for a face's orientation: tried again after the
    /// passes of every adaptation (not by the passes themselves, which would check the same
    /// faces again and again while a view lasts).
    refused: Vec<u32>,
    /// Split nodes whose collapse to try again after the passes, a face it would move having
    /// moved (`in_retry`: whether listed).
    retry: Vec<u32>,
    in_retry: Vec<bool>,
    /// Present triangles with a corner at the node (active nodes only).
    faces_at: Vec<SmallVec<[u32; 6]>>,
    /// The active nodes, and each node's place among them.
    active: Vec<u32>,
    active_slot: Vec<u32>,
    /// The active nodes again, a bit a node (bit v % 64 of word v / 64): a pass lists them
    /// in node order from it.
    active_bits: Vec<u64>,
    // Per triangle.
    leaf_corners: Vec<[NodeId; 3]>,
    corners: Vec<[u32; 3]>,
    present: Vec<bool>,
    /// Where the triangle stands in `suspects`.
    suspected: Vec<Suspicion>,
    faces: usize,
    /// Present triangles whose orientation is to be made certain: those splits moved or made
    /// since the last adaptation's guard, and those it could not yet make certain.
    suspects: Vec<u32>,
    /// Where an interrupted pass resumes: the node it stopped at (passes go in node order).
    cursor: u32,
    /// κ's scale, regulated to a face budget.
    scale: f64,
    /// The active nodes a pass visits (kept to save allocating one a pass).
    pass: Vec<u32>,
    /// Split nodes a collapse left with no split dependant: they may collapse now.
    freed: Vec<u32>,
    /// The view of the last adaptation, if its last pass changed nothing but splits waited
    /// for meta-nodes; the nodes those splits start from (and the list being made).
    waited_for: Option<View>,
    waiting_nodes: Vec<u32>,
    waited_now: Vec<u32>,
    /// Splits planned by a forced split, in order, and each node's mark of being planned;
    /// the nodes it works through (both kept to save allocating them a split).
    plan: Vec<u32>,
    stack: Vec<u32>,
    planned: Vec<bool>,
    // Meta-nodes.
    loader: Loader,
    units: Vec<UnitState>,
    /// Asked for and not arrived.
    outstanding: usize,
    /// Per meta-node: its bytes were handed over ([`Fetch::External`]).
    supplied: Vec<bool>,
    refusals: Vec<(usize, String)>,
    bytes_read: u64,
    stream_bytes: u64,
}

impl ViewMesh {
    /// The front at the root of the stream in `source`, having read its header, its index and
    /// its first meta-node only; the others are fetched as views need them.
    pub fn open(source: impl ByteSource + 'static, fetch: Fetch) -> Result<ViewMesh> {
        let (loader, opened) = Loader::open(Box::new(source), fetch)?;
        let mut units = vec![UnitState::Idle; opened.index.len()];
        units[0] = UnitState::Requested;
        let mut vm = ViewMesh {
            ids: Vec::new(),
            parent: Vec::new(),
            children: Vec::new(),
            opens: Vec::new(),
            spheres: Vec::new(),
            deviations: Vec::new(),
            cones: Vec::new(),
            state: Vec::new(),
            born: Vec::new(),
            depends_on: Vec::new(),
            split_dependants: Vec::new(),
            held_by: Vec::new(),
            refused_listed: Vec::new(),
            refused: Vec::new(),
            retry: Vec::new(),
            in_retry: Vec::new(),
            faces_at: Vec::new(),
            active: Vec::new(),
            active_slot: Vec::new(),
            active_bits: Vec::new(),
            leaf_corners: Vec::new(),
            corners: Vec::new(),
            present: Vec::new(),
            suspected: Vec::new(),
            faces: 0,
            suspects: Vec::new(),
            cursor: 0,
            scale: 1.0,
            pass: Vec::new(),
            freed: Vec::new(),
            waited_for: None,
            waiting_nodes: Vec::new(),
            waited_now: Vec::new(),
            plan: Vec::new(),
            stack: Vec::new(),
            planned: Vec::new(),
            loader,
            units,
            outstanding: 1,
            supplied: vec![false; opened.index.len()],
            refusals: Vec::new(),
            bytes_read: opened.head_bytes,
            stream_bytes: opened.stream_bytes,
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
        self.loader.take_wanted()
    }

    /// Hands over the bytes of meta-node `unit`, fetched as [`ViewMesh::wanted`] asked: the
    /// unit is decoded now and taken in at the next adaptation (refused there, its branch left
    /// coarse, if the bytes are cut or corrupt). An error if the unit was not asked for or was
    /// handed over already.
    pub fn supply(&mut self, unit: usize, bytes: &[u8]) -> Result<()> {
        match self.units.get(unit) {
            None => {
                return Err(Error::Unsupported(format!(
                    "unit {unit} supplied; the stream has {} units",
                    self.units.len()
                )))
            }
            Some(UnitState::Requested) if !self.supplied[unit] => {}
            Some(_) => {
                return Err(Error::Unsupported(format!(
                    "unit {unit} supplied, but it is not waited for"
                )))
            }
        }
        self.supplied[unit] = true;
        self.loader.supply(unit, bytes);
        Ok(())
    }

    /// Faces present.
    pub fn face_count(&self) -> usize {
        self.faces
    }

    /// Active nodes (the vertices of the adapted mesh).
    pub fn vertex_count(&self) -> usize {
        self.active.len()
    }

    /// κ's scale now (1 unless a face budget raised it).
    pub fn tolerance_scale(&self) -> f64 {
        self.scale
    }

    /// What has been fetched so far.
    pub fn fetched(&self) -> Fetched {
        Fetched {
            units_loaded: self
                .units
                .iter()
                .filter(|&&u| u == UnitState::Loaded)
                .count(),
            units_refused: self.refusals.len(),
            units: self.units.len(),
            bytes_read: self.bytes_read,
            stream_bytes: self.stream_bytes,
        }
    }

    /// Whether a node loaded so far has a normal cone (a `came` stream with cones), so that
    /// back faces can be culled.
    pub fn has_normal_cones(&self) -> bool {
        self.cones.iter().any(|c| c.is_some())
    }

    /// The meta-nodes refused, and why.
    pub fn refusals(&self) -> &[(usize, String)] {
        &self.refusals
    }

    /// Takes in a fetched meta-node: its nodes, triangles and dependencies join the hierarchy
    /// (under the front: nothing present changes).
    fn take_in(&mut self, loaded: Loaded) {
        self.outstanding -= 1;
        self.bytes_read += loaded.bytes;
        match loaded.outcome {
            Ok(delta) => {
                self.units[loaded.unit] = UnitState::Loaded;
                self.grow(delta);
                // The orientation certificates read the deepest loaded nodes: a collapse
                // refused before may be allowed now.
                for p in std::mem::take(&mut self.refused) {
                    if !self.in_retry[p as usize] {
                        self.in_retry[p as usize] = true;
                        self.retry.push(p);
                    }
                }
            }
            Err(e) => {
                self.units[loaded.unit] = UnitState::Refused;
                self.refusals.push((loaded.unit, e.to_string()));
            }
        }
    }

    fn grow(&mut self, delta: UnitDelta) {
        for n in delta.nodes {
            let v = self.ids.len() as u32;
            if n.parent != NONE {
                let p = n.parent as usize;
                self.children[p][n.id.bit(n.id.len() - 1) as usize] = v;
                self.opens[p] = NONE;
            }
            self.ids.push(n.id);
            self.parent.push(n.parent);
            self.children.push([NONE; 2]);
            self.opens.push(NONE);
            self.spheres.push((n.center, n.radius));
            self.deviations.push(n.deviation);
            self.cones.push(n.cone);
            self.state.push(State::Below);
            self.born.push(SmallVec::new());
            self.depends_on.push(SmallVec::new());
            self.split_dependants.push(0);
            self.held_by.push(NONE);
            self.refused_listed.push(false);
            self.in_retry.push(false);
            self.faces_at.push(SmallVec::new());
            self.active_slot.push(NONE);
            self.planned.push(false);
        }
        self.active_bits.resize(self.ids.len().div_ceil(64), 0);
        for (birth, corners) in delta.triangles {
            self.born[birth as usize].push(self.leaf_corners.len() as u32);
            self.leaf_corners.push(corners);
            self.corners.push([NONE; 3]);
            self.present.push(false);
            self.suspected.push(Suspicion::None);
        }
        for (s, deps) in delta.splits {
            self.depends_on[s as usize] = deps;
        }
        for (unit, root) in delta.opens {
            self.opens[root as usize] = unit as u32;
        }
    }

    /// Takes in the meta-nodes that have arrived (all those asked for when `block`).
    fn take_arrivals(&mut self, block: bool) -> usize {
        let arrived = self.loader.collect(self.outstanding, block);
        let count = arrived.len();
        for loaded in arrived {
            self.take_in(loaded);
        }
        count
    }

    /// Waits until every meta-node asked for has arrived, and takes them in.
    pub fn wait_for_units(&mut self) -> usize {
        self.take_arrivals(true)
    }

    fn activate(&mut self, v: u32) {
        self.state[v as usize] = State::Active;
        self.active_slot[v as usize] = self.active.len() as u32;
        self.active.push(v);
        self.active_bits[v as usize / 64] |= 1 << (v % 64);
    }

    fn deactivate(&mut self, v: u32, to: State) {
        self.state[v as usize] = to;
        let slot = self.active_slot[v as usize] as usize;
        self.active.swap_remove(slot);
        if let Some(&moved) = self.active.get(slot) {
            self.active_slot[moved as usize] = slot as u32;
        }
        self.active_slot[v as usize] = NONE;
        self.active_bits[v as usize / 64] &= !(1 << (v % 64));
    }

    /// The active node on leaf path `leaf`; `None` if the path ends at a split node (a
    /// corrupt stream's corner).
    fn active_on(&self, leaf: NodeId) -> Option<u32> {
        let mut v = 0u32;
        while self.state[v as usize] == State::Split {
            let len = self.ids[v as usize].len();
            if len >= leaf.len() {
                return None;
            }
            v = self.children[v as usize][leaf.bit(len) as usize];
        }
        Some(v)
    }

    /// Whether active node `v` can be split now; asks for its meta-node if that is missing.
    fn ready(&mut self, v: u32) -> Ready {
        let vu = v as usize;
        if self.children[vu][0] != NONE {
            return Ready::Now;
        }
        let unit = self.opens[vu];
        if unit == NONE {
            return Ready::Never;
        }
        match self.units[unit as usize] {
            UnitState::Idle => {
                self.units[unit as usize] = UnitState::Requested;
                self.outstanding += 1;
                self.loader.request(unit as usize);
                Ready::Waiting
            }
            UnitState::Requested => Ready::Waiting,
            UnitState::Loaded | UnitState::Refused => Ready::Never,
        }
    }

    /// The deepest loaded node on the path to `id`, and whether it is `id`.
    fn toward(&self, id: NodeId) -> (u32, bool) {
        self.toward_from(0, id)
    }

    /// [`ViewMesh::toward`], walking down from `start`, an ancestor of `id` (or `id`).
    fn toward_from(&self, start: u32, id: NodeId) -> (u32, bool) {
        let mut v = start;
        loop {
            let len = self.ids[v as usize].len();
            if len >= id.len() {
                return (v, self.ids[v as usize] == id);
            }
            match self.children[v as usize][id.bit(len) as usize] {
                NONE => return (v, false),
                c => v = c,
            }
        }
    }

    /// A node to split before `v` may be: its first dependency not split (or planned to be),
    /// or the deepest loaded node on the way to one not loaded yet.
    fn unmet_dependency(&mut self, v: u32) -> Option<u32> {
        for k in 0..self.depends_on[v as usize].len() {
            let dep = self.depends_on[v as usize][k];
            let node = if dep.node != NONE {
                dep.node
            } else {
                match self.toward(dep.id) {
                    (x, true) => {
                        self.depends_on[v as usize][k].node = x;
                        x
                    }
                    (x, false) => return Some(x),
                }
            };
            if self.planned_state(node) != State::Split {
                return Some(node);
            }
        }
        None
    }

    /// The active node on leaf path `leaf` among those sharing a face with active node `s`
    /// (where a triangle born at `s` finds its third corner: a neighbour of `v_s`, Hoppe's
    /// v_l or v_r), without a walk from the root.
    fn neighbour_on(&self, s: u32, leaf: NodeId) -> Option<u32> {
        self.faces_at[s as usize].iter().find_map(|&f| {
            self.corners[f as usize]
                .into_iter()
                .find(|&n| n != s && self.ids[n as usize].is_ancestor_of(leaf))
        })
    }

    /// vsplit of active inner node `s` whose dependencies are split. Does nothing and returns
    /// false if a corner cannot follow it (a leaf path ending at `s` or at a split node: only in
    /// a corrupt stream).
    fn split(&mut self, s: u32) -> bool {
        let su = s as usize;
        let depth = self.ids[su].len();
        let own = self.ids[su];
        let deep = |c: NodeId| c.len() > depth;
        for &f in &self.faces_at[su] {
            for k in 0..3 {
                if self.corners[f as usize][k] == s && !deep(self.leaf_corners[f as usize][k]) {
                    return false;
                }
            }
        }
        // The born triangles' corners: two under v_s, at v_t and v_u once it is split; the
        // third a neighbour (an active node elsewhere, which this split does not move).
        let mut born: SmallVec<[[u32; 3]; 4]> = SmallVec::new();
        for &f in &self.born[su] {
            let mut corners = [NONE; 3];
            for (k, &c) in self.leaf_corners[f as usize].iter().enumerate() {
                corners[k] = if own.is_ancestor_of(c) {
                    if !deep(c) {
                        return false;
                    }
                    self.children[su][c.bit(depth) as usize]
                } else {
                    match self.neighbour_on(s, c).or_else(|| self.active_on(c)) {
                        Some(v) => v,
                        None => return false,
                    }
                };
            }
            born.push(corners);
        }
        let [t, u] = self.children[su];
        self.deactivate(s, State::Split);
        self.activate(t);
        self.activate(u);
        for f in std::mem::take(&mut self.faces_at[su]) {
            let fu = f as usize;
            for k in 0..3 {
                if self.corners[fu][k] == s {
                    let child = self.children[su][self.leaf_corners[fu][k].bit(depth) as usize];
                    self.corners[fu][k] = child;
                    self.faces_at[child as usize].push(f);
                }
            }
            self.suspect(f);
        }
        for (i, corners) in born.into_iter().enumerate() {
            let f = self.born[su][i];
            for &c in &corners {
                self.faces_at[c as usize].push(f);
            }
            self.corners[f as usize] = corners;
            self.present[f as usize] = true;
            self.suspect(f);
        }
        self.faces += self.born[su].len();
        for &d in &self.depends_on[su] {
            self.split_dependants[d.node as usize] += 1;
        }
        true
    }

    /// Lists triangle `f` to have its orientation checked.
    fn suspect(&mut self, f: u32) {
        if self.suspected[f as usize] == Suspicion::None {
            self.suspects.push(f);
        }
        self.suspected[f as usize] = Suspicion::Moved;
        self.retry_around(f);
    }

    /// Lists the collapses that moving, making or removing present triangle `f` may have made
    /// possible for its orientation (those of its corners' parents) to be tried again.
    fn retry_around(&mut self, f: u32) {
        for c in self.corners[f as usize] {
            let p = self.parent[c as usize];
            if p != NONE && !self.in_retry[p as usize] {
                self.in_retry[p as usize] = true;
                self.retry.push(p);
            }
        }
    }

    /// Whether the face on active nodes `corners` shows in the view: it meets the frustum and
    /// spans the tolerance on the screen ([`View::shows_triangle`]).
    fn in_view(&self, view: &View, corners: [u32; 3]) -> bool {
        view.shows_triangle(corners.map(|v| self.spheres[v as usize].0))
    }

    /// Whether node `v` is a leaf of the hierarchy (not a node whose split is still to load).
    fn is_leaf(&self, v: u32) -> bool {
        self.children[v as usize][0] == NONE && self.opens[v as usize] == NONE
    }

    /// Whether triangle `f`, on active nodes `corners`, surely turns the way of its counterpart
    /// (the module docs' tests: leaves, error spheres, normal cones, and the spheres of the
    /// deepest loaded nodes on its corners' leaf paths).
    fn orientation_certain(&self, corners: [u32; 3], f: u32) -> bool {
        if corners.iter().all(|&v| self.is_leaf(v)) {
            return true;
        }
        let p = corners.map(|v| self.spheres[v as usize].0);
        let r = corners.map(|v| self.spheres[v as usize].1);
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let area = n.length();
        if !(area > 0.0 && area.is_finite()) {
            return false;
        }
        if spheres_hold_orientation(p, r).is_some_and(|cos| cos > 0.0) {
            return true;
        }
        let cones = corners.iter().any(|&v| {
            let cone = &self.cones[v as usize];
            let axis = DVec3::new(
                cone.axis[0] as f64,
                cone.axis[1] as f64,
                cone.axis[2] as f64,
            );
            // θ + α < 90° ⇔ cos θ > sin α (α widened by the cone's margin).
            cone.is_some() && n.dot(axis) > cone.sin as f64 * area * SLACK
        });
        cones || self.deeper_nodes_hold_orientation(n, corners, f)
    }

    /// The counterpart's corners lie within the spheres of the deepest loaded nodes on their
    /// leaf paths (the leaves themselves, radius 0, once loaded): a proxy triangle Q on those
    /// nodes, whose normal makes an angle β with the face's n, and whose spheres bound the
    /// angle γ between Q's normal and the counterpart's; the face is certain when β + γ < 90°.
    ///
    /// Each leaf path is walked down from the corner above the leaf (`corners`: active nodes,
    /// or a collapse's parent), not from the root: half the steps or fewer, in nodes near each
    /// other.
    fn deeper_nodes_hold_orientation(&self, n: DVec3, corners: [u32; 3], f: u32) -> bool {
        let leaves = self.leaf_corners[f as usize];
        let deepest = leaves.map(|leaf| {
            let above = corners
                .into_iter()
                .find(|&c| self.ids[c as usize].is_ancestor_of(leaf))
                .unwrap_or(0);
            self.toward_from(above, leaf).0
        });
        let q = deepest.map(|v| self.spheres[v as usize].0);
        let r = deepest.map(|v| self.spheres[v as usize].1);
        let Some(cos_gamma) = spheres_hold_orientation(q, r) else {
            return false;
        };
        let m = (q[1] - q[0]).cross(q[2] - q[0]);
        let cos_beta = n.dot(m) / (n.length() * m.length());
        if !(cos_beta > 0.0 && cos_gamma > 0.0) {
            return false;
        }
        // β + γ < 90° ⇔ cos(β + γ) > 0, with a margin for rounding.
        let (sin_beta, sin_gamma) = (
            (1.0 - cos_beta * cos_beta).max(0.0).sqrt(),
            (1.0 - cos_gamma * cos_gamma).max(0.0).sqrt(),
        );
        cos_beta * cos_gamma - sin_beta * sin_gamma > 1e-9
    }

    /// Whether ecol of split node `s` leaves every face it moves that is in view certain of
    /// its orientation (the faces born at `s`, on both children, go).
    ///
    /// A refused node is listed (`refused`), and the face that refused it is checked first the
    /// next time (a node the guard split is refused again and again while its view lasts: one
    /// face checked, not its dozen). `retry`: check a listed node again.
    ///
    /// While the front holds more faces than a face budget allows, the budget comes first: the
    /// collapse is made, and the faces it leaves not certain stay listed.
    fn collapse_keeps_orientation(
        &mut self,
        s: u32,
        view: &View,
        budget: Budget,
        retry: bool,
    ) -> bool {
        let su = s as usize;
        if !view.keeps_orientation() {
            return true;
        }
        // (Not when trying again after the guard, which would undo its splits over and over.)
        if !retry && budget.faces.is_some_and(|target| self.faces > target) {
            return true;
        }
        if self.refused_listed[su] && !retry {
            return false;
        }
        let [t, u] = self.children[su];
        // Face `f` once `s` is collapsed: in view and not certain?
        let spoilt = |f: u32| {
            let corners = self.corners[f as usize];
            if !self.present[f as usize] || corners.contains(&t) && corners.contains(&u) {
                return false;
            }
            if !corners.contains(&t) && !corners.contains(&u) {
                return false;
            }
            let moved = corners.map(|v| if v == t || v == u { s } else { v });
            self.in_view(view, moved) && !self.orientation_certain(moved, f)
        };
        let held = self.held_by[su];
        let culprit = if held != NONE && spoilt(held) {
            Some(held)
        } else {
            [t, u].iter().find_map(|&c| {
                self.faces_at[c as usize]
                    .iter()
                    .copied()
                    .find(|&f| spoilt(f))
            })
        };
        match culprit {
            Some(f) => {
                self.held_by[su] = f;
                if !self.refused_listed[su] {
                    self.refused_listed[su] = true;
                    self.refused.push(s);
                }
                false
            }
            None => true,
        }
    }

    /// Makes every listed face certain of its orientation (the module docs): splits its
    /// coarsest corner that can be split, with that split's dependencies, and the children
    /// those splits activate on down as far as the view wants; a face that must wait for a
    /// meta-node, or for the next call's budget, stays listed.
    fn guard(&mut self, view: &View, budget: Budget, done: &mut Adapted, below: &mut Vec<u32>) {
        if !view.keeps_orientation() {
            // The faces stay listed, for a view that keeps orientation.
            return;
        }
        let mut held = Vec::new();
        let mut unsure = 0;
        let mut activated = Vec::new();
        let waiting_before = done.waiting;
        // The view's splits that wait, of the children the guard's splits activate.
        self.waited_now.clear();
        while let Some(f) = self.suspects.pop() {
            let fu = f as usize;
            let corners = self.corners[fu];
            let certain = match self.suspected[fu] {
                _ if !self.present[fu] => true,
                Suspicion::Moved => self.orientation_certain(corners, f),
                _ => false,
            };
            if certain {
                self.suspected[fu] = Suspicion::None;
                continue;
            }
            self.suspected[fu] = Suspicion::Uncertain;
            if !self.in_view(view, corners) {
                held.push(f);
                continue;
            }
            if done.splits + done.collapses >= budget.operations
                || self.faces >= budget.faces.unwrap_or(usize::MAX)
            {
                held.push(f);
                unsure += 1;
                continue;
            }
            let mut corners = corners;
            corners.sort_by(|&a, &b| {
                let radius = |v: u32| self.spheres[v as usize].1;
                radius(b).total_cmp(&radius(a))
            });
            let mut outcome = Ready::Never;
            let mut no_room = false;
            for x in corners {
                if self.is_leaf(x) {
                    continue;
                }
                activated.clear();
                self.held_by[x as usize] = f;
                // Within a face budget: a split that would take the front past it waits.
                let room = budget
                    .faces
                    .map_or(usize::MAX, |f| f.saturating_sub(self.faces));
                let (splits, stop) = self.force_split(x, &mut activated, room);
                if splits == 0 && stop == Ready::Now {
                    no_room = true;
                    break;
                }
                done.splits += splits;
                // The view did not ask for these splits: their collapses are tried again
                // after the guard and whenever a face they would move moves (the plan's own
                // later splits may already have made them certain).
                for i in 0..splits {
                    let v = self.plan[i];
                    if !self.refused_listed[v as usize] {
                        self.refused_listed[v as usize] = true;
                        self.refused.push(v);
                    }
                    if !self.in_retry[v as usize] {
                        self.in_retry[v as usize] = true;
                        self.retry.push(v);
                    }
                }
                for &c in &activated {
                    if self.state[c as usize] == State::Active && self.wants(view, c) {
                        self.refine_down(c, view, budget, done, below);
                    }
                }
                outcome = stop;
                if stop != Ready::Never {
                    break;
                }
            }
            if no_room {
                held.push(f);
                unsure += 1;
                continue;
            }
            match outcome {
                // Its corner moved: it is checked again.
                Ready::Now => self.suspects.push(f),
                Ready::Waiting => {
                    done.waiting += 1;
                    held.push(f);
                    unsure += 1;
                }
                Ready::Never => {
                    done.blocked += 1;
                    held.push(f);
                    unsure += 1;
                }
            }
        }
        self.suspects = held;
        done.unsure = unsure;
        if done.waiting > waiting_before {
            // The next call with the same view revisits the view's splits that wait (as after
            // the passes) and then these faces.
            let waited = std::mem::take(&mut self.waited_now);
            self.waiting_nodes.extend_from_slice(&waited);
            self.waited_now = waited;
            if !done.capped && self.cursor == 0 {
                self.waited_for = Some(view.clone());
            }
            done.settled = false;
        }
        if done.splits + done.collapses >= budget.operations && !self.suspects.is_empty() {
            done.settled = false;
        }
    }

    /// Whether ecol of split node `s` is legal: both children active, no split dependant.
    fn can_collapse(&self, s: u32) -> bool {
        let su = s as usize;
        self.state[su] == State::Split
            && self.split_dependants[su] == 0
            && self.children[su]
                .iter()
                .all(|&c| self.state[c as usize] == State::Active)
    }

    /// ecol of `s` ([`Self::can_collapse`]).
    fn collapse(&mut self, s: u32) {
        let su = s as usize;
        for i in 0..self.born[su].len() {
            let f = self.born[su][i];
            self.retry_around(f);
            for c in self.corners[f as usize] {
                let list = &mut self.faces_at[c as usize];
                if let Some(at) = list.iter().position(|&g| g == f) {
                    list.swap_remove(at);
                }
            }
            self.corners[f as usize] = [NONE; 3];
            self.present[f as usize] = false;
        }
        self.faces -= self.born[su].len();
        for c in self.children[su] {
            for f in std::mem::take(&mut self.faces_at[c as usize]) {
                for corner in &mut self.corners[f as usize] {
                    if *corner == c {
                        *corner = s;
                    }
                }
                self.faces_at[su].push(f);
                self.suspect(f);
            }
            self.deactivate(c, State::Below);
        }
        self.activate(s);
        for &d in &self.depends_on[su] {
            let count = &mut self.split_dependants[d.node as usize];
            *count -= 1;
            if *count == 0 {
                self.freed.push(d.node);
            }
        }
    }

    /// The node's state once the splits planned so far are made.
    fn planned_state(&self, v: u32) -> State {
        let vu = v as usize;
        match self.state[vu] {
            _ if self.planned[vu] => State::Split,
            State::Below if self.planned[self.parent[vu] as usize] => State::Active,
            state => state,
        }
    }

    /// Splits active node `s`, and first whatever its dependencies need (Hoppe's forced
    /// split), all or nothing: the splits are planned first, and made only if every one can be
    /// (none waits for a meta-node) — so that a chain cut short is not left half made for the
    /// next pass to collapse and the one after to make again; and only if they add at most
    /// `room` faces (else none is made, and (0, `Ready::Now`) returned). Returns the splits made and
    /// whether it stopped short, and appends the children it activated to `activated`.
    fn force_split(&mut self, s: u32, activated: &mut Vec<u32>, room: usize) -> (usize, Ready) {
        let mut plan = std::mem::take(&mut self.plan);
        plan.clear();
        let mut stack = std::mem::take(&mut self.stack);
        stack.clear();
        stack.push(s);
        let outcome = loop {
            let Some(&v) = stack.last() else {
                break Ready::Now;
            };
            if stack.len() > self.ids.len() {
                // The dependencies form a cycle: a corrupt stream.
                break Ready::Never;
            }
            match self.planned_state(v) {
                State::Split => {
                    stack.pop();
                }
                State::Below => stack.push(self.parent[v as usize]),
                State::Active => match self.ready(v) {
                    Ready::Now => match self.unmet_dependency(v) {
                        Some(d) => stack.push(d),
                        None => {
                            self.planned[v as usize] = true;
                            plan.push(v);
                            stack.pop();
                        }
                    },
                    stop => break stop,
                },
            }
        };
        for &v in &plan {
            self.planned[v as usize] = false;
        }
        let mut made = 0;
        let mut outcome = outcome;
        let added: usize = plan.iter().map(|&v| self.born[v as usize].len()).sum();
        if outcome == Ready::Now && added <= room {
            for &v in &plan {
                if !self.split(v) {
                    outcome = Ready::Never;
                    break;
                }
                activated.extend(self.children[v as usize]);
                made += 1;
            }
        }
        self.plan = plan;
        self.stack = stack;
        (made, outcome)
    }

    /// Adapts the front to `view` with the meta-nodes at hand: takes in those that have
    /// arrived, then passes over the active nodes, refining each the view wants refined down
    /// its subtree (dependencies first) and collapsing the parents of the others up the tree
    /// while the view does not want them, until a pass changes nothing or the budget is spent.
    /// Splits that need a meta-node not loaded ask for it and wait.
    pub fn adapt(&mut self, view: &View, budget: Budget) -> Adapted {
        let mut done = Adapted {
            loaded: self.take_arrivals(false),
            ..Adapted::default()
        };
        let mut pass = std::mem::take(&mut self.pass);
        let new_view = self.adapt_passes(view, budget, &mut done, &mut pass);
        self.settle_orientation(view, budget, &mut done, &mut pass, new_view);
        self.pass = pass;
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

    fn wants(&self, view: &View, v: u32) -> bool {
        let (center, radius) = self.spheres[v as usize];
        let deviation = self.deviations[v as usize];
        view.wants_split(
            center,
            radius,
            deviation,
            &self.cones[v as usize],
            self.scale,
        )
    }

    /// Returns whether it passed over the front (rather than revisiting the splits that
    /// waited).
    fn adapt_passes(
        &mut self,
        view: &View,
        budget: Budget,
        done: &mut Adapted,
        pass: &mut Vec<u32>,
    ) -> bool {
        let mut below: Vec<u32> = Vec::new();
        // The same view again, its last pass having changed nothing, with splits waiting for
        // meta-nodes: only those splits can go further (the rest of the front is where that
        // pass left it), so only their nodes are visited.
        let revisit = self.waited_for.as_ref() == Some(view)
            && budget == Budget::UNLIMITED
            && self.cursor == 0;
        self.waited_for = None;
        if revisit {
            done.passes += 1;
            self.waited_now.clear();
            let waiting = std::mem::take(&mut self.waiting_nodes);
            for &v in &waiting {
                if self.state[v as usize] == State::Active && self.wants(view, v) {
                    self.refine_down(v, view, budget, done, &mut below);
                }
            }
            // The splits still waiting are the next list; the old one's buffer is reused.
            self.waiting_nodes = std::mem::replace(&mut self.waited_now, waiting);
            if done.waiting == 0 {
                done.settled = !done.capped;
            } else {
                self.waited_for = Some(view.clone());
            }
            return false;
        }
        loop {
            let before = *done;
            done.passes += 1;
            done.waiting = 0;
            done.blocked = 0;
            self.waited_now.clear();
            // In node order (the loader's, which keeps a meta-node's nodes together) rather
            // than the list's: the nodes' records are then read nearly in memory order. The
            // bits list them so (sorting the list cost more), from the cursor on.
            pass.clear();
            for (k, &word) in self.active_bits.iter().enumerate() {
                let mut word = word;
                while word != 0 {
                    pass.push((64 * k) as u32 + word.trailing_zeros());
                    word &= word - 1;
                }
            }
            let start = pass.partition_point(|&v| v < self.cursor);
            pass.rotate_left(start);
            self.cursor = 0;
            for (i, &v) in pass.iter().enumerate() {
                // The records the visit of a node a few visits on reads first: its sphere and
                // its parent's (the active nodes are sparse among all, too far apart for the
                // processor to foresee).
                if let Some(&ahead) = pass.get(i + 8) {
                    prefetch(self.spheres.as_ptr().wrapping_add(ahead as usize));
                    prefetch(self.parent.as_ptr().wrapping_add(ahead as usize));
                }
                if let Some(&ahead) = pass.get(i + 4) {
                    let p = self.parent[ahead as usize] as usize;
                    prefetch(self.spheres.as_ptr().wrapping_add(p));
                    prefetch(self.children.as_ptr().wrapping_add(p));
                    prefetch(self.split_dependants.as_ptr().wrapping_add(p));
                }
                if done.splits + done.collapses >= budget.operations {
                    self.cursor = v;
                    return true;
                }
                if self.state[v as usize] != State::Active {
                    continue;
                }
                if self.wants(view, v) && self.ready(v) != Ready::Never {
                    self.refine_down(v, view, budget, done, &mut below);
                    continue;
                }
                // Up the tree while the parent may and should go; then the same from each
                // node those collapses freed of its last split dependant (so that a chain of
                // dependencies unwinds in one pass, not one pass a link).
                self.collapse_from(self.parent[v as usize], view, budget, done, false);
            }
            // Without limits, a pass leaves nothing for the next: a refined node goes down its
            // subtree at once, a collapse goes on up the tree and on from every node it frees of
            // its last split dependant, and forced splits are made only whole (their nodes'
            // dependants keep them); the collapses refused for a face's orientation are tried
            // again after the pass (`settle_orientation`). So the pass that would confirm it is
            // skipped.
            let complete = budget == Budget::UNLIMITED && !done.capped;
            if complete || (done.splits, done.collapses) == (before.splits, before.collapses) {
                done.settled = !done.capped && done.waiting == 0;
                std::mem::swap(&mut self.waiting_nodes, &mut self.waited_now);
                if done.waiting > 0 && !done.capped {
                    self.waited_for = Some(view.clone());
                }
                return true;
            }
        }
    }

    /// Collapses split node `p` and on up the tree while the parent may and should go; then
    /// the same from each node those collapses freed of its last split dependant (so that a
    /// chain of dependencies unwinds in one pass, not one pass a link). `retry`: try again
    /// the collapses refused for a face's orientation in this adaptation.
    fn collapse_from(
        &mut self,
        mut p: u32,
        view: &View,
        budget: Budget,
        done: &mut Adapted,
        retry: bool,
    ) {
        loop {
            while p != NONE
                && done.splits + done.collapses < budget.operations
                && self.can_collapse(p)
                && !self.wants(view, p)
                && self.collapse_keeps_orientation(p, view, budget, retry)
            {
                self.collapse(p);
                done.collapses += 1;
                p = self.parent[p as usize];
            }
            match self.freed.pop() {
                Some(d) if done.splits + done.collapses < budget.operations => p = d,
                _ => break,
            }
        }
    }

    /// After the passes: the collapses a face's orientation may have refused tried again, and
    /// the guard ([`Self::guard`]), until neither does anything. Tried again: those near a face
    /// that moved, appeared or went since they were last tried (`retry`: the parents of its
    /// corners), and every refused one after a meta-node arrives (the certificates read the
    /// deepest loaded nodes) or after whole passes (a view that may be new).
    fn settle_orientation(
        &mut self,
        view: &View,
        budget: Budget,
        done: &mut Adapted,
        below: &mut Vec<u32>,
        new_view: bool,
    ) {
        let mut nodes = std::mem::take(&mut self.retry);
        if new_view {
            nodes.append(&mut self.refused);
        }
        if !view.keeps_orientation() {
            // Nothing was refused for orientation: the faces' moves need no retrying.
            for &p in &nodes {
                self.in_retry[p as usize] = false;
                self.refused_listed[p as usize] = false;
            }
            nodes.clear();
            self.retry = nodes;
            return;
        }
        loop {
            let before = (done.splits, done.collapses);
            for &p in &nodes {
                self.refused_listed[p as usize] = false;
                self.in_retry[p as usize] = false;
            }
            for &p in &nodes {
                if done.splits + done.collapses >= budget.operations {
                    // Kept for the next call.
                    if !self.in_retry[p as usize] {
                        self.in_retry[p as usize] = true;
                        self.retry.push(p);
                    }
                    continue;
                }
                self.collapse_from(p, view, budget, done, true);
            }
            self.guard(view, budget, done, below);
            nodes.clear();
            std::mem::swap(&mut nodes, &mut self.retry);
            let spent = done.splits + done.collapses >= budget.operations;
            if spent || (done.splits, done.collapses) == before && nodes.is_empty() {
                break;
            }
        }
        // Empty, or (the budget having run out) those left for the next call.
        self.retry = nodes;
        if done.splits + done.collapses >= budget.operations {
            // The budget ran out here, after the passes: a collapse chain may have stopped
            // short, so the next call makes whole passes rather than revisiting what waited.
            self.waited_for = None;
        }
    }

    /// Refines active node `v` down its subtree as far as the view wants (rather than a level
    /// a pass), dependencies first; a split waiting for a meta-node is noted.
    fn refine_down(
        &mut self,
        v: u32,
        view: &View,
        budget: Budget,
        done: &mut Adapted,
        below: &mut Vec<u32>,
    ) {
        let limit = budget.faces.unwrap_or(usize::MAX);
        below.clear();
        below.push(v);
        while let Some(x) = below.pop() {
            if self.state[x as usize] != State::Active
                || done.splits + done.collapses >= budget.operations
                || !self.wants(view, x)
            {
                continue;
            }
            match self.ready(x) {
                Ready::Now => {}
                Ready::Waiting => {
                    done.waiting += 1;
                    self.waited_now.push(x);
                    continue;
                }
                Ready::Never => continue,
            }
            if self.faces >= limit {
                done.capped = true;
                continue;
            }
            let (splits, stop) = self.force_split(x, below, usize::MAX);
            done.splits += splits;
            match stop {
                Ready::Now => {}
                Ready::Waiting => {
                    done.waiting += 1;
                    self.waited_now.push(x);
                }
                Ready::Never => done.blocked += 1,
            }
        }
    }

    /// Scales κ towards holding `faces`: up while there are more or the budget held splits
    /// back (`capped`), back down (not below 1) while there are clearly fewer.
    fn regulate(&mut self, faces: Option<usize>, capped: bool) {
        let Some(target) = faces else {
            self.scale = 1.0;
            return;
        };
        if self.faces > target || capped {
            self.scale *= 1.25;
        } else if (self.faces as f64) < 0.8 * target as f64 {
            self.scale = (self.scale / 1.25).max(1.0);
        }
    }

    /// Where the vertex with leaf path `leaf` stands in the adapted mesh: the position of the
    /// active node on its path (`None` if the path leaves the hierarchy above the front).
    pub fn position_of(&self, leaf: NodeId) -> Option<DVec3> {
        self.active_on(leaf).map(|v| self.spheres[v as usize].0)
    }

    /// The present triangles: each one's corners' leaf paths (which name the full mesh's
    /// triangle it stands for) and its corners' positions in the adapted mesh.
    pub fn present_triangles(&self) -> impl Iterator<Item = ([NodeId; 3], [DVec3; 3])> + '_ {
        (0..self.present.len())
            .filter(|&t| self.present[t])
            .map(|t| {
                let at = self.corners[t].map(|v| self.spheres[v as usize].0);
                (self.leaf_corners[t], at)
            })
    }

    /// The adapted mesh: the active nodes' positions, the present triangles.
    pub fn mesh(&self) -> TriMesh {
        let mut index = vec![NONE; self.ids.len()];
        let mut positions = Vec::with_capacity(self.active.len());
        for &v in &self.active {
            index[v as usize] = positions.len() as u32;
            positions.push(self.spheres[v as usize].0);
        }
        let faces = self
            .present
            .iter()
            .zip(&self.corners)
            .filter(|(&p, _)| p)
            .map(|(_, c)| c.map(|v| index[v as usize]))
            .collect();
        TriMesh { positions, faces }
    }

    /// The nearest present triangle the ray from `origin` along `direction` hits.
    pub fn pick(&self, origin: DVec3, direction: DVec3) -> Option<Pick> {
        let mut best: Option<Pick> = None;
        for (t, &present) in self.present.iter().enumerate() {
            if !present {
                continue;
            }
            let [a, b, c] = self.corners[t].map(|v| self.spheres[v as usize].0);
            if let Some(d) = ray_triangle(origin, direction, a, b, c) {
                if best.is_none_or(|p| d < p.distance) {
                    best = Some(Pick {
                        triangle: t as u32,
                        distance: d,
                        point: origin + direction * d,
                    });
                }
            }
        }
        best
    }

    /// Checks every invariant of the module docs; the first broken one, described.
    pub fn check_invariants(&self) -> std::result::Result<(), String> {
        let n = self.ids.len();
        if self.state[0] == State::Below {
            return Err("the root is below the front".into());
        }
        for v in 0..n {
            let st = self.state[v];
            let inner = self.children[v][0] != NONE;
            for c in self.children[v].into_iter().filter(|&c| c != NONE) {
                let cs = self.state[c as usize];
                let fine = match st {
                    State::Split => cs != State::Below,
                    _ => cs == State::Below,
                };
                if !fine {
                    return Err(format!("node {v} is {st:?}, its child {c} {cs:?}"));
                }
            }
            if st == State::Split && !inner {
                return Err(format!("leaf {v} is split"));
            }
            let bit = self.active_bits[v / 64] >> (v % 64) & 1 == 1;
            if (st == State::Active) != (self.active_slot[v] != NONE)
                || (st == State::Active) != bit
            {
                return Err(format!("node {v} is {st:?} but listed otherwise"));
            }
            if st == State::Split {
                if let Some(d) = self.depends_on[v]
                    .iter()
                    .find(|d| d.node == NONE || self.state[d.node as usize] != State::Split)
                {
                    return Err(format!(
                        "split node {v} depends on {:?}, which is not split",
                        d.id
                    ));
                }
            }
        }
        let mut dependants = vec![0u32; n];
        for v in (0..n).filter(|&v| self.state[v] == State::Split) {
            for d in &self.depends_on[v] {
                dependants[d.node as usize] += 1;
            }
        }
        if dependants != self.split_dependants {
            return Err("the counts of split dependants are off".into());
        }
        let mut listed = vec![0usize; n];
        let mut faces = 0;
        for v in 0..n {
            for &t in &self.born[v] {
                let tu = t as usize;
                if self.present[tu] != (self.state[v] == State::Split) {
                    return Err(format!(
                        "triangle {t} present {} at a {:?} birth node",
                        self.present[tu], self.state[v]
                    ));
                }
                if !self.present[tu] {
                    continue;
                }
                faces += 1;
                let c = self.corners[tu];
                for (k, (&corner, &leaf)) in c.iter().zip(&self.leaf_corners[tu]).enumerate() {
                    let cu = corner as usize;
                    if self.state[cu] != State::Active || !self.ids[cu].is_ancestor_of(leaf) {
                        return Err(format!(
                            "triangle {t}'s corner {k} is not its leaf's active node"
                        ));
                    }
                    listed[cu] += 1;
                }
                if c[0] == c[1] || c[1] == c[2] || c[0] == c[2] {
                    return Err(format!("triangle {t} has a repeated corner"));
                }
            }
        }
        if faces != self.faces {
            return Err(format!("{faces} triangles present, {} counted", self.faces));
        }
        if let Some(t) = (0..self.present.len()).find(|&t| {
            self.present[t]
                && self.suspected[t] == Suspicion::None
                && !self.orientation_certain(self.corners[t], t as u32)
        }) {
            return Err(format!(
                "triangle {t} is not certain of its orientation and not listed"
            ));
        }
        let marked = self
            .suspected
            .iter()
            .filter(|&&m| m != Suspicion::None)
            .count();
        if marked != self.suspects.len()
            || self
                .suspects
                .iter()
                .any(|&t| self.suspected[t as usize] == Suspicion::None)
        {
            return Err("the listed triangles and their marks disagree".into());
        }
        for &v in &self.active {
            let list = &self.faces_at[v as usize];
            if list.len() != listed[v as usize]
                || list.iter().any(|&t| !self.corners[t as usize].contains(&v))
            {
                return Err(format!("node {v}'s triangle list is off"));
            }
        }
        Ok(())
    }
}

/// Möller–Trumbore: the distance along the ray to triangle (a, b, c), either side facing.
fn ray_triangle(origin: DVec3, direction: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<f64> {
    let (e1, e2) = (b - a, c - a);
    let p = direction.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-300 {
        return None;
    }
    let s = origin - a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = direction.dot(q) / det;
    let t = e2.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t >= 0.0).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::super::loader::head_length;
    use super::super::view::Camera;
    use super::*;
    use crate::codecs::{self, EncodeOptions, Stop};
    use crate::container::read_header_and_index;
    use crate::mesh::generate;
    use crate::mesh::quantize::GridShape;
    use proptest::prelude::*;
    use std::collections::HashMap;
    use std::sync::OnceLock;

    /// A came stream of two spheres, a torus and a loose triangle sharing a vertex.
    pub(super) fn stream() -> &'static [u8] {
        static STREAM: OnceLock<Vec<u8>> = OnceLock::new();
        STREAM.get_or_init(|| {
            let mut mesh = generate::icosphere(3);
            mesh.append(&generate::icosphere(2), DVec3::new(2.5, 0.0, 0.0), 0.6);
            mesh.append(
                &generate::torus(1.0, 0.3, 24, 10),
                DVec3::new(0.0, 2.5, 0.0),
                1.0,
            );
            let base = mesh.positions.len() as u32;
            mesh.positions
                .extend([DVec3::new(0.0, 0.0, 1.5), DVec3::new(0.3, 0.0, 1.6)]);
            mesh.faces.push([0, base, base + 1]);
            let options = EncodeOptions {
                quant_bits: 12,
                grid: GridShape::Cubic,
            };
            let canonical = codecs::canonical_for(&mesh, &options).unwrap();
            codecs::by_name("came")
                .unwrap()
                .encode(&canonical)
                .unwrap()
                .bytes
        })
    }

    /// A mesh's triangles as sorted position triples, rotated to start at their least corner.
    fn triangles(mesh: &TriMesh) -> Vec<[[i64; 3]; 3]> {
        let key = |p: DVec3| (p * 1e6).round().to_array().map(|x| x as i64);
        let mut all: Vec<[[i64; 3]; 3]> = mesh
            .faces
            .iter()
            .map(|f| {
                let mut t = f.map(|v| key(mesh.positions[v as usize]));
                let least = (0..3).min_by_key(|&k| t[k]).unwrap();
                t.rotate_left(least);
                t
            })
            .collect();
        all.sort();
        all
    }

    #[test]
    fn refining_everything_gives_the_full_decode_and_coarsening_everything_the_root() {
        let mut vm = ViewMesh::from_stream(stream()).unwrap();
        vm.check_invariants().unwrap();
        assert_eq!(
            vm.fetched().units_loaded,
            1,
            "only the root meta-node at first"
        );
        let done = vm.settle(&View::everything(), Budget::UNLIMITED, 64);
        assert!(done.settled && done.collapses == 0);
        let fetched = vm.fetched();
        assert_eq!(fetched.units_loaded, fetched.units);
        assert_eq!(fetched.bytes_read, stream().len() as u64);
        vm.check_invariants().unwrap();
        let (full, _) = codecs::decode(stream(), Stop::All).unwrap();
        let adapted = vm.mesh();
        assert_eq!(adapted.vertex_count(), full.mesh.vertex_count());
        assert_eq!(triangles(&adapted), triangles(&full.mesh));
        let done = vm.adapt(&View::nothing(), Budget::UNLIMITED);
        assert_eq!(
            (done.splits, done.collapses),
            (0, full.mesh.vertex_count() - 1)
        );
        vm.check_invariants().unwrap();
        assert_eq!((vm.vertex_count(), vm.face_count()), (1, 0));
    }

    /// A client fetching meta-nodes itself (a browser's `Range` requests) from the header, the
    /// index and the first unit reaches the front that inline fetching reaches, asking for each
    /// unit once and reading only what it asks for.
    #[test]
    fn fetching_units_externally_reaches_the_inline_front() {
        let bytes = stream();
        assert_eq!(head_length(&bytes[..8]).unwrap(), None);
        let head = head_length(bytes).unwrap().unwrap() as usize;
        assert!(head < bytes.len());
        let view = View::new(&camera(DVec3::new(0.5, 0.8, 3.0)), 1.0).unwrap();
        let mut inline = ViewMesh::from_stream(bytes).unwrap();
        inline.settle(&view, Budget::UNLIMITED, 64);
        let mut external = ViewMesh::open(bytes[..head].to_vec(), Fetch::External).unwrap();
        assert!(
            external.supply(0, &bytes[..1]).is_err(),
            "the first unit is in"
        );
        assert!(external.supply(1 << 20, &[]).is_err(), "no such unit");
        let mut fetched = head as u64;
        let mut asked = std::collections::HashSet::new();
        let mut settled = false;
        for _ in 0..64 {
            let done = external.adapt(&view, Budget::UNLIMITED);
            external.check_invariants().unwrap();
            let wanted = external.wanted();
            if done.settled {
                assert!(wanted.is_empty());
                settled = true;
                break;
            }
            for (unit, range) in wanted {
                assert!(asked.insert(unit), "unit {unit} asked for twice");
                fetched += range.end - range.start;
                let unit_bytes = &bytes[range.start as usize..range.end as usize];
                external.supply(unit, unit_bytes).unwrap();
                assert!(external.supply(unit, unit_bytes).is_err(), "supplied twice");
            }
        }
        assert!(settled && !asked.is_empty());
        assert_eq!(external.fetched().bytes_read, fetched);
        assert_eq!(external.fetched().units_loaded, asked.len() + 1);
        assert_eq!(triangles(&external.mesh()), triangles(&inline.mesh()));
    }

    /// Bytes that are not a unit's (cut short) leave its branch coarse, refused, not a panic.
    #[test]
    fn a_cut_unit_supplied_is_refused() {
        let bytes = stream();
        let head = head_length(bytes).unwrap().unwrap() as usize;
        let mut external = ViewMesh::open(bytes[..head].to_vec(), Fetch::External).unwrap();
        external.adapt(&View::everything(), Budget::UNLIMITED);
        let wanted = external.wanted();
        let (unit, range) = wanted.first().cloned().expect("the full view wants units");
        let cut = &bytes[range.start as usize..range.end as usize - 1];
        external.supply(unit, cut).unwrap();
        external.adapt(&View::everything(), Budget::UNLIMITED);
        external.check_invariants().unwrap();
        assert_eq!(external.refusals().len(), 1);
        assert!(external.refusals()[0].1.contains("supplied"));
    }

    pub(super) fn camera(eye: DVec3) -> Camera {
        Camera {
            eye,
            target: DVec3::new(0.5, 0.8, 0.0),
            up: if eye.cross(DVec3::Y).length() < 1e-6 {
                DVec3::X
            } else {
                DVec3::Y
            },
            fov_degrees: 50.0,
            width: 320,
            height: 240,
        }
    }

    #[test]
    fn a_near_view_refines_what_it_sees_and_not_what_is_behind() {
        let mut vm = ViewMesh::from_stream(stream()).unwrap();
        let view = View::new(&camera(DVec3::new(0.5, 0.8, 6.0)), 1.0).unwrap();
        vm.settle(&view, Budget::UNLIMITED, 64);
        vm.check_invariants().unwrap();
        let near = vm.face_count();
        let far = View::new(&camera(DVec3::new(0.5, 0.8, 60.0)), 1.0).unwrap();
        let done = vm.settle(&far, Budget::UNLIMITED, 64);
        vm.check_invariants().unwrap();
        assert!(
            done.collapses > 0 && vm.face_count() < near,
            "{} vs {near}",
            vm.face_count()
        );
    }

    #[test]
    fn back_faces_stay_coarse_unless_the_view_is_two_sided() {
        let view = View::new(&camera(DVec3::new(0.5, 0.8, 4.0)), 0.5).unwrap();
        let mut one = ViewMesh::from_stream(stream()).unwrap();
        one.settle(&view, Budget::UNLIMITED, 64);
        one.check_invariants().unwrap();
        let mut two = ViewMesh::from_stream(stream()).unwrap();
        two.settle(&view.clone().two_sided(true), Budget::UNLIMITED, 64);
        two.check_invariants().unwrap();
        assert!(
            (one.face_count() as f64) < 0.9 * two.face_count() as f64,
            "{} faces one-sided, {} two-sided",
            one.face_count(),
            two.face_count()
        );
        // Nodes the two-sided front splits stay on the one-sided front because they face away.
        let faces_away = |v: u32| {
            let (c, r) = one.spheres[v as usize];
            view.faces_away(c, r, &one.cones[v as usize])
        };
        let split_in_two: std::collections::HashSet<NodeId> = (0..two.ids.len())
            .filter(|&v| two.state[v] == State::Split)
            .map(|v| two.ids[v])
            .collect();
        let culled = one
            .active
            .iter()
            .filter(|&&v| split_in_two.contains(&one.ids[v as usize]) && faces_away(v))
            .count();
        assert!(culled > 0);
    }

    #[test]
    fn an_operation_budget_spreads_the_work_over_calls_and_ends_where_one_call_does() {
        let view = View::new(&camera(DVec3::new(1.0, 1.0, 5.0)), 0.5).unwrap();
        let mut whole = ViewMesh::from_stream(stream()).unwrap();
        whole.settle(&view, Budget::UNLIMITED, 64);
        let mut stepped = ViewMesh::from_stream(stream()).unwrap();
        let budget = Budget {
            operations: 50,
            faces: None,
        };
        let mut calls = 0;
        loop {
            let done = stepped.adapt(&view, budget);
            stepped.check_invariants().unwrap();
            assert!(
                done.splits + done.collapses <= 50 + 52,
                "forced splits finish"
            );
            calls += 1;
            if done.settled {
                break;
            }
            assert!(calls < 10_000);
        }
        assert!(calls > 2);
        assert_eq!(triangles(&stepped.mesh()), triangles(&whole.mesh()));
    }

    #[test]
    fn a_face_budget_raises_the_tolerance_until_the_front_holds_it() {
        let view = View::new(&camera(DVec3::new(1.0, 1.0, 4.0)), 0.2).unwrap();
        let mut vm = ViewMesh::from_stream(stream()).unwrap();
        vm.settle(&view, Budget::UNLIMITED, 64);
        let free = vm.face_count();
        let target = free / 4;
        let budget = Budget {
            operations: usize::MAX,
            faces: Some(target),
        };
        for _ in 0..40 {
            vm.adapt(&view, budget);
        }
        vm.check_invariants().unwrap();
        assert!(
            vm.face_count() <= target + target / 10,
            "{} faces for {target}",
            vm.face_count()
        );
        assert!(
            vm.face_count() >= target / 2,
            "{} faces for {target}",
            vm.face_count()
        );
        assert!(vm.tolerance_scale() > 1.0);
    }

    #[test]
    fn picking_hits_the_front_where_the_ray_meets_it() {
        let mut vm = ViewMesh::from_stream(stream()).unwrap();
        vm.settle(&View::everything(), Budget::UNLIMITED, 64);
        // The unit sphere at the origin (icosphere of radius 1): a ray up the z axis, from the
        // side away from the loose triangle.
        let hit = vm.pick(DVec3::new(0.01, 0.02, -5.0), DVec3::Z).unwrap();
        assert!((hit.distance - 4.0).abs() < 0.05, "{hit:?}");
        assert!(vm.pick(DVec3::new(9.0, 9.0, 9.0), DVec3::Z).is_none());
    }

    #[test]
    fn a_view_of_one_part_fetches_only_the_meta_nodes_it_needs() {
        let mut vm = ViewMesh::from_stream(stream()).unwrap();
        // The torus, close; the spheres below it out of the frustum.
        let torus = Camera {
            eye: DVec3::new(0.0, 2.5, 3.0),
            target: DVec3::new(0.0, 2.5, 0.0),
            fov_degrees: 30.0,
            ..camera(DVec3::Z)
        };
        let view = View::new(&torus, 1.0).unwrap();
        let done = vm.settle(&view, Budget::UNLIMITED, 64);
        vm.check_invariants().unwrap();
        let fetched = vm.fetched();
        assert!(done.settled && done.loaded > 0, "{done:?}");
        assert!(fetched.units_loaded < fetched.units, "{fetched:?}");
        assert!(fetched.bytes_read < fetched.stream_bytes, "{fetched:?}");
    }

    #[test]
    fn a_loader_thread_over_a_reader_gives_what_inline_loading_gives() {
        let view = View::new(&camera(DVec3::new(1.0, 1.0, 5.0)), 0.5).unwrap();
        let mut inline = ViewMesh::from_stream(stream()).unwrap();
        inline.settle(&view, Budget::UNLIMITED, 64);
        let reader = SeekSource(std::io::Cursor::new(stream().to_vec()));
        let mut background = ViewMesh::open(reader, Fetch::Background).unwrap();
        let done = background.settle(&view, Budget::UNLIMITED, 64);
        assert!(done.settled, "{done:?}");
        background.check_invariants().unwrap();
        assert_eq!(triangles(&background.mesh()), triangles(&inline.mesh()));
        assert_eq!(background.fetched(), inline.fetched());
    }

    /// The stream with the unit laid out last in its payload given `length` bytes in the
    /// index (the payload itself unchanged), and that unit.
    fn with_last_unit_claiming(length: u64) -> (Vec<u8>, usize) {
        let (header, mut index, start) = read_header_and_index(stream()).unwrap();
        let last = (0..index.len())
            .max_by_key(|&i| index.units[i].offset)
            .unwrap();
        index.units[last].length = length;
        index.payload_bytes = index.units.iter().map(|u| u.length).sum();
        let mut bytes = Vec::new();
        header.write(&mut bytes);
        index.write(&mut bytes);
        bytes.extend_from_slice(&stream()[start..]);
        (bytes, last)
    }

    /// Everything refined over `bytes`: the front must hold every invariant, and the meta-nodes
    /// refused are returned.
    fn refine_everything(bytes: &[u8]) -> (ViewMesh, Vec<usize>) {
        let mut vm = ViewMesh::from_stream(bytes).unwrap();
        let done = vm.settle(&View::everything(), Budget::UNLIMITED, 64);
        assert!(done.settled, "{done:?}");
        vm.check_invariants().unwrap();
        let refused = vm.refusals().iter().map(|(u, _)| *u).collect();
        (vm, refused)
    }

    #[test]
    fn a_lying_index_is_refused_unread_for_that_branch_alone() {
        let (full, _) = refine_everything(stream());
        let (bytes, last) = with_last_unit_claiming(1 << 40);
        let (vm, refused) = refine_everything(&bytes);
        assert_eq!(refused, vec![last]);
        assert!(
            vm.refusals()[0].1.contains("past the stream's end"),
            "{:?}",
            vm.refusals()
        );
        let fetched = vm.fetched();
        assert!(fetched.bytes_read < bytes.len() as u64, "{fetched:?}");
        assert!(vm.face_count() < full.face_count() && vm.face_count() > full.face_count() / 2);
    }

    #[test]
    fn a_cut_or_corrupt_meta_node_is_refused_and_the_rest_refines() {
        let (full, _) = refine_everything(stream());
        let reader = crate::container::StreamReader::open(stream()).unwrap();
        let last = (0..reader.index().len())
            .max_by_key(|&i| reader.index().units[i].offset)
            .unwrap();
        let unit = reader.unit(last).unwrap();
        // Cut inside the last unit laid out.
        let cut = &stream()[..unit.start + unit.bytes.len() / 2];
        let (vm, refused) = refine_everything(cut);
        assert_eq!(refused, vec![last]);
        assert!(vm.face_count() < full.face_count());
        // Its bytes garbled instead.
        let mut garbled = stream().to_vec();
        for b in &mut garbled[unit.start..unit.start + unit.bytes.len()] {
            *b = !*b;
        }
        let (vm, refused) = refine_everything(&garbled);
        assert_eq!(refused, vec![last], "{:?}", vm.refusals());
        assert!(vm.face_count() < full.face_count());
    }

    /// The full mesh's triangles mapped through the front (each leaf corner to the active node
    /// on its path), those left with three distinct corners, as sorted corner triples in face
    /// order — computed from the whole stream's decode, independently of the front's lists.
    fn projection(
        vm: &ViewMesh,
        full: &crate::codecs::came::decoded::DecodedTree,
    ) -> Vec<[u32; 3]> {
        let mut out: Vec<[u32; 3]> = full
            .triangles
            .iter()
            .map(|t| t.corners.map(|c| vm.active_on(c).unwrap()))
            .filter(|c| c[0] != c[1] && c[1] != c[2] && c[0] != c[2])
            .map(|mut c| {
                let least = (0..3).min_by_key(|&k| c[k]).unwrap();
                c.rotate_left(least);
                c
            })
            .collect();
        out.sort_unstable();
        out
    }

    /// The present triangles' corners, as [`projection`] gives them.
    fn present_corners(vm: &ViewMesh) -> Vec<[u32; 3]> {
        let mut out: Vec<[u32; 3]> = (0..vm.present.len())
            .filter(|&t| vm.present[t])
            .map(|t| {
                let mut c = vm.corners[t];
                let least = (0..3).min_by_key(|&k| c[k]).unwrap();
                c.rotate_left(least);
                c
            })
            .collect();
        out.sort_unstable();
        out
    }

    #[test]
    fn the_adapted_mesh_is_the_full_mesh_projected_through_the_front_so_it_has_no_crack() {
        let (_, full) = crate::codecs::came::decode_tree(stream()).unwrap();
        let mut vm = ViewMesh::from_stream(stream()).unwrap();
        let eyes = [
            DVec3::new(0.5, 0.8, 6.0),
            DVec3::new(3.0, 0.5, 1.0),
            DVec3::new(0.0, 2.5, 2.0),
            DVec3::new(-4.0, -1.0, -3.0),
        ];
        for (i, eye) in eyes.into_iter().enumerate() {
            let view = View::new(&camera(eye), 0.3 + i as f64).unwrap();
            // Mid-way (meta-nodes still on their way) and settled.
            vm.adapt(&view, Budget::UNLIMITED);
            assert_eq!(present_corners(&vm), projection(&vm, &full));
            vm.settle(&view, Budget::UNLIMITED, 64);
            vm.check_invariants().unwrap();
            assert_eq!(present_corners(&vm), projection(&vm, &full));
        }
    }

    /// Present faces meeting `view`'s frustum whose normal makes 90° or more with their
    /// counterpart's (the full mesh's triangle, on the leaves' positions `full`), and the present faces that are not the full mesh's own.
    fn fold_overs_in_view(
        vm: &ViewMesh,
        full: &HashMap<u64, DVec3>,
        view: &View,
    ) -> (usize, usize) {
        let normal = |p: [DVec3; 3]| (p[1] - p[0]).cross(p[2] - p[0]);
        let (mut folded, mut coarse) = (0, 0);
        for t in (0..vm.present.len()).filter(|&t| vm.present[t]) {
            let at = vm.corners[t].map(|v| vm.spheres[v as usize].0);
            let counterpart = vm.leaf_corners[t].map(|l| full[&l.packed()]);
            if at != counterpart {
                coarse += 1;
            }
            if vm.in_view(view, vm.corners[t]) && normal(at).dot(normal(counterpart)) <= 0.0 {
                folded += 1;
            }
        }
        (folded, coarse)
    }

    /// Every leaf's position (by packed path) in the test stream refined everywhere, found once.
    fn full_positions() -> &'static HashMap<u64, DVec3> {
        static FULL: OnceLock<HashMap<u64, DVec3>> = OnceLock::new();
        FULL.get_or_init(|| {
            let (full, _) = refine_everything(stream());
            full.present_triangles()
                .flat_map(|(leaves, at)| (0..3).map(move |k| (leaves[k].packed(), at[k])))
                .collect()
        })
    }

    #[test]
    fn no_face_in_view_turns_against_the_full_meshs_triangle() {
        let full = full_positions();
        let mut vm = ViewMesh::from_stream(stream()).unwrap();
        let mut coarse = 0;
        for (i, eye) in [
            DVec3::new(0.5, 0.8, 6.0),
            DVec3::new(3.0, 0.5, 1.0),
            DVec3::new(0.0, 2.5, 2.0),
            DVec3::new(-4.0, -1.0, -3.0),
            DVec3::new(0.5, 0.8, 30.0),
        ]
        .into_iter()
        .enumerate()
        {
            for tolerance in [0.5, 4.0, 40.0] {
                let view = View::new(&camera(eye), tolerance + i as f64).unwrap();
                let done = vm.settle(&view, Budget::UNLIMITED, 64);
                assert!(done.settled);
                vm.check_invariants().unwrap();
                let (folded, not_full) = fold_overs_in_view(&vm, full, &view);
                assert_eq!(folded, 0, "eye {eye}, tolerance {tolerance}");
                // Every listed face is out of view once settled.
                assert!(vm
                    .suspects
                    .iter()
                    .all(|&t| !vm.in_view(&view, vm.corners[t as usize])));
                coarse += not_full;
            }
        }
        // The views left coarse faces to check.
        assert!(coarse > 100, "{coarse}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        #[test]
        fn random_view_sequences_keep_every_invariant(
            views in proptest::collection::vec(
                (-8.0f64..8.0, -8.0f64..8.0, -8.0f64..8.0, 0.1f64..8.0, 1usize..400),
                1..8,
            )
        ) {
            let mut vm = ViewMesh::from_stream(stream()).unwrap();
            for (x, y, z, tolerance, operations) in views {
                let eye = DVec3::new(x, y, z);
                if eye.distance(DVec3::new(0.5, 0.8, 0.0)) < 0.5 {
                    continue;
                }
                let view = View::new(&camera(eye), tolerance).unwrap();
                let budget = Budget { operations, faces: None };
                vm.adapt(&view, budget);
                prop_assert_eq!(vm.check_invariants(), Ok(()));
                if operations % 3 == 0 {
                    vm.wait_for_units();
                    prop_assert_eq!(vm.check_invariants(), Ok(()));
                }
                if operations % 5 == 0 {
                    // Settled means settled: another adaptation to the view changes nothing.
                    let done = vm.settle(&view, Budget::UNLIMITED, 64);
                    prop_assert!(done.settled);
                    prop_assert_eq!(fold_overs_in_view(&vm, full_positions(), &view).0, 0);
                    let again = vm.adapt(&view, Budget { operations: usize::MAX - 1, faces: None });
                    prop_assert_eq!((again.splits, again.collapses), (0, 0));
                }
            }
        }
    }
}
