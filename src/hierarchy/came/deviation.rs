//! Deviations: how far the surface a node stands for lies from the simplified surface around
//! it — the error view-dependent refinement projects to the screen (Hoppe 1997's δ_v, measured
//! the way Nanite measures a cluster group's error: on the simplified mesh the node belongs to).
//!
//! The error sphere bounds how far a node's vertices *spread*; a flat region's coarse node has
//! a large sphere and no error. The deviation e_v instead measures, on the **level mesh** of
//! v's depth k (every node at depth k and every leaf above it active: the mesh the front of
//! that depth shows, the full mesh projected through it), how far the original surface under v
//! lies from v's fan there (the level mesh's faces with a corner at v, and v itself) and the
//! faces around it:
//! - own_v = max over samples p of dist(p, fan(v) ∪ ring(v) ∪ {v}), ring(v) being the faces
//!   at the fan's other corners, the samples the leaves under v
//!   and the centroids of the full mesh's faces with a corner under v. A face of the full mesh
//!   with a corner under v is carried by the projection onto a face of v's fan (or collapses
//!   into an edge or a point of it), so the fan is where its points went.
//!   Then the other way: the points of v's fan faces (centroid, edge midpoints) to the full
//!   mesh's faces with a corner under one of the fan face's corners; own_v is the larger.
//! - Then both ways on **mixed** fronts, v's leaves at v and every other leaf at its ancestor
//!   one level deeper, then two: v kept coarse among finer neighbours, whose chords reach
//!   their descendants, which no level mesh has. The points of v's mixed fan faces to the full
//!   mesh's faces under their corners (on the fly-through's close-ups such a chord stood
//!   1.49 px off the surface at 1 px before this measure, 0.89 px after), and the full mesh's
//!   points (leaves and face centroids) under v and under its neighbours to the mixed front's
//!   faces around them (`MixedSurface`): where v's large fan faces cover a region its finer
//!   neighbours stand for, the surface there is farther from them than from any level mesh.
//!   With the second way and the front one level deeper (syntax 3), the front takes these
//!   deviations times 1.1 (`refine::DEVIATION_MARGIN`, measured on random views and the
//!   table's; BENCHMARKS.md); before, times 1.75.
//! - e_v = max(own_v, e_t, e_u): monotone, so a parent never claims less than its children,
//!   and a front whose every node projects its deviation under the tolerance has, over each
//!   node's region, the error of the coarsest level mesh among its nodes.
//!
//! On a plane the deviation is 0 (but where the boundary shrinks). It is measured, not proved:
//! a front can mix depths in more ways than the two fans measured; the tests and the
//! fly-through measure the adapted mesh against the full one.
//!
//! Coded top-down, rounded up, so that a decoded deviation never underestimates the measured
//! one and never exceeds its parent's:
//! - syntax 6 ([`anchored_step`]): on one grid anchored at the root's deviation ê_root, a node
//!   standing at step q holding ê_root · 2^(−q/4). A child above depth
//!   [`FINE_DEVIATION_DEPTHS`] codes how many quarter steps it lies below its parent (0..30,
//!   5 bits); a deeper child the parent's step or the j-th even step below it (4 bits). The far
//!   views' fronts hold coarse nodes, which the quarter steps bound 9% tighter on average; the
//!   deep nodes, most of the stream, keep half steps (quarter steps everywhere cost 0.5 bits a
//!   triangle, BENCHMARKS.md).
//! - before: the parent's deviation times 2^(−j/2) (j = 0..14) or 0 ([`decoded_deviation`]).

use glam::DVec3;
use rayon::prelude::*;

use super::VertexTree;

/// Codes a deviation takes: 0 (none) and 2^(−j/2) of the parent's for j = 14..=0 (syntax 6:
/// the parent's step for j = 0, else the j-th even step below it). (Steps of 2^(−1/4) bound a
/// deviation 9% tighter on average but cost 0.5 bits a triangle more.)
pub const DEVIATION_CODES: u32 = 16;
/// Bits of a deviation code.
pub const DEVIATION_BITS: u8 = 4;
/// Syntax 6: a child at a depth under this codes its deviation in quarter steps (from 11 on,
/// bunny.ply's and dragon-50k's far views keep their whole gain; BENCHMARKS.md).
pub const FINE_DEVIATION_DEPTHS: usize = 11;
/// Codes of a quarter-step deviation: 0 (none) and 30..=0 quarter steps below the parent.
pub const FINE_DEVIATION_CODES: u32 = 32;
/// Bits of a quarter-step deviation code.
pub const FINE_DEVIATION_BITS: u8 = 5;
/// How many levels finer than a node its neighbours are taken for the mixed-front measures
/// (each, in turn).
const FINER: [u8; 2] = [1, 2];

/// Each node's deviation (leaves: 0), in the units of `leaves` and `positions`; `positions`
/// holds every node's position (leaves and inner nodes).
pub fn deviations(
    tree: &VertexTree,
    leaves: &[[f64; 3]],
    faces: &[[u32; 3]],
    positions: &[[f64; 3]],
) -> Vec<f64> {
    let n = tree.leaves;
    let total = tree.node_count();
    let mut own = vec![0.0f64; total];
    if total == 0 || tree.is_leaf(tree.root) {
        return own;
    }
    let point = |v: u32| DVec3::from_array(positions[v as usize]);
    let leaf_point = |v: u32| DVec3::from_array(leaves[v as usize]);
    let depth_of = |v: u32| tree.ids[v as usize].len();
    let depth = tree.depth();
    let centroids: Vec<DVec3> = faces
        .iter()
        .map(|f| (leaf_point(f[0]) + leaf_point(f[1]) + leaf_point(f[2])) / 3.0)
        .collect();
    // The active node of each leaf on the level mesh being measured.
    let mut active = vec![tree.root; n];
    // Per level, the inner nodes at its depth, each with a slot.
    let mut slot = vec![u32::MAX; total];
    for k in 0..depth {
        // Leaves deeper than k step down to their ancestor at depth k.
        active.par_iter_mut().enumerate().for_each(|(l, a)| {
            let id = tree.ids[l];
            while depth_of(*a) < k {
                // A leaf above depth k stays itself.
                let Some([t, u]) = tree.children_of(*a) else {
                    break;
                };
                *a = if id.bit(depth_of(*a)) { u } else { t };
            }
        });
        let mut level: Vec<u32> = active
            .iter()
            .copied()
            .filter(|&a| !tree.is_leaf(a) && depth_of(a) == k)
            .collect();
        level.sort_unstable();
        level.dedup();
        if level.is_empty() {
            continue;
        }
        for (i, &v) in level.iter().enumerate() {
            slot[v as usize] = i as u32;
        }
        // The level mesh's faces (those keeping three distinct corners) by corner, and the
        // samples of each node of this depth: its leaves and the centroids of the faces with a
        // corner under it.
        let image = |f: usize| faces[f].map(|c| active[c as usize]);
        let mut at_corner: Vec<(u32, u32)> = Vec::new();
        let mut samples: Vec<(u32, DVec3)> = Vec::new();
        for (l, &a) in active.iter().enumerate() {
            if slot[a as usize] != u32::MAX {
                samples.push((slot[a as usize], leaf_point(l as u32)));
            }
        }
        for (f, &centroid) in centroids.iter().enumerate() {
            let corners = image(f);
            let three = distinct(corners);
            for (i, &a) in corners.iter().enumerate() {
                if three {
                    at_corner.push((a, f as u32));
                }
                let s = slot[a as usize];
                if s != u32::MAX && !corners[..i].contains(&a) {
                    samples.push((s, centroid));
                }
            }
        }
        at_corner.sort_unstable_by_key(|&(a, _)| a);
        samples.sort_unstable_by_key(|&(s, _)| s);
        let sample_at = run_starts(samples.iter().map(|&(s, _)| s), level.len());
        let faces_at = |node: u32| faces_of(&at_corner, node);
        let measured: Vec<f64> = (0..level.len())
            .into_par_iter()
            .map(|i| {
                let v = level[i];
                let triangle = |f: u32| image(f as usize).map(point);
                let fan: Vec<[DVec3; 3]> = faces_at(v).map(triangle).collect();
                // The faces around the fan's other corners, looked at only for the samples
                // the fan leaves furthest (any faces of the level mesh bound the distance to
                // it from above; these are where a sample under v can lie).
                let mut ring: Option<Vec<[DVec3; 3]>> = None;
                let mut worst = 0.0f64;
                for &(_, p) in &samples[sample_at[i]..sample_at[i + 1]] {
                    let near = fan
                        .iter()
                        .map(|t| point_triangle_distance_squared(p, t))
                        .fold(p.distance_squared(point(v)), f64::min);
                    if near <= worst {
                        continue;
                    }
                    let ring = ring.get_or_insert_with(|| {
                        let mut around: Vec<u32> = faces_at(v)
                            .flat_map(|f| image(f as usize))
                            .filter(|&c| c != v)
                            .collect();
                        around.sort_unstable();
                        around.dedup();
                        let mut ring: Vec<u32> = around.iter().flat_map(|&c| faces_at(c)).collect();
                        ring.sort_unstable();
                        ring.dedup();
                        ring.into_iter().map(triangle).collect()
                    });
                    let mut d = near;
                    for t in ring.iter() {
                        d = d.min(point_triangle_distance_squared(p, t));
                        if d <= worst {
                            break;
                        }
                    }
                    worst = worst.max(d);
                }
                worst.sqrt()
            })
            .collect();
        for (&v, e) in level.iter().zip(measured) {
            own[v as usize] = e;
        }
        // The other way: points of the level faces at a node of this depth (centroid and edge
        // midpoints) to the full mesh's faces with a corner under one of their corners — where
        // a coarse face bridges a gap or cuts a corner, its inside lies far from every sample.
        let mut under: Vec<(u32, u32)> = Vec::new();
        let mut level_faces: Vec<[u32; 3]> = Vec::new();
        for f in 0..faces.len() {
            let corners = image(f);
            for (i, &a) in corners.iter().enumerate() {
                if !corners[..i].contains(&a) {
                    under.push((a, f as u32));
                }
            }
            if distinct(corners) && corners.iter().any(|&a| slot[a as usize] != u32::MAX) {
                let mut key = corners;
                key.sort_unstable();
                level_faces.push(key);
            }
        }
        under.sort_unstable();
        level_faces.sort_unstable();
        level_faces.dedup();
        let reverse: Vec<f64> = level_faces
            .par_iter()
            .map(|corners| {
                let near: Vec<[DVec3; 3]> = corners
                    .iter()
                    .flat_map(|&x| faces_of(&under, x))
                    .map(|f| faces[f as usize].map(leaf_point))
                    .collect();
                farthest_probe(corners.map(point), &near, 0.0).sqrt()
            })
            .collect();
        for (corners, e) in level_faces.iter().zip(reverse) {
            for &x in corners {
                if slot[x as usize] != u32::MAX {
                    own[x as usize] = own[x as usize].max(e);
                }
            }
        }
        // A front mixes depths: v may stay coarse while its neighbours are finer, and its fan
        // then reaches their descendants, chords no level mesh has. The same way once more,
        // with v's leaves at v and every other leaf at its ancestor FINER levels down.
        for finer in FINER {
            let mut fine = active.clone();
            fine.par_iter_mut().enumerate().for_each(|(l, a)| {
                let id = tree.ids[l];
                while depth_of(*a) < k + finer {
                    let Some([t, u]) = tree.children_of(*a) else {
                        break;
                    };
                    *a = if id.bit(depth_of(*a)) { u } else { t };
                }
            });
            let mut under_fine: Vec<(u32, u32)> = Vec::new();
            let mut touching: Vec<(u32, u32)> = Vec::new();
            for (f, face) in faces.iter().enumerate() {
                let corners = face.map(|c| fine[c as usize]);
                for (i, &a) in corners.iter().enumerate() {
                    if !corners[..i].contains(&a) {
                        under_fine.push((a, f as u32));
                    }
                }
                let coarse = face.map(|c| active[c as usize]);
                for (i, &a) in coarse.iter().enumerate() {
                    if slot[a as usize] != u32::MAX && !coarse[..i].contains(&a) {
                        touching.push((slot[a as usize], f as u32));
                    }
                }
            }
            under_fine.sort_unstable();
            touching.sort_unstable();
            let touching_at = run_starts(touching.iter().map(|&(s, _)| s), level.len());
            let mixed: Vec<f64> = (0..level.len())
                .into_par_iter()
                .map(|i| {
                    let v = level[i];
                    // Where the mixed front shows a leaf: at v if it is under v, else at its
                    // finer ancestor.
                    let image = |c: u32| {
                        if active[c as usize] == v {
                            v
                        } else {
                            fine[c as usize]
                        }
                    };
                    let mut fan: Vec<[u32; 3]> = touching[touching_at[i]..touching_at[i + 1]]
                        .iter()
                        .map(|&(_, f)| faces[f as usize].map(image))
                        .filter(|&c| distinct(c))
                        .collect();
                    fan.sort_unstable();
                    fan.dedup();
                    let mut worst = 0.0f64;
                    for corners in &fan {
                        // v's own faces under v, the others' under their finer ancestors.
                        let near: Vec<[DVec3; 3]> = corners
                            .iter()
                            .flat_map(|&x| faces_of(if x == v { &under } else { &under_fine }, x))
                            .map(|f| faces[f as usize].map(leaf_point))
                            .collect();
                        worst = farthest_probe(corners.map(point), &near, worst);
                    }
                    // And the full mesh's points around the mixed fan to it and the finer
                    // faces around it.
                    let mut neighbours: Vec<u32> =
                        fan.iter().flatten().copied().filter(|&x| x != v).collect();
                    neighbours.sort_unstable();
                    neighbours.dedup();
                    let mut sampled: Vec<u32> = faces_of(&under, v).collect();
                    for &x in &neighbours {
                        sampled.extend(faces_of(&under_fine, x));
                    }
                    sampled.sort_unstable();
                    sampled.dedup();
                    let surface = MixedSurface::new(
                        v,
                        &neighbours,
                        &sampled,
                        &under_fine,
                        faces,
                        image,
                        point,
                    );
                    for &f in &sampled {
                        let face = faces[f as usize];
                        let mut samples = face.map(leaf_point).to_vec();
                        samples.push(centroids[f as usize]);
                        worst = surface.farthest(&samples, face.map(image), worst);
                    }
                    worst.sqrt()
                })
                .collect();
            for (&v, e) in level.iter().zip(mixed) {
                own[v as usize] = own[v as usize].max(e);
            }
        }
        for &v in &level {
            slot[v as usize] = u32::MAX;
        }
    }
    // Monotone: inner nodes come after their children.
    for (i, &[t, u]) in tree.children.iter().enumerate() {
        own[n + i] = own[n + i].max(own[t as usize]).max(own[u as usize]);
    }
    own
}

/// The surface a front shows around node v kept coarse among neighbours one or two levels
/// finer: the images of the full mesh's faces under v, under its neighbours and under their
/// other neighbours (each corner at v if it is under v, else at its finer ancestor), those
/// keeping three corners — so that a sample at the neighbours' outer edge finds the surface
/// beside it.
struct MixedSurface {
    triangles: Vec<[DVec3; 3]>,
    /// (node, triangle) pairs sorted by node: the triangles at each corner.
    at_node: Vec<(u32, u32)>,
}

impl MixedSurface {
    fn new(
        v: u32,
        neighbours: &[u32],
        sampled: &[u32],
        under_fine: &[(u32, u32)],
        faces: &[[u32; 3]],
        image: impl Fn(u32) -> u32,
        point: impl Fn(u32) -> DVec3,
    ) -> MixedSurface {
        let mut outer: Vec<u32> = sampled
            .iter()
            .flat_map(|&f| faces[f as usize].map(&image))
            .filter(|&x| x != v && neighbours.binary_search(&x).is_err())
            .collect();
        outer.sort_unstable();
        outer.dedup();
        let mut around = sampled.to_vec();
        for &x in &outer {
            around.extend(faces_of(under_fine, x));
        }
        around.sort_unstable();
        around.dedup();
        let mut corners: Vec<[u32; 3]> = around
            .iter()
            .map(|&f| faces[f as usize].map(&image))
            .filter(|c| distinct(*c))
            .map(|mut c| {
                c.sort_unstable();
                c
            })
            .collect();
        corners.sort_unstable();
        corners.dedup();
        let mut at_node: Vec<(u32, u32)> = corners
            .iter()
            .enumerate()
            .flat_map(|(i, c)| c.map(|x| (x, i as u32)))
            .collect();
        at_node.sort_unstable();
        MixedSurface {
            triangles: corners.iter().map(|c| c.map(&point)).collect(),
            at_node,
        }
    }

    /// The larger of `worst` and the largest squared distance from `samples` (of one full-mesh
    /// face, whose corners the front shows at `image`) to the surface. Each looks first at its
    /// own face's image and the triangles at its corners, nearly always the nearest, and at
    /// the rest only while it is farther than `worst`, which it could then raise.
    fn farthest(&self, samples: &[DVec3], image: [u32; 3], mut worst: f64) -> f64 {
        for &q in samples {
            let mut d = f64::INFINITY;
            'near: for x in image {
                for i in faces_of(&self.at_node, x) {
                    d = d.min(point_triangle_distance_squared(
                        q,
                        &self.triangles[i as usize],
                    ));
                    if d <= worst {
                        break 'near;
                    }
                }
            }
            if d > worst {
                d = nearest_within(q, &self.triangles, d, worst);
            }
            if d.is_finite() {
                worst = worst.max(d);
            }
        }
        worst
    }
}

/// The squared distance from `q` to the nearest of `near`, or `d` if that is nearer; it stops
/// looking once within `worst`, which it can then no longer raise.
fn nearest_within(q: DVec3, near: &[[DVec3; 3]], mut d: f64, worst: f64) -> f64 {
    for t in near {
        d = d.min(point_triangle_distance_squared(q, t));
        if d <= worst {
            break;
        }
    }
    d
}

/// Whether a triangle's corners are three distinct nodes.
fn distinct(c: [u32; 3]) -> bool {
    c[0] != c[1] && c[1] != c[2] && c[0] != c[2]
}

/// The faces listed for `node` in `list`, (node, face) pairs sorted by node.
fn faces_of(list: &[(u32, u32)], node: u32) -> impl Iterator<Item = u32> + '_ {
    let from = list.partition_point(|&(a, _)| a < node);
    let to = list.partition_point(|&(a, _)| a <= node);
    list[from..to].iter().map(|&(_, f)| f)
}

/// The larger of `worst` and the largest squared distance from a probe of the face on
/// corners `p` (its centroid and edge midpoints: where a face spanning a gap or cutting a
/// corner strays farthest) to the nearest of `near`; a probe with nothing near counts nothing.
/// A probe stops looking once it is within `worst`, which it can no longer raise.
fn farthest_probe(p: [DVec3; 3], near: &[[DVec3; 3]], mut worst: f64) -> f64 {
    let [a, b, c] = p;
    for q in [
        (a + b + c) / 3.0,
        (a + b) / 2.0,
        (b + c) / 2.0,
        (c + a) / 2.0,
    ] {
        let d = nearest_within(q, near, f64::INFINITY, worst);
        if d.is_finite() {
            worst = worst.max(d);
        }
    }
    worst
}

/// Where each slot's run starts in a list sorted by slot (and, last, where the list ends).
fn run_starts(slots: impl Iterator<Item = u32>, count: usize) -> Vec<usize> {
    let mut starts = vec![0usize; count + 1];
    for s in slots {
        starts[s as usize + 1] += 1;
    }
    for i in 0..count {
        starts[i + 1] += starts[i];
    }
    starts
}

/// The squared distance from `p` to the triangle `t` (a degenerate one is its edges).
pub fn point_triangle_distance_squared(p: DVec3, t: &[DVec3; 3]) -> f64 {
    let [a, b, c] = *t;
    let normal = (b - a).cross(c - a);
    let area = normal.length_squared();
    if area > 0.0 {
        let height = normal.dot(p - a) / area;
        let q = p - normal * height;
        let inside = (b - a).cross(q - a).dot(normal) >= 0.0
            && (c - b).cross(q - b).dot(normal) >= 0.0
            && (a - c).cross(q - c).dot(normal) >= 0.0;
        if inside {
            return height * height * area;
        }
    }
    segment_distance_squared(p, a, b)
        .min(segment_distance_squared(p, b, c))
        .min(segment_distance_squared(p, c, a))
}

fn segment_distance_squared(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let length = ab.length_squared();
    let t = if length > 0.0 {
        ((p - a).dot(ab) / length).clamp(0.0, 1.0)
    } else {
        0.0
    };
    p.distance_squared(a + ab * t)
}

/// 2^(−j/2) for j = 0, 1, the fractions every step of the code table is made of (products
/// with powers of two are exact, so the table is the same on every platform).
const HALF_STEPS: [f64; 2] = [1.0, std::f64::consts::FRAC_1_SQRT_2];

/// The deviation a code stands for under a parent's (decoded) deviation, as the decoder keeps
/// it: an `f32` rounded up (it fits in the padding of a decoded node), so that it never falls
/// below the `f64` product.
pub fn decoded_deviation(code: u32, parent: f32) -> f32 {
    if code == 0 || code >= DEVIATION_CODES {
        return 0.0;
    }
    let j = DEVIATION_CODES - 1 - code;
    round_up(parent as f64 * HALF_STEPS[(j % 2) as usize] / (1u64 << (j / 2)) as f64)
}

/// 2^(−k/4) for k = 0 … 3, the fractions every step of the anchored grid is made of.
const QUARTER_STEPS: [f64; 4] = [
    1.0,
    0.840_896_415_253_714_5,
    std::f64::consts::FRAC_1_SQRT_2,
    0.594_603_557_501_360_5,
];

/// The step code `code` gives a child whose parent stands at step `parent` of the anchored
/// grid (syntax 6); `None` for code 0 (no deviation). `fine`: a quarter-step code (the child
/// lies above [`FINE_DEVIATION_DEPTHS`]).
pub fn anchored_step(code: u32, parent: u16, fine: bool) -> Option<u16> {
    if code == 0 {
        return None;
    }
    let down = if fine {
        FINE_DEVIATION_CODES.saturating_sub(1 + code)
    } else {
        match DEVIATION_CODES.saturating_sub(1 + code) {
            0 => 0,
            // The j-th even step below the parent: from an odd step the first is one away.
            j => 2 * j - u32::from(parent % 2),
        }
    };
    Some(parent.saturating_add(down as u16))
}

/// The deviation at step `step` of the grid anchored at the root's deviation `root`:
/// root · 2^(−step/4) as an `f32` rounded up (never 0 for a positive root).
pub fn anchored_deviation(root: f32, step: u16) -> f32 {
    // Steps are at most 30 a level over at most 52 levels: the power of two stays normal.
    let halvings = u64::from(step / 4).min(1022);
    let power = f64::from_bits((1023 - halvings) << 52);
    let y = round_up(f64::from(root) * QUARTER_STEPS[usize::from(step % 4)] * power);
    if y == 0.0 && root > 0.0 {
        f32::from_bits(1)
    } else {
        y
    }
}

/// The code, and the step it gives, of the smallest anchored deviation at least `deviation`
/// for a child of a node at step `parent` whose deviation is at least `deviation`.
pub fn anchored_code(deviation: f64, root: f32, parent: u16, fine: bool) -> (u32, u16) {
    if deviation <= 0.0 {
        return (0, parent);
    }
    let codes = if fine {
        FINE_DEVIATION_CODES
    } else {
        DEVIATION_CODES
    };
    (1..codes)
        .filter_map(|code| Some((code, anchored_step(code, parent, fine)?)))
        .find(|&(_, step)| anchored_deviation(root, step) as f64 >= deviation)
        .unwrap_or((codes - 1, parent))
}

/// `x` as the nearest `f32` at or above it.
pub fn round_up(x: f64) -> f32 {
    let y = x as f32;
    if (y as f64) < x {
        y.next_up()
    } else {
        y
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hierarchy::came::{build, BuildOptions};
    use crate::mesh::generate;
    use std::f64::consts::FRAC_1_SQRT_2;

    /// The smallest code of syntaxes 1 to 5 whose deviation under `parent` is at least
    /// `deviation` (which is at most `parent`: the deviations are monotone), as their encoders
    /// chose it.
    fn deviation_code(deviation: f64, parent: f32) -> u32 {
        if deviation <= 0.0 {
            return 0;
        }
        (1..DEVIATION_CODES)
            .find(|&code| decoded_deviation(code, parent) as f64 >= deviation)
            .unwrap_or(DEVIATION_CODES - 1)
    }

    fn measured(cells: &[[u32; 3]], faces: &[[u32; 3]]) -> (VertexTree, Vec<f64>, Vec<f64>) {
        let tree = build(cells, faces, &BuildOptions::default()).unwrap();
        let leaves: Vec<[f64; 3]> = cells.iter().map(|c| c.map(|x| x as f64)).collect();
        let positions: Vec<[f64; 3]> = (0..tree.node_count() as u32)
            .map(|v| leaves[tree.representative(v) as usize])
            .collect();
        let e = deviations(&tree, &leaves, faces, &positions);
        let r = super::super::spheres::exact_radii(&leaves, &tree.children, &positions);
        (tree, e, r)
    }

    /// A square grid of `side` × `side` vertices in the plane z = 0.
    fn plane(side: u32) -> (Vec<[u32; 3]>, Vec<[u32; 3]>) {
        let cells = (0..side * side)
            .map(|i| [i % side * 4, i / side * 4, 0])
            .collect();
        let mut faces = Vec::new();
        for y in 0..side - 1 {
            for x in 0..side - 1 {
                let v = y * side + x;
                faces.push([v, v + 1, v + side]);
                faces.push([v + 1, v + side + 1, v + side]);
            }
        }
        (cells, faces)
    }

    #[test]
    fn a_plane_deviates_nowhere_and_a_sphere_less_than_its_spheres() {
        let (cells, faces) = plane(32);
        // Inside a plane nothing deviates; only where the boundary shrinks does a node count.
        let (tree, e, _) = measured(&cells, &faces);
        let inner = tree.leaves..tree.node_count();
        let flat = inner.clone().filter(|&v| e[v] < 1e-9).count();
        assert!(
            flat * 10 >= inner.len() * 7,
            "{flat} of {} flat",
            inner.len()
        );
        let sphere = generate::icosphere(3);
        let cells: Vec<[u32; 3]> = sphere
            .positions
            .iter()
            .map(|p| (p.to_array()).map(|x| ((x + 1.0) * 500.0).round() as u32))
            .collect();
        let (tree, e, r) = measured(&cells, &sphere.faces);
        for (i, &[t, u]) in tree.children.iter().enumerate() {
            let v = tree.leaves + i;
            assert!(
                e[v] >= e[t as usize] && e[v] >= e[u as usize],
                "not monotone at {v}"
            );
        }
        // Well under the spheres where the surface is smooth.
        let (sum_e, sum_r) = (tree.leaves..tree.node_count())
            .map(|v| (e[v], r[v]))
            .fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
        assert!(
            sum_e > 0.0 && sum_e < 0.6 * sum_r,
            "{sum_e} against {sum_r}"
        );
    }

    #[test]
    fn codes_round_up_and_stay_under_the_parent() {
        for parent in [0.3f32, 1.0, 17.0, 4096.5] {
            for i in 0..=400 {
                let e = parent as f64 * i as f64 / 400.0;
                let code = deviation_code(e, parent);
                let d = decoded_deviation(code, parent) as f64;
                let parent = parent as f64;
                assert!(
                    d >= e && d <= parent,
                    "{e} coded {code} → {d} under {parent}"
                );
                if e > parent / 128.0 {
                    assert!(d <= e * 1.415, "{e} → {d}");
                }
            }
        }
        assert_eq!(deviation_code(0.0, 5.0), 0);
        assert_eq!(decoded_deviation(DEVIATION_CODES - 1, 5.0), 5.0);
    }

    #[test]
    fn anchored_codes_round_up_stay_under_the_parent_and_keep_to_their_grid() {
        for root in [1.0f32, 17.0, 4096.0] {
            for parent in [0u16, 1, 2, 7, 30, 61] {
                let above = anchored_deviation(root, parent) as f64;
                for fine in [false, true] {
                    for i in 0..=400 {
                        let e = above * i as f64 / 400.0;
                        let (code, step) = anchored_code(e, root, parent, fine);
                        let d = anchored_deviation(root, step) as f64;
                        assert!(step >= parent, "{step} above {parent}");
                        if code == 0 {
                            assert_eq!(e, 0.0);
                            continue;
                        }
                        assert_eq!(anchored_step(code, parent, fine), Some(step));
                        assert!(d >= e && d <= above, "{e} coded {code} → {d} under {above}");
                        // Coarse codes take the parent or even steps; every code is within
                        // one step of the measure, where the grid reaches that far down.
                        assert!(fine || step == parent || step % 2 == 0, "step {step}");
                        let ratio = if fine { 1.190 } else { 1.415 };
                        if e > above / 64.0 {
                            assert!(d <= e * ratio, "{e} → {d} ({fine})");
                        }
                    }
                }
            }
        }
        assert_eq!(anchored_step(0, 3, true), None);
        assert_eq!(anchored_step(15, 3, false), Some(3));
        assert_eq!(anchored_step(14, 3, false), Some(4));
        assert_eq!(anchored_step(14, 4, false), Some(6));
        assert_eq!(anchored_step(31, 5, true), Some(5));
        assert_eq!(anchored_step(1, 5, true), Some(35));
        assert_eq!(anchored_deviation(8.0, 8), 2.0);
        assert_eq!(anchored_deviation(8.0, 2), round_up(8.0 * FRAC_1_SQRT_2));
        // Far down the grid a positive deviation stays positive.
        assert!(anchored_deviation(1.0, u16::MAX) > 0.0);
    }

    #[test]
    fn point_triangle_distances() {
        let t = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let d = |p: DVec3| point_triangle_distance_squared(p, &t).sqrt();
        assert!((d(DVec3::new(0.2, 0.2, 3.0)) - 3.0).abs() < 1e-12);
        assert!((d(DVec3::new(-1.0, 0.0, 0.0)) - 1.0).abs() < 1e-12);
        assert!((d(DVec3::new(1.0, 1.0, 0.0)) - 0.5f64.sqrt()).abs() < 1e-12);
        let flat = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        assert!(
            (point_triangle_distance_squared(DVec3::new(1.5, 1.0, 0.0), &flat) - 1.0).abs() < 1e-12
        );
    }
}
