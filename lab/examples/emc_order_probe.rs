//! What `emc`'s intermediate levels could gain from another order of the same octree decisions
//! (issue "EMC at every prefix"), estimated before any syntax is built.
//!
//! The octree of `emc` is a binary tree over the steps (three a level, one axis each): a node
//! either keeps all its vertices in one half (a "which half" bit) or splits. Coded in level
//! order, a cluster is shown at its cell's centre until its vertices part, so that by the level
//! where the prefix costs 5 bits a vertex on bunny.ply nearly every vertex is present at 7 bits of
//! precision. The order probed here lets a cluster's **representative** — the vertex on the
//! cluster's leftmost path of the tree, a real vertex of the mesh — refine ahead of the cluster's
//! split: *extend* codes the next decision on that path (where the path's node splits, the
//! representative takes the lower half by this convention, so the choice costs nothing; the
//! other half waits), and *split* shows the waiting half at the shallowest branch point as a
//! vertex of its own. Every decision of the tree is still coded exactly once, so the lossless
//! stream carries the same information; only the order changes.
//!
//! Bits per decision are `emc`'s own, level by level, from its encoding of the same mesh: a
//! split costs that level's connectivity bits per split, a "which half" bit that level's
//! geometry bits per such bit. A context model built for the new order would code them
//! differently: these are estimates, not a stream.
//!
//! Orders compared, at the bits of each `emc` level (every mesh shown with the original
//! triangles projected through the clusters, vertices at their representatives' cell centres,
//! RMS both ways relative to the diagonal, as `experiment` measures):
//! - *level order*: every decision of a level before the next (today's order, at cell centres);
//! - *greedy*: the decision that removes the most quadric error (the sum of squared distances of
//!   the cluster's vertices' face planes from its representative, plus a tenth of their area
//!   times the squared distance from the vertices) per estimated bit, chosen with the encoder's
//!   knowledge, which a decoder-side estimate would only approximate. Gains are taken at the
//!   representatives the decisions place, or, for splits, at the quadrics' least points (what the
//!   split could give once its halves are refined);
//! - and the level order with each cluster at its quadric's least point, its bits not counted:
//!   what knowing where a cluster should stand would be worth.
//!
//! BENCHMARKS.md ("`emc`'s intermediate levels", the second probe) has the figures.
//! Run: cargo run --release --example emc_order_probe -- [mesh…]

mod emc_octree;

use emc_octree::{build, least, priority, Built, Candidate, Tree};
use meshcodec::codecs::LevelMesh;
use meshcodec::metrics::{Reference, SampleBudget, DEFAULT_SEED};
use std::collections::BinaryHeap;

impl Tree {
    /// Estimated bits of the "which half" decisions on the leftmost path of `[lo, hi)` from
    /// depth `from` to `to` (its branch points cost nothing: the splits pay for them).
    fn path_bits(&self, lo: usize, hi: usize, from: usize, to: usize) -> f64 {
        (from..to)
            .filter(|&t| {
                let e = self.node_end(lo, hi, t);
                let m = self.middle(lo, e, t);
                !(m > lo && m < e)
            })
            .map(|t| self.half_bits[t / 3])
            .sum()
    }
}

#[derive(Clone, Copy)]
struct Cluster {
    lo: usize,
    hi: usize,
    /// Depth of the cluster's node (every member agrees on the steps before it).
    s: usize,
    /// Depth the representative is known to.
    r: usize,
}

enum Op {
    Extend,
    /// Show the waiting half at the shallowest branch point, its representative known to the
    /// given depth.
    Split(usize),
    /// Extend to the next branch point on the path, then split there (a cluster whose next
    /// steps would move its representative away from its vertices still splits).
    SplitNext,
}

/// The two operations of cluster `c` with their gain and estimated bits.
fn operations(tree: &Tree, c: &Cluster) -> Vec<(Op, f64, f64)> {
    let mut out = Vec::new();
    let q = tree.quadric(c.lo, c.hi);
    let here = tree.position(c.lo, c.r);
    if c.r < tree.steps {
        let e = tree.node_end(c.lo, c.hi, c.r);
        let m = tree.middle(c.lo, e, c.r);
        let branches = m > c.lo && m < e;
        let bits = if branches {
            0.0
        } else {
            tree.half_bits[c.r / 3]
        };
        let gain = q.error(here) - q.error(tree.position(c.lo, c.r + 1));
        out.push((Op::Extend, gain, bits));
    }
    if let Some((b, mid)) = branch(tree, c) {
        // The new vertex comes in at its sibling's precision (a coarse cell's centre can lie
        // farther from its vertices than the sibling's representative does).
        let right = tree.quadric(mid, c.hi);
        let best = (b + 1..=c.r)
            .map(|k| {
                let gain = if tree.splits_at_best {
                    least(&q) - least(&tree.quadric(c.lo, mid)) - least(&right)
                } else {
                    right.error(here) - right.error(tree.position(mid, k))
                };
                let bits = tree.split_bits[b / 3] + tree.path_bits(mid, c.hi, b + 1, k);
                (Op::Split(k), gain, bits)
            })
            .max_by(|a, b| priority(a.1, a.2).total_cmp(&priority(b.1, b.2)))
            .expect("b < r");
        out.push(best);
    } else if c.hi - c.lo > 1 {
        let mut bits = 0.0;
        for t in c.r..tree.steps {
            let e = tree.node_end(c.lo, c.hi, t);
            let m = tree.middle(c.lo, e, t);
            if m > c.lo && m < e {
                let (left, right) = (tree.quadric(c.lo, m), tree.quadric(m, c.hi));
                let gain = if tree.splits_at_best {
                    least(&q) - least(&left) - least(&right)
                } else {
                    q.error(here)
                        - left.error(tree.position(c.lo, t + 1))
                        - right.error(tree.position(m, t + 1))
                };
                out.push((Op::SplitNext, gain, bits + tree.split_bits[t / 3]));
                break;
            }
            bits += tree.half_bits[t / 3];
        }
    }
    out
}

/// The shallowest branch point known on the cluster's leftmost path, and where it parts.
fn branch(tree: &Tree, c: &Cluster) -> Option<(usize, usize)> {
    (c.s..c.r).find_map(|t| {
        let m = tree.middle(c.lo, c.hi, t);
        (m > c.lo && m < c.hi).then_some((t, m))
    })
}

struct State<'a> {
    tree: &'a Tree,
    clusters: Vec<Cluster>,
    owner: Vec<u32>,
    bits: f64,
}

impl<'a> State<'a> {
    fn new(tree: &'a Tree) -> State<'a> {
        State {
            tree,
            clusters: vec![Cluster {
                lo: 0,
                hi: tree.sorted.len(),
                s: 0,
                r: 0,
            }],
            owner: vec![0; tree.sorted.len()],
            bits: tree.fixed_bits,
        }
    }
    fn apply(&mut self, id: usize, op: &Op, bits: f64) -> Option<usize> {
        self.bits += bits;
        let c = self.clusters[id];
        match op {
            Op::Extend => {
                self.clusters[id].r += 1;
                None
            }
            Op::SplitNext => {
                while branch(self.tree, &self.clusters[id]).is_none() {
                    self.clusters[id].r += 1;
                }
                let r = self.clusters[id].r;
                self.apply(id, &Op::Split(r), 0.0)
            }
            &Op::Split(k) => {
                let (b, mid) = branch(self.tree, &c).expect("a split has a branch");
                self.clusters[id] = Cluster {
                    lo: c.lo,
                    hi: mid,
                    s: b + 1,
                    r: c.r,
                };
                let new = self.clusters.len();
                self.clusters.push(Cluster {
                    lo: mid,
                    hi: c.hi,
                    s: b + 1,
                    r: k,
                });
                for o in &mut self.owner[mid..c.hi] {
                    *o = new as u32;
                }
                Some(new)
            }
        }
    }
    /// The mesh shown: the original triangles through the clusters, each at its
    /// representative — or, `ideal`, where its quadric is least (bits not counted).
    fn mesh(&self, ideal: bool) -> LevelMesh {
        let positions = self
            .clusters
            .iter()
            .map(|c| {
                let coded = self.tree.position(c.lo, c.r);
                if ideal {
                    self.tree.quadric(c.lo, c.hi).minimizer().unwrap_or(coded)
                } else {
                    coded
                }
            })
            .collect();
        self.tree.project(&self.owner, positions)
    }
}

fn best(tree: &Tree, c: &Cluster) -> Option<(Op, f64, f64)> {
    operations(tree, c)
        .into_iter()
        .max_by(|a, b| priority(a.1, a.2).total_cmp(&priority(b.1, b.2)))
}

type Row = (f64, usize, f64);

/// RMS of a state's mesh, at its representatives or (`true`) at its quadrics' least points.
type Measure<'a> = dyn Fn(&State, bool) -> f64 + 'a;

/// Every decision of a depth before the next (today's order), measured at the end of each level.
fn level_order(tree: &Tree, rms: &Measure) -> Vec<(Row, f64)> {
    let mut rows = Vec::new();
    let mut state = State::new(tree);
    for t in 0..tree.steps {
        for id in 0..state.clusters.len() {
            let c = state.clusters[id];
            if c.r != t {
                continue;
            }
            let ops = operations(tree, &c);
            let extend = ops.iter().find(|o| matches!(o.0, Op::Extend)).map(|o| o.2);
            state.apply(id, &Op::Extend, extend.unwrap_or(0.0));
            let c = state.clusters[id];
            if branch(tree, &c).is_some() {
                state.apply(id, &Op::Split(t + 1), tree.split_bits[t / 3]);
            }
        }
        if t % 3 == 2 {
            rows.push((
                (state.bits, state.clusters.len(), rms(&state, false)),
                rms(&state, true),
            ));
        }
    }
    rows
}

/// The decision of most gain per bit first, measured where the bits reach each of `targets`.
fn greedy(tree: &Tree, targets: &[f64], rms: &Measure) -> Vec<Row> {
    let mut state = State::new(tree);
    let mut version = vec![0u32; 1];
    let mut heap = BinaryHeap::new();
    let push = |heap: &mut BinaryHeap<Candidate>, c: &Cluster, id, v| {
        if let Some((_, gain, bits)) = best(tree, c) {
            heap.push(Candidate {
                priority: priority(gain, bits),
                id,
                version: v,
            });
        }
    };
    push(&mut heap, &state.clusters[0], 0, 0);
    let mut rows = Vec::new();
    while rows.len() < targets.len() {
        let Some(top) = heap.pop() else {
            rows.push((state.bits, state.clusters.len(), rms(&state, false)));
            continue;
        };
        if top.version != version[top.id] {
            continue;
        }
        let c = state.clusters[top.id];
        let (op, _, bits) = best(tree, &c).expect("a candidate has an operation");
        while rows.len() < targets.len() && state.bits + bits > targets[rows.len()] {
            rows.push((state.bits, state.clusters.len(), rms(&state, false)));
        }
        let new = state.apply(top.id, &op, bits);
        version[top.id] += 1;
        push(&mut heap, &state.clusters[top.id], top.id, version[top.id]);
        if let Some(new) = new {
            version.push(0);
            push(&mut heap, &state.clusters[new], new, 0);
        }
    }
    rows
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut meshes: Vec<String> = std::env::args().skip(1).collect();
    if meshes.is_empty() {
        meshes = vec!["bunny".into()];
    }
    for name in meshes {
        let Built {
            original,
            mut tree,
            level_bits,
            emc_rms,
        } = build(&name)?;
        let reference = Reference::new(&original, SampleBudget::default(), DEFAULT_SEED);
        let n = tree.sorted.len() as f64;
        let rms = |state: &State, ideal: bool| {
            reference
                .compare(&state.mesh(ideal))
                .map_or(f64::NAN, |d| d.rms)
        };
        let levels = level_order(&tree, &rms);
        let at_representatives = greedy(&tree, &level_bits, &rms);
        tree.splits_at_best = true;
        let at_best = greedy(&tree, &level_bits, &rms);
        println!(
            "{name} (12 bits, {} vertices); estimated bits: {:.0} before the first decision; a split, by level: {:?}; a which-half bit: {:?}",
            n,
            tree.fixed_bits,
            tree.split_bits.iter().map(|b| (b * 10.0).round() / 10.0).collect::<Vec<_>>(),
            tree.half_bits.iter().map(|b| (b * 100.0).round() / 100.0).collect::<Vec<_>>()
        );
        println!("| level | bits/vertex | `emc` RMS (shown where predicted) | level order at cell centres: vertices, RMS | greedy, gains at the representatives: vertices, RMS | greedy, splits by their quadrics' least values: vertices, RMS | that / level order | level order, each cluster where its quadric is least (position bits not counted): RMS |");
        println!("|---:|---:|---:|---|---|---|---:|---:|");
        for l in 0..level_bits.len() {
            let ((_, lv, lr), ideal) = levels[l];
            let (_, av, ar) = at_representatives[l];
            let (_, bv, br) = at_best[l];
            println!(
                "| {} | {:.3} | {:.3e} | {}, {:.3e} | {}, {:.3e} | {}, {:.3e} | {:.2} | {:.3e} |",
                l + 1,
                level_bits[l] / n,
                emc_rms[l],
                lv,
                lr,
                av,
                ar,
                bv,
                br,
                br / lr,
                ideal
            );
        }
        println!();
    }
    Ok(())
}
