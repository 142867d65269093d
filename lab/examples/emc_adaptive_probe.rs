//! Would an adaptive-depth octree close the gap of `emc-ahead`'s middle levels (issue "EMC at
//! every prefix")? An estimate, not a coder: it prices every decision of `emc`'s octree as the
//! two codecs' streams price it, and measures the meshes that orders of those decisions show.
//!
//! `emc-ahead` refines the octree a level at a time, and every cluster's representative (one of
//! its mesh vertices) two levels ahead of its cell. Its worst level on dragon-50k (level 6)
//! stands at 1.72× `pm`'s RMS at the same bits, and BENCHMARKS.md measured that even with every
//! vertex of that level moved onto the surface the level would stand at 1.48×: a uniform depth
//! spends its vertices where the surface is flat as where it is curved. This probe lets each
//! cluster split when its split pays, in the order of error removed per bit, with the same
//! representatives, so that flat regions stay merged while curved ones refine:
//! - **Tree.** Vertices sorted by their octree keys; a cluster is a node, a range of that order.
//!   Its depth is where its vertices start to differ in the steps after the ones they share.
//! - **Representative.** A cluster shows one of its vertices at the centre of that vertex's cell
//!   `AHEAD` steps below the cluster's depth (two levels, as `emc-ahead`). A child keeps its
//!   parent's representative where it holds it (those bits are spent); the other child gets its
//!   own, chosen either by the encoder as the vertex whose shown position has the least quadric
//!   error (an oracle, free of bits) or by the rule "the larger half at every branch" (free too,
//!   but not what a decoder can follow; a bracket on the other side).
//! - **Bits.** A split costs `emc`'s bits per split at its level (its edges and the new
//!   vertex's questions). A representative's step coded ahead costs `emc`'s bits for a
//!   "which half" question at that level times (1 + α), or [`PREDICTED_STEP_BITS`] where its
//!   path meets a branch (`emc-ahead` measured 0.24 there). α is fitted so that the level order
//!   below spends exactly `emc-ahead`'s lossless bits; the table prints the order's bits at every
//!   level beside `emc-ahead`'s as a check of the model.
//! - **Orders.**
//!   - *Level order*: every split of a step before the next, every representative taken to two
//!     levels below the step at each level's end (`emc-ahead`'s order, in this model).
//!   - *Greedy*: the encoder's choice, among every cluster's split and its representative's next
//!     three steps, of most quadric error removed per estimated bit, with the quadrics of
//!     `emc_order_probe` (face planes plus a tenth of the area times the squared distance).
//!   - *Sent*: the greedy order with its schedule paid for ([`Schedule`]).
//!   - *Untold*: an order the decoder computes from the mesh it has ([`decoder_order`]).
//! - **Meshes.** The original triangles through the clusters, at the representatives' shown
//!   positions, or (the bound) at the representatives' own positions, the last step's cell
//!   centres; RMS both ways relative to the diagonal, as `experiment` measures. Every order is
//!   measured at the bits of the level order's levels, and reported as a ratio to it. The last
//!   column scales `emc-ahead`'s measured RMS over `pm`'s at the same bits (both read from
//!   results/ at 12 bits, `pm` interpolated on log–log axes, as paper-tables/emc-vs-anchors.md
//!   does) by those ratios: what the order would make of `emc-ahead`.
//!
//! docs/notes/benchmarks-history.md ("An adaptive depth, probed") has the figures.
//! Run: cargo run --release --example emc_adaptive_probe -- [mesh…]
//! (results/emc/adaptive-probe.md is its output for bunny dragon-50k armadillo-43k.)

// Shared with `emc_order_probe`, which reads parts of it this probe does not.
#[allow(dead_code)]
mod emc_octree;

use emc_octree::{build, least, priority, Built, Candidate, Tree};
use glam::DVec3;
use meshcodec::hierarchy::simplify::quadric::Quadric;
use meshcodec::metrics::{Reference, SampleBudget, DEFAULT_SEED};
use meshcodec_lab::tables::{load_at, log_log_interpolate, rms_curve};
use std::collections::{BinaryHeap, HashMap};
use std::path::Path;

/// Steps a representative is known below its cluster's depth: two levels, as `emc-ahead`.
const AHEAD: usize = 6;
/// Bits of a representative's step where its path meets a branch (taken as predicted).
const PREDICTED_STEP_BITS: f64 = 0.24;
/// Share of the clusters that act in each pass of the order a decoder follows untold. Chosen on
/// bunny.ply with [`SPLIT_PRIOR`] among shares 0.25, 0.5 and 1 (BENCHMARKS.md).
const DECODER_SHARE: f64 = 0.25;
/// The least squared bend a split is valued at in that order, in squared widths of the
/// cluster's cell: a flat-looking cluster still stands for a cell of surface. Chosen on
/// bunny.ply among floors 0, 0.01, 0.05 and 0.2.
const SPLIT_PRIOR: f64 = 0.01;

#[derive(Clone, Copy, PartialEq, Debug)]
enum Rule {
    /// The vertex whose shown position has the least quadric error (the encoder's choice).
    Oracle,
    /// The larger half at every branch below the cluster.
    Larger,
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Show {
    /// The centre of the representative's cell at the depth it is known to.
    Coded,
    /// The representative's own position (its cell at the last step): the bound.
    Exact,
}

struct Model<'a> {
    tree: &'a Tree,
    /// Per sorted vertex, bit `s`: its node at depth `s` holds vertices on both sides of step `s`.
    branches: Vec<u64>,
    /// Bits of a representative's non-branching step coded ahead, per level.
    ahead_bits: Vec<f64>,
    rule: Rule,
    show: Show,
}

#[derive(Clone, Copy)]
struct Cluster {
    lo: usize,
    hi: usize,
    /// Depth: every member agrees on the steps before it.
    depth: usize,
    /// The representative (sorted index) and the depth its cell is known to.
    rep: usize,
    known: usize,
}

impl Model<'_> {
    fn new(tree: &Tree, rule: Rule, show: Show, alpha: f64) -> Model<'_> {
        let n = tree.sorted.len();
        assert!(tree.steps <= 64, "a step a bit of a u64: 21 levels at most");
        let mut branches = vec![0u64; n];
        for s in 0..tree.steps {
            let mut lo = 0;
            while lo < n {
                let hi = tree.node_end(lo, n, s);
                let m = tree.middle(lo, hi, s);
                if m > lo && m < hi {
                    for b in &mut branches[lo..hi] {
                        *b |= 1 << s;
                    }
                }
                lo = hi;
            }
        }
        let ahead_bits = tree.half_bits.iter().map(|b| b * (1.0 + alpha)).collect();
        Model {
            tree,
            branches,
            ahead_bits,
            rule,
            show,
        }
    }
    fn branches_at(&self, i: usize, s: usize) -> bool {
        self.branches[i] >> s & 1 == 1
    }
    /// Bits of sorted vertex `i`'s steps `from..to` coded ahead.
    fn path_bits(&self, i: usize, from: usize, to: usize) -> f64 {
        (from..to)
            .map(|s| {
                if self.branches_at(i, s) {
                    PREDICTED_STEP_BITS
                } else {
                    self.ahead_bits[s / 3]
                }
            })
            .sum()
    }
    fn shown(&self, rep: usize, known: usize) -> DVec3 {
        match self.show {
            Show::Coded => self.tree.position(rep, known),
            Show::Exact => self.tree.position(rep, self.tree.steps),
        }
    }
    fn quadric(&self, c: &Cluster) -> Quadric {
        self.tree.quadric(c.lo, c.hi)
    }
    fn error(&self, c: &Cluster) -> f64 {
        self.quadric(c).error(self.shown(c.rep, c.known))
    }
    fn reach(&self, depth: usize) -> usize {
        (depth + AHEAD).min(self.tree.steps)
    }
    /// The first step at or below the cluster's depth where its vertices part.
    fn branch(&self, c: &Cluster) -> Option<usize> {
        (c.depth..self.tree.steps).find(|&s| self.branches_at(c.lo, s))
    }
    /// A representative for the node `[lo, hi)` at `depth`, shown to `known`.
    fn choose(&self, lo: usize, hi: usize, depth: usize, known: usize) -> usize {
        match self.rule {
            Rule::Oracle => {
                let q = self.tree.quadric(lo, hi);
                (lo..hi)
                    .min_by(|&a, &b| {
                        q.error(self.shown(a, known))
                            .total_cmp(&q.error(self.shown(b, known)))
                    })
                    .expect("a node holds a vertex")
            }
            Rule::Larger => {
                let (mut lo, mut hi) = (lo, hi);
                for s in depth..self.tree.steps {
                    if self.branches_at(lo, s) {
                        let m = self.tree.middle(lo, hi, s);
                        if m - lo >= hi - m {
                            hi = m;
                        } else {
                            lo = m;
                        }
                    }
                }
                lo
            }
        }
    }
    /// The cluster's split at its next branch: the two children, the bits and the error removed.
    fn split(&self, c: &Cluster) -> Option<([Cluster; 2], f64, f64)> {
        let s = self.branch(c)?;
        let m = self.tree.middle(c.lo, c.hi, s);
        let depth = s + 1;
        let known = self.reach(depth);
        let kept_known = known.max(c.known);
        let mut bits = self.tree.split_bits[s / 3] + self.path_bits(c.rep, c.known, kept_known);
        let child = |lo, hi| {
            if (lo..hi).contains(&c.rep) {
                (c.rep, kept_known, 0.0)
            } else {
                let rep = self.choose(lo, hi, depth, known);
                (rep, known, self.path_bits(rep, depth, known))
            }
        };
        let mut make = |lo, hi| {
            let (rep, known, rep_bits) = child(lo, hi);
            bits += rep_bits;
            Cluster {
                lo,
                hi,
                depth,
                rep,
                known,
            }
        };
        let children = [make(c.lo, m), make(m, c.hi)];
        // Valued by what the split makes possible, the children's quadrics at their least
        // values: at the representatives' shown positions a split's new child, coarse until its
        // representative is refined, often measures worse than its parent, and an order by
        // that value stalls with large clusters never split (tried: bunny's RMS stayed at
        // 1.0e-2 from 763 vertices on).
        let gain = least(&self.quadric(c))
            - least(&self.quadric(&children[0]))
            - least(&self.quadric(&children[1]));
        Some((children, bits, gain))
    }
    /// The representative's next three steps (a level of precision) without a split.
    fn extend(&self, c: &Cluster) -> Option<(Cluster, f64, f64)> {
        if c.known >= self.tree.steps || self.show == Show::Exact {
            return None;
        }
        let known = (c.known + 3).min(self.tree.steps);
        let next = Cluster { known, ..*c };
        let bits = self.path_bits(c.rep, c.known, known);
        Some((next, bits, self.error(c) - self.error(&next)))
    }
}

struct State<'a> {
    model: &'a Model<'a>,
    clusters: Vec<Cluster>,
    owner: Vec<u32>,
    bits: f64,
}

impl<'a> State<'a> {
    fn new(model: &'a Model<'a>) -> State<'a> {
        let n = model.tree.sorted.len();
        let known = model.reach(0);
        let rep = model.choose(0, n, 0, known);
        State {
            model,
            clusters: vec![Cluster {
                lo: 0,
                hi: n,
                depth: 0,
                rep,
                known,
            }],
            owner: vec![0; n],
            bits: model.tree.fixed_bits + model.path_bits(rep, 0, known),
        }
    }
    /// Replaces cluster `id` by its children; the second one's id is returned.
    fn apply_split(&mut self, id: usize, children: [Cluster; 2], bits: f64) -> usize {
        self.bits += bits;
        self.clusters[id] = children[0];
        let new = self.clusters.len();
        self.clusters.push(children[1]);
        for o in &mut self.owner[children[1].lo..children[1].hi] {
            *o = new as u32;
        }
        new
    }
    fn rms(&self, reference: &Reference) -> f64 {
        let m = self.model;
        let positions = self
            .clusters
            .iter()
            .map(|c| m.shown(c.rep, c.known))
            .collect();
        reference
            .compare(&m.tree.project(&self.owner, positions))
            .map_or(f64::NAN, |d| d.rms)
    }
}

/// Bits and RMS at the end of every level of the level order.
fn level_order(model: &Model, reference: Option<&Reference>) -> Vec<(f64, f64)> {
    let mut state = State::new(model);
    let mut rows = Vec::new();
    for s in 0..model.tree.steps {
        for id in 0..state.clusters.len() {
            let c = state.clusters[id];
            if model.branch(&c) != Some(s) {
                continue;
            }
            let (children, bits, _) = model.split(&c).expect("the cluster branches at s");
            state.apply_split(id, children, bits);
        }
        if s % 3 == 2 {
            // The level's lookahead: every representative to two levels below the level.
            let known = model.reach(s + 1);
            for c in &mut state.clusters {
                if c.known < known {
                    state.bits += model.path_bits(c.rep, c.known, known);
                    c.known = known;
                }
            }
            let rms = reference.map_or(f64::NAN, |r| state.rms(r));
            rows.push((state.bits, rms));
        }
    }
    rows
}

enum Op {
    Split([Cluster; 2]),
    Extend(Cluster),
}

fn best(model: &Model, c: &Cluster) -> Option<(Op, f64, f64)> {
    let split = model
        .split(c)
        .map(|(children, bits, gain)| (Op::Split(children), bits, gain));
    let extend = model
        .extend(c)
        .map(|(next, bits, gain)| (Op::Extend(next), bits, gain));
    [split, extend]
        .into_iter()
        .flatten()
        .max_by(|a, b| priority(a.2, a.1).total_cmp(&priority(b.2, b.1)))
}

/// The schedule a greedy order must send: in each layer, for every cluster that can still act,
/// a flag per operation it takes ("now") and one where it stops ("later"). Its cost is
/// estimated as the flags' empirical entropy, with no context and under contexts a decoder
/// knows, which an adaptive coder would approach: the cluster's level, how far ahead its
/// representative is, how many operations it took so far in the layer, and where the decoder's
/// own value of it ([`decoder_values`], at the layer's start; a new cluster takes its parent's)
/// stands against the layer's median, in powers of two.
#[derive(Default)]
struct Schedule {
    counts: HashMap<(usize, usize, usize, usize), [u64; 2]>,
    taken: Vec<usize>,
    rank: Vec<usize>,
}

impl Schedule {
    fn context(&self, c: &Cluster, id: usize) -> (usize, usize, usize, usize) {
        (
            c.depth / 3,
            c.known - c.depth,
            self.taken[id].min(2),
            self.rank[id],
        )
    }
    /// A new cluster, split off `parent`.
    fn push(&mut self, parent: usize) {
        self.taken.push(self.taken[parent]);
        self.rank.push(self.rank[parent]);
    }
    /// Counts the flag; returns what an adaptive coder of its context would have spent on it
    /// (counts from a half each).
    fn flag(&mut self, c: &Cluster, id: usize, now: bool) -> f64 {
        let k = self.context(c, id);
        let counts = self.counts.entry(k).or_default();
        let p = (counts[now as usize] as f64 + 0.5) / ((counts[0] + counts[1]) as f64 + 1.0);
        counts[now as usize] += 1;
        if now {
            self.taken[id] += 1;
        }
        -p.log2()
    }
    /// A layer starts: the decoder values every cluster.
    fn start_layer(&mut self, model: &Model, state: &State) {
        let values: Vec<f64> = decoder_values(model, state)
            .into_iter()
            .map(|v| v.map_or(0.0, |v| v.0))
            .collect();
        let mut positive: Vec<f64> = values.iter().copied().filter(|&v| v > 0.0).collect();
        positive.sort_by(f64::total_cmp);
        let median = positive.get(positive.len() / 2).copied().unwrap_or(1.0);
        self.rank = values
            .iter()
            .map(|&v| {
                if v > 0.0 {
                    ((v / median).log2().round() + 5.0).clamp(1.0, 10.0) as usize
                } else {
                    0
                }
            })
            .collect();
        self.taken = vec![0; state.clusters.len()];
    }
    /// A layer ends: every cluster that can still act says "later". Returns the flags' bits.
    fn end_layer(&mut self, model: &Model, state: &State) -> f64 {
        let mut bits = 0.0;
        for (id, c) in state.clusters.iter().enumerate() {
            if best(model, c).is_some() {
                bits += self.flag(c, id, false);
            }
        }
        self.start_layer(model, state);
        bits
    }
    /// (flags, bits with no context, bits under the contexts).
    fn bits(&self) -> (u64, f64, f64) {
        let h = |[a, b]: [u64; 2]| {
            let n = (a + b) as f64;
            [a, b]
                .iter()
                .filter(|&&x| x > 0)
                .map(|&x| -(x as f64) * (x as f64 / n).log2())
                .sum::<f64>()
        };
        let total = self
            .counts
            .values()
            .fold([0, 0], |t, c| [t[0] + c[0], t[1] + c[1]]);
        let contexts = self.counts.values().map(|&c| h(c)).sum();
        (total[0] + total[1], h(total), contexts)
    }
}

/// The operation of most error removed per bit first; vertices and RMS where the bits reach each
/// of `targets`, and the schedule of layers ending at `layers` (both ascending). With `send`, the
/// schedule's flags are paid for as an adaptive coder would, in the bits the targets count.
fn greedy(
    model: &Model,
    targets: &[f64],
    layers: &[f64],
    send: bool,
    reference: &Reference,
) -> (Vec<(usize, f64)>, Schedule) {
    let paid = if send { 1.0 } else { 0.0 };
    let mut state = State::new(model);
    let mut version = vec![0u32];
    let mut schedule = Schedule::default();
    schedule.start_layer(model, &state);
    let mut layer = 0;
    let mut heap = BinaryHeap::new();
    let push = |heap: &mut BinaryHeap<Candidate>, c: &Cluster, id, version| {
        if let Some((_, bits, gain)) = best(model, c) {
            heap.push(Candidate {
                priority: priority(gain, bits),
                id,
                version,
            });
        }
    };
    push(&mut heap, &state.clusters[0], 0, 0);
    let mut rows = Vec::new();
    let record = |state: &State, rows: &mut Vec<(usize, f64)>| {
        rows.push((state.clusters.len(), state.rms(reference)));
    };
    while rows.len() < targets.len() {
        let Some(top) = heap.pop() else {
            record(&state, &mut rows);
            continue;
        };
        if top.version != version[top.id] {
            continue;
        }
        let c = state.clusters[top.id];
        let (op, bits, _) = best(model, &c).expect("a candidate");
        while rows.len() < targets.len() && state.bits + bits > targets[rows.len()] {
            record(&state, &mut rows);
        }
        while layer < layers.len() && state.bits + bits > layers[layer] {
            state.bits += paid * schedule.end_layer(model, &state);
            layer += 1;
        }
        state.bits += paid * schedule.flag(&c, top.id, true);
        version[top.id] += 1;
        match op {
            Op::Extend(next) => {
                state.bits += bits;
                state.clusters[top.id] = next;
            }
            Op::Split(children) => {
                let new = state.apply_split(top.id, children, bits);
                version.push(0);
                schedule.push(top.id);
                push(&mut heap, &state.clusters[new], new, 0);
            }
        }
        push(&mut heap, &state.clusters[top.id], top.id, version[top.id]);
    }
    (rows, schedule)
}

/// Width of a cell `t` steps deep (its longest side).
fn cell_width(tree: &Tree, t: usize) -> f64 {
    (0..3)
        .map(|a| {
            let k = tree.axis[..t].iter().filter(|&&x| x == a).count() as i32;
            tree.mesh.grid.cell[a] * 2f64.powi(tree.levels as i32 - k)
        })
        .fold(0.0, f64::max)
}

/// What a decoder sees of each cluster in the mesh it shows: the area of the faces around it
/// (a third of each) and the distance of its representative from its neighbours' mean, along
/// the faces' normal (how far the surface bends there).
fn seen(model: &Model, state: &State) -> Vec<(f64, f64)> {
    let n = state.clusters.len();
    let positions: Vec<DVec3> = state
        .clusters
        .iter()
        .map(|c| model.shown(c.rep, c.known))
        .collect();
    let shown = model.tree.project(&state.owner, positions.clone());
    let mut area = vec![0.0; n];
    let mut normal = vec![DVec3::ZERO; n];
    let mut around = vec![(DVec3::ZERO, 0u32); n];
    for f in &shown.mesh.faces {
        let p = f.map(|v| positions[v as usize]);
        let cross = (p[1] - p[0]).cross(p[2] - p[0]);
        for (k, &v) in f.iter().enumerate() {
            let v = v as usize;
            area[v] += cross.length() / 6.0;
            normal[v] += cross;
            for other in [f[(k + 1) % 3], f[(k + 2) % 3]] {
                around[v].0 += positions[other as usize];
                around[v].1 += 1;
            }
        }
    }
    (0..n)
        .map(|v| {
            let (sum, count) = around[v];
            let offset = if count == 0 {
                0.0
            } else {
                (positions[v] - sum / count as f64).dot(normal[v].normalize_or_zero())
            };
            (area[v], offset)
        })
        .collect()
}

/// What the decoder values each cluster's next operation at, per bit it expects to spend, and
/// whether that operation is a split: a split by the area around the cluster times its bend
/// squared, less what its representative's own cell leaves open (a cell of width w leaves w²/12
/// along the normal), and at least [`SPLIT_PRIOR`] of its cell's width squared; a refinement of
/// its representative by the area times the squared error that the next level of precision
/// removes. The bits are `emc`'s for the level's splits and questions. `None`: nothing left.
fn decoder_values(model: &Model, state: &State) -> Vec<Option<(f64, bool)>> {
    let tree = model.tree;
    let seen = seen(model, state);
    state
        .clusters
        .iter()
        .zip(seen)
        .map(|(c, (area, offset))| {
            let open = if model.show == Show::Exact {
                0.0
            } else {
                cell_width(tree, c.known).powi(2) / 12.0
            };
            let level = (c.depth / 3).min(tree.levels - 1);
            let split = model.branch(c).map(|_| {
                let bits = tree.split_bits[level] + AHEAD as f64 * model.ahead_bits[level];
                let bend =
                    (offset * offset - open).max(SPLIT_PRIOR * cell_width(tree, c.depth).powi(2));
                (area * bend / bits, true)
            });
            let extend = model.extend(c).map(|_| {
                let bits = 3.0 * model.ahead_bits[(c.known / 3).min(tree.levels - 1)];
                (area * open * 0.75 / bits.max(1e-3), false)
            });
            split
                .into_iter()
                .chain(extend)
                .reduce(|a, b| if b.0 > a.0 { b } else { a })
        })
        .collect()
}

/// An order a decoder can follow untold: passes over the clusters, each ranking them by
/// [`decoder_values`] and acting on the first [`DECODER_SHARE`] of them (the encoder sends only
/// where each pass stops). Flat regions therefore stay merged while bent ones split.
fn decoder_order(model: &Model, targets: &[f64], reference: &Reference) -> Vec<(usize, f64)> {
    let mut state = State::new(model);
    let mut rows = Vec::new();
    let record = |state: &State, rows: &mut Vec<(usize, f64)>| {
        rows.push((state.clusters.len(), state.rms(reference)));
    };
    while rows.len() < targets.len() {
        // (value per bit, cluster, whether it splits)
        let mut ranked: Vec<(f64, usize, bool)> = decoder_values(model, &state)
            .into_iter()
            .enumerate()
            .filter_map(|(id, v)| v.map(|(value, splits)| (value, id, splits)))
            .collect();
        if ranked.is_empty() {
            record(&state, &mut rows);
            continue;
        }
        ranked.sort_by(|a, b| b.0.total_cmp(&a.0));
        let take = ((ranked.len() as f64 * DECODER_SHARE).ceil() as usize).max(1);
        for &(_, id, splits) in &ranked[..take] {
            let c = state.clusters[id];
            if splits {
                let (children, bits, _) = model.split(&c).expect("ranked as a split");
                while rows.len() < targets.len() && state.bits + bits > targets[rows.len()] {
                    record(&state, &mut rows);
                }
                state.apply_split(id, children, bits);
            } else {
                let (next, bits, _) = model.extend(&c).expect("ranked as a refinement");
                while rows.len() < targets.len() && state.bits + bits > targets[rows.len()] {
                    record(&state, &mut rows);
                }
                state.bits += bits;
                state.clusters[id] = next;
            }
            if rows.len() == targets.len() {
                break;
            }
        }
    }
    rows
}

/// One order's measurements: (bits, RMS) at the end of every level of the level order, and
/// (vertices, RMS) of the other orders at the same bits.
struct Columns {
    levels: Vec<(f64, f64)>,
    greedy: Vec<(usize, f64)>,
    sent: Vec<(usize, f64)>,
    untold: Vec<(usize, f64)>,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut meshes: Vec<String> = std::env::args().skip(1).collect();
    if meshes.is_empty() {
        meshes = vec!["bunny".into()];
    }
    let results = Path::new(env!("CARGO_MANIFEST_DIR")).join("../results");
    for name in meshes {
        let ahead: Vec<(f64, f64)> = load_at(&results, "emc-ahead", &name, 12)?
            .levels
            .iter()
            .map(|l| (l.bits as f64, l.rms.unwrap_or(f64::NAN)))
            .collect();
        let pm = rms_curve(&load_at(&results, "pm", &name, 12)?);
        let Built { original, tree, .. } = build(&name)?;
        let reference = Reference::new(&original, SampleBudget::default(), DEFAULT_SEED);
        if tree.levels != ahead.len() {
            return Err(format!(
                "{name}: `emc-ahead`'s results have {} levels, the octree {}",
                ahead.len(),
                tree.levels
            )
            .into());
        }
        let n = tree.sorted.len() as f64;
        // α: the level order's lossless bits equal to `emc-ahead`'s.
        let unfitted = Model::new(&tree, Rule::Oracle, Show::Coded, 0.0);
        let spent = level_order(&unfitted, None).last().expect("levels").0;
        let half_total = level_order(&Model::new(&tree, Rule::Oracle, Show::Coded, 1.0), None)
            .last()
            .expect("levels")
            .0
            - spent;
        let lossless = ahead.last().expect("levels").0;
        let alpha = (lossless - spent) / half_total;
        // Quality layers a bit-doubling apart, down from the lossless stream.
        let mut layers: Vec<f64> = std::iter::successors(Some(lossless), |b| Some(b / 2.0))
            .take_while(|&b| b > 2.0 * tree.fixed_bits)
            .collect();
        layers.reverse();
        println!(
            "{name}: {n} vertices; α = {alpha:.3} (ahead steps cost {:.0}% more than `emc`'s)",
            alpha * 100.0
        );
        let mut columns = Vec::new();
        for (rule, show) in [
            (Rule::Oracle, Show::Coded),
            (Rule::Larger, Show::Coded),
            (Rule::Oracle, Show::Exact),
        ] {
            let model = Model::new(&tree, rule, show, alpha);
            let levels = level_order(&model, Some(&reference));
            // Every other order at the level order's bits: its gain alone.
            let bits: Vec<f64> = levels.iter().map(|l| l.0).collect();
            let (greedy_rows, schedule) = greedy(&model, &bits, &layers, false, &reference);
            // (The exact bound's schedule is counted, not paid: the table has no use for it.)
            let sent = if show == Show::Coded {
                greedy(&model, &bits, &layers, true, &reference).0
            } else {
                Vec::new()
            };
            let (flags, plain, under_contexts) = schedule.bits();
            println!(
                "{name}, {rule:?}, {show:?}: the greedy order's schedule over {} layers: {flags} flags, {:.0} bits with no context ({:.2}% of the lossless stream), {:.0} under the contexts ({:.2}%)",
                layers.len(),
                plain,
                100.0 * plain / lossless,
                under_contexts,
                100.0 * under_contexts / lossless
            );
            columns.push(Columns {
                untold: decoder_order(&model, &bits, &reference),
                levels,
                greedy: greedy_rows,
                sent,
            });
        }
        println!();
        println!("| level | `emc-ahead` bits/vertex | the model's level order, bits/vertex | `emc-ahead` RMS | `pm` RMS at those bits | `emc-ahead` / `pm` | the model's level order, RMS: oracle, larger half, exact | greedy / level order at the same bits: oracle, larger half, exact | greedy with its schedule sent / level order: oracle, larger half | untold / level order: oracle, larger half, exact | `emc-ahead` / `pm` times the gain (larger half): greedy, sent, untold |");
        println!("|---:|---:|---:|---:|---:|---:|---|---|---|---|---|");
        for (l, &(bits, rms)) in ahead.iter().enumerate() {
            let pm_rms = log_log_interpolate(&pm, bits);
            let level = |k: usize| columns[k].levels[l].1;
            let gain = |k: usize, rows: &[(usize, f64)]| rows[l].1 / level(k);
            let greedy = |k: usize| gain(k, &columns[k].greedy);
            let sent = |k: usize| gain(k, &columns[k].sent);
            let untold = |k: usize| gain(k, &columns[k].untold);
            let (over_pm, estimate) = match pm_rms {
                Some(p) => (
                    format!("{:.2}", rms / p),
                    format!(
                        "{:.2}, {:.2}, {:.2}",
                        rms / p * greedy(1),
                        rms / p * sent(1),
                        rms / p * untold(1)
                    ),
                ),
                None => (String::new(), String::new()),
            };
            println!(
                "| {} | {:.3} | {:.3} | {rms:.3e} | {} | {over_pm} | {:.3e}, {:.3e}, {:.3e} | {:.2}, {:.2}, {:.2} | {:.2}, {:.2} | {:.2}, {:.2}, {:.2} | {estimate} |",
                l + 1,
                bits / n,
                columns[0].levels[l].0 / n,
                pm_rms.map_or(String::new(), |p| format!("{p:.3e}")),
                level(0),
                level(1),
                level(2),
                greedy(0),
                greedy(1),
                greedy(2),
                sent(0),
                sent(1),
                untold(0),
                untold(1),
                untold(2),
            );
        }
        println!();
    }
    Ok(())
}
