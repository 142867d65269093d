//! Meta-nodes taken in as they arrive: their nodes, triangles and dependencies join the
//! hierarchy under the front, and whether a node's split is loaded, on its way or impossible.

use super::super::loader::{Loaded, UnitDelta, NONE};
use super::orientation::CodedNormal;
use super::parts::{Bounds, Links};
use super::{Ready, State, Suspicion, UnitState, ViewMesh};
use smallvec::SmallVec;

impl ViewMesh {
    /// Takes in a fetched meta-node: its nodes, triangles and dependencies join the hierarchy
    /// (under the front: nothing present changes).
    pub(super) fn take_in(&mut self, loaded: Loaded) {
        self.loading.outstanding -= 1;
        self.loading.bytes_read += loaded.bytes;
        // Only a request reads a unit's open nodes (its priority).
        if let Some(opened) = self.loading.opened.get_mut(loaded.unit) {
            *opened = Vec::new();
        }
        match loaded.outcome {
            Ok(delta) => {
                self.loading.units[loaded.unit] = UnitState::Loaded;
                self.grow(delta);
            }
            Err(e) => {
                self.loading.units[loaded.unit] = UnitState::Refused;
                self.loading.refusals.push((loaded.unit, e.to_string()));
            }
        }
    }

    pub(super) fn grow(&mut self, delta: UnitDelta) {
        for n in delta.nodes {
            let v = self.nodes.links.len() as u32;
            if n.parent != NONE {
                let p = n.parent as usize;
                self.nodes.links[p].children[n.id.bit(n.id.len() - 1) as usize] = v;
                self.nodes.opens[p] = NONE;
            }
            self.nodes.links.push(Links {
                faces_at: SmallVec::new(),
                id: n.id,
                children: [NONE; 2],
                parent: n.parent,
                active_slot: NONE,
                split_dependants: 0,
                state: State::Below,
            });
            self.nodes.opens.push(NONE);
            self.nodes.bounds.push(Bounds {
                center: n.center,
                radius: n.radius,
                deviation: n.deviation,
                cone: n.cone,
            });
            self.nodes.born.push(SmallVec::new());
            self.nodes.depends_on.push(SmallVec::new());
            self.guard.held_by.push(NONE);
            self.guard.refused_listed.push(false);
            self.guard.in_retry.push(false);
            self.scratch.planned.push(false);
        }
        self.front
            .active_bits
            .resize(self.nodes.links.len().div_ceil(64), 0);
        for (birth, corners, normal) in delta.triangles {
            self.nodes.born[birth as usize].push(self.faces.leaf_corners.len() as u32);
            self.faces.leaf_corners.push(corners);
            self.faces.normals.push(CodedNormal::from(normal));
            self.faces.corners.push([NONE; 3]);
            self.guard.suspected.push(Suspicion::None);
        }
        // Paths that waited at nodes this unit splits, carried on below them.
        for (t, k, path) in delta.carried {
            if let Some(corners) = self.faces.leaf_corners.get_mut(t as usize) {
                corners[k as usize] = path;
            }
        }
        for (s, deps) in delta.splits {
            self.nodes.depends_on[s as usize] = deps;
        }
        for (unit, node) in delta.opens {
            self.nodes.opens[node as usize] = unit as u32;
            if let Some(opened) = self.loading.opened.get_mut(unit) {
                opened.push(node);
            }
        }
    }

    /// Takes in the meta-nodes that have arrived (all those asked for when `block`).
    pub(super) fn take_arrivals(&mut self, block: bool) -> usize {
        let arrived = self.loading.loader.collect(self.loading.outstanding, block);
        let count = arrived.len();
        let loaded_before = self.nodes.links.len();
        for loaded in arrived {
            self.take_in(loaded);
        }
        if self.nodes.links.len() > loaded_before {
            self.retry_after_arrivals();
        }
        count
    }

    /// Whether active node `v` can be split now; asks for its meta-node if that is missing.
    pub(super) fn ready(&mut self, v: u32) -> Ready {
        let vu = v as usize;
        if self.nodes.links[vu].children[0] != NONE {
            return Ready::Now;
        }
        let unit = self.nodes.opens[vu];
        if unit == NONE {
            return Ready::Never;
        }
        match self.loading.units[unit as usize] {
            UnitState::Idle => {
                self.loading.units[unit as usize] = UnitState::Requested;
                self.loading.outstanding += 1;
                let priority = self.unit_priority(unit as usize);
                self.loading.loader.request(unit as usize, priority);
                Ready::Waiting
            }
            UnitState::Requested | UnitState::Supplied => Ready::Waiting,
            UnitState::Loaded | UnitState::Refused => Ready::Never,
        }
    }

    /// How much the view wants meta-node `unit`: the largest screen error of the open nodes
    /// whose splits it holds ([`View::screen_error`]).
    pub(super) fn unit_priority(&self, unit: usize) -> f64 {
        self.loading.opened[unit]
            .iter()
            .map(|&v| {
                let b = &self.nodes.bounds[v as usize];
                self.loading
                    .view_now
                    .screen_error(b.center, b.radius, b.deviation, self.scale)
            })
            .fold(0.0, f64::max)
    }
}
