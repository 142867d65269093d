//! Meta-nodes taken in as they arrive: their nodes, triangles and dependencies join the
//! hierarchy under the front, and whether a node's split is loaded, on its way or impossible.

use super::super::loader::{Loaded, UnitDelta, NONE};
use super::{Ready, State, Suspicion, UnitState, ViewMesh};
use smallvec::SmallVec;

impl ViewMesh {
    /// Takes in a fetched meta-node: its nodes, triangles and dependencies join the hierarchy
    /// (under the front: nothing present changes).
    pub(super) fn take_in(&mut self, loaded: Loaded) {
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

    pub(super) fn grow(&mut self, delta: UnitDelta) {
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
    pub(super) fn take_arrivals(&mut self, block: bool) -> usize {
        let arrived = self.loader.collect(self.outstanding, block);
        let count = arrived.len();
        for loaded in arrived {
            self.take_in(loaded);
        }
        count
    }

    /// Whether active node `v` can be split now; asks for its meta-node if that is missing.
    pub(super) fn ready(&mut self, v: u32) -> Ready {
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
                let (center, radius) = self.spheres[vu];
                let priority =
                    self.view_now
                        .screen_error(center, radius, self.deviations[vu], self.scale);
                self.loader.request(unit as usize, priority);
                Ready::Waiting
            }
            UnitState::Requested | UnitState::Supplied => Ready::Waiting,
            UnitState::Loaded | UnitState::Refused => Ready::Never,
        }
    }
}
