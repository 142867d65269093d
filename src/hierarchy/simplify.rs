//! Garland–Heckbert quadric error simplification by edge collapses, and the progressive mesh it
//! defines (Hoppe: base mesh M⁰ plus the vertex splits that undo the collapses in reverse).
//!
//! Collapses are taken cheapest first from an indexed 8-ary heap of edges (each edge's key is
//! updated in place when a collapse changes it, so the heap never holds stale entries), and
//! simplification is O(f log f). Each vertex keeps its faces and its edges, so a check reads
//! only the two endpoints' lists. A collapse must keep the mesh a manifold
//! (link condition; no interior edge between two boundary vertices; no two faces on the same
//! three vertices), must not flip a face's normal, and keeps boundaries through constraint
//! quadrics on boundary edges. When the heap runs dry, every edge is queued again, until a
//! whole pass collapses nothing: the base mesh is then as small as these rules allow.
//!
//! Meshes of 200,000 faces or more are first simplified in parallel: a k-d split of the vertices
//! makes regions of 16k-32k faces, each collapses its own edges greedily on a compact copy (small
//! enough to stay in cache) up to a common cost (a high quantile of the initial costs) with the
//! vertices it shares with another region frozen, and the regions' collapses are interleaved
//! cheapest first. No two regions touch the same face, so any interleaving is a valid sequence.
//! A second round cuts what remains along diagonal planes, across the first round's seams, up to
//! the same cost; the single greedy loop does the rest.
//!
//! The progressive mesh needs no replay of the splits: each collapse records the face its split
//! is located from and which corners hold vs, and once the face ids a decoder will assign are
//! known (one pass in split order), every Vsplit record follows from its collapse alone.

use super::pmesh::{anchor, PmMesh, Rotation, Vsplit, NIL};
use glam::DVec3;
use orx_priority_queue::{DaryHeapOfIndices, PriorityQueue, PriorityQueueDecKey};
use rayon::prelude::*;
use smallvec::SmallVec;

/// Where a collapse puts the remaining vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placement {
    /// Where the summed quadric is smallest (rounded to a cell), else the best endpoint or
    /// midpoint.
    Optimal,
    /// One of the endpoints or their midpoint (Hoppe §6: vad_s = 0).
    EndpointOrMidpoint,
}

/// A symmetric 4 × 4 quadric: a2 ab ac ad b2 bc bd c2 cd d2.
#[derive(Clone, Copy, Debug, Default)]
struct Quadric([f64; 10]);

impl Quadric {
    fn plane(n: DVec3, d: f64, w: f64) -> Quadric {
        let (a, b, c) = (n.x, n.y, n.z);
        Quadric(
            [
                a * a,
                a * b,
                a * c,
                a * d,
                b * b,
                b * c,
                b * d,
                c * c,
                c * d,
                d * d,
            ]
            .map(|x| x * w),
        )
    }
    fn add(&mut self, o: &Quadric) {
        for i in 0..10 {
            self.0[i] += o.0[i];
        }
    }
    fn sum(a: &Quadric, b: &Quadric) -> Quadric {
        let mut q = *a;
        q.add(b);
        q
    }
    fn error(&self, p: DVec3) -> f64 {
        let q = &self.0;
        let (x, y, z) = (p.x, p.y, p.z);
        x * x * q[0]
            + 2.0 * x * y * q[1]
            + 2.0 * x * z * q[2]
            + 2.0 * x * q[3]
            + y * y * q[4]
            + 2.0 * y * z * q[5]
            + 2.0 * y * q[6]
            + z * z * q[7]
            + 2.0 * z * q[8]
            + q[9]
    }
    fn minimizer(&self) -> Option<DVec3> {
        let q = &self.0;
        let m = glam::DMat3::from_cols(
            DVec3::new(q[0], q[1], q[2]),
            DVec3::new(q[1], q[4], q[5]),
            DVec3::new(q[2], q[5], q[7]),
        );
        let det = m.determinant();
        let scale = (q[0] + q[4] + q[7]).powi(3).abs().max(f64::MIN_POSITIVE);
        if det.abs() < 1e-9 * scale {
            return None;
        }
        Some(m.inverse() * -DVec3::new(q[3], q[6], q[8]))
    }
}

/// One edge collapse, recorded with what its inverse split needs.
#[derive(Clone, Debug)]
pub struct Collapse {
    /// Remaining vertex.
    pub vs: u32,
    /// Removed vertex.
    pub vt: u32,
    /// Positions of vs and vt before the collapse.
    pub before: [[i32; 3]; 2],
    /// Position of vs after it.
    pub after: [i32; 3],
    /// Removed faces: fl holds directed edge vt → vs, fr (or NIL) vs → vt.
    pub fl: u32,
    /// See `fl`.
    pub fr: u32,
    /// Third corners of fl and fr (vr NIL when fr is).
    pub vl: u32,
    /// See `vl`.
    pub vr: u32,
    /// Faces of vt other than fl and fr, which now hold vs.
    pub moved: SmallVec<[u32; 6]>,
    /// Faces across (vs, vl) from fl and across (vs, vr) from fr (NIL where none): the split
    /// re-links them.
    pub beside: [u32; 2],
    /// The face the split is located from (Hoppe's flclw): the moved face on edge (vt, vl), or
    /// `beside[0]` when none moves.
    pub flclw: u32,
    /// Corner of flclw that holds vs after the collapse.
    pub flclw_corner: u8,
    /// Corners of fl and fr that hold vs (fr's is 0 when there is no fr).
    pub vs_corners: [u8; 2],
}

/// The result of simplification: collapses in order, and what remains.
pub struct Simplified {
    /// Collapses, first to last.
    pub collapses: Vec<Collapse>,
    /// Which vertices remain.
    pub vertex_alive: Vec<bool>,
    /// Which faces remain.
    pub face_alive: Vec<bool>,
    /// Positions after simplification.
    pub positions: Vec<[i32; 3]>,
    /// Faces (remaining ones valid) after simplification.
    pub faces: Vec<[u32; 3]>,
}

/// Heap key of an edge: its cost's bits above its id. Costs are never negative, so their bits
/// order as the costs do; the id breaks ties, for determinism.
fn heap_key(cost: f64, edge: u32) -> u64 {
    (u64::from((cost as f32).to_bits()) << 32) | u64::from(edge)
}

/// Grid step of a split's small delta vad_s: positions between a collapse and its split need
/// not be finer than 1/32 of the split's length, so the optimal placement is snapped to
/// multiples of this step from an endpoint (the full mesh stays exact: vad_l is not snapped).
pub fn vad_s_step(vad_l: [i32; 3]) -> i32 {
    let m = vad_l.iter().map(|x| x.unsigned_abs()).max().unwrap_or(0);
    let bits = 32 - m.leading_zeros();
    1 << bits.saturating_sub(5)
}

fn to_f(c: [i32; 3]) -> DVec3 {
    DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64)
}

/// Faces or edges around one vertex: most vertices have few, kept inline.
type Incident = SmallVec<[u32; 8]>;

/// A collapse that passed the checks: (vs, vt, fl, fr, vl, vr) as in [`Collapse`].
type Checked = (u32, u32, u32, u32, u32, u32);

struct State {
    cells: Vec<[i32; 3]>,
    faces: Vec<[u32; 3]>,
    face_alive: Vec<bool>,
    vertex_alive: Vec<bool>,
    /// Faces around each vertex.
    vfaces: Vec<Incident>,
    /// Edges around each vertex (ids into `edges`).
    vedges: Vec<Incident>,
    /// Both ends of each edge; an edge collapsed away or merged into another is in no `vedges`.
    edges: Vec<[u32; 2]>,
    /// Where the collapse of each edge puts the remaining vertex, as last computed.
    target: Vec<[i32; 3]>,
    quadrics: Vec<Quadric>,
    /// Vertices that must not move (shared with another region in the parallel phase).
    frozen: Vec<bool>,
    placement: Placement,
    /// Box of the input cells: placements stay inside it, hence on the grid.
    bounds: ([i32; 3], [i32; 3]),
}

impl State {
    fn new(
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
        }
    }

    fn normal(&self, f: [u32; 3], replace: u32, with: DVec3) -> DVec3 {
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

    fn other_end(&self, e: u32, v: u32) -> u32 {
        let [x, y] = self.edges[e as usize];
        if x == v {
            y
        } else {
            x
        }
    }

    fn neighbours(&self, v: u32, out: &mut Vec<u32>) {
        out.clear();
        out.extend(
            self.vedges[v as usize]
                .iter()
                .map(|&e| self.other_end(e, v)),
        );
    }

    /// Best position for collapsing (a, b) and its cost.
    fn place(&self, a: u32, b: u32) -> ([i32; 3], f64) {
        let q = Quadric::sum(&self.quadrics[a as usize], &self.quadrics[b as usize]);
        let (ca, cb) = (self.cells[a as usize], self.cells[b as usize]);
        let mut best = (ca, q.error(to_f(ca)));
        let mut consider = |c: [i32; 3]| {
            let e = q.error(to_f(c));
            if e < best.1 {
                best = (c, e);
            }
        };
        consider(cb);
        consider(anchor(1, ca, cb));
        consider(anchor(1, cb, ca));
        if self.placement == Placement::Optimal {
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
    fn place_edge(&mut self, e: u32) -> u64 {
        let [a, b] = self.edges[e as usize];
        let (p, cost) = self.place(a, b);
        self.target[e as usize] = p;
        heap_key(cost, e)
    }

    /// The collapse of (a, b) to `p` if it keeps the mesh valid.
    fn check(&self, a: u32, b: u32, p: [i32; 3], scratch: &mut [Vec<u32>; 3]) -> Option<Checked> {
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
    fn collapse(&mut self, (vs, vt, fl, fr, vl, vr): Checked, p: [i32; 3]) -> Collapse {
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
struct Topology {
    vfaces: Vec<Incident>,
    edges: Vec<[u32; 2]>,
    edge_faces: Vec<u32>,
    vedges: Vec<Incident>,
}

fn topology(n: usize, faces: &[[u32; 3]], alive: &[bool]) -> Topology {
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

/// Face planes (area-weighted) and boundary constraint planes, summed per vertex in parallel.
fn initial_quadrics(cells: &[[i32; 3]], faces: &[[u32; 3]], topology: &Topology) -> Vec<Quadric> {
    let Topology {
        vfaces,
        edges,
        edge_faces,
        vedges,
    } = topology;
    let face_quadric = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|v| to_f(cells[v as usize]));
        let cross = (b - a).cross(c - a);
        let area2 = cross.length();
        if area2 == 0.0 {
            return Quadric::default();
        }
        let n = cross / area2;
        Quadric::plane(n, -n.dot(a), area2 * 0.5)
    };
    let is_boundary = |v: u32, w: u32| {
        vedges[v as usize]
            .iter()
            .any(|&e| edges[e as usize].contains(&w) && edge_faces[e as usize] == 1)
    };
    (0..cells.len())
        .into_par_iter()
        .map(|v| {
            let mut q = Quadric::default();
            let on_boundary = vedges[v].iter().any(|&e| edge_faces[e as usize] == 1);
            for &f in &vfaces[v] {
                let t = faces[f as usize];
                q.add(&face_quadric(&t));
                if !on_boundary {
                    continue;
                }
                for k in 0..3 {
                    let (u, w) = (t[k], t[(k + 1) % 3]);
                    if (u == v as u32 || w == v as u32) && is_boundary(u, w) {
                        let (pu, pw) = (to_f(cells[u as usize]), to_f(cells[w as usize]));
                        let [a, b, c] = t.map(|x| to_f(cells[x as usize]));
                        let normal = (b - a).cross(c - a);
                        let side = (pw - pu).cross(normal);
                        if side.length_squared() > 0.0 {
                            let m = side.normalize();
                            let weight = 100.0 * (pw - pu).length_squared();
                            q.add(&Quadric::plane(m, -m.dot(pu), weight));
                        }
                    }
                }
            }
            q
        })
        .collect()
}

impl State {
    /// One pass of greedy collapses, cheapest first, over every edge without a frozen end, until
    /// none passes the checks or the cheapest costs more than `max_cost`. Appends the collapses
    /// and their costs.
    fn collapse_greedily(
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

/// Meshes below this many faces are simplified by one greedy loop; larger ones first in
/// regions, in parallel.
const REGION_MIN_FACES: usize = 200_000;
/// Faces per region in the first round. Small regions keep a greedy loop's data in cache: on
/// bunny-closed-35k ×16, regions of 140k faces collapse at 3.2 µs per collapse, of 35k at
/// 2.0 µs; 17k made the whole 7% faster than 35k.
const REGION_FACES: usize = 1 << 14;
/// At most this many regions (region ids are bytes).
const MAX_REGIONS: usize = 128;
/// Regions of the second round, which cuts across the first round's seams.
const SECOND_ROUND_REGIONS: usize = 8;
/// The first round makes the collapses cheaper than this quantile of its initial edge costs;
/// the seams go to the second round, which stops at the same cost, and the costlier collapses
/// to the last greedy loop. Measured with one round of 8 regions on bunny-closed-35k ×16: 0.5
/// leaves 50% of the collapses to the global loop, 0.97 leaves 7%. With both rounds, on
/// bunny-closed-35k ×4 (278k faces), the RMS error of every level stays within 2% of one
/// greedy loop (most of them better) and the stream grows 0.06%.
const REGION_COST_QUANTILE: f64 = 0.985;
/// About this many evenly spaced edges are placed to estimate that quantile.
const REGION_COST_SAMPLES: usize = 1 << 16;

/// The faces `face_ids` in `count` regions (a power of two): each face goes where its first
/// corner is in a k-d split of their vertices into sets of equal size, each set halved across
/// the one of `directions` along which it is longest.
fn split_into_regions(
    cells: &[[i32; 3]],
    faces: &[[u32; 3]],
    face_ids: &[u32],
    directions: &[[i64; 3]],
    count: usize,
) -> Vec<Vec<u32>> {
    let along = |d: &[i64; 3], v: u32| -> i64 {
        let c = cells[v as usize];
        (0..3).map(|a| d[a] * i64::from(c[a])).sum()
    };
    let split = |ids: &mut [u32]| {
        if ids.len() < 2 {
            return 0;
        }
        let extent = |d: &[i64; 3]| {
            let (lo, hi) = ids.par_iter().map(|&v| (along(d, v), along(d, v))).reduce(
                || (i64::MAX, i64::MIN),
                |(lo, hi), (l, h)| (lo.min(l), hi.max(h)),
            );
            hi.saturating_sub(lo)
        };
        let d = directions
            .iter()
            .max_by_key(|d| extent(d))
            .expect("a direction");
        let middle = ids.len() / 2;
        ids.select_nth_unstable_by_key(middle, |&v| (along(d, v), v));
        middle
    };
    let mut ids: Vec<u32> = face_ids.iter().map(|&f| faces[f as usize][0]).collect();
    ids.sort_unstable();
    ids.dedup();
    // Halve every set until there are `count`.
    let mut sets: Vec<&mut [u32]> = vec![&mut ids];
    while sets.len() < count {
        sets = sets
            .into_par_iter()
            .flat_map_iter(|set| {
                let middle = split(set);
                let (low, high) = set.split_at_mut(middle);
                [low, high]
            })
            .collect();
    }
    let mut vertex_region = vec![0u8; cells.len()];
    for (r, set) in sets.iter().enumerate() {
        for &v in set.iter() {
            vertex_region[v as usize] = r as u8;
        }
    }
    let mut regions = vec![Vec::new(); count];
    for &f in face_ids {
        regions[vertex_region[faces[f as usize][0] as usize] as usize].push(f);
    }
    regions
}

/// The mesh as the region phase keeps it: parts of it are simplified on compact copies and
/// written back.
struct Whole {
    cells: Vec<[i32; 3]>,
    faces: Vec<[u32; 3]>,
    quadrics: Vec<Quadric>,
    vertex_alive: Vec<bool>,
    face_alive: Vec<bool>,
    placement: Placement,
    bounds: ([i32; 3], [i32; 3]),
}

impl Whole {
    fn live_faces(&self) -> Vec<u32> {
        (0..self.faces.len() as u32)
            .filter(|&f| self.face_alive[f as usize])
            .collect()
    }
}

/// The vertices of some faces (sorted) and the faces in their indices.
fn compact(faces: &[[u32; 3]], face_ids: &[u32]) -> (Vec<u32>, Vec<[u32; 3]>) {
    let mut vertices: Vec<u32> = face_ids.iter().flat_map(|&f| faces[f as usize]).collect();
    vertices.sort_unstable();
    vertices.dedup();
    let local = |v: u32| vertices.binary_search(&v).expect("a corner") as u32;
    let local_faces = face_ids
        .iter()
        .map(|&f| faces[f as usize].map(local))
        .collect();
    (vertices, local_faces)
}

/// Some faces of the whole mesh, on a compact copy that keeps what a greedy loop touches in
/// cache.
struct Part {
    state: State,
    /// Whole-mesh id of each vertex and face of the part.
    vertices: Vec<u32>,
    face_ids: Vec<u32>,
}

/// What a part's simplification made, in whole-mesh ids.
struct RegionRun {
    collapses: Vec<Collapse>,
    costs: Vec<f32>,
    /// Whole-mesh id of each vertex of the part, and its final state.
    vertices: Vec<u32>,
    cells: Vec<[i32; 3]>,
    quadrics: Vec<Quadric>,
    vertex_alive: Vec<bool>,
    /// Whole-mesh id of each face of the part, and its final corners (whole-mesh ids) and state.
    face_ids: Vec<u32>,
    faces: Vec<[u32; 3]>,
    face_alive: Vec<bool>,
}

impl Part {
    /// The faces `face_ids` of `whole`, with the `frozen` vertices left where they are. With
    /// `own_quadrics` the part sums its vertices' quadrics itself, which is exact for every
    /// vertex whose faces all lie in the part; otherwise it takes them from `whole`.
    fn new(whole: &Whole, face_ids: Vec<u32>, frozen: &[bool], own_quadrics: bool) -> Part {
        let (vertices, faces) = compact(&whole.faces, &face_ids);
        let topology = topology(vertices.len(), &faces, &vec![true; faces.len()]);
        let cells: Vec<[i32; 3]> = vertices.iter().map(|&v| whole.cells[v as usize]).collect();
        let quadrics = if own_quadrics {
            initial_quadrics(&cells, &faces, &topology)
        } else {
            vertices
                .iter()
                .map(|&v| whole.quadrics[v as usize])
                .collect()
        };
        let state = State::new(
            cells,
            faces,
            quadrics,
            vertices.iter().map(|&v| frozen[v as usize]).collect(),
            whole.placement,
            whole.bounds,
            topology,
        );
        Part {
            state,
            vertices,
            face_ids,
        }
    }

    /// Collapse costs of every `stride`-th edge that may collapse.
    fn sample_costs(&self, stride: usize) -> Vec<f32> {
        let state = &self.state;
        state
            .edges
            .iter()
            .filter(|&&[a, b]| !state.frozen[a as usize] && !state.frozen[b as usize])
            .step_by(stride)
            .map(|&[a, b]| state.place(a, b).1 as f32)
            .collect()
    }

    /// Simplifies the part greedily up to `max_cost`: one pass, or with `until_dry` passes until
    /// one collapses nothing.
    fn simplify(self, max_cost: f32, until_dry: bool) -> RegionRun {
        let Part {
            state: mut region,
            vertices,
            face_ids,
        } = self;
        let (mut local_collapses, mut costs) = (Vec::new(), Vec::new());
        loop {
            let made = region.collapse_greedily(max_cost, &mut local_collapses, &mut costs);
            if made == 0 || !until_dry {
                break;
            }
        }
        let global_vertex = |v: u32| if v == NIL { NIL } else { vertices[v as usize] };
        let global_face = |f: u32| if f == NIL { NIL } else { face_ids[f as usize] };
        let collapses = local_collapses
            .into_iter()
            .map(|c| Collapse {
                vs: global_vertex(c.vs),
                vt: global_vertex(c.vt),
                vl: global_vertex(c.vl),
                vr: global_vertex(c.vr),
                fl: global_face(c.fl),
                fr: global_face(c.fr),
                moved: c.moved.iter().map(|&f| global_face(f)).collect(),
                beside: c.beside.map(global_face),
                flclw: global_face(c.flclw),
                ..c
            })
            .collect();
        RegionRun {
            collapses,
            costs,
            faces: region.faces.iter().map(|t| t.map(global_vertex)).collect(),
            cells: region.cells,
            quadrics: region.quadrics,
            vertex_alive: region.vertex_alive,
            face_alive: region.face_alive,
            vertices,
            face_ids,
        }
    }
}

impl RegionRun {
    /// Copies the run's faces and its vertices but the `frozen` ones back into `whole`.
    fn write_back(&self, whole: &mut Whole, frozen: &[bool]) {
        for (i, &v) in self.vertices.iter().enumerate() {
            if !frozen[v as usize] {
                whole.cells[v as usize] = self.cells[i];
                whole.quadrics[v as usize] = self.quadrics[i];
                whole.vertex_alive[v as usize] = self.vertex_alive[i];
            }
        }
        for (i, &f) in self.face_ids.iter().enumerate() {
            whole.faces[f as usize] = self.faces[i];
            whole.face_alive[f as usize] = self.face_alive[i];
        }
    }
}

/// Simplification in regions, in parallel, then one greedy loop for what remains.
///
/// In a round, each region collapses its own edges, greedily, with the vertices it shares with
/// other regions frozen, so that no two regions touch the same face or vertex and their
/// collapses can be interleaved in any order. The interleaving follows the costs (always the
/// cheapest next collapse of any region), so the sequence stays close to one greedy loop. The
/// first round cuts the mesh along the axes; the second cuts what remains along diagonal
/// planes, so that it collapses across the first round's seams. The last greedy loop does the
/// second round's seams and the costliest collapses.
///
/// No topology of the whole mesh is built: in the first round each region sums its own
/// quadrics (exact for its unshared vertices, all of whose faces it holds) and the shared
/// vertices get theirs from the band of faces around them.
fn simplify_in_regions(
    cells: &[[i32; 3]],
    faces: &[[u32; 3]],
    placement: Placement,
    bounds: ([i32; 3], [i32; 3]),
) -> Simplified {
    let n = cells.len();
    let mut whole = Whole {
        cells: cells.to_vec(),
        faces: faces.to_vec(),
        quadrics: vec![Quadric::default(); n],
        vertex_alive: vec![true; n],
        face_alive: vec![true; faces.len()],
        placement,
        bounds,
    };
    let axes = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
    let all: Vec<u32> = (0..faces.len() as u32).collect();
    // Regions of REGION_FACES to twice that many faces (a power of two of them).
    let count = (1usize << (faces.len() / REGION_FACES).max(2).ilog2()).min(MAX_REGIONS);
    let regions = split_into_regions(cells, faces, &all, &axes, count);
    let (first_runs, max_cost) = collapse_round(&mut whole, regions, None);
    // The first round's collapses are put in order while the rest are made.
    let (mut collapses, mut later) = rayon::join(
        || interleave(first_runs),
        || simplify_rest(&mut whole, max_cost),
    );
    collapses.append(&mut later);
    Simplified {
        collapses,
        vertex_alive: whole.vertex_alive,
        face_alive: whole.face_alive,
        positions: whole.cells,
        faces: whole.faces,
    }
}

/// After the first round: the second round, then one greedy loop over what remains.
fn simplify_rest(whole: &mut Whole, max_cost: f32) -> Vec<Collapse> {
    let n = whole.cells.len();
    let diagonals = [[1, 1, 1], [1, 1, -1], [1, -1, 1], [-1, 1, 1]];
    let regions = split_into_regions(
        &whole.cells,
        &whole.faces,
        &whole.live_faces(),
        &diagonals,
        SECOND_ROUND_REGIONS,
    );
    let (second_runs, _) = collapse_round(whole, regions, Some(max_cost));
    let mut collapses = interleave(second_runs);
    // What remains; when a pass runs dry, every remaining edge is queued again, until a pass
    // collapses nothing.
    let none_frozen = vec![false; n];
    let live = whole.live_faces();
    let mut rest = Part::new(whole, live, &none_frozen, false).simplify(f32::INFINITY, true);
    collapses.append(&mut rest.collapses);
    rest.write_back(whole, &none_frozen);
    collapses
}

/// Each region's collapses, with their costs.
type Streams = Vec<(Vec<Collapse>, Vec<f32>)>;

/// One round of the region phase over `regions` (faces of `whole`): up to `max_cost`, or in
/// the first round (`None`) up to a quantile of the initial costs. Returns each region's
/// collapses and the cost it stopped at. The first round's regions sum the quadrics of the
/// input mesh.
fn collapse_round(
    whole: &mut Whole,
    regions: Vec<Vec<u32>>,
    max_cost: Option<f32>,
) -> (Streams, f32) {
    let first = max_cost.is_none();
    let n = whole.cells.len();
    let mut region_of = vec![u32::MAX; n];
    let mut shared = vec![false; n];
    for (r, face_ids) in regions.iter().enumerate() {
        for &f in face_ids {
            for v in whole.faces[f as usize] {
                let slot = &mut region_of[v as usize];
                if *slot == u32::MAX {
                    *slot = r as u32;
                } else if *slot != r as u32 {
                    shared[v as usize] = true;
                }
            }
        }
    }
    if first {
        // Quadrics of the shared vertices, from the band of faces around them.
        let band: Vec<u32> = regions
            .iter()
            .flatten()
            .copied()
            .filter(|&f| whole.faces[f as usize].iter().any(|&v| shared[v as usize]))
            .collect();
        let band = Part::new(whole, band, &shared, true);
        for (&v, q) in band.vertices.iter().zip(&band.state.quadrics) {
            if shared[v as usize] {
                whole.quadrics[v as usize] = *q;
            }
        }
    }
    let parts: Vec<Part> = regions
        .into_par_iter()
        .map(|face_ids| Part::new(whole, face_ids, &shared, first))
        .collect();
    // Every region stops at the same cost, so that the seams, collapsed after, are the only
    // collapses out of cost order. The quantile is estimated from evenly spaced edges.
    let max_cost = max_cost.unwrap_or_else(|| {
        let edge_count: usize = parts.iter().map(|p| p.state.edges.len()).sum();
        let stride = (edge_count / REGION_COST_SAMPLES).max(1);
        let mut sampled: Vec<f32> = parts
            .par_iter()
            .flat_map_iter(|p| p.sample_costs(stride))
            .collect();
        if sampled.is_empty() {
            return f32::NEG_INFINITY;
        }
        let middle =
            ((sampled.len() as f64 * REGION_COST_QUANTILE) as usize).min(sampled.len() - 1);
        *sampled.select_nth_unstable_by(middle, f32::total_cmp).1
    });
    let runs: Vec<RegionRun> = parts
        .into_par_iter()
        .map(|part| part.simplify(max_cost, false))
        .collect();
    let streams = runs
        .into_iter()
        .map(|run| {
            run.write_back(whole, &shared);
            (run.collapses, run.costs)
        })
        .collect();
    (streams, max_cost)
}

/// The collapses of regions that share no face, in one sequence: always the cheapest next
/// collapse of any region (ties: the lower region), so that it stays close to one greedy loop.
fn interleave(streams: Streams) -> Vec<Collapse> {
    // Costs are not negative, so their bits order them.
    let mut made: Vec<_> = streams
        .into_iter()
        .map(|(collapses, costs)| collapses.into_iter().zip(costs).peekable())
        .collect();
    let mut heads: std::collections::BinaryHeap<_> = made
        .iter_mut()
        .enumerate()
        .filter_map(|(r, m)| Some(std::cmp::Reverse((m.peek()?.1.to_bits(), r))))
        .collect();
    let mut collapses = Vec::with_capacity(made.iter().map(|m| m.size_hint().0).sum());
    while let Some(std::cmp::Reverse((_, r))) = heads.pop() {
        collapses.extend(made[r].next().map(|(c, _)| c));
        if let Some((_, cost)) = made[r].peek() {
            heads.push(std::cmp::Reverse((cost.to_bits(), r)));
        }
    }
    collapses
}

/// Simplifies the oriented manifold mesh (`cells`, `faces`) as far as the rules allow.
pub fn simplify(cells: &[[i32; 3]], faces: &[[u32; 3]], placement: Placement) -> Simplified {
    let regions = faces.len() >= REGION_MIN_FACES && rayon::current_num_threads() > 1;
    simplify_with_regions(cells, faces, placement, regions)
}

/// [`simplify`], with or without the parallel phase.
fn simplify_with_regions(
    cells: &[[i32; 3]],
    faces: &[[u32; 3]],
    placement: Placement,
    regions: bool,
) -> Simplified {
    let n = cells.len();
    let bounds = cells
        .iter()
        .fold(([i32::MAX; 3], [i32::MIN; 3]), |(lo, hi), c| {
            (
                [0, 1, 2].map(|a| lo[a].min(c[a])),
                [0, 1, 2].map(|a| hi[a].max(c[a])),
            )
        });
    if regions {
        return simplify_in_regions(cells, faces, placement, bounds);
    }
    let t = topology(n, faces, &vec![true; faces.len()]);
    let quadrics = initial_quadrics(cells, faces, &t);
    let mut state = State::new(
        cells.to_vec(),
        faces.to_vec(),
        quadrics,
        vec![false; n],
        placement,
        bounds,
        t,
    );
    // When a pass runs dry, every remaining edge is queued again, until a pass collapses nothing.
    let (mut collapses, mut costs) = (Vec::new(), Vec::new());
    while state.collapse_greedily(f32::INFINITY, &mut collapses, &mut costs) > 0 {}
    Simplified {
        collapses,
        vertex_alive: state.vertex_alive,
        face_alive: state.face_alive,
        positions: state.cells,
        faces: state.faces,
    }
}

/// A progressive mesh: the base mesh and the splits that rebuild the full mesh, with the order
/// in which the full mesh's vertices and faces are created.
pub struct ProgressiveMesh {
    /// M⁰.
    pub base: PmMesh,
    /// vsplit₀ … vsplitₙ₋₁.
    pub vsplits: Vec<Vsplit>,
    /// Original vertex of each vertex of Mⁿ, in creation order.
    pub vertex_origin: Vec<u32>,
}

/// Builds the progressive mesh of a simplification: base mesh from what remains, then the
/// collapses in reverse as vertex splits with Hoppe's fields.
pub fn progressive_mesh(original_faces: &[[u32; 3]], s: &Simplified) -> ProgressiveMesh {
    let natural: Vec<usize> = (0..s.collapses.len()).rev().collect();
    build(original_faces, s, &natural)
}

/// The progressive mesh with the splits (collapse indices) applied in `order`, which must respect
/// their dependencies.
///
/// Every field of a split follows from its collapse record once the face ids a decoder will
/// assign are known (base faces, then fl and fr of each split in turn), so the records are made
/// in parallel without replaying the splits. Face corners keep their places through collapses
/// and splits; only the first corner differs: a split creates fl as (vs, vl, vt) and fr as
/// (vs, vt, vr), where the simplifier's face starts wherever the input face did.
fn build(original_faces: &[[u32; 3]], s: &Simplified, order: &[usize]) -> ProgressiveMesh {
    let n = s.vertex_alive.len();
    let mut vertex_origin: Vec<u32> = (0..n as u32)
        .filter(|&v| s.vertex_alive[v as usize])
        .collect();
    let mut new_id = vec![NIL; n];
    for (id, &v) in vertex_origin.iter().enumerate() {
        new_id[v as usize] = id as u32;
    }
    let mut face_id = vec![NIL; original_faces.len()];
    // Which of the simplifier's corners of each face is the decoder's first.
    let mut first_corner = vec![0u8; original_faces.len()];
    let mut base_faces = Vec::new();
    for (f, t) in s.faces.iter().enumerate() {
        if s.face_alive[f] {
            face_id[f] = base_faces.len() as u32;
            base_faces.push(t.map(|v| new_id[v as usize]));
        }
    }
    let mut next_face = base_faces.len() as u32;
    for c in order.iter().map(|&i| &s.collapses[i]) {
        for (f, corner) in [(c.fl, c.vs_corners[0]), (c.fr, c.vs_corners[1])] {
            if f != NIL {
                face_id[f as usize] = next_face;
                first_corner[f as usize] = corner;
                next_face += 1;
            }
        }
    }
    let base_positions: Vec<[i32; 3]> = vertex_origin
        .iter()
        .map(|&v| s.positions[v as usize])
        .collect();
    let base = PmMesh::from_triangles(base_positions, &base_faces)
        .expect("simplification keeps an oriented manifold");
    let vsplits: Vec<Vsplit> = order
        .par_iter()
        .map(|&i| {
            let c = &s.collapses[i];
            let f = c.flclw as usize;
            let vlr_rot = match (c.moved.len() as u32, c.vr == NIL) {
                (0, true) => Rotation::Empty,
                (0, false) => Rotation::EmptyAcrossGap,
                (_, true) => Rotation::ToBoundary,
                (k, false) => Rotation::Faces(k - 1),
            };
            let (ps, pt) = (c.before[0], c.before[1]);
            let vad_l = [pt[0] - ps[0], pt[1] - ps[1], pt[2] - ps[2]];
            let step = vad_s_step(vad_l);
            let (ii, vad_s) = (0..3u8)
                .map(|ii| {
                    let a = anchor(ii, ps, pt);
                    (
                        ii,
                        [a[0] - c.after[0], a[1] - c.after[1], a[2] - c.after[2]],
                    )
                })
                .filter(|(_, d)| d.iter().all(|x| x % step == 0))
                .min_by_key(|(ii, d)| {
                    (
                        d.iter().map(|x| x.unsigned_abs() as u64).sum::<u64>(),
                        2 - *ii as i32,
                    )
                })
                .expect("placements are snapped to an endpoint's step grid");
            Vsplit {
                flclw: face_id[f],
                vs_index: (c.flclw_corner + 3 - first_corner[f]) % 3,
                vlr_rot,
                ii,
                vad_l,
                vad_s,
            }
        })
        .collect();
    vertex_origin.extend(order.iter().map(|&i| s.collapses[i].vt));
    #[cfg(test)]
    {
        // The records rebuild the mesh: every split applies, keeps the invariants and puts vt
        // where it was.
        let mut mesh = base.clone();
        for (k, (split, &i)) in vsplits.iter().zip(order).enumerate() {
            let c = &s.collapses[i];
            let vt = mesh
                .vsplit(split)
                .unwrap_or_else(|e| panic!("split {k} {split:?} of {c:?}: {e:?}"));
            if let Err(e) = mesh.check_invariants() {
                panic!("after split {k} {split:?} of {c:?}: {e}");
            }
            assert_eq!(mesh.positions[vt as usize], c.before[1]);
        }
    }
    ProgressiveMesh {
        base,
        vsplits,
        vertex_origin,
    }
}

/// The progressive mesh of a simplification with its splits reordered so that successive
/// records name nearby faces (Hoppe §6.2, Table 4): among the splits whose dependencies are met,
/// always the one whose `flclw` is the next highest after the previous record's (circularly).
///
/// Dependencies: a split reads and rewrites its moved faces and the two faces it re-links (fl's
/// and fr's outer neighbours); it must come after the last split that wrote any of them and
/// before the next one, after the splits that created vs, vl and vr, and after the previous split
/// of vs (positions are deltas). The full mesh is the same in any order that keeps them.
pub fn reordered_progressive_mesh(original_faces: &[[u32; 3]], s: &Simplified) -> ProgressiveMesh {
    let splits: Vec<usize> = (0..s.collapses.len()).rev().collect();
    let n = splits.len();
    let mut successors: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut last_writer: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    let mut readers: std::collections::HashMap<u32, Vec<u32>> = std::collections::HashMap::new();
    let mut creator: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    let mut last_split_of: std::collections::HashMap<u32, u32> = std::collections::HashMap::new();
    for (j, &ci) in splits.iter().enumerate() {
        let c = &s.collapses[ci];
        let j = j as u32;
        let touched: Vec<u32> = c
            .moved
            .iter()
            .copied()
            .chain(c.beside)
            .filter(|&f| f != NIL)
            .collect();
        let mut preds: Vec<u32> = Vec::new();
        for &f in &touched {
            if let Some(&w) = last_writer.get(&f) {
                preds.push(w);
            }
            for &r in readers.get(&f).map(|v| v.as_slice()).unwrap_or(&[]) {
                preds.push(r);
            }
        }
        for v in [c.vs, c.vl, c.vr] {
            if let Some(&k) = creator.get(&v) {
                preds.push(k);
            }
        }
        if let Some(&k) = last_split_of.get(&c.vs) {
            preds.push(k);
        }
        preds.retain(|&p| p != j);
        preds.sort_unstable();
        preds.dedup();
        for p in preds {
            successors[p as usize].push(j);
        }
        for &f in &touched {
            last_writer.insert(f, j);
            readers.insert(f, Vec::new());
        }
        for f in [c.fl, c.fr] {
            if f != NIL {
                last_writer.insert(f, j);
            }
        }
        creator.insert(c.vt, j);
        last_split_of.insert(c.vs, j);
    }
    let mut indegree = vec![0u32; n];
    for list in &successors {
        for &k in list {
            indegree[k as usize] += 1;
        }
    }
    let flclw_origin: Vec<u32> = splits.iter().map(|&ci| s.collapses[ci].flclw).collect();
    // Face ids in the new order, assigned as faces are created.
    let mut face_id = vec![NIL; original_faces.len()];
    let mut next_face = 0u32;
    for (f, &alive) in s.face_alive.iter().enumerate() {
        if alive {
            face_id[f] = next_face;
            next_face += 1;
        }
    }
    let mut ready: std::collections::BTreeSet<(u32, u32)> = std::collections::BTreeSet::new();
    for j in 0..n {
        if indegree[j] == 0 {
            ready.insert((face_id[flclw_origin[j] as usize], j as u32));
        }
    }
    let mut order = Vec::with_capacity(n);
    let mut previous = 0u32;
    while let Some(&(key, j)) = ready
        .range((previous, 0)..)
        .next()
        .or_else(|| ready.iter().next())
    {
        ready.remove(&(key, j));
        previous = key;
        let c = &s.collapses[splits[j as usize]];
        face_id[c.fl as usize] = next_face;
        next_face += 1;
        if c.fr != NIL {
            face_id[c.fr as usize] = next_face;
            next_face += 1;
        }
        order.push(splits[j as usize]);
        for &k in &successors[j as usize] {
            indegree[k as usize] -= 1;
            if indegree[k as usize] == 0 {
                ready.insert((face_id[flclw_origin[k as usize] as usize], k));
            }
        }
    }
    debug_assert_eq!(order.len(), n, "the dependency graph is acyclic");
    build(original_faces, s, &order)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    fn cells_of(mesh: &crate::mesh::TriMesh) -> Vec<[i32; 3]> {
        mesh.positions
            .iter()
            .map(|p| {
                [
                    (p.x * 1000.0) as i32,
                    (p.y * 1000.0) as i32,
                    (p.z * 1000.0) as i32,
                ]
            })
            .collect()
    }

    fn check_round_trip(mesh: &crate::mesh::TriMesh, placement: Placement) {
        check_round_trip_with(mesh, placement, false);
    }

    fn check_round_trip_with(mesh: &crate::mesh::TriMesh, placement: Placement, regions: bool) {
        let cells = cells_of(mesh);
        let s = simplify_with_regions(&cells, &mesh.faces, placement, regions);
        let pm = progressive_mesh(&mesh.faces, &s);
        let mut m = pm.base.clone();
        m.check_invariants().unwrap();
        for (i, split) in pm.vsplits.iter().enumerate() {
            m.vsplit(split).unwrap();
            if i % 7 == 0 {
                m.check_invariants().unwrap();
            }
        }
        m.check_invariants().unwrap();
        // Same faces and positions as the original, through the vertex order.
        let mut got: Vec<[u32; 3]> = m
            .triangles()
            .iter()
            .map(|t| {
                crate::mesh::canonical::rotate_to_smallest(t.map(|v| pm.vertex_origin[v as usize]))
            })
            .collect();
        let mut want: Vec<[u32; 3]> = mesh
            .faces
            .iter()
            .map(|t| crate::mesh::canonical::rotate_to_smallest(*t))
            .collect();
        got.sort_unstable();
        want.sort_unstable();
        assert_eq!(got, want);
        for (v, &o) in pm.vertex_origin.iter().enumerate() {
            assert_eq!(m.positions[v], cells[o as usize]);
        }
        for split in pm.vsplits.iter().rev() {
            m.ecol(split);
        }
        assert_eq!(m, pm.base);
    }

    #[test]
    fn closed_and_open_meshes_simplify_and_rebuild_exactly() {
        for placement in [Placement::Optimal, Placement::EndpointOrMidpoint] {
            check_round_trip(&generate::icosphere(3), placement);
            check_round_trip(&generate::torus(2.0, 0.6, 24, 12), placement);
            check_round_trip(&generate::terrain(400, 5), placement);
        }
        // The parallel phase (regions with frozen seams, interleaved by cost) on small meshes.
        for placement in [Placement::Optimal, Placement::EndpointOrMidpoint] {
            check_round_trip_with(&generate::icosphere(3), placement, true);
            check_round_trip_with(&generate::torus(2.0, 0.6, 32, 16), placement, true);
            check_round_trip_with(&generate::terrain(800, 7), placement, true);
        }
        let sphere = generate::icosphere(3);
        let s = simplify(&cells_of(&sphere), &sphere.faces, Placement::Optimal);
        assert_eq!(
            s.vertex_alive.iter().filter(|&&a| a).count(),
            4,
            "a sphere ends as a tetrahedron"
        );
    }
}
