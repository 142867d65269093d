//! The front's moves: activating nodes, vertex splits and edge collapses, forced splits through
//! the dependencies (planned all or nothing), and walking leaf paths to the active nodes.

use super::super::loader::NONE;
use super::{Ready, State, ViewMesh};
use crate::hierarchy::came::NodeId;
use smallvec::SmallVec;

impl ViewMesh {
    pub(super) fn activate(&mut self, v: u32) {
        self.nodes.links[v as usize].state = State::Active;
        self.nodes.links[v as usize].active_slot = self.front.active.len() as u32;
        self.front.active.push(v);
        self.front.active_bits[v as usize / 64] |= 1 << (v % 64);
    }

    pub(super) fn deactivate(&mut self, v: u32, to: State) {
        self.nodes.links[v as usize].state = to;
        let slot = self.nodes.links[v as usize].active_slot as usize;
        self.front.active.swap_remove(slot);
        if let Some(&moved) = self.front.active.get(slot) {
            self.nodes.links[moved as usize].active_slot = slot as u32;
        }
        self.nodes.links[v as usize].active_slot = NONE;
        self.front.active_bits[v as usize / 64] &= !(1 << (v % 64));
    }

    /// The active node on leaf path `leaf`; `None` if the path ends at a split node (a
    /// corrupt stream's corner).
    pub(super) fn active_on(&self, leaf: NodeId) -> Option<u32> {
        let mut v = 0u32;
        while self.nodes.links[v as usize].state == State::Split {
            let len = self.nodes.links[v as usize].id.len();
            if len >= leaf.len() {
                return None;
            }
            v = self.nodes.links[v as usize].children[leaf.bit(len) as usize];
        }
        Some(v)
    }

    /// The deepest loaded node on the path to `id`, and whether it is `id`.
    pub(super) fn toward(&self, id: NodeId) -> (u32, bool) {
        self.toward_from(0, id)
    }

    /// [`ViewMesh::toward`], walking down from `start`, an ancestor of `id` (or `id`).
    pub(super) fn toward_from(&self, start: u32, id: NodeId) -> (u32, bool) {
        let mut v = start;
        while let Some(c) = self.child_toward(v, id) {
            v = c;
        }
        (v, self.nodes.links[v as usize].id == id)
    }

    /// The loaded child of `v` on the path to `id`: none when `v` is as deep as `id` (or,
    /// in a corrupt stream, deeper) or that child is not loaded.
    pub(super) fn child_toward(&self, v: u32, id: NodeId) -> Option<u32> {
        let depth = self.nodes.links[v as usize].id.len();
        if depth >= id.len() {
            return None;
        }
        Some(self.nodes.links[v as usize].children[id.bit(depth) as usize]).filter(|&c| c != NONE)
    }

    /// A node to split before `v` may be: its first dependency not split (or planned to be),
    /// or the deepest loaded node on the way to one not loaded yet.
    pub(super) fn unmet_dependency(&mut self, v: u32) -> Option<u32> {
        for k in 0..self.nodes.depends_on[v as usize].len() {
            let dep = self.nodes.depends_on[v as usize][k];
            let node = if dep.node != NONE {
                dep.node
            } else {
                match self.toward(dep.id) {
                    (x, true) => {
                        self.nodes.depends_on[v as usize][k].node = x;
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
    pub(super) fn neighbour_on(&self, s: u32, leaf: NodeId) -> Option<u32> {
        self.nodes.links[s as usize].faces_at.iter().find_map(|&f| {
            self.faces.corners[f as usize]
                .into_iter()
                .find(|&n| n != s && self.nodes.links[n as usize].id.is_ancestor_of(leaf))
        })
    }

    /// vsplit of active inner node `s` whose dependencies are split. Does nothing and returns
    /// false if a corner cannot follow it (a leaf path ending at `s` or at a split node: only in
    /// a corrupt stream).
    pub(super) fn split(&mut self, s: u32) -> bool {
        let su = s as usize;
        let depth = self.nodes.links[su].id.len();
        let own = self.nodes.links[su].id;
        let deep = |c: NodeId| c.len() > depth;
        for &f in &self.nodes.links[su].faces_at {
            for k in 0..3 {
                if self.faces.corners[f as usize][k] == s
                    && !deep(self.faces.leaf_corners[f as usize][k])
                {
                    return false;
                }
            }
        }
        // The born triangles' corners: two under v_s, at v_t and v_u once it is split; the
        // third a neighbour (an active node elsewhere, which this split does not move).
        let mut born: SmallVec<[[u32; 3]; 4]> = SmallVec::new();
        for &f in &self.nodes.born[su] {
            let mut corners = [NONE; 3];
            for (k, &c) in self.faces.leaf_corners[f as usize].iter().enumerate() {
                corners[k] = if own.is_ancestor_of(c) {
                    if !deep(c) {
                        return false;
                    }
                    self.nodes.links[su].children[c.bit(depth) as usize]
                } else {
                    match self.neighbour_on(s, c).or_else(|| self.active_on(c)) {
                        Some(v) => v,
                        None => return false,
                    }
                };
            }
            born.push(corners);
        }
        let [t, u] = self.nodes.links[su].children;
        self.deactivate(s, State::Split);
        self.activate(t);
        self.activate(u);
        for f in std::mem::take(&mut self.nodes.links[su].faces_at) {
            let fu = f as usize;
            for k in 0..3 {
                if self.faces.corners[fu][k] == s {
                    let child = self.nodes.links[su].children
                        [self.faces.leaf_corners[fu][k].bit(depth) as usize];
                    self.faces.corners[fu][k] = child;
                    self.nodes.links[child as usize].faces_at.push(f);
                }
            }
            self.suspect(f);
        }
        for (i, corners) in born.into_iter().enumerate() {
            let f = self.nodes.born[su][i];
            for &c in &corners {
                self.nodes.links[c as usize].faces_at.push(f);
            }
            self.faces.corners[f as usize] = corners;
            self.suspect(f);
        }
        self.faces.count += self.nodes.born[su].len();
        for &d in &self.nodes.depends_on[su] {
            self.nodes.links[d.node as usize].split_dependants += 1;
        }
        true
    }

    /// Whether node `v` is a leaf of the hierarchy (not a node whose split is still to load).
    pub(super) fn is_leaf(&self, v: u32) -> bool {
        self.nodes.links[v as usize].children[0] == NONE && self.nodes.opens[v as usize] == NONE
    }

    /// Whether ecol of split node `s` is legal: both children active, no split dependant.
    pub(super) fn can_collapse(&self, s: u32) -> bool {
        let su = s as usize;
        self.nodes.links[su].state == State::Split
            && self.nodes.links[su].split_dependants == 0
            && self.nodes.links[su]
                .children
                .iter()
                .all(|&c| self.nodes.links[c as usize].state == State::Active)
    }

    /// ecol of `s` ([`Self::can_collapse`]).
    pub(super) fn collapse(&mut self, s: u32) {
        let su = s as usize;
        for i in 0..self.nodes.born[su].len() {
            let f = self.nodes.born[su][i];
            self.retry_around(f);
            for c in self.faces.corners[f as usize] {
                let list = &mut self.nodes.links[c as usize].faces_at;
                if let Some(at) = list.iter().position(|&g| g == f) {
                    list.swap_remove(at);
                }
            }
            self.faces.corners[f as usize] = [NONE; 3];
        }
        self.faces.count -= self.nodes.born[su].len();
        for c in self.nodes.links[su].children {
            for f in std::mem::take(&mut self.nodes.links[c as usize].faces_at) {
                for corner in &mut self.faces.corners[f as usize] {
                    if *corner == c {
                        *corner = s;
                    }
                }
                self.nodes.links[su].faces_at.push(f);
                self.suspect(f);
            }
            self.deactivate(c, State::Below);
        }
        self.activate(s);
        for &d in &self.nodes.depends_on[su] {
            let count = &mut self.nodes.links[d.node as usize].split_dependants;
            *count -= 1;
            if *count == 0 {
                self.scratch.freed.push(d.node);
            }
        }
    }

    /// The node's state once the splits planned so far are made.
    pub(super) fn planned_state(&self, v: u32) -> State {
        let vu = v as usize;
        match self.nodes.links[vu].state {
            _ if self.scratch.planned[vu] => State::Split,
            State::Below if self.scratch.planned[self.nodes.links[vu].parent as usize] => {
                State::Active
            }
            state => state,
        }
    }

    /// Splits active node `s`, and first whatever its dependencies need (Hoppe's forced
    /// split), all or nothing: the splits are planned first, and made only if every one can be
    /// (none waits for a meta-node) — so that a chain cut short is not left half made for the
    /// next pass to collapse and the one after to make again; and only if they add at most
    /// `room` faces (else none is made, and (0, `Ready::Now`) returned). Returns the splits made and
    /// whether it stopped short, and appends the children it activated to `activated`.
    pub(super) fn force_split(
        &mut self,
        s: u32,
        activated: &mut Vec<u32>,
        room: usize,
    ) -> (usize, Ready) {
        let mut plan = std::mem::take(&mut self.scratch.plan);
        plan.clear();
        let mut stack = std::mem::take(&mut self.scratch.stack);
        stack.clear();
        stack.push(s);
        let outcome = loop {
            let Some(&v) = stack.last() else {
                break Ready::Now;
            };
            if stack.len() > self.nodes.links.len() {
                // The dependencies form a cycle: a corrupt stream.
                break Ready::Never;
            }
            match self.planned_state(v) {
                State::Split => {
                    stack.pop();
                }
                State::Below => stack.push(self.nodes.links[v as usize].parent),
                State::Active => match self.ready(v) {
                    Ready::Now => match self.unmet_dependency(v) {
                        Some(d) => stack.push(d),
                        None => {
                            self.scratch.planned[v as usize] = true;
                            plan.push(v);
                            stack.pop();
                        }
                    },
                    stop => break stop,
                },
            }
        };
        for &v in &plan {
            self.scratch.planned[v as usize] = false;
        }
        let mut made = 0;
        let mut outcome = outcome;
        let added: usize = plan
            .iter()
            .map(|&v| self.nodes.born[v as usize].len())
            .sum();
        if outcome == Ready::Now && added <= room {
            for &v in &plan {
                if !self.split(v) {
                    outcome = Ready::Never;
                    break;
                }
                activated.extend(self.nodes.links[v as usize].children);
                made += 1;
            }
        }
        self.scratch.plan = plan;
        self.scratch.stack = stack;
        (made, outcome)
    }
}
