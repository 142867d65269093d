//! The collapse engine: per-vertex face and edge lists, an indexed 8-ary heap of edges keyed by
//! cost, the checks a collapse must pass (link condition, boundary rules, no duplicate face, no
//! fold-over), and greedy loops of collapses cheapest first.

use super::quadric::Quadric;
use super::{vad_s_step, Collapse, Placement};
use crate::hierarchy::pmesh::{anchor, NIL};
use glam::DVec3;
use orx_priority_queue::{DaryHeapOfIndices, PriorityQueue, PriorityQueueDecKey};
use rayon::prelude::*;
use smallvec::SmallVec;

/// Heap key of an edge: its cost's bits above its id. Costs are never negative, so their bits
/// order as the costs do; the id breaks ties, for determinism.
pub(super) fn heap_key(cost: f64, edge: u32) -> u64 {
    (u64::from((cost as f32).to_bits()) << 32) | u64::from(edge)
}

pub(in crate::hierarchy) fn to_f(c: [i32; 3]) -> DVec3 {
    DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64)
}

/// Faces or edges around one vertex: most vertices have few, kept inline.
pub(in crate::hierarchy) type Incident = SmallVec<[u32; 8]>;

/// A collapse that passed the checks: (vs, vt, fl, fr, vl, vr) as in [`Collapse`].
pub(super) type Checked = (u32, u32, u32, u32, u32, u32);

pub(super) struct State {
    pub(super) cells: Vec<[i32; 3]>,
    pub(super) faces: Vec<[u32; 3]>,
    pub(super) face_alive: Vec<bool>,
    pub(super) vertex_alive: Vec<bool>,
    /// Faces around each vertex.
    pub(super) vfaces: Vec<Incident>,
    /// Edges around each vertex (ids into `edges`).
    pub(super) vedges: Vec<Incident>,
    /// Both ends of each edge; an edge collapsed away or merged into another is in no `vedges`.
    pub(super) edges: Vec<[u32; 2]>,
    /// Where the collapse of each edge puts the remaining vertex, as last computed.
    pub(super) target: Vec<[i32; 3]>,
    pub(super) quadrics: Vec<Quadric>,
    /// Vertices that must not move (shared with another region in the parallel phase).
    pub(super) frozen: Vec<bool>,
    pub(super) placement: Placement,
    /// Box of the input cells: placements stay inside it, hence on the grid.
    pub(super) bounds: ([i32; 3], [i32; 3]),
    /// Whether each edge is a seam to keep (empty: none; see `Constraints::seams`).
    pub(super) seam: Vec<bool>,
    /// Vertices that may survive a collapse, where they stay, but never vanish (empty: none;
    /// see `Constraints::pinned`).
    pub(super) pinned: Vec<bool>,
}

/// What the seams allow of a collapse of an edge.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum SeamRule {
    /// Either end may vanish.
    Free,
    /// Only the other end may vanish: this one survives.
    Survivor(u32),
    /// Neither may.
    Refused,
}

impl State {
    pub(super) fn new(
        cells: Vec<[i32; 3]>,
        faces: Vec<[u32; 3]>,
        quadrics: Vec<Quadric>,
        frozen: Vec<bool>,
        placement: Placement,
        bounds: ([i32; 3], [i32; 3]),
        t: Topology,
    ) -> State {
        State {
            face_alive: vec![true; faces.len()],
            vertex_alive: vec![true; cells.len()],
            target: vec![[0; 3]; t.edges.len()],
            vfaces: t.vfaces,
            vedges: t.vedges,
            edges: t.edges,
            cells,
            faces,
            quadrics,
            frozen,
            placement,
            bounds,
            seam: Vec::new(),
            pinned: Vec::new(),
        }
    }

    fn is_pinned(&self, v: u32) -> bool {
        self.pinned.get(v as usize).copied().unwrap_or(false)
    }

    /// The edge between `a` and `b`, if any.
    fn edge_between(&self, a: u32, b: u32) -> Option<u32> {
        self.vedges[a as usize]
            .iter()
            .copied()
            .find(|&e| self.other_end(e, a) == b)
    }

    fn is_seam(&self, a: u32, b: u32) -> bool {
        !self.seam.is_empty()
            && self
                .edge_between(a, b)
                .is_some_and(|e| self.seam[e as usize])
    }

    fn seams_at(&self, v: u32) -> usize {
        self.vedges[v as usize]
            .iter()
            .filter(|&&e| self.seam[e as usize])
            .count()
    }

    /// Which end of (a, b) may vanish without moving or joining seams: an end on no seam when
    /// the edge is none, an end on exactly two when the edge is one of them.
    /// A pinned end never vanishes.
    pub(super) fn seam_rule(&self, a: u32, b: u32) -> SeamRule {
        if self.seam.is_empty() && self.pinned.is_empty() {
            return SeamRule::Free;
        }
        let along = self.is_seam(a, b);
        let may_vanish = |v: u32| {
            if self.is_pinned(v) {
                return false;
            }
            if self.seam.is_empty() {
                return true;
            }
            let s = self.seams_at(v);
            if along {
                s == 2
            } else {
                s == 0
            }
        };
        match (may_vanish(a), may_vanish(b)) {
            (true, true) => SeamRule::Free,
            (true, false) => SeamRule::Survivor(b),
            (false, true) => SeamRule::Survivor(a),
            (false, false) => SeamRule::Refused,
        }
    }

    pub(super) fn normal(&self, f: [u32; 3], replace: u32, with: DVec3) -> DVec3 {
        let p = |v: u32| {
            if v == replace {
                with
            } else {
                to_f(self.cells[v as usize])
            }
        };
        let (a, b, c) = (p(f[0]), p(f[1]), p(f[2]));
        (b - a).cross(c - a)
    }

    pub(super) fn other_end(&self, e: u32, v: u32) -> u32 {
        let [x, y] = self.edges[e as usize];
        if x == v {
            y
        } else {
            x
        }
    }

    pub(super) fn neighbours(&self, v: u32, out: &mut Vec<u32>) {
        out.clear();
        out.extend(
            self.vedges[v as usize]
                .iter()
                .map(|&e| self.other_end(e, v)),
        );
    }

    /// Best position for collapsing (a, b) and its cost.
    pub(super) fn place(&self, a: u32, b: u32) -> ([i32; 3], f64) {
        // A survivor forced by the seams comes first, so that the endpoint and midpoint
        // placements are its own (vad_s = 0 holds for them).
        let (a, b) = match self.seam_rule(a, b) {
            SeamRule::Free => (a, b),
            SeamRule::Survivor(s) => (s, if s == a { b } else { a }),
            SeamRule::Refused => return (self.cells[a as usize], f64::INFINITY),
        };
        let forced = self.seam_rule(a, b) != SeamRule::Free;
        // A survivor on a seam the edge does not follow stays where it is; so does a pinned one.
        let stays = forced && (!self.is_seam(a, b) || self.is_pinned(a));
        let q = Quadric::sum(&self.quadrics[a as usize], &self.quadrics[b as usize]);
        let (ca, cb) = (self.cells[a as usize], self.cells[b as usize]);
        let mut best = (ca, q.error(to_f(ca)));
        let mut consider = |c: [i32; 3]| {
            let e = q.error(to_f(c));
            if e < best.1 {
                best = (c, e);
            }
        };
        if !stays {
            consider(cb);
            consider(anchor(1, ca, cb));
        }
        if !forced {
            consider(anchor(1, cb, ca));
        }
        if self.placement == Placement::Optimal && !self.is_pinned(a) {
            if let Some(p) = q.minimizer() {
                let lo = to_f(ca).min(to_f(cb));
                let hi = to_f(ca).max(to_f(cb));
                let span = (hi - lo).max_element().max(1.0);
                // An optimum far outside the edge's box is a numerical accident.
                if (p - (lo + hi) * 0.5).length() < 2.0 * span {
                    let (blo, bhi) = self.bounds;
                    let step = vad_s_step([cb[0] - ca[0], cb[1] - ca[1], cb[2] - ca[2]]);
                    let inverse_step = 1.0 / step as f64;
                    for end in [ca, cb] {
                        let snapped = [0, 1, 2].map(|a| {
                            // Rounds half away from zero, as f64::round, without a libm call.
                            let steps = (end[a] as f64 - p[a]) * inverse_step;
                            end[a] - (steps + 0.5f64.copysign(steps)) as i32 * step
                        });
                        if (0..3).all(|a| (blo[a]..=bhi[a]).contains(&snapped[a])) {
                            consider(snapped);
                        }
                    }
                }
            }
        }
        // Where the quadrics cannot tell edges apart (flat regions: error 0), shorter edges go
        // first; without this a vertex keeps winning ties and its valence explodes.
        let length2 = (to_f(ca) - to_f(cb)).length_squared();
        (best.0, best.1.max(0.0) + 1e-3 * length2)
    }

    /// Places edge `e` and returns its heap key.
    pub(super) fn place_edge(&mut self, e: u32) -> u64 {
        let [a, b] = self.edges[e as usize];
        let (p, cost) = self.place(a, b);
        self.target[e as usize] = p;
        heap_key(cost, e)
    }

    /// The collapse of (a, b) to `p` if it keeps the mesh valid.
    pub(super) fn check(
        &self,
        a: u32,
        b: u32,
        p: [i32; 3],
        scratch: &mut [Vec<u32>; 3],
    ) -> Option<Checked> {
        let mut edge_faces = [NIL; 2];
        let mut edge_face_count = 0;
        for &f in &self.vfaces[a as usize] {
            if self.faces[f as usize].contains(&b) {
                if edge_face_count == 2 {
                    return None;
                }
                edge_faces[edge_face_count] = f;
                edge_face_count += 1;
            }
        }
        let edge_faces = &edge_faces[..edge_face_count];
        if edge_faces.is_empty() {
            return None;
        }
        let [na, nb, _] = scratch;
        self.neighbours(a, na);
        self.neighbours(b, nb);
        let common = na.iter().filter(|&&x| x != b && nb.contains(&x)).count();
        if common != edge_faces.len() {
            return None; // link condition
        }
        // On a manifold, a vertex has as many edges as faces unless it is on a boundary.
        let (bound_a, bound_b) = (
            na.len() != self.vfaces[a as usize].len(),
            nb.len() != self.vfaces[b as usize].len(),
        );
        if edge_faces.len() == 2 && bound_a && bound_b {
            return None;
        }
        // Directed edge u → w lies in face f?
        let holds = |f: u32, u: u32, w: u32| {
            let t = self.faces[f as usize];
            (0..3).any(|k| t[k] == u && t[(k + 1) % 3] == w)
        };
        let third = |f: u32, u: u32, w: u32| {
            *self.faces[f as usize]
                .iter()
                .find(|&&x| x != u && x != w)
                .expect("third corner")
        };
        // Survivor: for a boundary edge, the face must hold vt → vs; else the endpoint nearer p.
        let (vs, vt) = if edge_faces.len() == 1 {
            if holds(edge_faces[0], b, a) {
                (a, b)
            } else {
                (b, a)
            }
        } else {
            let da = (to_f(self.cells[a as usize]) - to_f(p)).length_squared();
            let db = (to_f(self.cells[b as usize]) - to_f(p)).length_squared();
            if da <= db {
                (a, b)
            } else {
                (b, a)
            }
        };
        let (vs, vt) = match self.seam_rule(a, b) {
            SeamRule::Free => (vs, vt),
            SeamRule::Refused => return None,
            SeamRule::Survivor(s) if edge_faces.len() == 1 && s != vs => return None,
            SeamRule::Survivor(s) => (s, if s == a { b } else { a }),
        };
        let fl = *edge_faces.iter().find(|&&f| holds(f, vt, vs))?;
        let fr = edge_faces
            .iter()
            .copied()
            .find(|&f| holds(f, vs, vt))
            .unwrap_or(NIL);
        let (vl, vr) = (
            third(fl, vs, vt),
            if fr == NIL { NIL } else { third(fr, vs, vt) },
        );
        // Along a seam, fl and fr must not be wholly inside seams (two seams would join).
        if self.is_seam(vs, vt) {
            for v in [vl, vr] {
                if v != NIL && self.is_seam(vs, v) && self.is_seam(vt, v) {
                    return None;
                }
            }
        }
        // A split that gives vt no old face is located from vs's faces across (vs, vl) and
        // (vs, vr): they must exist.
        let vt_keeps_none = self.vfaces[vt as usize].iter().all(|&f| f == fl || f == fr);
        if !vt_keeps_none {
            // The moved faces must start at vl and end at vr: the faces across (vl, vt) and
            // (vt, vr) exist (otherwise the split could not be located from flclw).
            let beyond = |u: u32, w: u32, not: u32| {
                self.vfaces[vt as usize]
                    .iter()
                    .any(|&f| f != not && holds(f, u, w))
            };
            if !beyond(vt, vl, fl) || (fr != NIL && !beyond(vr, vt, fr)) {
                return None;
            }
        }
        if vt_keeps_none {
            let beside = |u: u32, w: u32, not: u32| {
                self.vfaces[vs as usize]
                    .iter()
                    .any(|&f| f != not && holds(f, u, w))
            };
            if !beside(vl, vs, fl) || (fr != NIL && !beside(vs, vr, fr)) {
                return None;
            }
        }
        let pf = to_f(p);
        // No fold-over, no degenerate face.
        for &v in &[a, b] {
            for &f in &self.vfaces[v as usize] {
                if f == fl || f == fr {
                    continue;
                }
                let t = self.faces[f as usize];
                let old = self.normal(t, NIL, DVec3::ZERO);
                let new = self.normal(t, v, pf);
                if new.length_squared() == 0.0 || old.dot(new) <= 0.0 {
                    return None;
                }
            }
        }
        // No two faces on the same three vertices afterwards.
        let [_, _, keys] = scratch;
        keys.clear();
        for &f in &self.vfaces[vs as usize] {
            if f != fl && f != fr {
                let mut t = self.faces[f as usize];
                t.sort_unstable();
                keys.push(t[0] ^ t[1].rotate_left(11) ^ t[2].rotate_left(22));
            }
        }
        for &f in &self.vfaces[vt as usize] {
            if f == fl || f == fr {
                continue;
            }
            let mut t = self.faces[f as usize].map(|x| if x == vt { vs } else { x });
            t.sort_unstable();
            let key = t[0] ^ t[1].rotate_left(11) ^ t[2].rotate_left(22);
            if keys.contains(&key) {
                let clash = self.vfaces[vs as usize].iter().any(|&g| {
                    let mut u = self.faces[g as usize];
                    u.sort_unstable();
                    g != fl && g != fr && u == t
                });
                if clash {
                    return None;
                }
            }
        }
        Some((vs, vt, fl, fr, vl, vr))
    }

    /// Collapses vt into vs at `p`, and records it.
    pub(super) fn collapse(&mut self, (vs, vt, fl, fr, vl, vr): Checked, p: [i32; 3]) -> Collapse {
        let moved: SmallVec<[u32; 6]> = self.vfaces[vt as usize]
            .iter()
            .copied()
            .filter(|&f| f != fl && f != fr)
            .collect();
        let across = |other: u32, not: u32| {
            if other == NIL {
                return NIL;
            }
            self.vfaces[vs as usize]
                .iter()
                .copied()
                .find(|&f| f != not && self.faces[f as usize].contains(&other))
                .unwrap_or(NIL)
        };
        let beside = [across(vl, fl), across(vr, fr)];
        let corner = |f: u32, v: u32| {
            self.faces[f as usize]
                .iter()
                .position(|&x| x == v)
                .expect("a corner of the face") as u8
        };
        let on_vt_vl = moved.iter().copied().find(|&f| {
            let t = self.faces[f as usize];
            (0..3).any(|k| t[k] == vt && t[(k + 1) % 3] == vl)
        });
        let (flclw, flclw_corner) = match on_vt_vl {
            Some(f) => (f, corner(f, vt)),
            None => (beside[0], corner(beside[0], vs)),
        };
        let vs_corners = [corner(fl, vs), if fr == NIL { 0 } else { corner(fr, vs) }];
        let record = Collapse {
            vs,
            vt,
            before: [self.cells[vs as usize], self.cells[vt as usize]],
            after: p,
            fl,
            fr,
            vl,
            vr,
            moved,
            beside,
            flclw,
            flclw_corner,
            vs_corners,
        };
        for &f in &record.moved {
            for x in self.faces[f as usize].iter_mut() {
                if *x == vt {
                    *x = vs;
                }
            }
        }
        for f in [fl, fr] {
            if f == NIL {
                continue;
            }
            self.face_alive[f as usize] = false;
            for v in self.faces[f as usize] {
                self.vfaces[v as usize].retain(|g| *g != f);
            }
        }
        self.vfaces[vs as usize].extend_from_slice(&record.moved);
        self.vfaces[vt as usize] = Incident::new();
        // vt's edges: to vs it vanishes; to vl and vr it merges into vs's edge; the rest now
        // end at vs.
        if !self.seam.is_empty() {
            for w in [vl, vr] {
                if w != NIL && self.is_seam(vt, w) {
                    if let Some(kept) = self.edge_between(vs, w) {
                        self.seam[kept as usize] = true;
                    }
                }
            }
        }
        for e in std::mem::take(&mut self.vedges[vt as usize]) {
            let w = self.other_end(e, vt);
            if w == vs || w == vl || w == vr {
                self.vedges[w as usize].retain(|g| *g != e);
            } else {
                let ends = &mut self.edges[e as usize];
                *ends = ends.map(|x| if x == vt { vs } else { x });
                self.vedges[vs as usize].push(e);
            }
        }
        self.vertex_alive[vt as usize] = false;
        let qt = self.quadrics[vt as usize];
        self.quadrics[vs as usize].add(&qt);
        self.cells[vs as usize] = p;
        record
    }
}

/// Faces around each vertex, the edges of the live faces (sorted by their ends) with how many
/// faces hold each (1: a boundary edge), and the edges around each vertex.
pub(in crate::hierarchy) struct Topology {
    pub(super) vfaces: Vec<Incident>,
    pub(in crate::hierarchy) edges: Vec<[u32; 2]>,
    pub(super) edge_faces: Vec<u32>,
    pub(super) vedges: Vec<Incident>,
}

pub(in crate::hierarchy) fn topology(n: usize, faces: &[[u32; 3]], alive: &[bool]) -> Topology {
    let mut vfaces = vec![Incident::new(); n];
    for (f, t) in faces.iter().enumerate().filter(|&(f, _)| alive[f]) {
        for &v in t {
            vfaces[v as usize].push(f as u32);
        }
    }
    let mut half_edges: Vec<(u32, u32)> = faces
        .par_iter()
        .zip(alive)
        .filter(|(_, &alive)| alive)
        .flat_map_iter(|(t, _)| {
            (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])))
        })
        .collect();
    half_edges.par_sort_unstable();
    let mut edges: Vec<[u32; 2]> = Vec::with_capacity(half_edges.len() / 2 + 1);
    let mut edge_faces: Vec<u32> = Vec::with_capacity(half_edges.len() / 2 + 1);
    for &(u, w) in &half_edges {
        if edges.last() == Some(&[u, w]) {
            *edge_faces.last_mut().expect("an edge") += 1;
        } else {
            edges.push([u, w]);
            edge_faces.push(1);
        }
    }
    let mut vedges = vec![Incident::new(); n];
    for (e, &[u, w]) in edges.iter().enumerate() {
        vedges[u as usize].push(e as u32);
        vedges[w as usize].push(e as u32);
    }
    Topology {
        vfaces,
        edges,
        edge_faces,
        vedges,
    }
}

impl State {
    /// One pass of greedy collapses, cheapest first, over every edge without a frozen end, until
    /// none passes the checks or the cheapest costs more than `max_cost`. Appends the collapses
    /// and their costs.
    pub(super) fn collapse_greedily(
        &mut self,
        max_cost: f32,
        collapses: &mut Vec<Collapse>,
        costs: &mut Vec<f32>,
    ) -> usize {
        let edge_count = self.edges.len();
        let movable = |state: &State, e: u32| {
            let [a, b] = state.edges[e as usize];
            !state.frozen[a as usize] && !state.frozen[b as usize]
        };
        let live: Vec<u32> = (0..edge_count as u32)
            .filter(|&e| {
                let [a, b] = self.edges[e as usize];
                self.vertex_alive[a as usize]
                    && self.vedges[a as usize].contains(&e)
                    && self.vertex_alive[b as usize]
                    && movable(self, e)
            })
            .collect();
        let placed: Vec<(usize, u64, [i32; 3])> = live
            .par_iter()
            .map(|&e| {
                let [a, b] = self.edges[e as usize];
                let (p, cost) = self.place(a, b);
                (e as usize, heap_key(cost, e), p)
            })
            .collect();
        for &(e, _, p) in &placed {
            self.target[e] = p;
        }
        let mut queue: DaryHeapOfIndices<usize, u64, 8> =
            DaryHeapOfIndices::from_iter_with_index_bound(
                edge_count,
                placed.into_iter().map(|(e, key, _)| (e, key)),
            );
        let mut scratch: [Vec<u32>; 3] = Default::default();
        let mut made = 0;
        while let Some((e, key)) = queue.pop() {
            let cost = f32::from_bits((key >> 32) as u32);
            if cost > max_cost {
                break;
            }
            let [a, b] = self.edges[e];
            let p = self.target[e];
            let Some(checked) = self.check(a, b, p, &mut scratch) else {
                continue;
            };
            let (vs, vt, vl, vr) = (checked.0, checked.1, checked.4, checked.5);
            // vt's edges to vl and vr merge into vs's; its others are re-placed below.
            for &gone in &self.vedges[vt as usize] {
                let w = self.other_end(gone, vt);
                if (w == vl || w == vr) && queue.contains(&(gone as usize)) {
                    queue.remove(&(gone as usize));
                }
            }
            collapses.push(self.collapse(checked, p));
            costs.push(cost);
            made += 1;
            for i in 0..self.vedges[vs as usize].len() {
                let e = self.vedges[vs as usize][i];
                if movable(self, e) {
                    let key = self.place_edge(e);
                    queue.update_key_or_push(&(e as usize), key);
                }
            }
        }
        made
    }
}
