//! One adaptation's passes over the active nodes: refining what the view wants refined (down
//! each subtree, dependencies first), collapsing what it does not, and a face budget's
//! regulation of the tolerance.

use super::super::loader::NONE;
use super::super::view::View;
use super::{Adapted, Budget, Ready, State, ViewMesh};
use crate::prefetch::prefetch;

impl ViewMesh {
    pub(super) fn wants(&self, view: &View, v: u32) -> bool {
        let b = &self.nodes.bounds[v as usize];
        view.wants_split(b.center, b.radius, b.deviation, &b.cone, self.scale)
    }

    /// Returns whether it passed over the front (rather than revisiting the splits that
    /// waited).
    pub(super) fn adapt_passes(
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
        let revisit = self.loading.waited_for.as_ref() == Some(view)
            && budget == Budget::UNLIMITED
            && self.scratch.cursor == 0;
        self.loading.waited_for = None;
        if revisit {
            done.passes += 1;
            self.loading.waited_now.clear();
            let waiting = std::mem::take(&mut self.loading.waiting_nodes);
            for &v in &waiting {
                if self.nodes.links[v as usize].state == State::Active && self.wants(view, v) {
                    self.refine_down(v, view, budget, done, &mut below);
                }
            }
            // The splits still waiting are the next list; the old one's buffer is reused.
            self.loading.waiting_nodes = std::mem::replace(&mut self.loading.waited_now, waiting);
            if done.waiting == 0 {
                done.settled = !done.capped;
            } else {
                self.loading.waited_for = Some(view.clone());
            }
            return false;
        }
        loop {
            let before = *done;
            done.passes += 1;
            done.waiting = 0;
            done.blocked = 0;
            self.loading.waited_now.clear();
            // In node order (the loader's, which keeps a meta-node's nodes together) rather
            // than the list's: the nodes' records are then read nearly in memory order. The
            // bits list them so (sorting the list cost more), from the cursor on.
            pass.clear();
            for (k, &word) in self.front.active_bits.iter().enumerate() {
                let mut word = word;
                while word != 0 {
                    pass.push((64 * k) as u32 + word.trailing_zeros());
                    word &= word - 1;
                }
            }
            let start = pass.partition_point(|&v| v < self.scratch.cursor);
            pass.rotate_left(start);
            self.scratch.cursor = 0;
            // The parent whose collapse the last visit tried, and the operations made by then:
            // its other child, visited next with nothing done between, would try it again.
            let (mut tried, mut tried_at) = (NONE, usize::MAX);
            for (i, &v) in pass.iter().enumerate() {
                // The records the visit of a node a few visits on reads first: its sphere and
                // its parent's (the active nodes are sparse among all, too far apart for the
                // processor to foresee).
                if let Some(&ahead) = pass.get(i + 8) {
                    prefetch(self.nodes.bounds.as_ptr().wrapping_add(ahead as usize));
                    prefetch(self.nodes.links.as_ptr().wrapping_add(ahead as usize));
                }
                if let Some(&ahead) = pass.get(i + 4) {
                    let p = self.nodes.links[ahead as usize].parent as usize;
                    prefetch(self.nodes.bounds.as_ptr().wrapping_add(p));
                    prefetch(self.nodes.links.as_ptr().wrapping_add(p));
                }
                if done.splits + done.collapses >= budget.operations {
                    self.scratch.cursor = v;
                    return true;
                }
                if self.nodes.links[v as usize].state != State::Active {
                    continue;
                }
                if self.wants(view, v) && self.ready(v) != Ready::Never {
                    self.refine_down(v, view, budget, done, &mut below);
                    continue;
                }
                // Up the tree while the parent may and should go; then the same from each
                // node those collapses freed of its last split dependant (so that a chain of
                // dependencies unwinds in one pass, not one pass a link).
                let p = self.nodes.links[v as usize].parent;
                if p == tried && done.splits + done.collapses == tried_at {
                    continue;
                }
                self.collapse_from(p, view, budget, done, false);
                (tried, tried_at) = (p, done.splits + done.collapses);
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
                std::mem::swap(
                    &mut self.loading.waiting_nodes,
                    &mut self.loading.waited_now,
                );
                if done.waiting > 0 && !done.capped {
                    self.loading.waited_for = Some(view.clone());
                }
                return true;
            }
        }
    }

    /// Collapses split node `p` and on up the tree while the parent may and should go; then
    /// the same from each node those collapses freed of its last split dependant (so that a
    /// chain of dependencies unwinds in one pass, not one pass a link). `retry`: try again
    /// the collapses refused for a face's orientation in this adaptation.
    pub(super) fn collapse_from(
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
                p = self.nodes.links[p as usize].parent;
            }
            match self.scratch.freed.pop() {
                Some(d) if done.splits + done.collapses < budget.operations => p = d,
                _ => break,
            }
        }
    }

    /// Refines active node `v` down its subtree as far as the view wants (rather than a level
    /// a pass), dependencies first; a split waiting for a meta-node is noted.
    pub(super) fn refine_down(
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
            if self.nodes.links[x as usize].state != State::Active
                || done.splits + done.collapses >= budget.operations
                || !self.wants(view, x)
            {
                continue;
            }
            match self.ready(x) {
                Ready::Now => {}
                Ready::Waiting => {
                    done.waiting += 1;
                    self.loading.waited_now.push(x);
                    continue;
                }
                Ready::Never => continue,
            }
            if self.faces.count >= limit {
                done.capped = true;
                continue;
            }
            let (splits, stop) = self.force_split(x, below, usize::MAX);
            done.splits += splits;
            match stop {
                Ready::Now => {}
                Ready::Waiting => {
                    done.waiting += 1;
                    self.loading.waited_now.push(x);
                }
                Ready::Never => done.blocked += 1,
            }
        }
    }

    /// Scales κ towards holding `faces`: up while there are more or the budget held splits
    /// back (`capped`), back down (not below 1) while there are clearly fewer.
    pub(super) fn regulate(&mut self, faces: Option<usize>, capped: bool) {
        let Some(target) = faces else {
            self.scale = 1.0;
            return;
        };
        if self.faces.count > target || capped {
            self.scale *= 1.25;
        } else if (self.faces.count as f64) < 0.8 * target as f64 {
            self.scale = (self.scale / 1.25).max(1.0);
        }
    }
}
