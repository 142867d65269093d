//! Triangles from an edge graph, as EMC's decoder rebuilds them: every 3-cycle (3-clique) of the
//! graph is a candidate triangle; orientations are propagated across edges that exactly two
//! candidates share, so that neighbours agree, starting each connected patch from a guess.
//!
//! The propagation is the same in encoder and decoder; the encoder compares its result with the
//! real faces and transmits only where it is wrong (see `codecs::emc`).

use crate::prefetch::prefetch;
use glam::DVec3;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The edge graph of `faces` over `n` vertices, as sorted adjacency lists.
pub fn adjacency(n: usize, faces: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let mut adj = vec![Vec::new(); n];
    for f in faces {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            adj[a as usize].push(b);
            adj[b as usize].push(a);
        }
    }
    for list in &mut adj {
        list.sort_unstable();
        list.dedup();
    }
    adj
}

/// The 3-cliques of a graph, with the ids of their edges (numbered as by [`EdgeIds`]), so that
/// per-edge work needs no search.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Cliques {
    /// Ascending triples in lexicographic order.
    pub tris: Vec<[u32; 3]>,
    /// Ids of each triple's edges (a, b), (b, c), (a, c).
    pub edges: Vec<[u32; 3]>,
    /// Number of edges of the graph.
    pub edge_count: usize,
}

impl Cliques {
    /// Number of cliques.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }
}

/// All 3-cliques of an undirected graph given as sorted adjacency lists, each as an ascending
/// triple, in lexicographic order; `None` as soon as there are more than `limit` (a decoder's
/// bound on what a hostile stream may make it build).
///
/// Intersecting the neighbour lists of each edge's ends costs Σ deg(v)² — fine for meshes, but
/// quadratic for a star. When that sum is large the vertices are ranked by degree and each edge
/// intersects only the lists of higher-ranked neighbours, which are at most √(2e) long
/// (Chiba & Nishizeki): O(e^1.5) whatever the graph.
pub fn triangles<L: AsRef<[u32]> + Sync>(
    adjacency: &[L],
    limit: usize,
    listing: Listing,
) -> Option<Cliques> {
    let (ends, merge_cost) = adjacency
        .par_iter()
        .map(|l| (l.as_ref().len(), l.as_ref().len() * l.as_ref().len()))
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    let edges = ends / 2;
    if merge_cost <= 64 * edges + (1 << 20) {
        triangles_by_merge(adjacency, limit, listing)
    } else {
        let tris = triangles_by_degree_rank(adjacency, limit)?;
        let ids = EdgeIds::new(adjacency);
        let edges = tris
            .iter()
            .map(|&[a, b, c]| [ids.id(a, b), ids.id(b, c), ids.id(a, c)].map(|e| e as u32))
            .collect();
        Some(Cliques {
            tris,
            edges,
            edge_count: ids.len(),
        })
    }
}

/// How [`triangles`] lists: in the least memory, or faster with memory to spare.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Listing {
    /// On one thread, straight into the result (for a caller listing at its memory peak).
    InPlace,
    /// In runs on rayon's threads, then joined: for a moment the runs' lists and the result
    /// are held at once, twice the triangles' memory.
    OnThreads,
}

/// Where each vertex's neighbours above it start in its list, and the id of its first edge to
/// one of them ([`EdgeIds`]); the last entry of the ids is the edge count.
fn above_and_first<L: AsRef<[u32]> + Sync>(adjacency: &[L]) -> (Vec<u32>, Vec<u32>) {
    let above: Vec<u32> = adjacency
        .par_iter()
        .enumerate()
        .map(|(a, list)| list.as_ref().partition_point(|&x| x <= a as u32) as u32)
        .collect();
    let mut first = Vec::with_capacity(adjacency.len() + 1);
    let mut total = 0u32;
    for (list, &start) in adjacency.iter().zip(&above) {
        first.push(total);
        total += list.as_ref().len() as u32 - start;
    }
    first.push(total);
    (above, first)
}

fn triangles_by_merge<L: AsRef<[u32]> + Sync>(
    adjacency: &[L],
    limit: usize,
    listing: Listing,
) -> Option<Cliques> {
    let (above, first) = above_and_first(adjacency);
    let edge_count = *first.last().unwrap_or(&0) as usize;
    let list = |vertices: Range<usize>, capacity: usize, report: &mut dyn FnMut(usize) -> bool| {
        let mut run = Cliques {
            tris: Vec::with_capacity(capacity),
            edges: Vec::with_capacity(capacity),
            edge_count,
        };
        for a in vertices {
            let above_a = &adjacency[a].as_ref()[above[a] as usize..];
            for (i, &b) in above_a.iter().enumerate() {
                let around_b = adjacency[b as usize].as_ref();
                // c > b and adjacent to both.
                let above_b = &around_b[above[b as usize] as usize..];
                let (ab, base_b) = (first[a] + i as u32, first[b as usize]);
                for_each_common(&above_a[i + 1..], above_b, |c, p, q| {
                    run.tris.push([a as u32, b, c]);
                    run.edges.push([ab, base_b + q as u32, ab + 1 + p as u32]);
                });
            }
            if !report(run.tris.len()) {
                return None;
            }
        }
        Some(run)
    };
    let threads = rayon::current_num_threads();
    let runs = match listing {
        Listing::OnThreads if threads > 1 => 16 * threads,
        _ => 1,
    };
    if runs == 1 {
        // A closed mesh has two triangles for every three edges.
        let expected = (edge_count * 2 / 3).min(limit);
        let mut out = list(0..adjacency.len(), expected, &mut |n| n <= limit)?;
        // Past the estimate, both grew by doubling: give back what they do not use.
        out.tris.shrink_to_fit();
        out.edges.shrink_to_fit();
        return Some(out);
    }
    // Runs of about equal numbers of edges, each listing its vertices' triangles; every run
    // adds what it lists to one count now and then, so that all of them stop soon after the
    // count passes the limit.
    let ends: Vec<usize> = (0..=runs)
        .map(|k| {
            let edges = (edge_count * k / runs) as u32;
            first.partition_point(|&f| f < edges).min(adjacency.len())
        })
        .collect();
    let listed = AtomicUsize::new(0);
    let parts: Vec<Cliques> = ends
        .par_windows(2)
        .map(|run| {
            // Room for a triangle an edge, more than a run of a manifold mesh lists (untouched
            // room costs no memory): past it a run grows by doubling, and copies.
            let capacity = (first[run[1]] - first[run[0]]) as usize;
            let mut reported = 0;
            list(run[0]..run[1], capacity, &mut |n| {
                if n - reported < 1024 {
                    return n <= limit;
                }
                let total = listed.fetch_add(n - reported, Ordering::Relaxed) + n - reported;
                reported = n;
                total <= limit
            })
        })
        .collect::<Option<_>>()?;
    let total: usize = parts.iter().map(Cliques::len).sum();
    if total > limit {
        return None;
    }
    // Joined on the threads too: the result is fresh memory, and its first touches cost as
    // much as the copy (zeroed pages come from the system untouched).
    let mut out = Cliques {
        tris: vec![[0; 3]; total],
        edges: vec![[0; 3]; total],
        edge_count,
    };
    let mut places = Vec::with_capacity(parts.len());
    let (mut tris, mut edges) = (&mut out.tris[..], &mut out.edges[..]);
    for part in &parts {
        let (tris_here, tris_rest) = std::mem::take(&mut tris).split_at_mut(part.len());
        let (edges_here, edges_rest) = std::mem::take(&mut edges).split_at_mut(part.len());
        places.push((part, tris_here, edges_here));
        (tris, edges) = (tris_rest, edges_rest);
    }
    places.into_par_iter().for_each(|(part, tris, edges)| {
        tris.copy_from_slice(&part.tris);
        edges.copy_from_slice(&part.edges);
    });
    Some(out)
}

fn triangles_by_degree_rank<L: AsRef<[u32]>>(
    adjacency: &[L],
    limit: usize,
) -> Option<Vec<[u32; 3]>> {
    let n = adjacency.len();
    let mut by_degree: Vec<u32> = (0..n as u32).collect();
    by_degree.sort_unstable_by_key(|&v| (adjacency[v as usize].as_ref().len(), v));
    let mut rank = vec![0u32; n];
    for (r, &v) in by_degree.iter().enumerate() {
        rank[v as usize] = r as u32;
    }
    // Each vertex's higher-ranked neighbours, as ranks, ascending.
    let higher: Vec<Vec<u32>> = (0..n)
        .map(|v| {
            let mut list: Vec<u32> = adjacency[v]
                .as_ref()
                .iter()
                .map(|&w| rank[w as usize])
                .filter(|&r| r > rank[v])
                .collect();
            list.sort_unstable();
            list
        })
        .collect();
    let mut out = Vec::new();
    for u in 0..n {
        let above_u = &higher[u];
        for (i, &rw) in above_u.iter().enumerate() {
            let above_w = &higher[by_degree[rw as usize] as usize];
            for_each_common(&above_u[i + 1..], above_w, |rx, _, _| {
                let mut t = [u as u32, by_degree[rw as usize], by_degree[rx as usize]];
                t.sort_unstable();
                out.push(t);
            });
            if out.len() > limit {
                return None;
            }
        }
    }
    out.sort_unstable();
    Some(out)
}

/// Calls `found` with every value in both ascending lists and its positions in `a` and `b`.
fn for_each_common(a: &[u32], b: &[u32], mut found: impl FnMut(u32, usize, usize)) {
    let (mut p, mut q) = (0, 0);
    while p < a.len() && q < b.len() {
        let (x, y) = (a[p], b[q]);
        if x == y {
            found(x, p, q);
        }
        // Both steps without branches: which list is behind is as good as random.
        p += (x <= y) as usize;
        q += (y <= x) as usize;
    }
}

/// Numbers the edges of a graph: edge (a, b) with a < b gets `first[a]` + the rank of b among
/// a's neighbours above a. Lets per-edge data live in flat arrays instead of sorted pair lists.
pub struct EdgeIds<'g, L> {
    adjacency: &'g [L],
    first: Vec<u32>,
    /// Where each vertex's neighbours above it start in its list.
    above: Vec<u32>,
}

impl<'g, L: AsRef<[u32]> + Sync> EdgeIds<'g, L> {
    /// Numbers the edges of `adjacency` (sorted lists).
    pub fn new(adjacency: &'g [L]) -> Self {
        let (above, first) = above_and_first(adjacency);
        EdgeIds {
            adjacency,
            first,
            above,
        }
    }

    /// Number of edges.
    pub fn len(&self) -> usize {
        *self.first.last().unwrap_or(&0) as usize
    }

    /// True for a graph without edges.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Id of edge (a, b), a < b, which must exist.
    pub fn id(&self, a: u32, b: u32) -> usize {
        let list = self.adjacency[a as usize].as_ref();
        let above = &list[self.above[a as usize] as usize..];
        self.first[a as usize] as usize + above.partition_point(|&x| x < b)
    }
}

/// Edges of the graph that lie on no clique of `cliques` (its 3-cliques) but those `skipped`.
pub fn loose_edges<L: AsRef<[u32]>>(
    adjacency: &[L],
    cliques: &Cliques,
    skipped: Option<&[bool]>,
) -> Vec<[u32; 2]> {
    let mut covered = vec![false; cliques.edge_count];
    for (t, edges) in cliques.edges.iter().enumerate() {
        if skipped.is_some_and(|s| s[t]) {
            continue;
        }
        for &e in edges {
            covered[e as usize] = true;
        }
    }
    // Edges in id order: each vertex's neighbours above it, vertex by vertex.
    let mut loose = Vec::new();
    let mut id = 0;
    for (a, list) in adjacency.iter().enumerate() {
        for &b in list.as_ref().iter().filter(|&&b| b > a as u32) {
            if !covered[id] {
                loose.push([a as u32, b]);
            }
            id += 1;
        }
    }
    loose
}

/// A triangle as an ascending triple plus whether it is flipped: unflipped means the cycle
/// a → b → c, flipped a → c → b.
pub fn oriented(tri: [u32; 3], flipped: bool) -> [u32; 3] {
    if flipped {
        [tri[0], tri[2], tri[1]]
    } else {
        tri
    }
}

/// Orients the triangles `tris` (ascending triples of edges of the graph `adjacency`) that are
/// not `skipped`.
///
/// Visits them patch by patch in a fixed order: a patch starts at its lowest unvisited
/// triangle, whose orientation is guessed so that its normal points away from `centre`, and
/// grows breadth-first across edges shared by exactly two non-skipped triangles, each reached
/// triangle predicted to agree with the one it was reached from. `decide(visit, triangle,
/// predicted)`
/// returns the orientation to use for the `visit`-th triangle visited (true = flipped); the
/// result holds the chosen orientation of every triangle (skipped ones: false). `decide` is
/// also told which triangle it decides: the visiting order depends only on the graph.
pub fn propagate_orientation(
    cliques: &Cliques,
    skipped: &[bool],
    positions: &[DVec3],
    centre: DVec3,
    mut decide: impl FnMut(usize, usize, bool) -> bool,
) -> Vec<bool> {
    let tris = &cliques.tris;
    // For each edge, in one word so that a triangle's update touches one place: the XOR of
    // the ids of the non-skipped triangles using it (bits 0–31: seen from one of two, the
    // other's id), how many they are (bits 32–33, saturating at 3: only "two" matters) and
    // the XOR of the directions in which they traverse it unflipped (bit 34; low to high id on
    // their edges (a,b) and (b,c), high to low on (a,c)): 0 when two use it the same way
    // round. Each thread takes a range of the edges and reads every triangle for those (the
    // reads go in order; the scattered writes are what costs).
    const USERS: u64 = 1 << 32;
    const DIRECTION: u64 = 1 << 34;
    let users = |tally: u64| (tally / USERS) & 3;
    let mut tallies = vec![0u64; cliques.edge_count];
    let range = cliques
        .edge_count
        .div_ceil(rayon::current_num_threads())
        .max(1);
    tallies
        .par_chunks_mut(range)
        .enumerate()
        .for_each(|(k, tallies)| {
            let first = k * range;
            // Touched in order first: pages first touched by scattered writes from several
            // threads fault in each other's way (18 → 50 ms on the ×16 mesh's decode).
            tallies.fill(0);
            for (t, edges) in cliques.edges.iter().enumerate() {
                if skipped[t] {
                    continue;
                }
                for (slot, &e) in edges.iter().enumerate() {
                    let Some(tally) = (e as usize)
                        .checked_sub(first)
                        .and_then(|e| tallies.get_mut(e))
                    else {
                        continue;
                    };
                    let direction = DIRECTION * (slot != 2) as u64;
                    let more = USERS * (users(*tally) < 3) as u64;
                    *tally = (*tally ^ t as u32 as u64 ^ direction) + more;
                }
            }
        });
    // For each triangle, across each of its edges (a,b), (b,c), (a,c): the one other
    // triangle, if exactly two share the edge, and whether the two traverse it the same way
    // round unflipped (bit `slot` of the second field). Side by side, so that reaching a
    // triangle (in an order the cache cannot foresee) reads one place.
    let nodes: Vec<([u32; 3], u8)> = cliques
        .edges
        .par_iter()
        .enumerate()
        .map(|(t, edges)| {
            let mut same = 0;
            let across = std::array::from_fn(|slot| {
                let tally = tallies[edges[slot] as usize];
                same |= ((tally & DIRECTION == 0) as u8) << slot;
                if users(tally) == 2 && !skipped[t] {
                    tally as u32 ^ t as u32
                } else {
                    u32::MAX
                }
            });
            (across, same)
        })
        .collect();
    drop(tallies);
    let mut flipped = vec![false; tris.len()];
    let mut seen = skipped.to_vec();
    let mut queue = Vec::with_capacity(tris.len());
    let mut visit = 0;
    for start in 0..tris.len() {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        let [a, b, c] = tris[start].map(|v| positions[v as usize]);
        let outward = (b - a).cross(c - a).dot((a + b + c) / 3.0 - centre) >= 0.0;
        flipped[start] = decide(visit, start, !outward);
        visit += 1;
        // Breadth-first: the queue, read from `next` on, holds each reached triangle with its
        // orientation.
        queue.clear();
        queue.push((start as u32, flipped[start]));
        let mut next = 0;
        while let Some(&(t, flip)) = queue.get(next) {
            next += 1;
            let (across, same) = nodes[t as usize];
            for (slot, &other) in across.iter().enumerate() {
                if other == u32::MAX || seen[other as usize] {
                    continue;
                }
                seen[other as usize] = true;
                // It is read when the queue reaches it: fetch it into the cache now.
                prefetch(&nodes[other as usize]);
                // The neighbour agrees when it traverses the shared edge the other way round:
                // flipped unlike t where the two traverse it alike unflipped, else like t.
                let predicted = flip ^ (same >> slot & 1 == 1);
                let chosen = decide(visit, other as usize, predicted);
                flipped[other as usize] = chosen;
                visit += 1;
                queue.push((other, chosen));
            }
        }
    }
    flipped
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    #[test]
    fn a_sphere_is_rebuilt_with_outward_orientation() {
        let sphere = generate::icosphere(2);
        let adj = adjacency(sphere.positions.len(), &sphere.faces);
        let cliques = triangles(&adj, usize::MAX, Listing::OnThreads).unwrap();
        let tris = &cliques.tris;
        assert_eq!(tris.len(), sphere.faces.len());
        let skipped = vec![false; tris.len()];
        let mut guesses = 0;
        let flipped = propagate_orientation(
            &cliques,
            &skipped,
            &sphere.positions,
            DVec3::ZERO,
            |_, _, p| {
                guesses += 1;
                p
            },
        );
        assert_eq!(guesses, tris.len());
        let mut ours: Vec<[u32; 3]> = tris
            .iter()
            .zip(&flipped)
            .map(|(t, &f)| crate::mesh::canonical::rotate_to_smallest(oriented(*t, f)))
            .collect();
        let mut theirs: Vec<[u32; 3]> = sphere
            .faces
            .iter()
            .map(|f| crate::mesh::canonical::rotate_to_smallest(*f))
            .collect();
        ours.sort_unstable();
        theirs.sort_unstable();
        assert_eq!(ours, theirs);
        assert!(loose_edges(&adj, &cliques, None).is_empty());
        let mut dropped = skipped.clone();
        dropped[0] = true;
        assert!(loose_edges(&adj, &cliques, Some(&dropped)).is_empty());
        // An edge of no triangle.
        let mut adj = adj;
        let n = adj.len() as u32;
        adj.push(vec![0]);
        adj[0].push(n);
        let cliques = triangles(&adj, usize::MAX, Listing::OnThreads).unwrap();
        assert_eq!(loose_edges(&adj, &cliques, None), vec![[0, n]]);
    }

    #[test]
    fn both_clique_listings_agree_and_stop_at_the_limit() {
        let mut x = 0x9e37_79b9_7f4a_7c15_u64;
        for n in [3usize, 10, 40, 120] {
            // A random graph plus a hub joined to everything (the degree-ranked case).
            let mut faces = Vec::new();
            for _ in 0..3 * n {
                let mut f = [0u32; 3];
                for v in &mut f {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    *v = (x % n as u64) as u32;
                }
                if f[0] != f[1] && f[1] != f[2] && f[0] != f[2] {
                    faces.push(f);
                }
            }
            for v in 1..n as u32 - 1 {
                faces.push([0, v, v + 1]);
            }
            let adj = adjacency(n, &faces);
            let merged = triangles_by_merge(&adj, usize::MAX, Listing::InPlace).unwrap();
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(3)
                .build()
                .unwrap();
            let on_threads =
                pool.install(|| triangles_by_merge(&adj, usize::MAX, Listing::OnThreads));
            assert_eq!(on_threads.as_ref(), Some(&merged));
            let ranked = triangles_by_degree_rank(&adj, usize::MAX).unwrap();
            assert_eq!(merged.tris, ranked);
            let ids = EdgeIds::new(&adj);
            for (&[a, b, c], &edges) in merged.tris.iter().zip(&merged.edges) {
                let want = [ids.id(a, b), ids.id(b, c), ids.id(a, c)].map(|e| e as u32);
                assert_eq!(edges, want);
            }
            let merged = merged.tris;
            assert!(merged.windows(2).all(|w| w[0] < w[1]));
            let k = merged.len();
            for listing in [Listing::InPlace, Listing::OnThreads] {
                assert_eq!(triangles(&adj, k, listing).unwrap().len(), k);
                assert!(pool
                    .install(|| triangles_by_merge(&adj, k - 1, listing))
                    .is_none());
            }
            assert!(triangles_by_degree_rank(&adj, k - 1).is_none());
        }
    }
}
