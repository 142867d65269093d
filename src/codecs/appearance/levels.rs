//! Appearance refined with the levels (docs/FORMAT.md §10), for codecs whose levels keep their
//! vertices' ids and add new ones (`emc`, `emc-ahead`): each level's unit ends with an
//! appearance part that codes the values of the representatives the level gives a vertex of
//! their own ([`super::births`]), and, in the level whose faces are the full mesh's, which
//! wedge every corner takes and the values of the wedges no representative showed
//! ([`super::coder`], with the representatives' values known). Every level so shows the
//! appearance of the vertices it stands for, and from that level on the full appearance,
//! exactly.

use super::births::{Births, LevelView, RepValue, Seams};
use super::coder::{self, FirstValue, Symbols, Truth};
use super::traversal::Traversal;
use super::{spec_of, to_attributes, Appearance};
use crate::codecs::{LevelDecoder, LevelMesh};
use crate::coding::arith::{ArithEncoder, BitContext};
use crate::container::{AppearanceSpec, StreamReader};
use crate::error::{Error, Result};
use crate::mesh::attributes::Attributes;
use crate::mesh::canonical_attributes::{CanonicalAttributes, CornerCode};
use crate::mesh::{CanonicalMesh, TriMesh};
use std::collections::{BTreeMap, HashMap};

/// What the levels' appearance parts carry, and the encoder's estimate of their bits.
pub struct LevelParts {
    /// The appearance part of each level, in order (empty after the level that settles).
    pub parts: Vec<Vec<u8>>,
    /// The level (1-based) whose part codes the full appearance.
    pub settled_at: usize,
    /// Estimated bits per field, over every part.
    pub fields: BTreeMap<&'static str, f64>,
    /// Estimated bits of each level's part.
    pub level_bits: Vec<f64>,
}

/// A level's mesh, made the first time a part needs it.
struct LazyMesh<'m> {
    /// Makes it (`None` once it is made).
    make: Option<&'m dyn Fn() -> Result<LevelMesh>>,
    mesh: Option<LevelMesh>,
}

impl LazyMesh<'_> {
    /// A mesh already made.
    fn made(mesh: LevelMesh) -> LazyMesh<'static> {
        LazyMesh {
            make: None,
            mesh: Some(mesh),
        }
    }

    /// The mesh, which must have `vertices` vertices (one a representative).
    fn get(&mut self, vertices: usize) -> Result<&LevelMesh> {
        if let Some(make) = self.make.take() {
            let mesh = make()?;
            if mesh.mesh.positions.len() != vertices {
                return Err(Error::malformed(
                    0,
                    0,
                    "appearance: representatives and vertices disagree",
                ));
            }
            self.mesh = Some(mesh);
        }
        Ok(self.mesh.as_ref().expect("made above"))
    }
}

/// The state both sides keep between levels.
struct Progress {
    births: Births,
    /// Whether levels still code their births: once a level does not, no later level does.
    coding_births: bool,
    births_coded: BitContext,
    settled: BitContext,
    /// The full appearance, once a level's faces are final.
    full: Option<(Vec<[u32; 3]>, Appearance)>,
}

impl Progress {
    fn new(vertices: usize) -> Progress {
        Progress {
            births: Births::new(vertices),
            coding_births: true,
            births_coded: BitContext::default(),
            settled: BitContext::default(),
            full: None,
        }
    }

    /// Codes or reads the plan's uv precision, at the start of the first level's part (a
    /// count: 0 exactly, else the precision plus one).
    fn plan(&mut self, symbols: &mut impl Symbols, plan: Option<PartsPlan>) -> Result<()> {
        let mut context = crate::coding::arith::UintContext::default();
        let coded = plan
            .and_then(|p| p.uv_precision)
            .map_or(0, |p| p as u64 + 1);
        let precision = symbols.uint(&mut context, coded, "plan")?;
        if precision > 32 {
            return Err(Error::malformed(
                0,
                0,
                "appearance: uv precision past 31 bits",
            ));
        }
        self.births.uv_precision = precision.checked_sub(1).map(|p| p as u8);
        Ok(())
    }

    /// Codes or reads one level's part: the births of the representatives that `tokens` (per
    /// vertex of `level`) names and that have no values yet, then whether the level's faces
    /// are final and, if so, the full appearance. `truth`: the encoder's values.
    /// `level` gives the level's mesh, made only when the part needs it: to code births, to
    /// sketch uvs, or to settle.
    fn level(
        &mut self,
        symbols: &mut impl Symbols,
        level: &mut LazyMesh,
        tokens: &[u32],
        spec: &AppearanceSpec,
        truth: Option<(&EncoderTruth, bool, bool)>,
    ) -> Result<()> {
        let born: Vec<u32> = (0..tokens.len() as u32)
            .filter(|&v| {
                self.births
                    .values
                    .get(tokens[v as usize] as usize)
                    .is_some_and(Option::is_none)
            })
            .collect();
        if self.coding_births {
            self.coding_births = symbols.bit(
                &mut self.births_coded,
                truth.is_some_and(|(_, births, _)| births),
                "births_coded",
            )?;
        }
        let births_truth = truth.map(|(t, _, _)| (&t.reps[..], &t.seams[..]));
        // A sketch without uvs codes nothing: what a level shows of those representatives, it
        // works out when shown.
        if !born.is_empty() && (self.coding_births || spec.uv_grid.is_some()) {
            let level = level.get(tokens.len())?;
            let view = LevelView {
                positions: &level.mesh.positions,
                faces: &level.mesh.faces,
                loose_edges: &level.loose_edges,
            };
            let token = |v: u32| tokens[v as usize];
            if self.coding_births {
                self.births
                    .code(symbols, &view, &born, token, spec, births_truth)?;
            } else {
                self.births
                    .sketch(symbols, &view, &born, token, spec, births_truth)?;
            }
        }
        let settles = symbols.bit(
            &mut self.settled,
            truth.is_some_and(|(_, _, settles)| settles),
            "settled",
        )?;
        if settles {
            let level = level.get(tokens.len())?;
            let mut first = Vec::with_capacity(tokens.len());
            for &t in tokens {
                let value = self.births.values.get(t as usize).ok_or_else(|| {
                    Error::malformed(0, 0, "appearance: a vertex with no representative")
                })?;
                let mut known = coder::Known::new();
                if let Some(v) = value.filter(|v| !v.sketched) {
                    known.push(FirstValue {
                        code: v.code,
                        uv_low_bits: v.uv_low_bits,
                    });
                    known.extend(
                        self.births.seams[t as usize]
                            .iter()
                            .map(|&code| FirstValue {
                                code,
                                uv_low_bits: 0,
                            }),
                    );
                }
                first.push(known);
            }
            let truth = truth.map(|(t, _, _)| Truth {
                corners: &t.corners,
                materials: t.materials.as_deref(),
            });
            let full = coder::run(symbols, &level.mesh, spec, truth.as_ref(), Some(&first))?;
            self.full = Some((level.mesh.faces.clone(), full));
        }
        Ok(())
    }

    /// What `level` (whose vertices stand for `tokens`) shows: the full appearance once
    /// settled, else each vertex its representative's values, or those its neighbours
    /// predict where the representative's are not coded yet.
    fn shown(
        &self,
        level: &LevelMesh,
        tokens: &[u32],
        spec: &AppearanceSpec,
    ) -> Result<Attributes> {
        if let Some((faces, full)) = &self.full {
            if *faces != level.mesh.faces {
                return Err(Error::malformed(
                    0,
                    0,
                    "appearance: the faces changed after the level that settled them",
                ));
            }
            return Ok(to_attributes(full, spec));
        }
        let view = LevelView {
            positions: &level.mesh.positions,
            faces: &level.mesh.faces,
            loose_edges: &level.loose_edges,
        };
        let values = self.births.shown(&view, |v| tokens[v as usize], spec);
        let materials = spec.materials.as_ref().map(|_| {
            level
                .mesh
                .faces
                .iter()
                .map(|f| majority(f.map(|v| values[v as usize].material.unwrap_or(0))))
                .collect()
        });
        let seams: Vec<&[CornerCode]> = tokens
            .iter()
            .map(|&t| {
                self.births
                    .seams
                    .get(t as usize)
                    .map_or(&[][..], |s| &s[..])
            })
            .collect();
        let shown = super::charts::faces_in_charts(&view, &values, &seams, spec.uv_grid, materials);
        Ok(to_attributes(&shown, spec))
    }
}

/// The most common of three ids (the first of a tie).
fn majority([a, b, c]: [u32; 3]) -> u32 {
    if b == c {
        b
    } else {
        a
    }
}

/// The encoder's knowledge: each representative's values (by token), and the full mesh's
/// corners' values and materials in the decoder's face order.
struct EncoderTruth {
    reps: Vec<RepValue>,
    seams: Vec<Seams>,
    corners: Vec<[CornerCode; 3]>,
    materials: Option<Vec<u32>>,
}

/// Each vertex of `full` (the stream's full decode) as a vertex of `canonical`.
fn canonical_vertices(full: &TriMesh, canonical: &CanonicalMesh) -> Result<Vec<usize>> {
    let by_cell: HashMap<[u32; 3], usize> = canonical
        .cells
        .iter()
        .enumerate()
        .map(|(i, &c)| (c, i))
        .collect();
    full.positions
        .iter()
        .map(|&p| {
            by_cell
                .get(&canonical.grid.quantize(p))
                .copied()
                .ok_or_else(|| {
                    Error::Unsupported("the decoded geometry is not the canonical mesh".into())
                })
        })
        .collect()
}

/// What the encoder codes: every corner of `full`'s faces with its canonical values, and
/// each representative's — the first wedge the settling traversal meets at its vertex.
fn encoder_truth(
    full: &TriMesh,
    final_tokens: &[u32],
    canonical: &CanonicalMesh,
    appearance: &CanonicalAttributes,
) -> Result<EncoderTruth> {
    let vertex_of = canonical_vertices(full, canonical)?;
    // Canonical faces by their (rotated) vertex triple.
    let key = |f: [usize; 3]| {
        let r = (0..3).min_by_key(|&k| f[k]).expect("three corners");
        ([f[r], f[(r + 1) % 3], f[(r + 2) % 3]], r)
    };
    let mut face_of: HashMap<[usize; 3], (usize, usize)> = HashMap::new();
    for (f, face) in canonical.faces.iter().enumerate() {
        let (k, r) = key(face.map(|v| v as usize));
        face_of.insert(k, (f, r));
    }
    let mut corners = Vec::with_capacity(full.faces.len());
    let mut materials = appearance.materials.as_ref().map(|_| Vec::new());
    for face in &full.faces {
        let (k, r) = key(face.map(|v| vertex_of[v as usize]));
        let &(f, s) = face_of.get(&k).ok_or_else(|| {
            Error::Unsupported("the decoded geometry is not the canonical mesh".into())
        })?;
        let wedges = appearance.corners[f];
        corners.push(std::array::from_fn(|i| {
            appearance.code(wedges[(i + 3 - r + s) % 3])
        }));
        if let (Some(out), Some(m)) = (materials.as_mut(), &appearance.materials) {
            out.push(m.face[f]);
        }
    }
    let traversal = Traversal::new(full);
    let mut reps = vec![None; full.positions.len()];
    let mut seams = vec![Seams::new(); full.positions.len()];
    for &f in &traversal.order {
        let face = full.faces[f as usize];
        for (&v, &code) in face.iter().zip(&corners[f as usize]) {
            let token = final_tokens[v as usize] as usize;
            match &reps[token] {
                None => {
                    reps[token] = Some(RepValue {
                        code,
                        material: materials.as_ref().map(|m| m[f as usize]),
                        uv_low_bits: 0,
                        sketched: false,
                    })
                }
                Some(first) if first.code != code && !seams[token].contains(&code) => {
                    seams[token].push(code)
                }
                Some(_) => {}
            }
        }
    }
    // A vertex on no face shows nothing; its representative's values are zero.
    let reps = reps.into_iter().map(Option::unwrap_or_default).collect();
    Ok(EncoderTruth {
        reps,
        seams,
        corners,
        materials,
    })
}

/// The representatives a decoder's vertices stand for, which codecs that carry appearance
/// with their levels say.
fn tokens_of(decoder: &dyn LevelDecoder) -> Result<Vec<u32>> {
    decoder.representatives().ok_or_else(|| {
        Error::Unsupported("the codec does not say what its levels' vertices stand for".into())
    })
}

/// How the encoder spends the levels' appearance before the faces settle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PartsPlan {
    /// Levels (from the first) whose births are coded; the later ones sketch theirs until
    /// the level that settles.
    pub birth_levels: usize,
    /// A born uv is coded to this many bits below the spread of its neighbours' uvs, the rest
    /// in the level that settles; `None`: exactly.
    pub uv_precision: Option<u8>,
}

impl PartsPlan {
    /// The plan for a stream whose levels hold `vertices` (per level) of `total`: births
    /// coded while a level holds at most [`BIRTH_SHARE`] of the vertices.
    pub fn for_levels(vertices: &[usize], total: usize) -> PartsPlan {
        let birth_levels = vertices
            .iter()
            .take_while(|&&n| (n as f64) <= BIRTH_SHARE * total as f64)
            .count()
            .max(1);
        PartsPlan {
            birth_levels,
            uv_precision: Some(UV_PRECISION),
        }
    }
}

/// Births are coded in the levels that hold at most this share of the vertices, sketched in
/// the later ones (see [`PartsPlan`]). On spot.obj at 12 bits, 5% → 25% (levels 1–3 → 1–4)
/// costs 3.3% more and lowers the uv error of levels 5–8 from 65–69 to 26–32 texels; 60%
/// (1–5) 6.4% more again for 9–12 texels (docs/notes/benchmarks-history.md, "Appearance with the levels").
pub const BIRTH_SHARE: f64 = 0.25;

/// A born uv is coded to this many bits below its neighbours' spread ([`PartsPlan`]): on
/// spot.obj 0.6% smaller than exact births, the first levels' parts a third smaller.
pub const UV_PRECISION: u8 = 4;

/// The appearance parts of `stream` (a codec's stream without appearance, whose full decode
/// is `canonical`) carrying `appearance`, as `plan` says.
pub fn encode(
    stream: &[u8],
    canonical: &CanonicalMesh,
    appearance: &CanonicalAttributes,
    plan: PartsPlan,
) -> Result<LevelParts> {
    let spec = spec_of(appearance);
    // The full decode first: which vertex each final id is, and the faces that settle.
    let mut decoder = crate::codecs::open(stream)?;
    while decoder.advance()? {}
    let full = decoder.mesh()?;
    let final_tokens = tokens_of(decoder.as_ref())?;
    let truth = encoder_truth(&full.mesh, &final_tokens, canonical, appearance)?;
    let mut decoder = crate::codecs::open(stream)?;
    let mut progress = Progress::new(full.mesh.positions.len());
    let mut parts = Vec::new();
    let mut fields = BTreeMap::new();
    let mut level_bits = Vec::new();
    let mut settled_at = 0;
    while decoder.advance()? {
        if progress.full.is_some() {
            parts.push(Vec::new());
            level_bits.push(0.0);
            continue;
        }
        let level = decoder.mesh()?;
        let tokens = tokens_of(decoder.as_ref())?;
        let settles = tokens == final_tokens && level.mesh.faces == full.mesh.faces;
        let mut encoder = ArithEncoder::default();
        let births = parts.len() < plan.birth_levels;
        if parts.is_empty() {
            progress.plan(&mut encoder, Some(plan))?;
        }
        progress.level(
            &mut encoder,
            &mut LazyMesh::made(level),
            &tokens,
            &spec,
            Some((&truth, births, settles)),
        )?;
        for (field, bits) in &encoder.field_bits {
            *fields.entry(*field).or_default() += bits;
        }
        level_bits.push(encoder.field_bits.values().sum());
        let (bytes, _) = encoder.finish();
        parts.push(bytes);
        if settles {
            settled_at = parts.len();
        }
    }
    Ok(LevelParts {
        parts,
        settled_at,
        fields,
        level_bits,
    })
}

/// A codec's level decoder whose levels each carry an appearance part (docs/FORMAT.md §10):
/// after each level, its part is decoded, and every mesh carries what its level shows.
pub struct WithLevelParts<'a> {
    inner: Box<dyn LevelDecoder + 'a>,
    /// The stream again, for the parts (the codec's decoder reads the levels).
    parts: StreamReader<'a>,
    spec: AppearanceSpec,
    progress: Progress,
    /// Levels whose parts are decoded.
    decoded: usize,
    /// The mesh of the last level, when decoding its part needed it.
    last: Option<LevelMesh>,
}

impl<'a> WithLevelParts<'a> {
    /// Wraps `inner`, the codec's decoder of the stream `parts` reads too, which declares
    /// `spec`.
    pub fn new(
        inner: Box<dyn LevelDecoder + 'a>,
        parts: StreamReader<'a>,
        spec: AppearanceSpec,
    ) -> Self {
        let vertices = inner.header().vertices as usize;
        WithLevelParts {
            inner,
            parts,
            spec,
            progress: Progress::new(vertices),
            decoded: 0,
            last: None,
        }
    }

    /// Decodes the part of level `level` (from 0), whose mesh the codec has just decoded.
    fn decode_part(&mut self, level: usize) -> Result<()> {
        let Some(part) = self.parts.level_part(level) else {
            return Err(Error::Truncated(format!(
                "level {} arrived without its appearance part",
                level + 1
            )));
        };
        let (unit, start) = (part.index, part.start);
        let malformed = |e: Error| match e {
            Error::Malformed { what, .. } => Error::malformed(unit, start, what),
            e => e,
        };
        if self.progress.full.is_some() {
            if !part.bytes.is_empty() {
                return Err(Error::malformed(
                    unit,
                    start,
                    "an appearance part after the level that settled",
                ));
            }
            return Ok(());
        }
        let coder = crate::coding::arith::ArithDecoder::new(part.bytes).ok_or_else(|| {
            Error::malformed(unit, start, "appearance part is not whole 32-bit words")
        })?;
        let mut reader = coder::Reader { coder, unit, start };
        let tokens = tokens_of(self.inner.as_ref())?;
        if level == 0 {
            self.progress.plan(&mut reader, None).map_err(malformed)?;
        }
        let inner = &self.inner;
        let make = || inner.mesh();
        let mut mesh = LazyMesh {
            make: Some(&make),
            mesh: None,
        };
        self.progress
            .level(&mut reader, &mut mesh, &tokens, &self.spec, None)
            .map_err(malformed)?;
        self.last = mesh.mesh;
        Ok(())
    }
}

impl LevelDecoder for WithLevelParts<'_> {
    fn header(&self) -> &crate::container::Header {
        self.inner.header()
    }
    fn levels(&self) -> usize {
        self.inner.levels()
    }
    fn levels_decoded(&self) -> usize {
        self.inner.levels_decoded()
    }
    fn advance(&mut self) -> Result<bool> {
        let advanced = self.inner.advance()?;
        if advanced {
            self.last = None;
            self.decode_part(self.decoded)?;
            self.decoded += 1;
        }
        Ok(advanced)
    }
    fn mesh(&self) -> Result<LevelMesh> {
        // A stop inside a level (passes, a cut level) leaves the codec past the parts read.
        let mut mesh = match &self.last {
            Some(mesh) if self.inner.levels_decoded() == self.decoded => mesh.clone(),
            _ => self.inner.mesh()?,
        };
        let tokens = tokens_of(self.inner.as_ref())?;
        if tokens.len() != mesh.mesh.positions.len() {
            return Err(Error::malformed(
                0,
                0,
                "appearance: representatives and vertices disagree",
            ));
        }
        mesh.attributes = Some(self.progress.shown(&mesh, &tokens, &self.spec)?);
        Ok(mesh)
    }
    fn pass_stops(&mut self) -> Option<&mut dyn crate::codecs::PassStops> {
        self.last = None;
        self.inner.pass_stops()
    }
    fn partial_levels(&mut self) -> Option<&mut dyn crate::codecs::PartialLevels> {
        self.last = None;
        self.inner.partial_levels()
    }
    fn extend(&mut self, more: &[u8]) -> Result<bool> {
        if !self.inner.extend(more)? {
            return Ok(false);
        }
        self.parts.extend(more)?;
        Ok(true)
    }
    fn representatives(&self) -> Option<Vec<u32>> {
        self.inner.representatives()
    }
}
