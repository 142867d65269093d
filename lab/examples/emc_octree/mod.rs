//! The octree of `emc` over one mesh, as the probes of its intermediate levels use it
//! (`emc_order_probe`, `emc_adaptive_probe`): every vertex's key (one bit a step, three steps a
//! level, in `emc`'s axis order), the vertices sorted by key so that every node of the tree is a
//! range, prefix sums of the vertices' quadrics over that order, and `emc`'s own bits per
//! decision, level by level, from its encoding of the same mesh.

use glam::DVec3;
use meshcodec::codecs::emc::{EmcParams, Syntax};
use meshcodec::codecs::{self, EncodeOptions, LevelMesh};
use meshcodec::hierarchy::simplify::quadric::Quadric;
use meshcodec::mesh::canonical::rotate_to_smallest;
use meshcodec::mesh::io::{read_mesh, resolve};
use meshcodec::mesh::quantize::GridShape;
use meshcodec::mesh::{CanonicalMesh, TriMesh};
use meshcodec::metrics::{Reference, SampleBudget, DEFAULT_SEED};
use std::cmp::Ordering;
use std::collections::HashSet;

/// A quadric's least value (every vertex's quadric here holds a point term, so it has one).
pub fn least(q: &Quadric) -> f64 {
    q.minimizer().map_or(0.0, |p| q.error(p).max(0.0))
}

/// The octree of one mesh as sorted keys, with per-level costs.
pub struct Tree {
    pub mesh: CanonicalMesh,
    pub steps: usize,
    pub levels: usize,
    pub axis: Vec<usize>,
    /// Vertex ids sorted by key, their keys, and each vertex's place in that order.
    pub sorted: Vec<u32>,
    pub keys: Vec<u128>,
    pub rank: Vec<u32>,
    /// Prefix sums of the vertices' quadrics in sorted order.
    pub prefix: Vec<Quadric>,
    /// Estimated bits of a split and of a "which half" bit, per level (0-based).
    pub split_bits: Vec<f64>,
    pub half_bits: Vec<f64>,
    /// Bits before the first decision (header, index, flushes).
    pub fixed_bits: f64,
    /// `emc_order_probe`'s choice: whether a split is valued by the quadrics' least values
    /// (where the clusters' vertices could best stand) rather than at the representatives the
    /// decisions so far place.
    pub splits_at_best: bool,
}

impl Tree {
    /// The mesh a cut of the tree shows: the original triangles through the clusters
    /// (`owner[sorted index]`), each cluster at `positions[cluster]`; triangles that lose a
    /// corner to a merge are dropped and repeated ones kept once, as `emc`'s 3-cliques would be.
    pub fn project(&self, owner: &[u32], positions: Vec<DVec3>) -> LevelMesh {
        let mut seen = HashSet::new();
        let mut faces = Vec::new();
        for f in &self.mesh.faces {
            let t = f.map(|v| owner[self.rank[v as usize] as usize]);
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                continue;
            }
            if seen.insert(rotate_to_smallest(t)) {
                faces.push(t);
            }
        }
        LevelMesh {
            mesh: TriMesh::new(positions, faces),
            loose_edges: Vec::new(),
            attributes: None,
        }
    }
    pub fn bit(&self, i: usize, t: usize) -> u32 {
        ((self.keys[i] >> (self.steps - 1 - t)) & 1) as u32
    }
    /// End of the node at depth `t` holding sorted vertex `lo`, within `[lo, hi)`.
    pub fn node_end(&self, lo: usize, hi: usize, t: usize) -> usize {
        if t == 0 {
            return hi;
        }
        let shift = self.steps - t;
        let key = self.keys[lo] >> shift;
        lo + self.keys[lo..hi].partition_point(|k| (k >> shift) == key)
    }
    /// Where the node `[lo, e)` at depth `t` parts (first vertex of the upper half).
    pub fn middle(&self, lo: usize, e: usize, t: usize) -> usize {
        lo + (lo..e).take_while(|&i| self.bit(i, t) == 0).count()
    }
    pub fn quadric(&self, lo: usize, hi: usize) -> Quadric {
        Quadric::difference(&self.prefix[hi], &self.prefix[lo])
    }
    /// World position of sorted vertex `lo` known to depth `r`: its cell's centre there.
    pub fn position(&self, lo: usize, r: usize) -> DVec3 {
        let v = self.sorted[lo] as usize;
        let g = &self.mesh.grid;
        let l = self.levels as u32;
        DVec3::from_array(std::array::from_fn(|a| {
            let k = (0..r).filter(|&t| self.axis[t] == a).count() as u32;
            let c = self.mesh.cells[v][a];
            let span = 1u64 << (l - k);
            let centre = ((c as u64 >> (l - k)) * span) as f64 + (span as f64 - 1.0) / 2.0;
            g.origin[a] + (centre + 0.5) * g.cell[a]
        }))
    }
}

/// A cluster's best decision in a greedy order's heap, under the cluster's `version` when it
/// was pushed (a later version makes it stale); the most gain per bit first, then the lowest id.
#[derive(PartialEq)]
pub struct Candidate {
    pub priority: f64,
    pub id: usize,
    pub version: u32,
}
impl Eq for Candidate {}
impl PartialOrd for Candidate {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Candidate {
    fn cmp(&self, o: &Self) -> Ordering {
        self.priority
            .total_cmp(&o.priority)
            .then(o.id.cmp(&self.id))
    }
}

/// Gain per bit; a decision the model prices at nothing (the path meeting a branch, whose
/// flag the split's bits pay) is taken at once, whatever it does to the error: the split
/// needs it.
pub fn priority(gain: f64, bits: f64) -> f64 {
    if bits <= 0.0 {
        f64::INFINITY
    } else {
        gain / bits
    }
}

/// A mesh as read, its octree, and `emc`'s bits and RMS at the end of each level.
pub struct Built {
    pub original: TriMesh,
    pub tree: Tree,
    pub level_bits: Vec<f64>,
    pub emc_rms: Vec<f64>,
}

pub fn build(name: &str) -> Result<Built, Box<dyn std::error::Error>> {
    let mesh = read_mesh(&resolve(name)?)?;
    let options = EncodeOptions {
        quant_bits: 12,
        grid: GridShape::Cubic,
    };
    let canonical = codecs::canonical_for(&mesh, &options)?;
    let encoded = codecs::by_name("emc")?.encode(&canonical)?;
    let order = EmcParams::for_mesh(&canonical, Syntax::Modelled).order;
    let levels = order.levels as usize;
    let steps = 3 * levels;
    let axis: Vec<usize> = (0..steps).map(|t| order.axis(t)).collect();
    let n = canonical.vertex_count();
    let key = |v: usize| -> u128 {
        (0..steps).fold(0u128, |k, t| {
            let c = canonical.cells[v][axis[t]];
            (k << 1) | ((c >> (levels - 1 - t / 3)) & 1) as u128
        })
    };
    let mut sorted: Vec<u32> = (0..n as u32).collect();
    let all: Vec<u128> = (0..n).map(key).collect();
    sorted.sort_by_key(|&v| all[v as usize]);
    let keys: Vec<u128> = sorted.iter().map(|&v| all[v as usize]).collect();
    let mut rank = vec![0u32; n];
    for (i, &v) in sorted.iter().enumerate() {
        rank[v as usize] = i as u32;
    }
    // Area-weighted face planes at the cells' centres.
    let world = canonical.to_mesh();
    let mut per_vertex = vec![Quadric::default(); n];
    let mut areas = vec![0.0f64; n];
    for f in &canonical.faces {
        let p = f.map(|v| world.positions[v as usize]);
        let cross = (p[1] - p[0]).cross(p[2] - p[0]);
        let area = cross.length() / 2.0;
        if area <= 0.0 {
            continue;
        }
        let normal = cross.normalize();
        let q = Quadric::plane(normal, -normal.dot(p[0]), area);
        for &v in f {
            per_vertex[v as usize].add(&q);
            areas[v as usize] += area;
        }
    }
    // Plus a tenth of each vertex's area times its squared distance from the representative:
    // planes alone let a coarse cluster sit on a plane of its vertices far from them.
    // (With 1.0, the greedy order's RMS on bunny at levels 4–7 was 1.1–1.3× higher; with the
    // planes alone, it stalled on clusters that no single decision improves.)
    let weight = 0.1;
    for (v, q) in per_vertex.iter_mut().enumerate() {
        q.add(&Quadric::point(world.positions[v], weight * areas[v]));
    }
    let mut prefix = vec![Quadric::default(); n + 1];
    for (i, &v) in sorted.iter().enumerate() {
        prefix[i + 1] = prefix[i];
        prefix[i + 1].add(&per_vertex[v as usize]);
    }
    // Distinct prefixes at each depth: nodes; a level's splits and "which half" bits.
    let distinct: Vec<usize> = (0..=steps)
        .map(|t| {
            if t == 0 {
                return 1;
            }
            1 + keys
                .windows(2)
                .filter(|w| (w[0] >> (steps - t)) != (w[1] >> (steps - t)))
                .count()
        })
        .collect();
    let mut split_bits = vec![0.0; levels];
    let mut half_bits = vec![0.0; levels];
    let mut conn_before = 0;
    let mut geom_before = 0;
    for l in 0..levels {
        let record = &encoded.levels[l];
        let conn = (record.connectivity_bits - conn_before) as f64;
        let geom = (record.geometry_bits - geom_before) as f64;
        conn_before = record.connectivity_bits;
        geom_before = record.geometry_bits;
        let splits = (distinct[3 * l + 3] - distinct[3 * l]) as f64;
        let halves: usize = (3 * l..3 * l + 3)
            .map(|t| 2 * distinct[t] - distinct[t + 1])
            .sum();
        split_bits[l] = if splits > 0.0 { conn / splits } else { 0.0 };
        half_bits[l] = if halves > 0 {
            geom / halves as f64
        } else {
            0.0
        };
    }
    let last = encoded.levels.last().expect("levels");
    let fixed_bits =
        8.0 * last.end_byte as f64 - last.connectivity_bits as f64 - last.geometry_bits as f64;
    let level_bits: Vec<f64> = encoded
        .levels
        .iter()
        .map(|r| 8.0 * r.end_byte as f64)
        .collect();
    let reference = Reference::new(&mesh, SampleBudget::default(), DEFAULT_SEED);
    let mut emc_rms = Vec::new();
    let mut decoder = codecs::open(&encoded.bytes)?;
    while decoder.advance()? {
        emc_rms.push(
            reference
                .compare(&decoder.mesh()?)
                .map_or(f64::NAN, |d| d.rms),
        );
    }
    let tree = Tree {
        mesh: canonical,
        steps,
        levels,
        axis,
        sorted,
        keys,
        rank,
        prefix,
        split_bits,
        half_bits,
        fixed_bits,
        splits_at_best: false,
    };
    Ok(Built {
        original: mesh,
        tree,
        level_bits,
        emc_rms,
    })
}
