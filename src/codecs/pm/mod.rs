//! `pm`: Hoppe's progressive meshes, coded.
//!
//! Based on: H. Hoppe, *Efficient Implementation of Progressive Meshes*, Computers & Graphics
//! 22(1), 1998 (../shared/papers/000_54780623804685d2.txt), with the simplification of M. Garland
//! and P. Heckbert, *Surface Simplification Using Quadric Error Metrics*, SIGGRAPH 1997, made
//! O(f log f) with an indexed heap as in ../shared/papers/001_461dc93ddc91cb51.txt.
//!
//! # Glossary
//! | paper | here |
//! |---|---|
//! | M⁰, base mesh; Mⁿ = M̂, full mesh | `PmMesh` of `hierarchy::pmesh`; first stream level / the canonical mesh |
//! | vsplit(vs, vl, vr), ecol | [`Vsplit`](crate::hierarchy::pmesh::Vsplit), `PmMesh::vsplit` / `PmMesh::ecol` |
//! | vt, fl, fr | the new vertex (appended) and faces (appended: fl = (vs, vl, vt), fr = (vs, vt, vr)) |
//! | flclw, vs_index, vlr_rot | face next to the split, vs's corner in it, rotations from vl to vr (with boundary symbols, Fig. 8) |
//! | ii, vad_l, vad_s | position prediction (Fig. 10) and the large / small position deltas, in grid cells |
//! | PMeshIter next / prev / goto | [`iter::PMeshIter`] |
//! | Geomorph, Ancestry | [`iter::Geomorph`] |
//! | wedge, corners field, wedge deltas, matid | [`wedges`]: a corner's value is a candidate choice or a predicted residual |
//! | Δflclw, reordering by a dependency graph | `pm-reordered` (Table 4); `pm` keeps the collapse order (Table 3) |
//!
//! # Any mesh
//! Hoppe's PM needs an oriented 2-manifold. A canonical mesh that is none is first cut to one
//! ([`ManifoldInput`], `mesh::manifold`: vertex copies where fans meet, faces flipped to agree
//! with their component), with every copied vertex and its copies pinned in the simplifier, so
//! that they stay in M⁰ at their one cell and no level opens a crack along the cut. The stream's
//! parameters say how many copies there are; the last level ends with the flipped faces, and
//! its decoded mesh welds the vertices that share a cell and turns those faces back
//! ([`repair`], docs/FORMAT.md §6.2): the canonical mesh, exactly. An oriented manifold is coded
//! as it always was. `experiment repair-cost` measures the price of the cut.
//!
//! # Stream
//! Level 1 is M⁰: vertex and face counts, cells as Q raw bits a coordinate, corners as
//! ⌈log2 V⁰⌉ raw bits. Each further level holds a batch of vsplits, the vertex count about
//! doubling per level, the last level reaching Mⁿ. Every field is arithmetic-coded with an
//! adaptive binary context of its own ([`syntax`]); the coder is flushed per level.
//!
//! Positions are the canonical mesh's cells (docs/CONTRACT.md §2, 16 bits by default as Hoppe §6.2), so
//! the full level is lossless. Appearance (wedges: normals, texture coordinates, colours; face
//! materials) travels in an appearance unit after the last level, as for every codec, or, with
//! [`AttributeFit`] (`--attributes fit|keep`), inside the splits so that every level carries it
//! ([`wedges`], docs/FORMAT.md §6.3): Hoppe's `corners` / wedge-delta / `matid` fields as
//! candidate choices and predicted residuals, the simplifier keeping seams
//! ([`simplify::Constraints::seams`]) and the encoder valuing collapsed wedges by the rule
//! ([`wedge_levels`]).

pub mod iter;
pub mod repair;
pub mod syntax;
pub mod wedge_levels;
pub mod wedges;
pub mod weld;

use super::stats::{PmField, WedgeField};
use super::{
    names, AttributeFit, Capability, Codec, Encoded, LevelDecoder, LevelMesh, Stat, Stats,
};
use crate::codecs::descriptor::cubic;
use crate::codecs::{CodecFacts, Descriptor};
use crate::coding::arith::{ArithDecoder, ArithEncoder};
use crate::coding::bits::index_bits;
use crate::coding::SyntaxClass;
use crate::container::{AppearanceSpec, Header, LevelCost, StreamReader, StreamWriter};
use crate::error::{Error, Result};
use crate::hierarchy::pmesh::PmMesh;
use crate::hierarchy::simplify::{self, Placement};
use crate::mesh::canonical_attributes::{CanonicalAttributes, CornerCode};
use crate::mesh::manifold::ManifoldCut;
use crate::mesh::CanonicalMesh;
use iter::PMeshIter;

/// The statistic of the bits that code the base mesh's appearance.
pub const BASE_APPEARANCE_BITS: &str = "bits_base_appearance";
use syntax::{FlclwCoding, SplitContexts};

/// Ordering of the vertex splits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ordering {
    /// Collapse order reversed; QEM-optimal placement, vad_s coded (Hoppe Table 3).
    Natural,
    /// Reordered along a dependency graph for small Δflclw; endpoint or midpoint placement,
    /// vad_s = 0 (Hoppe Table 4).
    Reordered,
}

/// Parameters stored in the header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PmParams {
    /// Split order.
    pub ordering: Ordering,
    /// For a mesh cut to a manifold ([`repair`]): how many vertices the cut copied, so that
    /// Mⁿ has the header's vertices plus these; `None` for a mesh that was one already.
    pub copies: Option<u64>,
}

/// The first parameter byte of a stream whose mesh was cut to a manifold (docs/FORMAT.md §6).
const REPAIRED: u8 = 1;

impl PmParams {
    /// The parameters' bytes: 0, or [`REPAIRED`] and the copies as a varint (the ordering is
    /// the codec's).
    fn to_bytes(self) -> Vec<u8> {
        let mut out = Vec::new();
        match self.copies {
            None => out.push(0),
            Some(copies) => {
                out.push(REPAIRED);
                crate::coding::varint::put(&mut out, copies);
            }
        }
        out
    }

    /// The parameters of a `pm` or `pm-reordered` stream, checked with its codec and syntax.
    fn from_header(header: &Header) -> Result<PmParams> {
        let unknown = || Error::malformed(0, 7, "pm parameters of unknown syntax");
        let codec = crate::codecs::for_header(header)?;
        let ordering = if codec.id() == names::PM.id {
            Ordering::Natural
        } else if codec.id() == names::PM_REORDERED.id {
            Ordering::Reordered
        } else {
            return Err(Error::malformed(
                0,
                5,
                format!("{} stream read as a pm stream", codec.name()),
            ));
        };
        let copies = match header.params.first() {
            Some(0) if header.params.len() == 1 => None,
            Some(&REPAIRED) => {
                let mut pos = 1;
                let copies =
                    crate::coding::varint::get(&header.params, &mut pos).map_err(|_| unknown())?;
                if pos != header.params.len() {
                    return Err(unknown());
                }
                // A copy is a corner's vertex given to another fan: fewer than the corners.
                if copies > 3 * header.triangles
                    || header.vertices + copies > crate::limits::MAX_VERTICES
                {
                    return Err(Error::malformed(
                        0,
                        7,
                        "pm parameters declare more vertex copies than the mesh has corners",
                    ));
                }
                Some(copies)
            }
            _ => return Err(unknown()),
        };
        Ok(PmParams { ordering, copies })
    }

    /// Vertices of Mⁿ: the header's, plus the copies of a mesh cut to a manifold.
    fn full_vertices(self, header: &Header) -> u64 {
        header.vertices + self.copies.unwrap_or(0)
    }

    fn layout(self) -> syntax::Layout {
        syntax::Layout {
            flclw: self.flclw_coding(),
            with_vad_s: self.with_vad_s(),
        }
    }

    fn flclw_coding(self) -> FlclwCoding {
        match self.ordering {
            Ordering::Natural => FlclwCoding::Index,
            Ordering::Reordered => FlclwCoding::Delta,
        }
    }

    fn with_vad_s(self) -> bool {
        self.ordering == Ordering::Natural
    }
}

/// The `pm` codec, in one of its orderings.
pub struct Pm {
    /// Which ordering this registry entry uses.
    pub ordering: Ordering,
}

/// The oriented 2-manifold pm builds its progressive mesh on: the canonical mesh itself when it
/// is one, else its cut ([`ManifoldCut`]: copies of vertices where fans meet, faces flipped to
/// agree with their component) with every copied vertex pinned, so that a vertex and its
/// copies stay in one cell at every level (`simplify::Constraints::pinned`).
pub struct ManifoldInput {
    /// Cells of the manifold's vertices: the canonical mesh's, then the copies'.
    pub cells: Vec<[i32; 3]>,
    /// The manifold's faces, in the canonical mesh's order.
    pub faces: Vec<[u32; 3]>,
    /// The cut, when the canonical mesh was no oriented manifold.
    pub cut: Option<ManifoldCut>,
    /// Vertices that must stay where they are (none for a mesh that was not cut).
    pub pinned: Vec<bool>,
}

impl ManifoldInput {
    /// The manifold of `mesh`.
    pub fn of(mesh: &CanonicalMesh) -> Result<ManifoldInput> {
        let n = mesh.vertex_count();
        // The cut leaves an oriented manifold as it is, and only one: nothing copied and
        // nothing flipped means every edge has one face or two running it both ways, and every
        // vertex one fan.
        let cut = ManifoldCut::new(n, &mesh.faces);
        let mut cells = cells_of(mesh);
        if cut.is_identity() {
            return Ok(ManifoldInput {
                cells,
                faces: cut.faces,
                cut: None,
                pinned: Vec::new(),
            });
        }
        for &v in &cut.copy_of {
            cells.push(cells[v as usize]);
        }
        Ok(ManifoldInput {
            cells,
            faces: cut.faces.clone(),
            pinned: cut.copied(n),
            cut: Some(cut),
        })
    }

    /// What the simplifier must keep: the pinned vertices.
    pub fn constraints(&self) -> simplify::Constraints<'_> {
        simplify::Constraints {
            seams: &[],
            pinned: &self.pinned,
        }
    }
}

/// What cutting a mesh to a manifold costs a pm stream, against the progressive mesh of the
/// same manifold coded as if it were the input (no vertex pinned, no flips coded, its full
/// decode the manifold rather than the mesh): the price of getting the mesh back.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RepairCost {
    /// Bytes of the stream `encode` writes.
    pub repaired_bytes: usize,
    /// Bytes of the manifold's own stream.
    pub manifold_bytes: usize,
    /// Bits of the flips field.
    pub flip_bits: f64,
    /// Vertices copied, faces flipped, edges cut.
    pub copies: usize,
    /// See `copies`.
    pub flips: usize,
    /// See `copies`.
    pub cut_edges: usize,
    /// Vertices of the base mesh, repaired and not.
    pub base_vertices: [usize; 2],
}

impl Pm {
    /// What the cut costs on `mesh`; `None` when it is an oriented manifold (nothing cut).
    pub fn repair_cost(&self, mesh: &CanonicalMesh) -> Result<Option<RepairCost>> {
        let input = ManifoldInput::of(mesh)?;
        let Some(cut) = &input.cut else {
            return Ok(None);
        };
        let repaired = self.encode_cut(mesh, &input, cut)?;
        let plain = self.progressive_mesh(&input.cells, &input.faces, None);
        // The manifold as a mesh of its own: its cells are not all distinct, which only the
        // weld at the decoder's last level would need.
        let manifold = CanonicalMesh {
            grid: mesh.grid,
            cells: input.cells.iter().map(|c| c.map(|x| x as u32)).collect(),
            faces: input.faces.clone(),
        };
        let manifold_stream = encode_pm(
            self.descriptor().naming,
            self.params(),
            &manifold,
            &plain,
            None,
            None,
        );
        let stat = |s: &Stats, name: &str| s.get_named(name).unwrap_or(0.0);
        Ok(Some(RepairCost {
            repaired_bytes: repaired.bytes.len(),
            manifold_bytes: manifold_stream.bytes.len(),
            flip_bits: stat(&repaired.stats, "bits_repair"),
            copies: cut.copy_of.len(),
            flips: cut.flip_count(),
            cut_edges: cut.cut_edges,
            base_vertices: [
                stat(&repaired.stats, &Stat::BaseVertices.key()) as usize,
                plain.base.positions.len(),
            ],
        }))
    }
}

/// What the decoder needs of a mesh cut to a manifold ([`repair`]).
struct RepairPlan {
    /// Vertices the cut copied.
    copies: u64,
    /// Edges the cut made join no faces.
    cut_edges: usize,
    /// Whether each face of Mⁿ (in the decoder's face order) was flipped.
    flips: Vec<bool>,
}

impl RepairPlan {
    /// The plan of `cut` for the progressive mesh `pm` built on it.
    fn of(cut: &ManifoldCut, pm: &simplify::ProgressiveMesh) -> RepairPlan {
        RepairPlan {
            copies: cut.copy_of.len() as u64,
            cut_edges: cut.cut_edges,
            flips: pm
                .face_origin
                .iter()
                .map(|&f| cut.flipped[f as usize])
                .collect(),
        }
    }
}

/// How many vertices the cut to a manifold copied, for a pm stream of a mesh that was none
/// (docs/FORMAT.md §6.2); `None` for other streams.
pub fn vertex_copies(header: &Header) -> Option<u64> {
    PmParams::from_header(header).ok()?.copies
}

/// The most vertices a level of a pm stream with `header` has: Mⁿ's, copies included.
pub fn most_vertices(header: &Header) -> u64 {
    PmParams::from_header(header).map_or(header.vertices, |p| p.full_vertices(header))
}

/// A base-mesh level as read: the mesh, its values when the stream carries appearance, and
/// its restoration when it is already Mⁿ of a mesh cut to a manifold.
type Base = (
    PmMesh,
    Option<wedges::WedgeState>,
    Option<repair::Restoration>,
);

/// Reads a base-mesh level.
fn read_base(header: &Header, bytes: &[u8]) -> Option<Base> {
    let params = PmParams::from_header(header).ok()?;
    let mut dec = ArithDecoder::new(bytes)?;
    let mut ctx = SplitContexts::default();
    let v = syntax::get_count(&mut dec, &mut ctx)?;
    let f = syntax::get_count(&mut dec, &mut ctx)?;
    let q = header.grid.bits as u64;
    let b = index_bits(v) as u64;
    // Raw bits cost one bit each: the payload must hold them before anything is allocated.
    if v > params.full_vertices(header)
        || f > header.triangles
        || 3 * q * v + 3 * b * f > bytes.len() as u64 * 8 + 64
    {
        return None;
    }
    let mut positions = Vec::with_capacity(v as usize);
    for _ in 0..v {
        let mut c = [0i32; 3];
        for x in &mut c {
            *x = dec.raw(q as u32)? as i32;
        }
        positions.push(c);
    }
    let mut faces = Vec::with_capacity(f as usize);
    for _ in 0..f {
        let mut t = [0u32; 3];
        for x in &mut t {
            *x = dec.raw(b as u32)? as u32;
            if *x as u64 >= v {
                return None;
            }
        }
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            return None;
        }
        faces.push(t);
    }
    // from_triangles links faces across shared edges; a base mesh whose vertices are not
    // manifold (two fans meeting at one vertex) links but is no mesh PM can split.
    let mesh =
        PmMesh::from_triangles(positions, &faces).filter(|mesh| mesh.check_invariants().is_ok())?;
    let restoration = match params.copies {
        Some(_) if v == params.full_vertices(header) => {
            Some(repair::Restoration::read(&mut dec, &mesh).ok()?)
        }
        _ => None,
    };
    let state = match header.appearance.as_ref().filter(|a| a.in_levels) {
        Some(spec) => {
            let mut reader = crate::codecs::appearance::coder::Reader {
                coder: dec,
                unit: 1,
                start: 0,
            };
            let mut contexts = wedges::WedgeContexts::default();
            Some(wedges::code_base(&mut reader, &mut contexts, &mesh, spec, None).ok()?)
        }
        None => None,
    };
    Some((mesh, state, restoration))
}

/// The canonical mesh's cells as the simplifier takes them.
fn cells_of(mesh: &CanonicalMesh) -> Vec<[i32; 3]> {
    mesh.cells.iter().map(|c| c.map(|x| x as i32)).collect()
}

/// Seams of a manifold's appearance: edges whose two faces differ in material or in the values
/// at either end (sorted vertex pairs, sorted). `code(f, k)` is the value of corner k of face f.
fn seams_of(
    faces: &[[u32; 3]],
    code: impl Fn(usize, usize) -> CornerCode,
    material: impl Fn(usize) -> Option<u32>,
) -> Vec<[u32; 2]> {
    let mut directed: std::collections::HashMap<(u32, u32), (usize, usize)> =
        std::collections::HashMap::with_capacity(faces.len() * 3);
    for (f, t) in faces.iter().enumerate() {
        for k in 0..3 {
            directed.insert((t[k], t[(k + 1) % 3]), (f, k));
        }
    }
    let mut seams = Vec::new();
    for (&(u, w), &(f, k)) in &directed {
        if u > w {
            continue;
        }
        let Some(&(g, j)) = directed.get(&(w, u)) else {
            continue;
        };
        // f holds u at k and w at k + 1; g holds w at j and u at j + 1.
        if code(f, k) != code(g, (j + 1) % 3)
            || code(f, (k + 1) % 3) != code(g, j)
            || material(f) != material(g)
        {
            seams.push([u, w]);
        }
    }
    seams.sort_unstable();
    seams
}

impl Pm {
    fn params(&self) -> PmParams {
        self.params_with(None)
    }

    /// The parameters of a stream, of a mesh cut to a manifold when `plan` is given.
    fn params_with(&self, plan: Option<&RepairPlan>) -> PmParams {
        PmParams {
            ordering: self.ordering,
            copies: plan.map(|p| p.copies),
        }
    }

    /// The progressive mesh of the oriented manifold (`cells`, `faces`), under `constraints`
    /// when given.
    fn progressive_mesh(
        &self,
        cells: &[[i32; 3]],
        faces: &[[u32; 3]],
        constraints: Option<simplify::Constraints>,
    ) -> simplify::ProgressiveMesh {
        let placement = match self.ordering {
            Ordering::Natural => Placement::Optimal,
            Ordering::Reordered => Placement::EndpointOrMidpoint,
        };
        let simplified = match constraints {
            Some(c) => simplify::simplify_constrained(cells, faces, placement, c),
            None => simplify::simplify(cells, faces, placement),
        };
        match self.ordering {
            Ordering::Natural => simplify::progressive_mesh(faces, &simplified),
            Ordering::Reordered => simplify::reordered_progressive_mesh(faces, &simplified),
        }
    }

    /// Encodes a mesh that is no oriented manifold: the progressive mesh of its cut
    /// ([`ManifoldCut`]), copied vertices pinned, and the flips at the last level ([`repair`]).
    fn encode_cut(
        &self,
        mesh: &CanonicalMesh,
        input: &ManifoldInput,
        cut: &ManifoldCut,
    ) -> Result<Encoded> {
        let pm = self.progressive_mesh(&input.cells, &input.faces, Some(input.constraints()));
        let plan = RepairPlan::of(cut, &pm);
        let params = self.params_with(Some(&plan));
        Ok(encode_pm(
            self.descriptor().naming,
            params,
            mesh,
            &pm,
            None,
            Some(&plan),
        ))
    }

    /// Encodes with the appearance inside the vertex splits ([`wedges`]).
    fn encode_appearance(
        &self,
        mesh: &CanonicalMesh,
        appearance: &CanonicalAttributes,
        fit: AttributeFit,
    ) -> Result<Encoded> {
        let input = ManifoldInput::of(mesh)?;
        let derived_normals = appearance.bits.derive_normals && appearance.normals.is_some();
        if derived_normals && input.cut.is_some() {
            // Copies of a vertex at the cut would each derive a normal of their own faces.
            return Err(Error::Unsupported(
                "pm derives normals inside its levels on oriented manifolds only; this mesh is cut to one (code its normals, or encode them in an appearance unit without --attributes)".into(),
            ));
        }
        let flipped = |f: usize| input.cut.as_ref().is_some_and(|c| c.flipped[f]);
        // Corner k of manifold face f is the canonical face's corner k, or for a flipped face
        // (its last two corners swapped) the other of the last two.
        let code = |f: usize, k: usize| {
            let k = if flipped(f) { [0, 2, 1][k] } else { k };
            appearance.code(appearance.corners[f][k])
        };
        let material = |f: usize| appearance.materials.as_ref().map(|m| m.face[f]);
        let seams = seams_of(&input.faces, code, material);
        let pm = self.progressive_mesh(
            &input.cells,
            &input.faces,
            Some(simplify::Constraints {
                seams: &seams,
                pinned: &input.pinned,
            }),
        );
        let mut full = pm.base.clone();
        for split in &pm.vsplits {
            full.vsplit(split).expect("the encoder's own splits apply");
        }
        // Derived normals travel as labels: one per normal group (a vertex's corners with one
        // normal), numbered in order of first corner.
        let mut labels: std::collections::HashMap<(u32, [u32; 2]), u32> =
            std::collections::HashMap::new();
        // Each face of Mⁿ is a manifold face: its values, rotated to its first corner.
        let mut state = wedges::WedgeState {
            corners: Vec::with_capacity(full.faces.len()),
            materials: appearance.materials.as_ref().map(|_| Vec::new()),
        };
        for (face, &f) in full.faces.iter().zip(&pm.face_origin) {
            let f = f as usize;
            let t = face.v.map(|v| pm.vertex_origin[v as usize]);
            let m = input.faces.get(f);
            let r = (0..3)
                .find(|&r| m == Some(&[t[r], t[(r + 1) % 3], t[(r + 2) % 3]]))
                .ok_or_else(|| Error::Unsupported("pm rebuilt a face the mesh lacks".into()))?;
            // Manifold corner i is our corner (i + r).
            let mut codes = [Default::default(); 3];
            for i in 0..3 {
                codes[(i + r) % 3] = code(f, i);
            }
            if derived_normals {
                for (c, &v) in codes.iter_mut().zip(&face.v) {
                    let next = labels.len() as u32;
                    let label = *labels
                        .entry((v, c.normal.unwrap_or_default()))
                        .or_insert(next);
                    c.normal = Some(wedges::label_code(label));
                }
            }
            state.corners.push(codes);
            if let (Some(out), Some(m)) = (state.materials.as_mut(), &appearance.materials) {
                out.push(m.face[f]);
            }
        }
        let mut spec = super::appearance::spec_of(appearance);
        spec.in_levels = true;
        spec.derived_normals = derived_normals;
        spec.geometric_normals = spec.normal_bits.is_some() && !derived_normals;
        let levels = wedge_levels::derive(&full, state, &pm.vsplits, fit, &spec);
        let plan = input.cut.as_ref().map(|cut| RepairPlan::of(cut, &pm));
        let params = self.params_with(plan.as_ref());
        Ok(encode_pm(
            self.descriptor().naming,
            params,
            mesh,
            &pm,
            Some((&spec, &levels)),
            plan.as_ref(),
        ))
    }
}

/// What `pm` is.
const PM_DESCRIPTOR: Descriptor = Descriptor {
    naming: names::PM,
    summary: "Hoppe's progressive meshes: QEM collapses, arithmetic-coded vsplits in collapse order (Table 3)",
    default_options: cubic(16),
    capabilities: &[Capability::Attributes, Capability::AppearanceInLevels],
    lossless: true,
};

/// What `pm-reordered` is: `pm` in another order.
const PM_REORDERED_DESCRIPTOR: Descriptor = Descriptor {
    naming: names::PM_REORDERED,
    summary: "Hoppe's progressive meshes, vsplits reordered for small Δflclw, vad_s = 0 (Table 4)",
    ..PM_DESCRIPTOR
};

impl Codec for Pm {
    fn descriptor(&self) -> &'static Descriptor {
        match self.ordering {
            Ordering::Natural => &PM_DESCRIPTOR,
            Ordering::Reordered => &PM_REORDERED_DESCRIPTOR,
        }
    }

    fn facts(&self, header: &Header) -> CodecFacts {
        CodecFacts {
            vertex_copies: vertex_copies(header),
            ..CodecFacts::default()
        }
    }

    fn most_level_vertices(&self, header: &Header) -> u64 {
        most_vertices(header)
    }

    fn encode(&self, mesh: &CanonicalMesh) -> Result<Encoded> {
        // An oriented manifold is coded as it is (its streams as they always were); any other
        // mesh through its cut.
        let input = ManifoldInput::of(mesh)?;
        if let Some(cut) = &input.cut {
            return self.encode_cut(mesh, &input, cut);
        }
        let pm = self.progressive_mesh(&input.cells, &input.faces, None);
        Ok(encode_pm(
            self.descriptor().naming,
            self.params(),
            mesh,
            &pm,
            None,
            None,
        ))
    }

    fn encode_with_appearance(
        &self,
        mesh: &CanonicalMesh,
        appearance: &CanonicalAttributes,
        fit: AttributeFit,
    ) -> Option<Result<Encoded>> {
        Some(self.encode_appearance(mesh, appearance, fit))
    }

    fn measure(&self, stream: &[u8]) -> Result<Stats> {
        // Hoppe's Table 2: iteration rates over a PMesh in memory, forwards to Mⁿ and back to
        // M⁰ (best of a few passes), and the full stream decode rate.
        let started = std::time::Instant::now();
        let mut iter = PMeshIter::from_stream(stream)?;
        while iter.next()? {}
        let decode = started.elapsed().as_secs_f64();
        let header = iter.header().clone();
        let (base, records) = iter.pmesh();
        let mut memory = PMeshIter::from_records(base.clone(), records.to_vec(), header);
        let n = records.len() as f64;
        let (mut forward, mut backward) = (f64::INFINITY, f64::INFINITY);
        for _ in 0..5 {
            let t = std::time::Instant::now();
            memory.goto_nvertices(usize::MAX)?;
            forward = forward.min(t.elapsed().as_secs_f64());
            let t = std::time::Instant::now();
            memory.goto_nvertices(0)?;
            backward = backward.min(t.elapsed().as_secs_f64());
        }
        let mut out = Stats::default();
        out.set(Stat::GotoFullVerticesPerSecond, n / forward.max(1e-9));
        out.set(Stat::GotoBaseVerticesPerSecond, n / backward.max(1e-9));
        out.set(Stat::StreamDecodeVerticesPerSecond, n / decode.max(1e-9));
        Ok(out)
    }

    fn decoder<'a>(&self, stream: StreamReader<'a>) -> Result<Box<dyn LevelDecoder + 'a>> {
        stream.require_layered()?;
        let header = stream.header().clone();
        PmParams::from_header(&header)?;
        Ok(Box::new(PmDecoder {
            levels: stream.index().len(),
            stream: Some(stream),
            header,
            iter: None,
            decoded: 0,
        }))
    }
}

/// Writes the stream of a progressive mesh.
fn encode_pm(
    naming: names::Naming,
    params: PmParams,
    mesh: &CanonicalMesh,
    pm: &simplify::ProgressiveMesh,
    appearance: Option<(&AppearanceSpec, &wedge_levels::WedgeLevels)>,
    repair: Option<&RepairPlan>,
) -> Encoded {
    let base = &pm.base;
    let mut schedule = Vec::new();
    let (mut done, mut vertices) = (0usize, base.positions.len());
    while done < pm.vsplits.len() {
        let target = (vertices * 2).max(vertices + 1).max(64);
        let n = (target - vertices).min(pm.vsplits.len() - done);
        schedule.push(n);
        done += n;
        vertices += n;
    }
    let header = Header {
        codec_id: naming.id,
        syntax: naming.syntax,
        params: params.to_bytes(),
        grid: mesh.grid,
        vertices: mesh.vertex_count() as u64,
        triangles: mesh.face_count() as u64,
        appearance: appearance.map(|(spec, _)| spec.clone()),
    };
    let mut writer = StreamWriter::new(&header);
    let mut stats = Stats::default();

    // Level 1: the base mesh.
    let mut enc = ArithEncoder::default();
    let mut ctx = SplitContexts::default();
    syntax::put_count(&mut enc, &mut ctx, base.positions.len() as u64);
    syntax::put_count(&mut enc, &mut ctx, base.faces.len() as u64);
    let q = mesh.grid.bits as u32;
    let field = PmField::Base.name();
    for c in &base.positions {
        for &x in c {
            enc.raw(x as u64, q, SyntaxClass::Geometry, field);
        }
    }
    let b = index_bits(base.positions.len() as u64);
    for f in &base.faces {
        for &v in &f.v {
            enc.raw(v as u64, b, SyntaxClass::Connectivity, field);
        }
    }
    if let (Some(plan), true) = (repair, pm.vsplits.is_empty()) {
        repair::put_flips(&mut enc, base, &plan.flips);
    }
    // The base level's contexts are its own, as the decoder reads it apart.
    let mut base_contexts = wedges::WedgeContexts::default();
    let mut wedge_state = appearance.map(|(spec, levels)| {
        wedges::code_base(&mut enc, &mut base_contexts, base, spec, Some(&levels.base))
            .expect("the encoder codes its own values")
    });
    let mut wedge_contexts =
        wedges::WedgeContexts::after_base(wedge_state.as_ref(), Some(base_contexts));
    // The base mesh's appearance is counted apart, so that the wedge fields are the splits'.
    let mut pushed = 0usize;
    let mut push = |enc: ArithEncoder, vertices: usize, triangles: usize, stats: &mut Stats| {
        let base = pushed == 0;
        pushed += 1;
        for (field, bits) in &enc.field_bits {
            let wedge = WedgeField::ALL.iter().any(|w| w.name() == *field);
            if base && wedge {
                stats.add_named(BASE_APPEARANCE_BITS, *bits);
            } else {
                stats.add_named(&format!("bits_{field}"), *bits);
            }
        }
        let (payload, ledger) = enc.finish();
        writer.push_level(
            &payload,
            LevelCost {
                connectivity_bits: ledger.connectivity,
                geometry_bits: ledger.geometry,
                vertices,
                triangles,
            },
        );
    };
    let vertices = match (repair, pm.vsplits.is_empty()) {
        (Some(_), true) => mesh.vertex_count(),
        _ => base.positions.len(),
    };
    push(enc, vertices, base.faces.len(), &mut stats);

    // Further levels: batches of vsplits, coded against the mesh as the decoder will hold it.
    let mut state = base.clone();
    let mut ctx = SplitContexts::default();
    let mut previous = 0u32;
    let mut next = 0usize;
    for n in schedule {
        let mut enc = ArithEncoder::default();
        syntax::put_count(&mut enc, &mut ctx, n as u64);
        for (i, split) in pm.vsplits[next..next + n].iter().enumerate() {
            let faces = state.faces.len() as u32;
            let tangent = syntax::Tangent::at(&state, split);
            syntax::put_split(
                &mut enc,
                &mut ctx,
                split,
                faces,
                previous,
                params.layout(),
                tangent,
            );
            previous = split.flclw;
            let coarse = wedge_state
                .as_ref()
                .and_then(|w| wedges::coarse(&state, w, split));
            state.vsplit(split).expect("the encoder's own splits apply");
            if let (Some((spec, levels)), Some(w), Some(coarse)) =
                (appearance, wedge_state.as_mut(), coarse)
            {
                wedges::code_split(
                    &mut enc,
                    &mut wedge_contexts,
                    &state,
                    w,
                    &coarse,
                    spec,
                    Some(&levels.truths[next + i]),
                )
                .expect("the encoder codes its own values");
            }
        }
        next += n;
        let mut vertices = state.positions.len();
        if let (Some(plan), true) = (repair, next == pm.vsplits.len()) {
            repair::put_flips(&mut enc, &state, &plan.flips);
            vertices = mesh.vertex_count(); // copies welded
        }
        push(enc, vertices, state.faces.len(), &mut stats);
    }
    let (bytes, levels) = writer.finish();
    if appearance.is_some() {
        let bits: f64 = WedgeField::ALL
            .iter()
            .filter_map(|f| stats.get_named(&format!("bits_{}", f.name())))
            .chain(stats.get_named(BASE_APPEARANCE_BITS))
            .sum();
        stats.add_named("appearance_bits", bits);
    }
    if let Some(plan) = repair {
        stats.add_named("repair_copies", plan.copies as f64);
        let flips = plan.flips.iter().filter(|&&f| f).count();
        stats.add_named("repair_flips", flips as f64);
        stats.add_named("repair_cut_edges", plan.cut_edges as f64);
    }
    stats.set(Stat::Vsplits, pm.vsplits.len() as f64);
    stats.set(Stat::BaseVertices, base.positions.len() as f64);
    stats.set(Stat::BaseFaces, base.faces.len() as f64);
    Encoded {
        bytes,
        levels,
        stats,
    }
}

/// Level-by-level decoder over a [`PMeshIter`]; the first level (the base mesh) is read by the
/// first `advance`.
struct PmDecoder<'a> {
    /// The stream, until the iterator takes it (once its base mesh is present).
    stream: Option<StreamReader<'a>>,
    header: Header,
    iter: Option<PMeshIter<'a>>,
    levels: usize,
    decoded: usize,
}

impl LevelDecoder for PmDecoder<'_> {
    fn header(&self) -> &Header {
        &self.header
    }

    fn levels(&self) -> usize {
        self.levels
    }

    fn levels_decoded(&self) -> usize {
        self.decoded
    }

    fn advance(&mut self) -> Result<bool> {
        let advanced = match self.iter.as_mut() {
            Some(iter) => iter.next_level()?,
            None => match self.stream.take_if(|s| s.unit(0).is_some()) {
                Some(stream) => {
                    self.iter = Some(PMeshIter::from_source(Box::new(stream))?);
                    true
                }
                None => false,
            },
        };
        self.decoded += advanced as usize;
        Ok(advanced)
    }

    fn mesh(&self) -> Result<LevelMesh> {
        Ok(self
            .iter
            .as_ref()
            .map(|i| i.level_mesh())
            .unwrap_or_default())
    }

    /// The next bytes go to the stream, or to the iterator once it has taken the stream: the
    /// splits of the levels they complete are applied to the mesh as it stands.
    fn extend(&mut self, more: &[u8]) -> Result<bool> {
        match (self.iter.as_mut(), self.stream.as_mut()) {
            (Some(iter), _) => iter.extend(more),
            (None, Some(stream)) => {
                stream.extend(more)?;
                Ok(true)
            }
            (None, None) => Ok(false),
        }
    }
}
