//! `came-paper`: CAME as published (Grabner §3.2–§3.3; docs/FORMAT.md §8.3).
//!
//! Every unit is a bit field stream. A split record holds, in this order: its children's leaf
//! flags; d_t and d_u as components in the meta-node's PCA frame at B bits each ([`Frame`],
//! normalized by c·2^(l/2)); the 2-bit radius ratios of its children; its triangles, each
//! as the Huffman-coded length of n1, n1's bits, the same for n2, then n3.up and n3's length
//! (Huffman) and n3's bits, and an orientation bit; its dependencies, each as up, length and bits.
//! The first bit of every path is implied and omitted. The Huffman tables (code lengths) open the
//! first unit, which every other unit's decoder holds.
//!
//! Inner nodes sit at the quadric optimum; positions are coded closed-loop (each difference
//! vector against the decoded parent), so errors do not pile up down the tree, and the spheres
//! bound the vertices as decoded. The full level is not the input mesh: it is reported with its
//! Hausdorff error.

use super::decoded::{Bounds, CameDecoder, DecodedTree, FaceNormal, Triangle, UnitDecoder};
use super::frame::Frame;
use super::partition::{Partition, Shape, Tails};
use super::{born_triangles, cut_at, encode_stream, BornTriangle, Layout, Params, META_LEVELS};
use crate::codecs::descriptor::cubic;
use crate::codecs::{names, Capability, Codec, Encoded, LevelDecoder, Stats};
use crate::codecs::{CodecFacts, Descriptor};
use crate::coding::huffman::{get_gamma, Huffman, LENGTH_FIELD_BITS};
use crate::coding::{BitSink, BitSource, SyntaxClass};
use crate::container::{Header, StreamReader};
use crate::error::{Error, Result};
use crate::hierarchy::came::cones::CodedCone;
use crate::hierarchy::came::deviation::round_up;
use crate::hierarchy::came::spheres::{decoded_radius, exact_radii, ratio_base, ratio_code};
use crate::hierarchy::came::{BuildOptions, NodeId, VertexTree, MAX_DEPTH};
use crate::mesh::CanonicalMesh;
use glam::DVec3;
use std::cell::OnceCell;
use std::collections::BTreeMap;

/// Bits per PCA component by default (Tables 2–3).
pub const DEFAULT_COMPONENT_BITS: u8 = 5;
/// Bits per radius ratio (§3.3.2: "as few as two bits per node").
pub const RADIUS_BITS: u8 = 2;
/// Symbols of every table: path lengths 0..=51, ups 1..=52, counts 0..=50 and an escape.
const SYMBOLS: usize = MAX_DEPTH as usize;
/// The count symbol followed by an Elias-gamma remainder.
const ESCAPE: usize = SYMBOLS - 1;
/// Dependencies a split may name (Hoppe's fn0..fn3 per vanishing face; far below on real meshes).
const MAX_DEPENDENCIES: u64 = 64;

/// The Huffman tables, in stream order.
#[derive(Clone, Copy)]
enum Table {
    /// Lengths of n1 and n2.
    SiblingLength,
    /// n3.up − 1.
    ThirdUp,
    /// Lengths of n3.
    ThirdLength,
    /// Triangles a split creates.
    Triangles,
    /// Dependencies of a split.
    Dependencies,
    /// A dependency's up − 1.
    DependencyUp,
    /// A dependency's length.
    DependencyLength,
}

const TABLES: usize = 7;

/// The field each syntax element is counted in, and its class.
#[derive(Clone, Copy)]
enum Field {
    Connectivity,
    Dependencies,
    Coordinates,
    Spheres,
}

impl Field {
    fn name(self) -> &'static str {
        match self {
            Field::Connectivity => "connectivity",
            Field::Dependencies => "dependencies",
            Field::Coordinates => "coordinates",
            Field::Spheres => "spheres",
        }
    }

    fn class(self) -> SyntaxClass {
        match self {
            Field::Connectivity | Field::Dependencies => SyntaxClass::Connectivity,
            Field::Coordinates | Field::Spheres => SyntaxClass::Geometry,
        }
    }
}

/// Where the encoder's syntax elements go: counted for the tables, then written.
trait Out {
    /// A `bits`-bit field (bits ≤ 64).
    fn bits(&mut self, field: Field, bits: u32, value: u64);
    /// A symbol of `table`.
    fn symbol(&mut self, table: Table, field: Field, symbol: usize);

    /// A count: its symbol, escaped above [`ESCAPE`] with an Elias-gamma remainder.
    fn count(&mut self, table: Table, field: Field, n: u64) {
        if n < ESCAPE as u64 {
            self.symbol(table, field, n as usize);
            return;
        }
        self.symbol(table, field, ESCAPE);
        let v = n - ESCAPE as u64 + 1;
        let width = 64 - v.leading_zeros();
        self.bits(field, width - 1, 0);
        self.bits(field, width, v);
    }
}

/// Counts table symbols.
struct Counter {
    counts: [[u64; SYMBOLS]; TABLES],
}

impl Out for Counter {
    fn bits(&mut self, _: Field, _: u32, _: u64) {}
    fn symbol(&mut self, table: Table, _: Field, symbol: usize) {
        self.counts[table as usize][symbol] += 1;
    }
}

/// Writes bit fields and books them per field.
struct Writer<'t> {
    sink: BitSink,
    tables: &'t [Huffman],
    fields: BTreeMap<&'static str, f64>,
}

impl Out for Writer<'_> {
    fn bits(&mut self, field: Field, bits: u32, value: u64) {
        if bits > 32 {
            self.sink
                .put(field.class(), bits - 32, (value >> 32) as u32);
            self.sink.put(field.class(), 32, value as u32);
        } else {
            self.sink.put(field.class(), bits, value as u32);
        }
        *self.fields.entry(field.name()).or_default() += bits as f64;
    }

    fn symbol(&mut self, table: Table, field: Field, symbol: usize) {
        let code = &self.tables[table as usize];
        code.put(&mut self.sink, field.class(), symbol);
        *self.fields.entry(field.name()).or_default() += code.length(symbol) as f64;
    }
}

/// The `came-paper` codec, at `component_bits` bits per PCA component.
pub struct CamePaper {
    /// B: bits per component of a normalized difference vector.
    pub component_bits: u8,
}

/// What `CamePaper` is.
const DESCRIPTOR: Descriptor = Descriptor {
    naming: names::CAME_PAPER,
    summary: "Grabner's compressed vertex hierarchy of any mesh as published: Huffman-coded paths, 5-bit PCA components (lossy)",
    default_options: cubic(12),
    capabilities: &[Capability::SelectiveRefinement],
    lossless: false,
};

impl Codec for CamePaper {
    fn descriptor(&self) -> &'static Descriptor {
        &DESCRIPTOR
    }

    /// The paper's hierarchy has no normal cones.
    fn facts(&self, _header: &Header) -> CodecFacts {
        CodecFacts {
            normal_cones: Some(false),
            ..CodecFacts::default()
        }
    }

    fn selective_refinement(&self) -> Option<&dyn super::selective::SelectiveRefinement> {
        Some(self)
    }

    fn measure(&self, _stream: &[u8]) -> Result<Stats> {
        Ok(Stats::default())
    }

    fn encode(&self, mesh: &CanonicalMesh) -> Result<Encoded> {
        if !(1..=16).contains(&self.component_bits) {
            return Err(Error::Unsupported(
                "came-paper codes 1 to 16 bits per component".into(),
            ));
        }
        let layout = Layout {
            naming: self.descriptor().naming,
            per_node_bounds: false,
            build: BuildOptions::PAPER,
            shape: Shape::Levels {
                levels: META_LEVELS,
                tails: Tails::Split,
            },
            component_bits: self.component_bits,
            radius_bits: RADIUS_BITS,
            cone_bits: 0,
            deviation_bits: 0,
            face_normal_steps: 0,
        };
        let bits = self.component_bits;
        encode_stream(mesh, layout, |tree, part| {
            let encoder = Encoder::new(tree, mesh, part, bits);
            let mut counter = Counter {
                counts: [[0; SYMBOLS]; TABLES],
            };
            for m in 0..part.units.len() {
                encoder.unit(m, &mut counter);
            }
            let tables: Vec<Huffman> = counter
                .counts
                .iter()
                .map(|c| Huffman::from_lengths(&Huffman::lengths_for(c)))
                .collect();
            let units = (0..part.units.len())
                .map(|m| {
                    let mut writer = Writer {
                        sink: BitSink::default(),
                        tables: &tables,
                        fields: BTreeMap::new(),
                    };
                    if m == 0 {
                        let bits = (SYMBOLS as u32 * LENGTH_FIELD_BITS) as f64;
                        for (table, field) in tables.iter().zip(TABLE_FIELDS) {
                            table.write_lengths(&mut writer.sink, field.class());
                            *writer.fields.entry(field.name()).or_default() += bits;
                        }
                    }
                    encoder.unit(m, &mut writer);
                    let (bytes, ledger) = writer.sink.finish();
                    (bytes, ledger, writer.fields)
                })
                .collect();
            (units, 0)
        })
    }

    fn level_ends(&self, stream: &StreamReader) -> Result<Vec<u64>> {
        super::level_ends(stream, &params(stream.header())?)
    }

    fn decoder<'a>(&self, stream: StreamReader<'a>) -> Result<Box<dyn LevelDecoder + 'a>> {
        let params = params(stream.header())?;
        Ok(Box::new(CameDecoder::new(
            stream,
            params,
            PaperUnits::default(),
        )?))
    }
}

/// A `came-paper` stream's parameters, checked.
pub fn params(header: &Header) -> Result<Params> {
    let params = Params::from_bytes(&header.params, 1..=16, false)?;
    if params.cone_bits != 0 || params.deviation_bits != 0 {
        return Err(Error::malformed(
            0,
            0,
            "came-paper streams code no normal cones and no deviations",
        ));
    }
    Ok(params)
}

/// The field each table's symbols are booked in.
const TABLE_FIELDS: [Field; TABLES] = [
    Field::Connectivity,
    Field::Connectivity,
    Field::Connectivity,
    Field::Connectivity,
    Field::Dependencies,
    Field::Dependencies,
    Field::Dependencies,
];

/// What the encoder derives once for all units: the closed-loop positions, frames, components
/// and spheres.
struct Encoder<'a> {
    tree: &'a VertexTree,
    part: &'a Partition,
    bits: u8,
    grid_bits: u8,
    /// Per unit: its frame.
    frames: Vec<Frame>,
    /// Per inner node: the components of d_t and d_u.
    components: Vec<[[u32; 3]; 2]>,
    /// Decoded position of each node.
    decoded: Vec<[f64; 3]>,
    /// The root's radius and each inner non-root node's ratio code.
    root_radius: u64,
    ratio_codes: Vec<u32>,
    born: Vec<Vec<BornTriangle>>,
}

/// Clamps a decoded position into the grid (every vertex of the input lies in it).
fn clamp_to_grid(p: DVec3, cells: f64) -> [f64; 3] {
    p.clamp(DVec3::ZERO, DVec3::splat(cells - 1.0)).to_array()
}

impl<'a> Encoder<'a> {
    fn new(
        tree: &'a VertexTree,
        mesh: &CanonicalMesh,
        part: &'a Partition,
        bits: u8,
    ) -> Encoder<'a> {
        let cells = mesh.grid.cells_per_axis() as f64;
        let target = |v: u32| DVec3::from_array(tree.positions[v as usize]);
        let mut decoded = vec![[0.0; 3]; tree.node_count()];
        decoded[tree.root as usize] = clamp_to_grid(target(tree.root).round(), cells);
        let mut components = vec![[[0; 3]; 2]; tree.children.len()];
        let mut frames = Vec::with_capacity(part.units.len());
        for meta in &part.units {
            let top = tree.ids[meta.root as usize].len();
            let depth_in = |s: u32| tree.ids[s as usize].len() - top;
            let vectors: Vec<(DVec3, u8)> = meta
                .nodes
                .iter()
                .flat_map(|&s| {
                    let children = tree.children_of(s).expect("inner");
                    children.map(|c| (target(c) - target(s), depth_in(s)))
                })
                .collect();
            let frame = Frame::fit(&vectors, bits);
            for &s in &meta.nodes {
                let l = depth_in(s);
                let ps = DVec3::from_array(decoded[s as usize]);
                let children = tree.children_of(s).expect("inner");
                for (side, c) in children.into_iter().enumerate() {
                    let q = frame.quantize(target(c) - ps, l, bits);
                    components[s as usize - tree.leaves][side] = q;
                    decoded[c as usize] = clamp_to_grid(ps + frame.dequantize(q, l, bits), cells);
                }
            }
            frames.push(frame);
        }
        let exact = exact_radii(&decoded[..tree.leaves], &tree.children, &decoded);
        let mut radii = vec![0.0; tree.node_count()];
        let root_radius = exact[tree.root as usize].ceil() as u64;
        radii[tree.root as usize] = root_radius as f64;
        let mut ratio_codes = vec![0; tree.node_count()];
        for s in tree.breadth_first() {
            for c in tree.children_of(s).expect("inner") {
                if tree.is_leaf(c) {
                    continue;
                }
                let base = ratio_base(radii[s as usize], decoded[s as usize], decoded[c as usize]);
                let code = ratio_code(exact[c as usize], base, RADIUS_BITS);
                radii[c as usize] = decoded_radius(code, base, RADIUS_BITS);
                ratio_codes[c as usize] = code;
            }
        }
        Encoder {
            tree,
            part,
            bits,
            grid_bits: mesh.grid.bits,
            frames,
            components,
            decoded,
            root_radius,
            ratio_codes,
            born: born_triangles(tree, mesh),
        }
    }

    /// Codes unit `m` (after the tables, in the first unit).
    fn unit(&self, m: usize, out: &mut impl Out) {
        let tree = self.tree;
        let meta = &self.part.units[m];
        if m == 0 {
            for x in self.decoded[tree.root as usize] {
                out.bits(Field::Coordinates, self.grid_bits as u32, x as u64);
            }
            let v = self.root_radius + 1;
            let width = 64 - v.leading_zeros();
            out.bits(Field::Spheres, width - 1, 0);
            out.bits(Field::Spheres, width, v);
        }
        let frame = &self.frames[m];
        for (width, value) in frame.fields() {
            out.bits(Field::Coordinates, width, value as u64);
        }
        let widths = frame.component_bits(self.bits);
        for &s in &meta.nodes {
            let children = tree.children_of(s).expect("inner");
            let sid = tree.ids[s as usize];
            for c in children {
                out.bits(Field::Connectivity, 1, tree.is_leaf(c) as u64);
            }
            for q in self.components[s as usize - tree.leaves] {
                for axis in 0..3 {
                    out.bits(Field::Coordinates, widths[axis], q[axis] as u64);
                }
            }
            // Every child's ratio, a leaf's too (as Table 3's MR column counts them).
            for c in children {
                out.bits(
                    Field::Spheres,
                    RADIUS_BITS as u32,
                    self.ratio_codes[c as usize] as u64,
                );
            }
            let born = &self.born[s as usize - tree.leaves];
            out.count(Table::Triangles, Field::Connectivity, born.len() as u64);
            for tri in born {
                let [l1, l2, l3] = tri.leaves.map(|l| tree.ids[l as usize]);
                for leaf in [l1, l2] {
                    let below = sid.len() + 1;
                    path(out, Table::SiblingLength, Field::Connectivity, leaf, below);
                }
                let tables = (Table::ThirdUp, Table::ThirdLength);
                relative_path(out, tables, Field::Connectivity, l3, sid);
                out.bits(Field::Connectivity, 1, tri.flipped as u64);
            }
            let deps = &tree.dependencies[s as usize - tree.leaves];
            out.count(Table::Dependencies, Field::Dependencies, deps.len() as u64);
            for &y in deps {
                let tables = (Table::DependencyUp, Table::DependencyLength);
                relative_path(out, tables, Field::Dependencies, tree.ids[y as usize], sid);
            }
        }
    }
}

/// Writes `id` relative to split `sid`: up − 1 to the junction, then the path below the
/// junction's other child (its first bit implied).
fn relative_path(
    out: &mut impl Out,
    (up, length): (Table, Table),
    field: Field,
    id: NodeId,
    sid: NodeId,
) {
    let junction = id.common_len(sid);
    out.symbol(up, field, (sid.len() - junction) as usize - 1);
    path(out, length, field, id, junction + 1);
}

/// Writes the bits of `id` from depth `from` on, after their count.
fn path(out: &mut impl Out, table: Table, field: Field, id: NodeId, from: u8) {
    let len = id.len() - from;
    out.symbol(table, field, len as usize);
    let bits = (from..id.len()).fold(0u64, |acc, i| acc << 1 | id.bit(i) as u64);
    out.bits(field, len as u32, bits);
}

/// The unit decoder of `came-paper`: holds the tables once the first unit is decoded.
#[derive(Default)]
pub struct PaperUnits {
    tables: OnceCell<Vec<Huffman>>,
}

struct PaperReader<'b, 't> {
    source: BitSource<'b>,
    tables: &'t [Huffman],
    at: usize,
}

impl PaperReader<'_, '_> {
    fn bits(&mut self, width: u32) -> Result<u64> {
        let cut = || cut_at(self.at);
        if width > 32 {
            let high = self.source.get(width - 32).ok_or_else(cut)? as u64;
            let low = self.source.get(32).ok_or_else(cut)? as u64;
            return Ok(high << 32 | low);
        }
        self.source.get(width).map(u64::from).ok_or_else(cut)
    }

    fn symbol(&mut self, table: Table) -> Result<usize> {
        self.tables[table as usize]
            .get(&mut self.source)
            .ok_or_else(|| cut_at(self.at))
    }

    fn count(&mut self, table: Table, max: u64, what: &str) -> Result<u64> {
        let s = self.symbol(table)?;
        let n = if s == ESCAPE {
            get_gamma(&mut self.source).ok_or_else(|| cut_at(self.at))? + ESCAPE as u64 - 1
        } else {
            s as u64
        };
        if n > max {
            return Err(Error::malformed(
                0,
                self.at,
                format!("{what} {n} exceed {max}"),
            ));
        }
        Ok(n)
    }

    /// A path from `start`, its first bit implied: its length, then its bits.
    fn path(&mut self, table: Table, start: NodeId) -> Result<NodeId> {
        let len = self.symbol(table)?;
        if start.len() as usize + len > MAX_DEPTH as usize {
            return Err(Error::malformed(
                0,
                self.at,
                "a path is longer than 52 bits",
            ));
        }
        let bits = self.bits(len as u32)?;
        let mut x = start;
        for i in (0..len).rev() {
            x = x.child(bits >> i & 1 == 1).expect("length checked");
        }
        Ok(x)
    }

    /// The junction's other child `up` levels above `sid`.
    fn other_child(&self, sid: NodeId, up: usize) -> Result<NodeId> {
        if up == 0 || up > sid.len() as usize {
            return Err(Error::malformed(
                0,
                self.at,
                "a relative path goes above the root",
            ));
        }
        let junction = sid.ancestor(sid.len() - up as u8);
        Ok(junction
            .child(!sid.bit(junction.len()))
            .expect("the junction is above sid"))
    }
}

impl UnitDecoder for PaperUnits {
    fn decode_unit(
        &self,
        tree: &mut DecodedTree,
        header: &Header,
        params: &Params,
        root: u32,
        bytes: &[u8],
        at: usize,
    ) -> Result<Vec<u32>> {
        let mut source = BitSource::new(bytes);
        let first = tree.nodes.is_empty();
        let cells = header.grid.cells_per_axis() as f64;
        if first {
            let mut tables = Vec::with_capacity(TABLES);
            for _ in 0..TABLES {
                let table = Huffman::read_lengths(&mut source, SYMBOLS).ok_or_else(|| {
                    Error::malformed(0, at, "a came-paper table is cut or no prefix code")
                })?;
                tables.push(table);
            }
            // A second decode of the first unit is refused by the level decoder before this.
            let _ = self.tables.set(tables);
        }
        let tables = self
            .tables
            .get()
            .ok_or_else(|| Error::malformed(0, at, "the first unit is not decoded"))?;
        let mut r = PaperReader { source, tables, at };
        if first {
            let mut p = [0.0; 3];
            for x in &mut p {
                *x = r.bits(header.grid.bits as u32)? as f64;
            }
            let radius = get_gamma(&mut r.source).ok_or_else(|| cut_at(at))? - 1;
            tree.add_root(
                clamp_to_grid(DVec3::from_array(p), cells),
                radius as f64,
                // The paper refines by its spheres.
                round_up(radius as f64),
                CodedCone::NONE,
            );
        }
        let bits = params.component_bits;
        let frame = Frame::read(&mut r.source, bits)
            .ok_or_else(|| Error::malformed(0, at, "a meta-node's frame is cut or out of range"))?;
        let widths = frame.component_bits(bits);
        let unit = tree.nodes[root as usize].id;
        let top = unit.len();
        let mut queue = vec![root];
        let mut children_units = Vec::new();
        let mut next = 0;
        while next < queue.len() {
            let s = queue[next];
            next += 1;
            let node = &tree.nodes[s as usize];
            let (sid, ps, rs) = (node.id, DVec3::from_array(node.position), node.radius);
            let l = sid.len() - top;
            let mut leaf = [false; 2];
            for flag in &mut leaf {
                *flag = r.bits(1)? == 1;
            }
            let mut positions = [[0.0; 3]; 2];
            for p in &mut positions {
                let mut q = [0u32; 3];
                for axis in 0..3 {
                    q[axis] = r.bits(widths[axis])? as u32;
                }
                *p = clamp_to_grid(ps + frame.dequantize(q, l, bits), cells);
            }
            let mut radii = [0.0; 2];
            for side in 0..2 {
                let code = r.bits(params.radius_bits as u32)? as u32;
                if !leaf[side] {
                    let base = ratio_base(rs, ps.to_array(), positions[side]);
                    radii[side] = decoded_radius(code, base, params.radius_bits);
                }
            }
            let bounds = radii.map(|radius| Bounds {
                radius,
                deviation: round_up(radius),
                deviation_step: 0,
            });
            let children =
                tree.split(s, leaf, positions, bounds, [CodedCone::NONE; 2], unit, at)?;
            for side in 0..2 {
                if leaf[side] {
                    continue;
                }
                if sid.len() + 1 < top + params.meta_levels {
                    queue.push(children[side]);
                } else {
                    children_units.push(children[side]);
                }
            }
            let count = r.count(Table::Triangles, header.triangles, "triangles at a split")?;
            for _ in 0..count {
                let n1 = r.path(
                    Table::SiblingLength,
                    sid.child(false).ok_or_else(|| deep(at))?,
                )?;
                let n2 = r.path(
                    Table::SiblingLength,
                    sid.child(true).ok_or_else(|| deep(at))?,
                )?;
                let up = r.symbol(Table::ThirdUp)? + 1;
                let start = r.other_child(sid, up)?;
                let n3 = r.path(Table::ThirdLength, start)?;
                let flipped = r.bits(1)? == 1;
                let corners = if flipped { [n2, n1, n3] } else { [n1, n2, n3] };
                tree.add_triangle(
                    Triangle {
                        corners,
                        birth_depth: sid.len(),
                        normal: FaceNormal::UNKNOWN,
                    },
                    at,
                )?;
            }
            let count = r.count(
                Table::Dependencies,
                MAX_DEPENDENCIES,
                "dependencies of a split",
            )?;
            let first = tree.dependency_nodes.len();
            for _ in 0..count {
                let up = r.symbol(Table::DependencyUp)? + 1;
                let start = r.other_child(sid, up)?;
                let dependency = r.path(Table::DependencyLength, start)?;
                tree.dependency_nodes.push(dependency);
            }
            tree.close_dependencies(sid, first);
        }
        Ok(children_units)
    }
}

fn deep(at: usize) -> Error {
    Error::malformed(0, at, "the hierarchy is deeper than 52 levels")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::codecs::{canonical_for, decode, Stop};
    use crate::mesh::{generate, TriMesh};

    fn stream(mesh: &TriMesh, component_bits: u8) -> (CanonicalMesh, Vec<u8>) {
        let codec = CamePaper { component_bits };
        let canonical = canonical_for(mesh, &codec.default_options()).unwrap();
        let bytes = codec.encode(&canonical).unwrap().bytes;
        (canonical, bytes)
    }

    fn decoder(bytes: &[u8]) -> CameDecoder<'_, PaperUnits> {
        let reader = StreamReader::open(bytes).unwrap();
        let params = params(reader.header()).unwrap();
        CameDecoder::new(reader, params, PaperUnits::default()).unwrap()
    }

    #[test]
    fn every_sphere_holds_every_decoded_vertex_of_its_subtree() {
        let mut mesh = generate::icosphere(4);
        mesh.append(
            &generate::torus(1.0, 0.3, 30, 12),
            glam::DVec3::new(3.0, 0.5, 0.0),
            1.0,
        );
        let (_, bytes) = stream(&mesh, 5);
        let mut d = decoder(&bytes);
        while d.advance().unwrap() {}
        let tree = d.tree();
        let mut checked = 0;
        for leaf in tree.nodes.iter().filter(|n| n.leaf) {
            let p = DVec3::from_array(leaf.position);
            for len in 0..leaf.id.len() {
                let a = &tree.nodes[tree.get(leaf.id.ancestor(len)).unwrap() as usize];
                let distance = p.distance(DVec3::from_array(a.position));
                assert!(
                    distance <= a.radius,
                    "{:?}: {distance} > {}",
                    a.id,
                    a.radius
                );
                checked += 1;
            }
        }
        assert!(checked > 10 * tree.nodes.len() / 2);
    }

    #[test]
    fn the_full_level_has_every_face_and_more_bits_bring_it_closer() {
        let mesh = generate::icosphere(5);
        let mut errors = Vec::new();
        for bits in [3u8, 5, 8] {
            let (canonical, bytes) = stream(&mesh, bits);
            let (whole, _) = decode(&bytes, Stop::All).unwrap();
            assert_eq!(whole.mesh.face_count(), canonical.face_count());
            // How far the worst decoded vertex lies from every original one.
            let original = canonical.to_mesh();
            let worst = whole
                .mesh
                .positions
                .iter()
                .map(|p| {
                    original
                        .positions
                        .iter()
                        .map(|q| p.distance(*q))
                        .fold(f64::INFINITY, f64::min)
                })
                .fold(0.0, f64::max);
            errors.push(worst);
        }
        assert!(errors[0] > errors[1] && errors[1] > errors[2], "{errors:?}");
        assert!(errors[2] < 0.01, "{errors:?}");
    }

    #[test]
    fn prefixes_decode_the_levels_they_hold() {
        let (canonical, bytes) = stream(&generate::icosphere(4), 5);
        crate::codecs::came::tests::check_prefixes(&canonical, &bytes);
    }

    #[test]
    fn a_meta_node_decodes_alone_once_its_ancestors_are() {
        let (_, bytes) = stream(&generate::icosphere(5), 5);
        let mut full = decoder(&bytes);
        while full.advance().unwrap() {}
        let units = StreamReader::open(&bytes).unwrap().index().units.clone();
        assert!(units.len() > 8, "{} units", units.len());
        let last = units.len() - 1;
        let mut chain = vec![last];
        while let Some(p) = units[*chain.last().unwrap()].parent {
            chain.push(p);
        }
        let mut alone = decoder(&bytes);
        for &i in chain.iter().rev() {
            assert!(alone.decode_unit(i).unwrap());
        }
        let corners = |d: &CameDecoder<'_, PaperUnits>| -> Vec<[NodeId; 3]> {
            let triangles = d.unit_triangles(last).unwrap();
            triangles.iter().map(|t| t.corners).collect()
        };
        assert!(!corners(&alone).is_empty());
        assert_eq!(corners(&alone), corners(&full));
    }
}
