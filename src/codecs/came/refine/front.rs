//! The view-dependent mesh: the front of a decoded CAME hierarchy, split and collapsed to a
//! view, with the triangles it holds.
//!
//! Invariants ([`ViewMesh::check_invariants`], after every step in the tests):
//! - the active nodes form a cut: the root is split or active, a split node's children are
//!   active or split, an active or below node's children are below;
//! - a triangle is present exactly when the node it is born at is split, and its corners are
//!   then the active nodes on its corners' leaf paths (distinct, since two corners part at its
//!   birth node and the third at an ancestor of it);
//! - every split node's dependencies are split, and each node counts the split nodes that
//!   depend on it;
//! - each active node lists exactly the present triangles with a corner at it.
//!
//! Refining everything gives the full decode's triangles on the full decode's vertices.

use super::view::View;
use crate::codecs::came::decoded::{to_world, DecodedTree};
use crate::container::Header;
use crate::error::{Error, Result};
use crate::hierarchy::came::NodeId;
use crate::mesh::TriMesh;
use glam::DVec3;
use smallvec::SmallVec;

const NONE: u32 = u32::MAX;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    /// Under the front.
    Below,
    /// On the front.
    Active,
    /// Above the front.
    Split,
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
    /// Whether the face budget held back a split the view wanted (the tolerance is raised for
    /// the next call).
    pub capped: bool,
    /// Whether the front is settled for this view: a pass found nothing more to do and
    /// nothing was held back.
    pub settled: bool,
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
    // Per node, in the decoded tree's numbering.
    ids: Vec<NodeId>,
    parent: Vec<u32>,
    /// Children, `[NONE; 2]` for leaves.
    children: Vec<[u32; 2]>,
    /// Position and error-sphere radius, in world units.
    center: Vec<DVec3>,
    radius: Vec<f64>,
    state: Vec<State>,
    /// Triangles born at the node's split.
    born: Vec<SmallVec<[u32; 2]>>,
    /// Nodes whose splits the node's split needs.
    depends_on: Vec<SmallVec<[u32; 2]>>,
    /// Split nodes depending on the node.
    split_dependants: Vec<u32>,
    /// Present triangles with a corner at the node (active nodes only).
    faces_at: Vec<SmallVec<[u32; 6]>>,
    /// The active nodes, and each node's place among them.
    active: Vec<u32>,
    active_slot: Vec<u32>,
    // Per triangle.
    leaf_corners: Vec<[NodeId; 3]>,
    corners: Vec<[u32; 3]>,
    present: Vec<bool>,
    faces: usize,
    /// Where an interrupted pass resumes.
    cursor: usize,
    /// κ's scale, regulated to a face budget.
    scale: f64,
    /// The active nodes a pass visits (kept to save allocating one a pass).
    pass: Vec<u32>,
}

impl ViewMesh {
    /// The front at the root of a completely decoded `tree` of the stream with `header`.
    pub fn new(tree: &DecodedTree, header: &Header) -> Result<ViewMesh> {
        let bad = |what: &str| Error::malformed(0, 0, what.to_string());
        let n = tree.nodes.len();
        if n == 0 {
            return Err(bad("the hierarchy has no root"));
        }
        let grid = header.grid;
        let cell = grid.cell.iter().fold(0.0f64, |m, &c| m.max(c.abs()));
        let mut parent = vec![NONE; n];
        let mut children = vec![[NONE; 2]; n];
        for (i, node) in tree.nodes.iter().enumerate() {
            match (node.leaf, node.children) {
                (false, Some(c)) => {
                    children[i] = c;
                    for x in c {
                        parent[x as usize] = i as u32;
                    }
                }
                (true, None) => {}
                _ => return Err(bad("the hierarchy is not completely decoded")),
            }
        }
        let mut born: Vec<SmallVec<[u32; 2]>> = vec![SmallVec::new(); n];
        let mut leaf_corners = Vec::with_capacity(tree.triangles.len());
        for (t, triangle) in tree.triangles.iter().enumerate() {
            let c = triangle.corners;
            // Two corners part at the birth node, the third higher up.
            let birth_len = c[0]
                .common_len(c[1])
                .max(c[1].common_len(c[2]))
                .max(c[0].common_len(c[2]));
            let birth = (0..3)
                .map(|k| c[k].ancestor(birth_len))
                .find(|b| b.len() == triangle.birth_depth)
                .and_then(|b| tree.get(b))
                .ok_or_else(|| bad("a triangle's corners do not part at its split"))?;
            born[birth as usize].push(t as u32);
            leaf_corners.push(c);
        }
        let mut depends_on: Vec<SmallVec<[u32; 2]>> = vec![SmallVec::new(); n];
        for i in 0..tree.dependencies.len() {
            let (s, deps) = tree.dependencies_of(i);
            let s = tree.get(s).ok_or_else(|| bad("a dependency of no node"))?;
            for &d in deps {
                let d = tree
                    .get(d)
                    .filter(|&d| children[d as usize][0] != NONE)
                    .ok_or_else(|| bad("a dependency on no split of the hierarchy"))?;
                depends_on[s as usize].push(d);
            }
        }
        let mut state = vec![State::Below; n];
        state[0] = State::Active;
        let mut active_slot = vec![NONE; n];
        active_slot[0] = 0;
        let triangles = tree.triangles.len();
        Ok(ViewMesh {
            ids: tree.nodes.iter().map(|n| n.id).collect(),
            parent,
            children,
            center: tree
                .nodes
                .iter()
                .map(|n| to_world(&grid, n.position))
                .collect(),
            radius: tree.nodes.iter().map(|n| n.radius * cell).collect(),
            state,
            born,
            depends_on,
            split_dependants: vec![0; n],
            faces_at: vec![SmallVec::new(); n],
            active: vec![0],
            active_slot,
            leaf_corners,
            corners: vec![[NONE; 3]; triangles],
            present: vec![false; triangles],
            faces: 0,
            cursor: 0,
            scale: 1.0,
            pass: Vec::new(),
        })
    }

    /// The front of a whole CAME stream (either codec), at its root.
    pub fn from_stream(bytes: &[u8]) -> Result<ViewMesh> {
        let (header, tree) = crate::codecs::came::decode_tree(bytes)?;
        ViewMesh::new(&tree, &header)
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

    fn is_inner(&self, v: u32) -> bool {
        self.children[v as usize][0] != NONE
    }

    fn activate(&mut self, v: u32) {
        self.state[v as usize] = State::Active;
        self.active_slot[v as usize] = self.active.len() as u32;
        self.active.push(v);
    }

    fn deactivate(&mut self, v: u32, to: State) {
        self.state[v as usize] = to;
        let slot = self.active_slot[v as usize] as usize;
        self.active.swap_remove(slot);
        if let Some(&moved) = self.active.get(slot) {
            self.active_slot[moved as usize] = slot as u32;
        }
        self.active_slot[v as usize] = NONE;
    }

    /// The active node on leaf path `leaf`.
    fn active_on(&self, leaf: NodeId) -> u32 {
        let mut v = 0u32;
        while self.state[v as usize] == State::Split {
            let bit = leaf.bit(self.ids[v as usize].len());
            v = self.children[v as usize][bit as usize];
        }
        v
    }

    /// vsplit of active inner node `s` whose dependencies are split.
    fn split(&mut self, s: u32) {
        let su = s as usize;
        let [t, u] = self.children[su];
        self.deactivate(s, State::Split);
        self.activate(t);
        self.activate(u);
        let depth = self.ids[su].len();
        for f in std::mem::take(&mut self.faces_at[su]) {
            let fu = f as usize;
            for k in 0..3 {
                if self.corners[fu][k] == s {
                    let child = self.children[su][self.leaf_corners[fu][k].bit(depth) as usize];
                    self.corners[fu][k] = child;
                    self.faces_at[child as usize].push(f);
                }
            }
        }
        let own = self.ids[su];
        for i in 0..self.born[su].len() {
            let f = self.born[su][i];
            // The two corners under v_s are at v_t and v_u now; only the third needs a walk.
            let corners = self.leaf_corners[f as usize].map(|c| {
                if own.is_ancestor_of(c) {
                    self.children[su][c.bit(depth) as usize]
                } else {
                    self.active_on(c)
                }
            });
            for &c in &corners {
                self.faces_at[c as usize].push(f);
            }
            self.corners[f as usize] = corners;
            self.present[f as usize] = true;
        }
        self.faces += self.born[su].len();
        for &d in &self.depends_on[su] {
            self.split_dependants[d as usize] += 1;
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
            }
            self.deactivate(c, State::Below);
        }
        self.activate(s);
        for &d in &self.depends_on[su] {
            self.split_dependants[d as usize] -= 1;
        }
    }

    /// Splits active node `s`, and first whatever its dependencies need (Hoppe's forced
    /// split); returns the splits made, and appends the children it activated to `activated`.
    fn force_split(&mut self, s: u32, activated: &mut Vec<u32>) -> Result<usize> {
        let mut stack = vec![s];
        let mut splits = 0;
        while let Some(&v) = stack.last() {
            if stack.len() > self.ids.len() {
                return Err(Error::malformed(0, 0, "the dependencies form a cycle"));
            }
            match self.state[v as usize] {
                State::Split => {
                    stack.pop();
                }
                State::Below => stack.push(self.parent[v as usize]),
                State::Active => {
                    let waiting = self.depends_on[v as usize]
                        .iter()
                        .copied()
                        .find(|&d| self.state[d as usize] != State::Split);
                    match waiting {
                        Some(d) => stack.push(d),
                        None => {
                            self.split(v);
                            activated.extend(self.children[v as usize]);
                            splits += 1;
                            stack.pop();
                        }
                    }
                }
            }
        }
        Ok(splits)
    }

    /// Adapts the front to `view`: passes over the active nodes, refining each the view wants
    /// refined down its subtree (dependencies first) and collapsing the parents of the others
    /// up the tree while the view does not want them, until a pass changes nothing or the
    /// budget is spent. Errors only on a stream whose dependencies form a cycle.
    pub fn adapt(&mut self, view: &View, budget: Budget) -> Result<Adapted> {
        let mut done = Adapted::default();
        let mut pass = std::mem::take(&mut self.pass);
        let result = self.adapt_passes(view, budget, &mut done, &mut pass);
        self.pass = pass;
        self.regulate(budget.faces, done.capped);
        result.map(|()| done)
    }

    fn adapt_passes(
        &mut self,
        view: &View,
        budget: Budget,
        done: &mut Adapted,
        pass: &mut Vec<u32>,
    ) -> Result<()> {
        let limit = budget.faces.unwrap_or(usize::MAX);
        let wants = |m: &ViewMesh, v: u32| {
            let vu = v as usize;
            m.is_inner(v) && view.wants_split(m.center[vu], m.radius[vu], m.scale)
        };
        let mut below: Vec<u32> = Vec::new();
        loop {
            let before = *done;
            done.passes += 1;
            let start = self.cursor.min(self.active.len());
            pass.clear();
            pass.extend_from_slice(&self.active[start..]);
            pass.extend_from_slice(&self.active[..start]);
            self.cursor = 0;
            for (i, &v) in pass.iter().enumerate() {
                if done.splits + done.collapses >= budget.operations {
                    self.cursor = (start + i) % pass.len().max(1);
                    return Ok(());
                }
                if self.state[v as usize] != State::Active {
                    continue;
                }
                if wants(self, v) {
                    // Down the subtree at once rather than a level a pass.
                    below.clear();
                    below.push(v);
                    while let Some(x) = below.pop() {
                        if self.state[x as usize] != State::Active
                            || done.splits + done.collapses >= budget.operations
                            || !wants(self, x)
                        {
                            continue;
                        }
                        if self.faces >= limit {
                            done.capped = true;
                            continue;
                        }
                        done.splits += self.force_split(x, &mut below)?;
                    }
                    continue;
                }
                // Up the tree while the parent may and should go.
                let mut p = self.parent[v as usize];
                while p != NONE
                    && done.splits + done.collapses < budget.operations
                    && self.can_collapse(p)
                    && !wants(self, p)
                {
                    self.collapse(p);
                    done.collapses += 1;
                    p = self.parent[p as usize];
                }
            }
            if (done.splits, done.collapses) == (before.splits, before.collapses) {
                done.settled = !done.capped;
                return Ok(());
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

    /// The adapted mesh: the active nodes' positions, the present triangles.
    pub fn mesh(&self) -> TriMesh {
        let mut index = vec![NONE; self.ids.len()];
        let mut positions = Vec::with_capacity(self.active.len());
        for &v in &self.active {
            index[v as usize] = positions.len() as u32;
            positions.push(self.center[v as usize]);
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
            let [a, b, c] = self.corners[t].map(|v| self.center[v as usize]);
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
            if (st == State::Active) != (self.active_slot[v] != NONE) {
                return Err(format!("node {v} is {st:?} but listed otherwise"));
            }
            if st == State::Split {
                if let Some(d) = self.depends_on[v]
                    .iter()
                    .find(|&&d| self.state[d as usize] != State::Split)
                {
                    return Err(format!("split node {v} depends on {d}, which is not split"));
                }
            }
        }
        let mut dependants = vec![0u32; n];
        for v in (0..n).filter(|&v| self.state[v] == State::Split) {
            for &d in &self.depends_on[v] {
                dependants[d as usize] += 1;
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
    use super::super::view::Camera;
    use super::*;
    use crate::codecs::{self, EncodeOptions, Stop};
    use crate::mesh::generate;
    use crate::mesh::quantize::GridShape;
    use proptest::prelude::*;
    use std::sync::OnceLock;

    /// A came stream of two spheres, a torus and a loose triangle sharing a vertex.
    fn stream() -> &'static [u8] {
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
        let done = vm.adapt(&View::everything(), Budget::UNLIMITED).unwrap();
        assert!(done.settled && done.collapses == 0);
        vm.check_invariants().unwrap();
        let (full, _) = codecs::decode(stream(), Stop::All).unwrap();
        let adapted = vm.mesh();
        assert_eq!(adapted.vertex_count(), full.mesh.vertex_count());
        assert_eq!(triangles(&adapted), triangles(&full.mesh));
        let done = vm.adapt(&View::nothing(), Budget::UNLIMITED).unwrap();
        assert_eq!(
            (done.splits, done.collapses),
            (0, full.mesh.vertex_count() - 1)
        );
        vm.check_invariants().unwrap();
        assert_eq!((vm.vertex_count(), vm.face_count()), (1, 0));
    }

    fn camera(eye: DVec3) -> Camera {
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
        vm.adapt(&view, Budget::UNLIMITED).unwrap();
        vm.check_invariants().unwrap();
        let near = vm.face_count();
        let far = View::new(&camera(DVec3::new(0.5, 0.8, 60.0)), 1.0).unwrap();
        let done = vm.adapt(&far, Budget::UNLIMITED).unwrap();
        vm.check_invariants().unwrap();
        assert!(
            done.collapses > 0 && vm.face_count() < near,
            "{} vs {near}",
            vm.face_count()
        );
    }

    #[test]
    fn an_operation_budget_spreads_the_work_over_calls_and_ends_where_one_call_does() {
        let view = View::new(&camera(DVec3::new(1.0, 1.0, 5.0)), 0.5).unwrap();
        let mut whole = ViewMesh::from_stream(stream()).unwrap();
        whole.adapt(&view, Budget::UNLIMITED).unwrap();
        let mut stepped = ViewMesh::from_stream(stream()).unwrap();
        let budget = Budget {
            operations: 50,
            faces: None,
        };
        let mut calls = 0;
        loop {
            let done = stepped.adapt(&view, budget).unwrap();
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
        vm.adapt(&view, Budget::UNLIMITED).unwrap();
        let free = vm.face_count();
        let target = free / 4;
        let budget = Budget {
            operations: usize::MAX,
            faces: Some(target),
        };
        for _ in 0..40 {
            vm.adapt(&view, budget).unwrap();
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
        vm.adapt(&View::everything(), Budget::UNLIMITED).unwrap();
        // The unit sphere at the origin (icosphere of radius 1): a ray up the z axis, from the
        // side away from the loose triangle.
        let hit = vm.pick(DVec3::new(0.01, 0.02, -5.0), DVec3::Z).unwrap();
        assert!((hit.distance - 4.0).abs() < 0.05, "{hit:?}");
        assert!(vm.pick(DVec3::new(9.0, 9.0, 9.0), DVec3::Z).is_none());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
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
                vm.adapt(&view, budget).unwrap();
                prop_assert_eq!(vm.check_invariants(), Ok(()));
            }
        }
    }
}
