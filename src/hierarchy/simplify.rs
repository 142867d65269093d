//! Garland–Heckbert quadric error simplification by edge collapses, and the progressive mesh it
//! defines (Hoppe: base mesh M⁰ plus the vertex splits that undo the collapses in reverse).
//!
//! Collapses are taken cheapest first from a binary heap with lazy invalidation (a per-vertex
//! version stamp), so simplification is O(f log f). A collapse must keep the mesh a manifold
//! (link condition; no interior edge between two boundary vertices; no two faces on the same
//! three vertices), must not flip a face's normal, and keeps boundaries through constraint
//! quadrics on boundary edges. When the heap runs dry, every edge is queued again, until a
//! whole pass collapses nothing: the base mesh is then as small as these rules allow.

use super::pmesh::{anchor, PmMesh, Rotation, Vsplit, NIL};
use dary_heap::QuaternaryHeap as BinaryHeap;
use glam::DVec3;
use rayon::prelude::*;
use std::cmp::Ordering;

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
    pub moved: Vec<u32>,
    /// Faces across (vs, vl) from fl and across (vs, vr) from fr (NIL where none): the split
    /// re-links them.
    pub beside: [u32; 2],
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

/// A queued collapse: 16 bytes, so the heap of a million-face mesh stays cache-friendly. The
/// cost is an f32 (ordering only), the stamps wrap (a wrapped stale entry is only re-checked).
#[derive(PartialEq)]
struct Candidate {
    cost: f32,
    a: u32,
    b: u32,
    stamps: (u16, u16),
}
impl Eq for Candidate {}
impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> Ordering {
        // Reversed: the heap pops the cheapest first; ties by vertex ids, for determinism.
        other
            .cost
            .total_cmp(&self.cost)
            .then_with(|| (other.a, other.b).cmp(&(self.a, self.b)))
    }
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

struct State {
    cells: Vec<[i32; 3]>,
    faces: Vec<[u32; 3]>,
    face_alive: Vec<bool>,
    vertex_alive: Vec<bool>,
    vfaces: Vec<Vec<u32>>,
    quadrics: Vec<Quadric>,
    stamp: Vec<u16>,
    placement: Placement,
    /// Box of the input cells: placements stay inside it, hence on the grid.
    bounds: ([i32; 3], [i32; 3]),
}

impl State {
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

    fn neighbours(&self, v: u32, out: &mut Vec<u32>) {
        out.clear();
        for &f in &self.vfaces[v as usize] {
            out.extend(self.faces[f as usize].iter().filter(|&&w| w != v));
        }
        out.sort_unstable();
        out.dedup();
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
                    for end in [ca, cb] {
                        let snapped = [0, 1, 2].map(|a| {
                            end[a] - ((end[a] as f64 - p[a]) / step as f64).round() as i32 * step
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

    /// The collapse of (a, b) to `p` if it keeps the mesh valid: (vs, vt, fl, fr, vl, vr).
    fn check(
        &self,
        a: u32,
        b: u32,
        p: [i32; 3],
        scratch: &mut [Vec<u32>; 3],
    ) -> Option<(u32, u32, u32, u32, u32, u32)> {
        let edge_faces: Vec<u32> = self.vfaces[a as usize]
            .iter()
            .copied()
            .filter(|&f| self.faces[f as usize].contains(&b))
            .collect();
        if edge_faces.is_empty() || edge_faces.len() > 2 {
            return None;
        }
        let [na, nb, _] = scratch;
        self.neighbours(a, na);
        self.neighbours(b, nb);
        let common = na.iter().filter(|x| nb.binary_search(x).is_ok()).count();
        if common != edge_faces.len() {
            return None; // link condition
        }
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
}

/// Simplifies the oriented manifold mesh (`cells`, `faces`) as far as the rules allow.
pub fn simplify(cells: &[[i32; 3]], faces: &[[u32; 3]], placement: Placement) -> Simplified {
    let n = cells.len();
    let mut vfaces = vec![Vec::new(); n];
    for (f, t) in faces.iter().enumerate() {
        for &v in t {
            vfaces[v as usize].push(f as u32);
        }
    }
    // Face planes (area-weighted) and boundary constraint planes, summed per vertex in parallel.
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
    let mut edge_count: std::collections::HashMap<(u32, u32), u32> =
        std::collections::HashMap::new();
    for t in faces {
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            *edge_count.entry((u.min(v), u.max(v))).or_default() += 1;
        }
    }
    let quadrics: Vec<Quadric> = (0..n)
        .into_par_iter()
        .map(|v| {
            let mut q = Quadric::default();
            for &f in &vfaces[v] {
                let t = faces[f as usize];
                q.add(&face_quadric(&t));
                for k in 0..3 {
                    let (u, w) = (t[k], t[(k + 1) % 3]);
                    if (u == v as u32 || w == v as u32) && edge_count[&(u.min(w), u.max(w))] == 1 {
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
        .collect();
    let mut state = State {
        cells: cells.to_vec(),
        faces: faces.to_vec(),
        face_alive: vec![true; faces.len()],
        vertex_alive: vec![true; n],
        vfaces,
        quadrics,
        stamp: vec![0; n],
        placement,
        bounds: cells
            .iter()
            .fold(([i32::MAX; 3], [i32::MIN; 3]), |(lo, hi), c| {
                (
                    [0, 1, 2].map(|a| lo[a].min(c[a])),
                    [0, 1, 2].map(|a| hi[a].max(c[a])),
                )
            }),
    };
    let mut collapses = Vec::new();
    let mut scratch: [Vec<u32>; 3] = Default::default();
    let mut neighbours = Vec::new();
    loop {
        let edges: Vec<(u32, u32)> = edge_list(&state);
        let initial: Vec<Candidate> = edges
            .par_iter()
            .map(|&(a, b)| {
                let (_, cost) = state.place(a, b);
                Candidate {
                    cost: cost as f32,
                    a,
                    b,
                    stamps: (state.stamp[a as usize], state.stamp[b as usize]),
                }
            })
            .collect();
        let mut heap = BinaryHeap::from(initial);
        let before = collapses.len();
        while let Some(c) = heap.pop() {
            let (a, b) = (c.a, c.b);
            if !state.vertex_alive[a as usize]
                || !state.vertex_alive[b as usize]
                || (state.stamp[a as usize], state.stamp[b as usize]) != c.stamps
            {
                continue;
            }
            let (p, _) = state.place(a, b);
            let Some((vs, vt, fl, fr, vl, vr)) = state.check(a, b, p, &mut scratch) else {
                continue;
            };
            let moved: Vec<u32> = state.vfaces[vt as usize]
                .iter()
                .copied()
                .filter(|&f| f != fl && f != fr)
                .collect();
            let across = |other: u32, not: u32| {
                if other == NIL {
                    return NIL;
                }
                state.vfaces[vs as usize]
                    .iter()
                    .copied()
                    .find(|&f| f != not && state.faces[f as usize].contains(&other))
                    .unwrap_or(NIL)
            };
            let beside = [across(vl, fl), across(vr, fr)];
            collapses.push(Collapse {
                vs,
                vt,
                before: [state.cells[vs as usize], state.cells[vt as usize]],
                after: p,
                fl,
                fr,
                vl,
                vr,
                moved: moved.clone(),
                beside,
            });
            for &f in &moved {
                for x in state.faces[f as usize].iter_mut() {
                    if *x == vt {
                        *x = vs;
                    }
                }
            }
            for &f in &[fl, fr] {
                if f == NIL {
                    continue;
                }
                state.face_alive[f as usize] = false;
                for &v in &state.faces[f as usize] {
                    state.vfaces[v as usize].retain(|&g| g != f);
                }
            }
            state.vfaces[vs as usize].extend(moved);
            state.vfaces[vt as usize].clear();
            state.vertex_alive[vt as usize] = false;
            let qt = state.quadrics[vt as usize];
            state.quadrics[vs as usize].add(&qt);
            state.cells[vs as usize] = p;
            state.stamp[vs as usize] = state.stamp[vs as usize].wrapping_add(1);
            state.neighbours(vs, &mut neighbours);
            for &w in &neighbours {
                let (_, cost) = state.place(vs, w);
                heap.push(Candidate {
                    cost: cost as f32,
                    a: vs,
                    b: w,
                    stamps: (state.stamp[vs as usize], state.stamp[w as usize]),
                });
            }
        }
        if collapses.len() == before {
            break;
        }
    }
    Simplified {
        collapses,
        vertex_alive: state.vertex_alive,
        face_alive: state.face_alive,
        positions: state.cells,
        faces: state.faces,
    }
}

fn edge_list(state: &State) -> Vec<(u32, u32)> {
    let mut edges: Vec<(u32, u32)> = state
        .faces
        .iter()
        .zip(&state.face_alive)
        .filter(|(_, &alive)| alive)
        .flat_map(|(t, _)| {
            (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3])))
        })
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
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
/// collapses in reverse as vertex splits with Hoppe's fields, each applied as it is made so that
/// its face ids are those a decoder will have.
pub fn progressive_mesh(original_faces: &[[u32; 3]], s: &Simplified) -> ProgressiveMesh {
    let natural: Vec<usize> = (0..s.collapses.len()).rev().collect();
    build(original_faces, s, &natural)
}

/// The progressive mesh with the splits (collapse indices) applied in `order`, which must respect
/// their dependencies.
fn build(original_faces: &[[u32; 3]], s: &Simplified, order: &[usize]) -> ProgressiveMesh {
    let n = s.vertex_alive.len();
    let mut new_id = vec![NIL; n];
    let mut vertex_origin = Vec::with_capacity(n);
    for (v, id) in new_id.iter_mut().enumerate() {
        if s.vertex_alive[v] {
            *id = vertex_origin.len() as u32;
            vertex_origin.push(v as u32);
        }
    }
    let mut face_id = vec![NIL; original_faces.len()];
    let mut base_faces = Vec::new();
    for (f, t) in s.faces.iter().enumerate() {
        if s.face_alive[f] {
            face_id[f] = base_faces.len() as u32;
            base_faces.push(t.map(|v| new_id[v as usize]));
        }
    }
    let base_positions: Vec<[i32; 3]> = vertex_origin
        .iter()
        .map(|&v| s.positions[v as usize])
        .collect();
    let base = PmMesh::from_triangles(base_positions, &base_faces)
        .expect("simplification keeps an oriented manifold");
    let mut mesh = base.clone();
    // A face of each vertex, to start walks around it.
    let mut vertex_face = vec![NIL; n];
    for (f, face) in mesh.faces.iter().enumerate() {
        for &v in &face.v {
            vertex_face[v as usize] = f as u32;
        }
    }
    let mut vsplits = Vec::with_capacity(s.collapses.len());
    for c in order.iter().map(|&i| &s.collapses[i]) {
        let (vs, vl) = (new_id[c.vs as usize], new_id[c.vl as usize]);
        let vr = if c.vr == NIL {
            NIL
        } else {
            new_id[c.vr as usize]
        };
        let moved: std::collections::HashSet<u32> =
            c.moved.iter().map(|&f| face_id[f as usize]).collect();
        debug_assert!(
            mesh.faces[vertex_face[vs as usize] as usize]
                .v
                .contains(&vs),
            "vertex_face of {vs} (orig {}) is {} = {:?}",
            c.vs,
            vertex_face[vs as usize],
            mesh.faces[vertex_face[vs as usize] as usize].v
        );
        let (flclw, vs_index, vlr_rot) =
            locate_split(&mesh, vs, vl, vr, vertex_face[vs as usize], &moved);
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
        let split = Vsplit {
            flclw,
            vs_index,
            vlr_rot,
            ii,
            vad_l,
            vad_s,
        };
        let vt = mesh
            .vsplit(&split)
            .expect("a split made from a collapse applies");
        #[cfg(test)]
        if let Err(e) = mesh.check_invariants() {
            panic!(
                "after split {} {:?} (moved {} {:?} {:?}): {e}",
                vsplits.len(),
                split,
                moved.len(),
                c,
                s.collapses.len()
            );
        }
        debug_assert_eq!(mesh.positions[vt as usize], pt);
        new_id[c.vt as usize] = vt;
        vertex_origin.push(c.vt);
        let fl = mesh.faces.len() as u32 - if c.fr == NIL { 1 } else { 2 };
        vertex_face[vs as usize] = fl;
        vertex_face[vt as usize] = fl;
        face_id[c.fl as usize] = mesh.faces.len() as u32 - if c.fr == NIL { 1 } else { 2 };
        if c.fr != NIL {
            face_id[c.fr as usize] = mesh.faces.len() as u32 - 1;
        }
        vsplits.push(split);
    }
    ProgressiveMesh {
        base,
        vsplits,
        vertex_origin,
    }
}

/// Hoppe's location fields of the split of `vs` between `vl` and `vr` that gives vt the faces
/// `moved` (face ids of `mesh`).
fn locate_split(
    mesh: &PmMesh,
    vs: u32,
    vl: u32,
    vr: u32,
    face_of_vs: u32,
    moved: &std::collections::HashSet<u32>,
) -> (u32, u8, Rotation) {
    // Faces around vs, via any face that holds it.
    let holds = |f: u32, u: u32, w: u32| {
        let t = mesh.faces[f as usize].v;
        (0..3).find(|&k| t[k] == u && t[(k + 1) % 3] == w)
    };
    let fan = mesh.fan(face_of_vs, vs);
    if moved.is_empty() {
        let f = *fan
            .iter()
            .find(|&&f| holds(f, vl, vs).is_some())
            .expect("face across (vs, vl)");
        let i = mesh.corner(f, vs).expect("corner") as u8;
        let rot = if vr == NIL {
            Rotation::Empty
        } else {
            Rotation::EmptyAcrossGap
        };
        return (f, i, rot);
    }
    let f0 = *fan
        .iter()
        .find(|&&f| moved.contains(&f) && holds(f, vs, vl).is_some())
        .expect("a moved face starts at vl");
    let i = mesh.corner(f0, vs).expect("corner") as u8;
    let rot = if vr == NIL {
        Rotation::ToBoundary
    } else {
        Rotation::Faces(moved.len() as u32 - 1)
    };
    (f0, i, rot)
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
    // flclw of each split, as an original face id, from the natural order's records.
    let natural = progressive_mesh(original_faces, s);
    let mut origin_face: Vec<u32> = (0..original_faces.len() as u32)
        .filter(|&f| s.face_alive[f as usize])
        .collect();
    for &ci in &splits {
        let c = &s.collapses[ci];
        origin_face.push(c.fl);
        if c.fr != NIL {
            origin_face.push(c.fr);
        }
    }
    let flclw_origin: Vec<u32> = natural
        .vsplits
        .iter()
        .map(|v| origin_face[v.flclw as usize])
        .collect();
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
        let cells = cells_of(mesh);
        let s = simplify(&cells, &mesh.faces, placement);
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
        let sphere = generate::icosphere(3);
        let s = simplify(&cells_of(&sphere), &sphere.faces, Placement::Optimal);
        assert_eq!(
            s.vertex_alive.iter().filter(|&&a| a).count(),
            4,
            "a sphere ends as a tetrahedron"
        );
    }
}
