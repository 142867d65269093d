//! PMeshIter (Hoppe §4): a mesh that walks the PM sequence, split by split, forwards over records
//! read on demand from a stream (or held in memory) and backwards over those already read; and
//! Geomorph (§5), which blends a finer mesh towards its ancestors in a coarser one.

use super::syntax::{self, Layout, SplitContexts};
use super::wedges::{self, SplitWedges, WedgeContexts, WedgeState};
use super::weld;
use super::PmParams;
use crate::codecs::LevelMesh;
use crate::coding::arith::ArithDecoder;
use crate::container::{AppearanceSpec, Header, LevelSource, ReadLevels, StreamReader};
use crate::error::{Error, Result};
use crate::hierarchy::pmesh::{PmMesh, Vsplit};
use crate::mesh::attributes::Attributes;
use crate::mesh::canonical_attributes::CornerCode;
use crate::mesh::{Grid, TriMesh};
use glam::DVec3;

/// Reads vsplit records one at a time from a stream's levels.
struct SplitReader<'a> {
    source: Box<dyn LevelSource + Send + 'a>,
    contexts: SplitContexts,
    coder: Option<ArithDecoder>,
    left_in_level: u64,
    level_start: usize,
    levels_read: usize,
    previous_flclw: u32,
    layout: Layout,
    wedge_contexts: WedgeContexts,
}

impl SplitReader<'_> {
    /// Opens the next level; `Ok(false)` when there is none (complete) in the stream.
    fn open_level(&mut self) -> Result<bool> {
        let Some(level) = self.source.next_owned_level()? else {
            return Ok(false);
        };
        let fault = || {
            Error::malformed(
                level.index + 1,
                level.start,
                "level is not an arithmetic-coded payload",
            )
        };
        let mut coder = ArithDecoder::new(&level.bytes).ok_or_else(fault)?;
        self.left_in_level = syntax::get_count(&mut coder, &mut self.contexts).ok_or_else(fault)?;
        self.level_start = level.start;
        self.coder = Some(coder);
        self.levels_read += 1;
        Ok(true)
    }

    /// The next record for a mesh of `faces` faces, if the current level has one.
    fn next_in_level(&mut self, mesh: &PmMesh) -> Result<Option<Vsplit>> {
        let faces = mesh.faces.len() as u32;
        if self.left_in_level == 0 {
            return Ok(None);
        }
        let coder = self.coder.as_mut().expect("a level is open");
        let tangent = |split: &Vsplit| syntax::Tangent::at(mesh, split);
        let split = syntax::get_split(
            coder,
            &mut self.contexts,
            faces,
            self.previous_flclw,
            self.layout,
            tangent,
        )
        .ok_or_else(|| {
            Error::malformed(
                self.levels_read,
                self.level_start,
                "vsplit record cannot be read",
            )
        })?;
        self.left_in_level -= 1;
        self.previous_flclw = split.flclw;
        Ok(Some(split))
    }
}

/// The corner values a stream with appearance carries along the sequence: those of the
/// current mesh, and what each split read so far changed.
struct Wedges {
    state: WedgeState,
    splits: Vec<SplitWedges>,
}

/// An iterator over the meshes M⁰ … Mⁿ of a progressive mesh. For a mesh cut to a manifold
/// ([`super::repair`]) these are the manifold's meshes; the level mesh of Mⁿ is the mesh
/// itself, copies welded and flipped faces turned back.
pub struct PMeshIter<'a> {
    base: PmMesh,
    mesh: PmMesh,
    /// Whether the stream's mesh was cut to a manifold.
    repaired: bool,
    /// How Mⁿ turns back into the mesh, once its last level is read.
    restoration: Option<super::repair::Restoration>,
    wedges: Option<Wedges>,
    records: Vec<Vsplit>,
    applied: usize,
    reader: Option<SplitReader<'a>>,
    header: Header,
    full_vertices: u64,
}

impl<'a> PMeshIter<'a> {
    /// An iterator at M⁰ of the stream `bytes` (its first level must be present).
    pub fn from_stream(bytes: &'a [u8]) -> Result<PMeshIter<'a>> {
        Self::from_source(Box::new(StreamReader::open(bytes)?))
    }

    /// An iterator at M⁰ of a stream read from `reader` (a file, a socket) as records are needed:
    /// Hoppe's PMeshRStream over an input stream. Records read are kept, so `prev` works.
    pub fn from_reader(reader: impl std::io::Read + Send + 'a) -> Result<PMeshIter<'a>> {
        Self::from_source(Box::new(ReadLevels::open(reader)?))
    }

    pub(crate) fn from_source(
        mut stream: Box<dyn LevelSource + Send + 'a>,
    ) -> Result<PMeshIter<'a>> {
        let header = stream.header().clone();
        let params = PmParams::from_header(&header)?;
        let base = stream
            .next_owned_level()?
            .ok_or_else(|| Error::Truncated("the stream ends before its base mesh".into()))?;
        let (mesh, values, restoration) = super::read_base(&header, &base.bytes)
            .ok_or_else(|| Error::malformed(1, base.start, "base mesh cannot be read"))?;
        let wedge_contexts = WedgeContexts::after_base(values.as_ref(), None);
        Ok(PMeshIter {
            base: mesh.clone(),
            mesh,
            repaired: params.copies.is_some(),
            restoration,
            wedges: values.map(|state| Wedges {
                state,
                splits: Vec::new(),
            }),
            records: Vec::new(),
            applied: 0,
            full_vertices: params.full_vertices(&header),
            header,
            reader: Some(SplitReader {
                source: stream,
                contexts: SplitContexts::default(),
                coder: None,
                left_in_level: 0,
                level_start: 0,
                levels_read: 1,
                previous_flclw: 0,
                layout: Layout {
                    flclw: params.flclw_coding(),
                    with_vad_s: params.with_vad_s(),
                },
                wedge_contexts,
            }),
        })
    }

    /// An iterator over records held in memory (a PMesh), at M⁰; geometry only, and the
    /// manifold's meshes only for a mesh cut to one.
    pub fn from_records(base: PmMesh, records: Vec<Vsplit>, header: Header) -> PMeshIter<'static> {
        PMeshIter {
            full_vertices: (base.positions.len() + records.len()) as u64,
            repaired: false,
            restoration: None,
            mesh: base.clone(),
            wedges: None,
            base,
            records,
            applied: 0,
            reader: None,
            header,
        }
    }

    /// The base mesh M⁰ and the records read so far: a PMesh in memory.
    pub fn pmesh(&self) -> (&PmMesh, &[Vsplit]) {
        (&self.base, &self.records)
    }

    /// The current mesh.
    pub fn mesh(&self) -> &PmMesh {
        &self.mesh
    }

    /// Number of vertices of the current mesh.
    pub fn nvertices(&self) -> usize {
        self.mesh.positions.len()
    }

    /// Number of faces of the current mesh.
    pub fn nfaces(&self) -> usize {
        self.mesh.faces.len()
    }

    /// Levels of the stream read so far (the base mesh is level 1).
    pub fn levels_read(&self) -> usize {
        self.reader.as_ref().map_or(1, |r| r.levels_read)
    }

    /// The next record, reading it from the stream if needed; `None` at the end of what is
    /// present. Reads records only within open levels unless `cross_levels`.
    fn peek_record(&mut self, cross_levels: bool) -> Result<Option<Vsplit>> {
        if self.applied < self.records.len() {
            return Ok(Some(self.records[self.applied]));
        }
        let Some(reader) = self.reader.as_mut() else {
            return Ok(None);
        };
        loop {
            if let Some(split) = reader.next_in_level(&self.mesh)? {
                self.records.push(split);
                return Ok(Some(split));
            }
            if !cross_levels || !reader.open_level()? {
                return Ok(None);
            }
        }
    }

    fn apply(&mut self, split: Vsplit) -> Result<()> {
        let vs = self
            .mesh
            .faces
            .get(split.flclw as usize)
            .map(|f| f.v[(split.vs_index as usize).min(2)]);
        // A split read for the first time reads its wedges after it applies.
        let coarse = match &self.wedges {
            Some(w) if w.splits.len() == self.applied => {
                wedges::coarse(&self.mesh, &w.state, &split)
            }
            _ => None,
        };
        if self.mesh.positions.len() as u64 >= self.full_vertices {
            return Err(Error::malformed(
                self.levels_read(),
                0,
                "more vertex splits than the header's vertices",
            ));
        }
        self.mesh.vsplit(&split).map_err(|e| {
            Error::malformed(
                self.levels_read(),
                0,
                format!("vsplit {}: {}", self.applied, e.0),
            )
        })?;
        let top = 1i64 << self.header.grid.bits;
        let out = |c: [i32; 3]| c.iter().any(|&x| (x as i64) < 0 || x as i64 >= top);
        let vt = self.mesh.positions.len() - 1;
        let vs = vs.unwrap_or(vt as u32) as usize;
        if out(self.mesh.positions[vt]) || out(self.mesh.positions[vs]) {
            // Undone so that the mesh stays the one the records applied so far describe.
            self.mesh.ecol(&split);
            return Err(Error::malformed(
                self.levels_read(),
                0,
                "vsplit moves a vertex off the grid",
            ));
        }
        if let Some(w) = self.wedges.as_mut() {
            if let Some(done) = w.splits.get(self.applied) {
                w.state.redo(done);
            } else {
                let read = match (coarse, self.reader.as_mut()) {
                    (Some(coarse), Some(reader)) => {
                        let spec = self
                            .header
                            .appearance
                            .as_ref()
                            .expect("a stream with appearance");
                        let mut symbols = crate::codecs::appearance::coder::Reader {
                            coder: reader.coder.take().expect("a level is open"),
                            unit: reader.levels_read,
                            start: reader.level_start,
                        };
                        let read = wedges::code_split(
                            &mut symbols,
                            &mut reader.wedge_contexts,
                            &self.mesh,
                            &mut w.state,
                            &coarse,
                            spec,
                            None,
                        );
                        reader.coder = Some(symbols.coder);
                        read.map_err(|e| match e {
                            Error::Malformed { what, .. } => what,
                            e => e.to_string(),
                        })
                    }
                    _ => Err("its record does not locate".to_string()),
                };
                let read = match read {
                    Ok(read) => read,
                    Err(what) => {
                        self.mesh.ecol(&split);
                        return Err(Error::malformed(
                            self.levels_read(),
                            0,
                            format!("vsplit {}: {what}", self.applied),
                        ));
                    }
                };
                w.splits.push(read);
            }
        }
        if self.repaired
            && self.restoration.is_none()
            && self.mesh.positions.len() as u64 == self.full_vertices
        {
            // Mⁿ of a mesh cut to a manifold: its flips close the last level.
            let read = match self.reader.as_mut().and_then(|r| r.coder.as_mut()) {
                Some(coder) => super::repair::Restoration::read(coder, &self.mesh),
                None => Err("the flipped faces of the last level cannot be read"),
            };
            let fault = match read {
                Ok(restoration) => {
                    self.restoration = Some(restoration);
                    None
                }
                Err(what) => Some(what),
            };
            if let Some(what) = fault {
                self.mesh.ecol(&split);
                if let Some(w) = self.wedges.as_mut() {
                    if let Some(done) = w.splits.pop() {
                        w.state.undo(&done);
                    }
                }
                return Err(Error::malformed(self.levels_read(), 0, what));
            }
        }
        self.applied += 1;
        Ok(())
    }

    /// Applies the next vertex split; `Ok(false)` at the end of the sequence (or of the bytes).
    /// Hoppe's PMeshIter::next: it can fail on a corrupt stream, so this is no `Iterator`.
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> Result<bool> {
        match self.peek_record(true)? {
            Some(split) => self.apply(split).map(|_| true),
            None => Ok(false),
        }
    }

    /// Applies the splits left in the level being read, then every split of the next level;
    /// `Ok(false)` when no further complete level is present.
    pub fn next_level(&mut self) -> Result<bool> {
        while self.applied < self.records.len() {
            self.apply(self.records[self.applied])?;
        }
        let opened = match self.reader.as_mut() {
            Some(reader) => reader.open_level()?,
            None => return Ok(false),
        };
        if !opened {
            return Ok(false);
        }
        while let Some(split) = self.peek_record(false)? {
            self.apply(split)?;
        }
        Ok(true)
    }

    /// Takes the stream's next bytes as they arrive, for an iterator over bytes it holds: the
    /// levels they complete are read by the next [`PMeshIter::next_level`]. `Ok(false)` where its
    /// source cannot take them (an input stream, records in memory).
    pub(crate) fn extend(&mut self, more: &[u8]) -> Result<bool> {
        match self.reader.as_mut() {
            Some(reader) => reader.source.extend(more),
            None => Ok(false),
        }
    }

    /// Undoes the last vertex split; `false` at M⁰.
    pub fn prev(&mut self) -> bool {
        if self.applied == 0 {
            return false;
        }
        self.applied -= 1;
        let split = self.records[self.applied];
        self.mesh.ecol(&split);
        if let Some(w) = self.wedges.as_mut() {
            w.state.undo(&w.splits[self.applied]);
        }
        true
    }

    /// Moves to the mesh with `n` vertices (or as near as the sequence allows).
    pub fn goto_nvertices(&mut self, n: usize) -> Result<()> {
        while self.nvertices() < n && self.next()? {}
        while self.nvertices() > n && self.prev() {}
        Ok(())
    }

    /// Moves to the first mesh with at least `n` faces (or as near as the sequence allows).
    pub fn goto_nfaces(&mut self, n: usize) -> Result<()> {
        while self.nfaces() < n && self.next()? {}
        while self.nfaces() > n && self.prev() {}
        Ok(())
    }

    /// The current mesh with positions at cell centres; at Mⁿ of a mesh cut to a manifold, the
    /// mesh itself (copies welded, flipped faces turned back).
    pub fn level_mesh(&self) -> LevelMesh {
        let mesh = match self.restoration() {
            Some(r) => r.mesh(&self.mesh, &self.header.grid),
            None => to_trimesh(&self.mesh, &self.header.grid),
        };
        LevelMesh {
            mesh,
            loose_edges: Vec::new(),
            attributes: self.attributes(),
        }
    }

    /// At Mⁿ of a mesh cut to a manifold, how it turns back into the mesh.
    fn restoration(&self) -> Option<&super::repair::Restoration> {
        self.restoration
            .as_ref()
            .filter(|_| self.mesh.positions.len() as u64 == self.full_vertices)
    }

    /// The current mesh's appearance, when the stream carries one: its wedges welded from the
    /// corners' values.
    pub fn attributes(&self) -> Option<Attributes> {
        let (w, spec) = (self.wedges.as_ref()?, self.header.appearance.as_ref()?);
        let (corners, wedge_vertex, codes) = match self.restoration() {
            // Mⁿ of a mesh cut to a manifold: the wedges of the mesh itself.
            Some(r) => weld::weld_face_values(
                r.faces(&self.mesh).into_iter(),
                &r.corners(&w.state.corners),
                r.vertex_count(),
            ),
            None => weld::weld(&w.state, &self.mesh),
        };
        let cells = match self.restoration() {
            Some(r) => r.cells(),
            None => &self.mesh.positions,
        };
        Some(decoded_attributes(
            Welded {
                corners,
                wedge_vertex,
                codes,
            },
            &w.state,
            spec,
            cells,
            &self.header.grid,
        ))
    }

    /// The stream's header.
    pub fn header(&self) -> &Header {
        &self.header
    }
}

/// Welded corner codes: each corner's wedge, each wedge's vertex and code.
struct Welded {
    corners: Vec<[u32; 3]>,
    wedge_vertex: Vec<u32>,
    codes: Vec<CornerCode>,
}

/// The values of welded corner codes, with the state's face materials; when the stream's
/// normals are derived, the normals of the wedges' groups over the vertices at `cells`.
fn decoded_attributes(
    wedges: Welded,
    state: &WedgeState,
    spec: &AppearanceSpec,
    cells: &[[i32; 3]],
    grid: &Grid,
) -> Attributes {
    let Welded {
        corners,
        wedge_vertex,
        mut codes,
    } = wedges;
    if let (true, Some(bits)) = (spec.derived_normals, spec.normal_bits) {
        derive_normals(&corners, &wedge_vertex, &mut codes, cells, grid, bits);
    }
    let appearance = crate::codecs::appearance::Appearance {
        corners,
        wedge_vertex,
        codes,
        materials: state.materials.clone(),
    };
    crate::codecs::appearance::to_attributes(&appearance, spec)
}

/// Replaces the normal labels of `codes` by the normals derived over their groups: the corners
/// of one vertex with one label ([`crate::mesh::derived_normals`]).
fn derive_normals(
    corners: &[[u32; 3]],
    wedge_vertex: &[u32],
    codes: &mut [CornerCode],
    cells: &[[i32; 3]],
    grid: &Grid,
    bits: u8,
) {
    use crate::mesh::derived_normals::{group_normal_codes, groups_by_key};
    let faces: Vec<[u32; 3]> = corners
        .iter()
        .map(|c| c.map(|w| wedge_vertex[w as usize]))
        .collect();
    let labels = corners
        .iter()
        .map(|c| c.map(|w| wedges::label_of(codes[w as usize])));
    let (group, groups) = groups_by_key(&faces, labels);
    let cell = |v: u32| cells.get(v as usize).copied().unwrap_or_default();
    let normals = group_normal_codes(&faces, &group, groups, cell, grid.cell, bits);
    // A wedge's corners share its vertex and label, so any of them names its group.
    for (wedges, group) in corners.iter().zip(&group) {
        for (&w, &g) in wedges.iter().zip(group) {
            codes[w as usize].normal = Some(normals[g as usize]);
        }
    }
}

fn cell_centre(grid: &Grid, c: [i32; 3]) -> DVec3 {
    grid.dequantize(c.map(|x| x.max(0) as u32))
}

/// A PM mesh as a triangle mesh on its grid.
pub fn to_trimesh(mesh: &PmMesh, grid: &Grid) -> TriMesh {
    TriMesh::new(
        mesh.positions
            .iter()
            .map(|&c| cell_centre(grid, c))
            .collect(),
        mesh.triangles(),
    )
}

/// A smooth transition between a coarser mesh Mᶜ and a finer Mᶠ: Mᶠ's faces, each vertex moving
/// from its ancestor's position in Mᶜ (alpha 0) to its own (alpha 1), and, when the stream
/// carries appearance in its splits, each corner's values from its ancestor corner's in Mᶜ to
/// its own (Hoppe 1996 §5: wedge attributes morph with the positions).
pub struct Geomorph {
    /// Faces of Mᶠ.
    pub faces: Vec<[u32; 3]>,
    /// Positions at alpha = 0: each vertex at its ancestor in Mᶜ.
    pub coarse: Vec<DVec3>,
    /// Positions at alpha = 1.
    pub fine: Vec<DVec3>,
    /// The appearance at both ends, when the stream carries it in its splits.
    pub appearance: Option<AppearanceMorph>,
}

/// A geomorph's appearance: the wedges of Mᶠ, split where corners sharing a value in Mᶠ come
/// from different values in Mᶜ, with their values at alpha 0 and at alpha 1. Materials are
/// Mᶠ's at every alpha (an id does not blend).
pub struct AppearanceMorph {
    /// Values at alpha = 0: each corner's ancestor in Mᶜ.
    pub coarse: Attributes,
    /// Values at alpha = 1: Mᶠ's own.
    pub fine: Attributes,
}

impl Geomorph {
    /// Builds the geomorph from the iterator's current mesh (Mᶜ) to the mesh with `nvertices`
    /// vertices, leaving the iterator at Mᶠ (Hoppe's nextA with ancestry tracking).
    pub fn new(iter: &mut PMeshIter, nvertices: usize) -> Result<Geomorph> {
        let grid = iter.header.grid;
        let mut ancestor: Vec<[i32; 3]> = iter.mesh.positions.clone();
        // Each face's corners' values in Mᶜ: a face of Mᶜ keeps its own (a corner that moved
        // from vs to vt keeps its index), a face a split creates takes its neighbours'.
        let mut ancestor_values = iter.wedges.as_ref().map(|w| w.state.corners.clone());
        while iter.nvertices() < nvertices {
            let Some(split) = iter.peek_record(true)? else {
                break;
            };
            let face = iter
                .mesh
                .faces
                .get(split.flclw as usize)
                .ok_or_else(|| Error::malformed(iter.levels_read(), 0, "flclw out of range"))?;
            let vs = face.v[(split.vs_index as usize).min(2)];
            let created = iter.mesh.faces.len() as u32;
            iter.apply(split)?;
            ancestor.push(ancestor[vs as usize]);
            if let (Some(values), Some(w)) = (ancestor_values.as_mut(), iter.wedges.as_ref()) {
                for f in created..iter.mesh.faces.len() as u32 {
                    let own = w.state.corners[f as usize];
                    values.push(created_face_ancestors(&iter.mesh, values, f, created, own));
                }
            }
        }
        let appearance = match (ancestor_values, &iter.wedges, &iter.header.appearance) {
            (Some(coarse), Some(w), Some(spec)) => {
                let pairs: Vec<[(CornerCode, CornerCode); 3]> = w
                    .state
                    .corners
                    .iter()
                    .zip(&coarse)
                    .map(|(f, c)| std::array::from_fn(|k| (f[k], c[k])))
                    .collect();
                let (corners, wedge_vertex, codes) = weld::weld_values(&iter.mesh, &pairs);
                let end = |pick: fn(&(CornerCode, CornerCode)) -> CornerCode,
                           cells: &[[i32; 3]]| {
                    let wedges = Welded {
                        corners: corners.clone(),
                        wedge_vertex: wedge_vertex.clone(),
                        codes: codes.iter().map(pick).collect(),
                    };
                    decoded_attributes(wedges, &w.state, spec, cells, &grid)
                };
                // Derived normals at alpha 0 are those of Mᶠ's faces at the ancestors' places.
                Some(AppearanceMorph {
                    coarse: end(|p| p.1, &ancestor),
                    fine: end(|p| p.0, &iter.mesh.positions),
                })
            }
            _ => None,
        };
        Ok(Geomorph {
            faces: iter.mesh.triangles(),
            coarse: ancestor.iter().map(|&c| cell_centre(&grid, c)).collect(),
            fine: iter
                .mesh
                .positions
                .iter()
                .map(|&c| cell_centre(&grid, c))
                .collect(),
            appearance,
        })
    }

    /// The mesh at `alpha` in [0, 1].
    pub fn evaluate(&self, alpha: f64) -> TriMesh {
        TriMesh::new(
            self.coarse
                .iter()
                .zip(&self.fine)
                .map(|(c, f)| blend(*c, *f, alpha))
                .collect(),
            self.faces.clone(),
        )
    }

    /// The appearance at `alpha` in [0, 1], when the geomorph has one: uvs and colours blended
    /// linearly, normals blended and renormalized, materials Mᶠ's.
    pub fn evaluate_appearance(&self, alpha: f64) -> Option<Attributes> {
        let morph = self.appearance.as_ref()?;
        let mut out = morph.fine.clone();
        if let (Some(fine), Some(coarse)) = (out.uvs.as_mut(), &morph.coarse.uvs) {
            for (f, c) in fine.iter_mut().zip(coarse) {
                *f = *c * (1.0 - alpha) + *f * alpha;
            }
        }
        if let (Some(fine), Some(coarse)) = (out.normals.as_mut(), &morph.coarse.normals) {
            for (f, c) in fine.iter_mut().zip(coarse) {
                // Opposite normals blend to zero halfway; the fine one stands in there.
                *f = blend(*c, *f, alpha).try_normalize().unwrap_or(*f);
            }
        }
        if let (Some(fine), Some(coarse)) = (out.colours.as_mut(), &morph.coarse.colours) {
            for (f, c) in fine.iter_mut().zip(coarse) {
                for (x, y) in f.iter_mut().zip(c) {
                    *x = *y * (1.0 - alpha) + *x * alpha;
                }
            }
        }
        Some(out)
    }
}

/// Weighted sum, not c + (f − c)·alpha: exact at both ends.
fn blend(c: DVec3, f: DVec3, alpha: f64) -> DVec3 {
    c * (1.0 - alpha) + f * alpha
}

/// The Mᶜ values of the corners of face `f`, which the split that just applied created (its
/// faces start at `created`): each corner takes the ancestor value of the same vertex in a face
/// across one of its two edges, a face older than the split first (so that fr's vs corner
/// follows the face beyond vr rather than fl); `own` where no neighbour has one.
fn created_face_ancestors(
    mesh: &PmMesh,
    ancestors: &[[CornerCode; 3]],
    f: u32,
    created: u32,
    own: [CornerCode; 3],
) -> [CornerCode; 3] {
    let face = &mesh.faces[f as usize];
    std::array::from_fn(|k| {
        let across = [face.nei[k], face.nei[(k + 2) % 3]];
        let from = |limit: u32| {
            across.iter().find_map(|&g| {
                if g >= limit {
                    return None; // NIL included
                }
                let c = mesh.corner(g, face.v[k])?;
                Some(ancestors[g as usize][c])
            })
        };
        from(created).or_else(|| from(f)).unwrap_or(own[k])
    })
}
