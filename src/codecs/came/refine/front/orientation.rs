//! The orientation guard (the module docs of `front`): which present faces are certain to turn
//! as their counterparts do, the faces listed to be made certain, and the splits and refused
//! collapses that make them so.

use super::super::loader::NONE;
use super::super::view::View;
use super::{Adapted, Budget, Ready, State, Suspicion, ViewMesh};
use crate::hierarchy::came::face_normals::FaceNormal;
use crate::hierarchy::came::NodeId;
use glam::DVec3;

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

/// What a triangle's own coded normal proves (`came` syntax 4,
/// `hierarchy::came::face_normals`): its counterpart's normal lies within the angle whose sine
/// is `sin` of the unit vector `direction` — `sin` below 0 for a counterpart of no area (which
/// turns no way), above 1 where the stream says nothing.
#[derive(Clone, Copy, Debug)]
pub(super) struct CodedNormal {
    direction: [f32; 3],
    sin: f32,
}

impl CodedNormal {
    pub(super) fn from(normal: FaceNormal) -> CodedNormal {
        match normal.cone() {
            Some((direction, degrees)) => CodedNormal {
                direction: direction.as_vec3().to_array(),
                // The direction's rounding to f32 is within 1e-7.
                sin: (degrees.to_radians().sin() + 1e-6) as f32,
            },
            None if normal.is_known() => CodedNormal {
                direction: [0.0; 3],
                sin: -1.0,
            },
            None => CodedNormal {
                direction: [0.0; 3],
                sin: 2.0,
            },
        }
    }

    /// Whether it decides every face standing for the triangle: certain, or folding over.
    pub(super) fn decides(self) -> bool {
        self.sin <= 1.0
    }

    /// Whether a face of normal `n` (of length `area`) surely turns within 90° of the
    /// counterpart's: n's angle to the direction and the bound sum to less than 90°.
    fn holds(self, n: DVec3, area: f64) -> bool {
        let d = glam::Vec3::from(self.direction).as_dvec3();
        self.decides() && n.dot(d) > area * self.sin as f64 * SLACK
    }
}

impl ViewMesh {
    /// Lists triangle `f` to have its orientation checked.
    pub(super) fn suspect(&mut self, f: u32) {
        if self.guard.suspected[f as usize] == Suspicion::None {
            self.guard.suspects.push(f);
        }
        self.guard.suspected[f as usize] = Suspicion::Moved;
        self.retry_around(f);
    }

    /// Lists the collapses that moving, making or removing present triangle `f` may have made
    /// possible for its orientation (those of its corners' parents) to be tried again: those
    /// the guard refused (the passes try every other collapse themselves).
    pub(super) fn retry_around(&mut self, f: u32) {
        for c in self.faces.corners[f as usize] {
            let p = self.nodes.links[c as usize].parent;
            if p != NONE
                && self.guard.refused_listed[p as usize]
                && !self.guard.in_retry[p as usize]
            {
                self.guard.in_retry[p as usize] = true;
                self.guard.retry.push(p);
            }
        }
    }

    /// After meta-nodes arrived: the collapses refused for a face whose certificate reads the
    /// deepest loaded nodes are listed to be tried again (it may hold now). Those refused for
    /// a face whose own coded normal decides it stay refused: no meta-node changes what that
    /// face proves, and a move of the face lists them again ([`Self::retry_around`]).
    pub(super) fn retry_after_arrivals(&mut self) {
        let mut refused = std::mem::take(&mut self.guard.refused);
        refused.retain(|&p| {
            let culprit = self.guard.held_by[p as usize];
            if culprit != NONE && self.faces.normals[culprit as usize].decides() {
                return true;
            }
            if !self.guard.in_retry[p as usize] {
                self.guard.in_retry[p as usize] = true;
                self.guard.retry.push(p);
            }
            false
        });
        self.guard.refused = refused;
    }

    /// Whether the face on active nodes `corners` shows in the view: it meets the frustum and
    /// spans the tolerance on the screen ([`View::shows_triangle`]).
    pub(super) fn in_view(&self, view: &View, corners: [u32; 3]) -> bool {
        view.shows_triangle(corners.map(|v| self.nodes.bounds[v as usize].center))
    }

    /// Whether triangle `f`, on active nodes `corners`, surely turns the way of its counterpart
    /// (the module docs' tests: leaves, error spheres, normal cones, and the spheres of the
    /// deepest loaded nodes on its corners' leaf paths).
    pub(super) fn orientation_certain(&self, corners: [u32; 3], f: u32) -> bool {
        if corners.iter().all(|&v| self.is_leaf(v)) {
            return true;
        }
        let p = corners.map(|v| self.nodes.bounds[v as usize].center);
        let r = corners.map(|v| self.nodes.bounds[v as usize].radius);
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let area = n.length();
        if !(area > 0.0 && area.is_finite()) {
            return false;
        }
        let coded = self.faces.normals[f as usize];
        if coded.holds(n, area) || spheres_hold_orientation(p, r).is_some_and(|cos| cos > 0.0) {
            return true;
        }
        // A triangle's own normal decides it: nothing deeper would prove more.
        corners.iter().any(|&v| self.cone_holds(v, n, area))
            || !coded.decides() && self.deeper_nodes_hold_orientation(n, corners, f)
    }

    /// Whether normal `n` (of length `area`) is within 90° − α of the axis of node `v`'s normal
    /// cone, which holds the normal of every face with a corner under `v`.
    fn cone_holds(&self, v: u32, n: DVec3, area: f64) -> bool {
        let cone = &self.nodes.bounds[v as usize].cone;
        let axis = DVec3::new(
            cone.axis[0] as f64,
            cone.axis[1] as f64,
            cone.axis[2] as f64,
        );
        // θ + α < 90° ⇔ cos θ > sin α (α widened by the cone's margin).
        cone.is_some() && n.dot(axis) > cone.sin as f64 * area * SLACK
    }

    /// Walks down face `f`'s leaf path to `leaf` from the corner among `corners` above it
    /// (active nodes, or a collapse's parent) rather than from the root — half the steps or
    /// fewer, in nodes near each other — to the deepest loaded node on it; `None` as soon as
    /// `stop` holds for a node below the corner.
    fn down_leaf_path(
        &self,
        corners: [u32; 3],
        leaf: NodeId,
        stop: impl Fn(u32) -> bool,
    ) -> Option<u32> {
        let mut v = corners
            .into_iter()
            .find(|&c| self.nodes.links[c as usize].id.is_ancestor_of(leaf))
            .unwrap_or(0);
        while let Some(c) = self.child_toward(v, leaf) {
            v = c;
            if stop(v) {
                return None;
            }
        }
        Some(v)
    }

    /// The deepest loaded node on each of face `f`'s leaf paths.
    fn deepest_loaded(&self, corners: [u32; 3], f: u32) -> [u32; 3] {
        self.faces.leaf_corners[f as usize]
            .map(|leaf| self.down_leaf_path(corners, leaf, |_| false).unwrap_or(0))
    }

    /// Asks for the meta-nodes under the deepest loaded nodes on face `f`'s leaf paths, which
    /// take its certificate closer to its counterpart (exact once they are leaves); true when
    /// one of them is on its way.
    pub(super) fn ask_for_certificate(&mut self, f: u32) -> bool {
        let corners = self.faces.corners[f as usize];
        let mut on_its_way = false;
        for v in self.deepest_loaded(corners, f) {
            if !self.is_leaf(v) {
                on_its_way |= self.ready(v) == Ready::Waiting;
            }
        }
        on_its_way
    }

    /// The loaded nodes on the counterpart's leaf paths below `corners` (down to the leaves
    /// themselves, radius 0, once loaded) hold it: the counterpart has a corner under each, so
    /// its normal lies in each one's normal cone, which is narrower the deeper the node (every
    /// node on the paths, not only the deepest: a deeper node's coded cone need not lie inside
    /// its parent's, and a face once certain must stay so as more meta-nodes arrive); or, from
    /// the deepest ones' spheres, a proxy triangle Q on them, whose normal makes an angle β
    /// with the face's n, and whose spheres bound the angle γ between Q's normal and the
    /// counterpart's; the face is certain when β + γ < 90°.
    pub(super) fn deeper_nodes_hold_orientation(
        &self,
        n: DVec3,
        corners: [u32; 3],
        f: u32,
    ) -> bool {
        let area = n.length();
        let leaves = self.faces.leaf_corners[f as usize];
        let mut deepest = [0u32; 3];
        for (k, leaf) in leaves.into_iter().enumerate() {
            match self.down_leaf_path(corners, leaf, |v| self.cone_holds(v, n, area)) {
                Some(v) => deepest[k] = v,
                None => return true,
            }
        }
        let q = deepest.map(|v| self.nodes.bounds[v as usize].center);
        let r = deepest.map(|v| self.nodes.bounds[v as usize].radius);
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

    /// Whether ecol of split node `s` may be made, for the faces it moves.
    ///
    /// In the passes (`retry` false) it may, unless the guard refused it in this view: the
    /// faces it moves are listed (`collapse` suspects them), and the guard after the passes
    /// splits again where one in view is left not certain, and lists that split as refused.
    /// Checking those faces before the collapse as well read each of them twice in a frame
    /// (the fly-through's median frame 16% longer: BENCHMARKS.md).
    ///
    /// Tried again (`retry`: a refused collapse, after the guard, when a face it would move
    /// has moved, or in a new view), it is made only if it leaves every face it moves that is
    /// in view certain of its orientation (the faces born at `s`, on both children, go):
    /// made and split again, it would be tried again and again. A refused node is listed
    /// (`refused`), and the face that refused it is checked first the next time (a node the
    /// guard split is refused again and again while its view lasts: one face checked, not its
    /// dozen).
    ///
    /// While the front holds more faces than a face budget allows, the budget comes first: the
    /// passes' collapse is made, and the faces it leaves not certain stay listed.
    pub(super) fn collapse_keeps_orientation(
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
        // The passes: the guard settles what they leave (a retry is checked, or it would undo
        // the guard's splits over and over).
        if !retry {
            return budget.faces.is_some_and(|target| self.faces.count > target)
                || !self.guard.refused_listed[su];
        }
        let [t, u] = self.nodes.links[su].children;
        // Face `f` once `s` is collapsed: in view and not certain?
        let spoilt = |f: u32| {
            let corners = self.faces.corners[f as usize];
            // (Not present: its corners are NONE.)
            if corners.contains(&t) && corners.contains(&u) {
                return false;
            }
            if !corners.contains(&t) && !corners.contains(&u) {
                return false;
            }
            let moved = corners.map(|v| if v == t || v == u { s } else { v });
            self.in_view(view, moved) && !self.orientation_certain(moved, f)
        };
        let held = self.guard.held_by[su];
        let culprit = if held != NONE && spoilt(held) {
            Some(held)
        } else {
            [t, u].iter().find_map(|&c| {
                self.nodes.links[c as usize]
                    .faces_at
                    .iter()
                    .copied()
                    .find(|&f| spoilt(f))
            })
        };
        match culprit {
            Some(f) => {
                self.guard.held_by[su] = f;
                if !self.guard.refused_listed[su] {
                    self.guard.refused_listed[su] = true;
                    self.guard.refused.push(s);
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
    pub(super) fn guard(
        &mut self,
        view: &View,
        budget: Budget,
        done: &mut Adapted,
        below: &mut Vec<u32>,
    ) {
        if !view.keeps_orientation() {
            // The faces stay listed, for a view that keeps orientation.
            return;
        }
        let mut held = Vec::new();
        let mut unsure = 0;
        let mut activated = Vec::new();
        let waiting_before = done.waiting;
        // The view's splits that wait, of the children the guard's splits activate.
        self.loading.waited_now.clear();
        while let Some(f) = self.guard.suspects.pop() {
            let fu = f as usize;
            let corners = self.faces.corners[fu];
            let certain = match self.guard.suspected[fu] {
                _ if !self.faces.present(fu) => true,
                Suspicion::Moved => self.orientation_certain(corners, f),
                _ => false,
            };
            if certain {
                self.guard.suspected[fu] = Suspicion::None;
                continue;
            }
            self.guard.suspected[fu] = Suspicion::Uncertain;
            if !self.in_view(view, corners) {
                held.push(f);
                continue;
            }
            if done.splits + done.collapses >= budget.operations
                || self.faces.count >= budget.faces.unwrap_or(usize::MAX)
            {
                held.push(f);
                unsure += 1;
                continue;
            }
            // Not certain from what is loaded, but the stream holds what would tell: the
            // face waits for it. Splitting instead chases its counterpart down the hierarchy,
            // and the faces each split makes may be no more certain than it.
            let mut waits = !self.faces.normals[fu].decides() && self.ask_for_certificate(f);
            let mut corners = corners;
            if !waits {
                corners.sort_by(|&a, &b| {
                    let radius = |v: u32| self.nodes.bounds[v as usize].radius;
                    radius(b).total_cmp(&radius(a))
                });
                // First the coarsest corner whose split alone turns the face the right way
                // (its child on the counterpart's leaf path in its place), if one does: on
                // dragon-50k's far view 1,178 faces against 1,264 splitting the coarsest (990
                // unguarded).
                let now = self.faces.corners[fu];
                let leaves = self.faces.leaf_corners[fu];
                let fixes = |x: u32| {
                    let Some(k) = now.iter().position(|&c| c == x) else {
                        return false;
                    };
                    let Some(child) = self.child_toward(x, leaves[k]) else {
                        return false;
                    };
                    let mut moved = now;
                    moved[k] = child;
                    self.orientation_certain(moved, f)
                };
                match (0..3).find(|&i| fixes(corners[i])) {
                    Some(i) => corners[..=i].rotate_right(1),
                    // A corner whose split is not loaded may be the one that fixes it: the
                    // face waits for those splits rather than splitting the coarsest corner
                    // blind (`ready` asks for a corner's meta-node only where it is missing).
                    None => {
                        for x in corners {
                            waits |= self.ready(x) == Ready::Waiting;
                        }
                    }
                }
            }
            if waits {
                self.guard.suspected[fu] = Suspicion::Moved;
                done.waiting += 1;
                held.push(f);
                unsure += 1;
                continue;
            }
            let mut outcome = Ready::Never;
            let mut no_room = false;
            for x in corners {
                if self.is_leaf(x) {
                    continue;
                }
                activated.clear();
                self.guard.held_by[x as usize] = f;
                // Within a face budget: a split that would take the front past it waits.
                let room = budget
                    .faces
                    .map_or(usize::MAX, |f| f.saturating_sub(self.faces.count));
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
                    let v = self.scratch.plan[i];
                    if !self.guard.refused_listed[v as usize] {
                        self.guard.refused_listed[v as usize] = true;
                        self.guard.refused.push(v);
                    }
                    if !self.guard.in_retry[v as usize] {
                        self.guard.in_retry[v as usize] = true;
                        self.guard.retry.push(v);
                    }
                }
                for &c in &activated {
                    if self.nodes.links[c as usize].state == State::Active && self.wants(view, c) {
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
                Ready::Now => self.guard.suspects.push(f),
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
        self.guard.suspects = held;
        done.unsure = unsure;
        if done.waiting > waiting_before {
            // The next call with the same view revisits the view's splits that wait (as after
            // the passes) and then these faces.
            let waited = std::mem::take(&mut self.loading.waited_now);
            self.loading.waiting_nodes.extend_from_slice(&waited);
            self.loading.waited_now = waited;
            if !done.capped && self.scratch.cursor == 0 {
                self.loading.waited_for = Some(view.clone());
            }
            done.settled = false;
        }
        if done.splits + done.collapses >= budget.operations && !self.guard.suspects.is_empty() {
            done.settled = false;
        }
    }

    /// After the passes: the collapses a face's orientation may have refused tried again, and
    /// the guard ([`Self::guard`]), until neither does anything. Tried again: those near a face
    /// that moved, appeared or went since they were last tried (`retry`: the parents of its
    /// corners), after meta-nodes arrive those refused for a face whose certificate reads the
    /// deepest loaded nodes ([`Self::retry_after_arrivals`]), and every refused one after whole
    /// passes (a view that may be new).
    pub(super) fn settle_orientation(
        &mut self,
        view: &View,
        budget: Budget,
        done: &mut Adapted,
        below: &mut Vec<u32>,
        new_view: bool,
    ) {
        let mut nodes = std::mem::take(&mut self.guard.retry);
        if new_view {
            nodes.append(&mut self.guard.refused);
        }
        if !view.keeps_orientation() {
            // Nothing was refused for orientation: the faces' moves need no retrying.
            for &p in &nodes {
                self.guard.in_retry[p as usize] = false;
                self.guard.refused_listed[p as usize] = false;
            }
            nodes.clear();
            self.guard.retry = nodes;
            return;
        }
        loop {
            let before = (done.splits, done.collapses);
            for &p in &nodes {
                self.guard.refused_listed[p as usize] = false;
                self.guard.in_retry[p as usize] = false;
            }
            for &p in &nodes {
                if done.splits + done.collapses >= budget.operations {
                    // Kept for the next call.
                    if !self.guard.in_retry[p as usize] {
                        self.guard.in_retry[p as usize] = true;
                        self.guard.retry.push(p);
                    }
                    continue;
                }
                self.collapse_from(p, view, budget, done, true);
            }
            self.guard(view, budget, done, below);
            nodes.clear();
            std::mem::swap(&mut nodes, &mut self.guard.retry);
            let spent = done.splits + done.collapses >= budget.operations;
            if spent || (done.splits, done.collapses) == before && nodes.is_empty() {
                break;
            }
        }
        // Empty, or (the budget having run out) those left for the next call.
        self.guard.retry = nodes;
        if done.splits + done.collapses >= budget.operations {
            // The budget ran out here, after the passes: a collapse chain may have stopped
            // short, so the next call makes whole passes rather than revisiting what waited.
            self.loading.waited_for = None;
        }
    }
}
