//! The wedges of a progressive mesh, level by level: the base mesh's corners, and what each
//! vertex split changes (Hoppe 1998 §3's `corners`, wedge deltas and `matid` fields, with our
//! predictions), written once for both directions over [`Symbols`] (docs/FORMAT.md §6.3).
//!
//! Every mesh of the sequence carries a value (a [`CornerCode`]) at every face corner; wedges
//! are the distinct values at a vertex, as in the canonical mesh. A split of vs changes only the
//! corners at vs and vt and the corners of vl in fl and vr in fr; the decoder holds the coarse
//! values of vs's corners before the split and, for each changed corner, reads whether it takes
//! one of the values its vertex already shows (the coarse value carried over, the value its
//! neighbour across an edge took, another wedge of the vertex) or a new one. A new value is
//! predicted from the coarse wedge it refines — for uvs through the affine map that fits that
//! wedge's chart around vs in the coarse mesh (least squares over the tangent plane), applied
//! at the corner's new position — and its residual is arithmetic-coded in contexts by how far
//! the prediction moved it. Face materials of fl and fr are predicted from the faces across
//! their edges at vl and vr.
//!
//! When the stream's normals are derived from geometry (Hoppe 1998's Table 4 mode), a corner's
//! normal is not a value but a **label** naming its normal group among its vertex's: a new
//! value takes its chart's label, another label of the vertex, or a fresh one, and no normal is
//! coded; each level's normals are derived from its positions over the groups
//! ([`crate::mesh::derived_normals`]).

use crate::codecs::appearance::coder::Symbols;
use crate::codecs::appearance::predict::{face_normal, uv_by_fit, vertex_normal_by_angles};
use crate::codecs::stats::WedgeField;
use crate::coding::arith::{BitContext, IntContext, UintContext};
use crate::container::AppearanceSpec;
use crate::error::{Error, Result};
use crate::hierarchy::pmesh::{PmMesh, Vsplit, NIL};
use crate::mesh::attribute_quantization::{octahedral_code, octahedral_max};
use crate::mesh::canonical_attributes::CornerCode;
use glam::{DVec2, DVec3};
use std::collections::HashMap;

/// Context sets for a new value's residual, by how far its prediction moved from the coarse
/// value (log2 buckets of cells).
const SCALES: usize = 12;

/// The three kinds of changed corner: at vs in a face it keeps, at vt in a face that moved, in
/// the new faces fl and fr.
#[derive(Clone, Copy)]
enum Class {
    Survivor = 0,
    Moved = 1,
    New = 2,
}

/// Adaptive contexts of the wedge fields, kept across levels.
#[derive(Default)]
pub struct WedgeContexts {
    /// Takes the first / second candidate: [class][candidate].
    same: [[BitContext; 2]; 3],
    /// Takes one of the further candidates: [class].
    other: [BitContext; 3],
    other_index: UintContext,
    /// [class][scale][axis]
    uv: [[[IntContext; 2]; SCALES]; 3],
    /// [class][axis]
    normal: [[IntContext; 5]; 3],
    /// [class][channel]
    colour: [[IntContext; 4]; 3],
    material_same: [BitContext; 2],
    material: UintContext,
    base_known: BitContext,
    base_index: UintContext,
    base_uv: [IntContext; 2],
    base_normal: [IntContext; 5],
    base_colour: [IntContext; 4],
    labels: Labels,
}

impl WedgeContexts {
    /// The splits' contexts after the base mesh whose values are `base` (the encoder passes
    /// the base mesh's contexts too): fresh normal labels continue after the base mesh's, which
    /// are numbered from 0 in order.
    pub fn after_base(base: Option<&WedgeState>, coded_base: Option<WedgeContexts>) -> Self {
        let mut contexts = WedgeContexts::default();
        contexts.labels.next = base.map_or(0, |state| {
            state
                .corners
                .iter()
                .flatten()
                .map(|&c| label_of(c).saturating_add(1))
                .max()
                .unwrap_or(0)
        });
        if let Some(coded) = coded_base {
            contexts.labels.decoder_label = coded.labels.decoder_label;
        }
        contexts
    }
}

/// The normal labels of a stream whose normals are derived: the state's `normal` of a corner
/// holds [`label_code`] of its label.
#[derive(Default)]
struct Labels {
    /// The label the next fresh group takes.
    next: u32,
    /// The encoder's: the decoder's label of each of its own labels met so far.
    decoder_label: HashMap<u32, u32>,
    /// Takes the predicted label: [class], the base mesh's last.
    predicted: [BitContext; 4],
    /// Takes another label of the vertex rather than a fresh one: [class].
    other: [BitContext; 4],
    other_index: UintContext,
}

/// The class index of the base mesh's corners in [`Labels`]' contexts.
const BASE_CLASS: usize = 3;

/// What no label is: an encoder's label not met yet.
const UNMET: u32 = u32::MAX;

/// The `normal` field that holds normal label `label`.
pub fn label_code(label: u32) -> [u32; 2] {
    [label, 0]
}

/// The normal label a corner's value holds.
pub fn label_of(code: CornerCode) -> u32 {
    code.normal.unwrap_or_default()[0]
}

/// How a new value's normal label is chosen: the vertex's labels, the one predicted, the class
/// of corner, and (encoder) the encoder's own label.
struct LabelChoice<'a> {
    pool: &'a [u32],
    predicted: Option<u32>,
    class: usize,
    own: Option<u32>,
}

impl Labels {
    /// The encoder's value with its label turned into the decoder's ([`UNMET`] before it is
    /// coded), and its own label.
    fn translate(&self, value: CornerCode) -> (CornerCode, u32) {
        let own = label_of(value);
        let label = self.decoder_label.get(&own).copied().unwrap_or(UNMET);
        let mut out = value;
        out.normal = Some(label_code(label));
        (out, own)
    }

    /// Codes a new value's label: the predicted one, another of the vertex's, or a fresh one.
    fn code(
        &mut self,
        symbols: &mut impl Symbols,
        choice: &LabelChoice,
        target: u32,
    ) -> Result<u32> {
        let field = WedgeField::Corners.name();
        let predicted = choice.predicted.filter(|p| choice.pool.contains(p));
        if let Some(p) = predicted {
            if symbols.bit(&mut self.predicted[choice.class], target == p, field)? {
                return Ok(p);
            }
        }
        let others: Vec<u32> = choice
            .pool
            .iter()
            .copied()
            .filter(|&l| Some(l) != predicted)
            .collect();
        if !others.is_empty() {
            let index = others.iter().position(|&l| l == target);
            if symbols.bit(&mut self.other[choice.class], index.is_some(), field)? {
                let i = symbols.uint(&mut self.other_index, index.unwrap_or(0) as u64, field)?;
                return others
                    .get(i as usize)
                    .copied()
                    .ok_or_else(|| malformed("normal label beyond the vertex's"));
            }
        }
        if let Some(own) = choice.own {
            if self.decoder_label.contains_key(&own) {
                return Err(malformed("a normal group met before is not at its vertex"));
            }
            self.decoder_label.insert(own, self.next);
        }
        let label = self.next;
        self.next = self
            .next
            .checked_add(1)
            .filter(|&n| n != UNMET)
            .ok_or_else(|| malformed("more normal groups than labels"))?;
        Ok(label)
    }
}

/// The distinct normal labels of `values`, in order.
fn labels_of(values: impl IntoIterator<Item = CornerCode>) -> Vec<u32> {
    let mut out: Vec<u32> = Vec::new();
    for v in values {
        let l = label_of(v);
        if !out.contains(&l) {
            out.push(l);
        }
    }
    out
}

/// The corner values and face materials of the current mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WedgeState {
    /// Values of each face's corners.
    pub corners: Vec<[CornerCode; 3]>,
    /// Material of each face, when faces carry materials.
    pub materials: Option<Vec<u32>>,
}

/// What one split changed, so that the split can be undone and redone without decoding again.
#[derive(Clone, Debug)]
pub struct SplitWedges {
    /// Faces that existed before the split: values before and after.
    changed: Vec<(u32, [CornerCode; 3], [CornerCode; 3])>,
    /// Values and material of fl (and fr).
    created: Vec<([CornerCode; 3], u32)>,
}

impl WedgeState {
    /// Redoes a split's changes on the mesh it was decoded on (the split itself just applied).
    pub fn redo(&mut self, s: &SplitWedges) {
        for &(f, _, after) in &s.changed {
            self.corners[f as usize] = after;
        }
        for &(codes, material) in &s.created {
            self.corners.push(codes);
            if let Some(m) = self.materials.as_mut() {
                m.push(material);
            }
        }
    }

    /// Undoes a split's changes (the split itself undone too).
    pub fn undo(&mut self, s: &SplitWedges) {
        for _ in &s.created {
            self.corners.pop();
            if let Some(m) = self.materials.as_mut() {
                m.pop();
            }
        }
        for &(f, before, _) in &s.changed {
            self.corners[f as usize] = before;
        }
    }
}

/// The split's neighbourhood before it applies: vs and its faces as they were.
pub struct Coarse {
    vs: u32,
    faces: Vec<CoarseFace>,
}

/// One face of vs before the split.
struct CoarseFace {
    face: u32,
    codes: [CornerCode; 3],
    vs_corner: usize,
    vertices: [u32; 3],
    positions: [[i32; 3]; 3],
}

/// What the decoder knows of vs before `split` applies to `mesh`; `None` if the record does not
/// locate (the split will fail on it too).
pub fn coarse(mesh: &PmMesh, state: &WedgeState, split: &Vsplit) -> Option<Coarse> {
    let face = mesh.faces.get(split.flclw as usize)?;
    let vs = *face.v.get(split.vs_index as usize)?;
    let faces = mesh
        .fan(split.flclw, vs)
        .into_iter()
        .map(|f| {
            let vertices = mesh.faces[f as usize].v;
            CoarseFace {
                face: f,
                codes: state.corners[f as usize],
                vs_corner: mesh.corner(f, vs).expect("a face of vs's fan"),
                vertices,
                positions: vertices.map(|v| mesh.positions[v as usize]),
            }
        })
        .collect();
    Some(Coarse { vs, faces })
}

/// The truth of one split for the encoder: every face at vs and vt after it, with its values
/// and material.
pub type SplitTruth = Vec<(u32, [CornerCode; 3], u32)>;

fn point(c: [i32; 3]) -> DVec3 {
    DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64)
}

fn malformed(what: &str) -> Error {
    Error::malformed(0, 0, format!("vsplit wedges: {what}"))
}

/// One corner's coding: its candidates (distinct values, likeliest first), and the coarse
/// value and chart a new value is predicted from.
struct Corner<'a> {
    class: Class,
    candidates: Vec<CornerCode>,
    chart: Option<CornerCode>,
    at: [i32; 3],
    coarse: &'a Coarse,
    /// The normal labels of the corner's vertex, when normals are derived.
    labels: Vec<u32>,
    /// Whether the encoder runs (its values are true).
    encoding: bool,
    /// The mesh after the split, the corner's vertex and one of its faces: what predicts a new
    /// normal when normals are predicted from geometry ([`Corner::geometric_normal`]).
    mesh: &'a PmMesh,
    vertex: u32,
    face: u32,
}

impl Corner<'_> {
    /// The angle-weighted normal of the corner's vertex's faces after the split (zero when they
    /// have no area); computed only for a new value, which is when it predicts.
    fn geometric_normal(&self) -> DVec3 {
        let mesh = self.mesh;
        vertex_normal_by_angles(
            mesh.fan(self.face, self.vertex)
                .into_iter()
                .filter_map(|g| {
                    let face = mesh.faces[g as usize].v;
                    let k = face.iter().position(|&v| v == self.vertex)?;
                    Some([0, 1, 2].map(|i| point(mesh.positions[face[(k + i) % 3] as usize])))
                }),
        )
    }
}

/// Codes the wedges of the split that just applied to `mesh` (whose state before it `coarse`
/// describes), updating `state`; the encoder passes `truth`. On an error `state` is left as
/// it was before the split.
pub fn code_split(
    symbols: &mut impl Symbols,
    contexts: &mut WedgeContexts,
    mesh: &PmMesh,
    state: &mut WedgeState,
    coarse: &Coarse,
    spec: &AppearanceSpec,
    truth: Option<&SplitTruth>,
) -> Result<SplitWedges> {
    let faces = state.corners.len();
    let coded = code_split_fields(symbols, contexts, mesh, state, coarse, spec, truth);
    if coded.is_err() {
        state.corners.truncate(faces);
        if let Some(m) = state.materials.as_mut() {
            m.truncate(faces);
        }
        for c in &coarse.faces {
            state.corners[c.face as usize] = c.codes;
        }
    }
    coded
}

fn code_split_fields(
    symbols: &mut impl Symbols,
    contexts: &mut WedgeContexts,
    mesh: &PmMesh,
    state: &mut WedgeState,
    coarse: &Coarse,
    spec: &AppearanceSpec,
    truth: Option<&SplitTruth>,
) -> Result<SplitWedges> {
    let vs = coarse.vs;
    let vt = mesh.positions.len() as u32 - 1;
    let last = mesh.faces.len() as u32 - 1;
    let (fl, fr) = if mesh.faces[last as usize].v[1] == vt {
        (last - 1, last)
    } else {
        (last, NIL)
    };
    let created = if fr == NIL { 1 } else { 2 };
    let truth_of = |f: u32| -> ([CornerCode; 3], u32) {
        truth
            .and_then(|t| t.iter().find(|x| x.0 == f))
            .map_or(([CornerCode::default(); 3], 0), |x| (x.1, x.2))
    };
    let coarse_of = |f: u32| coarse.faces.iter().find(|x| x.face == f);
    for _ in 0..created {
        state.corners.push([CornerCode::default(); 3]);
        if let Some(m) = state.materials.as_mut() {
            m.push(0);
        }
    }
    // Values decoded at vs and vt so far, and what each coarse value became there.
    let mut known_s: Vec<CornerCode> = Vec::new();
    let mut known_t: Vec<CornerCode> = Vec::new();
    let mut map_s: Vec<(CornerCode, CornerCode)> = Vec::new();
    let mut map_t: Vec<(CornerCode, CornerCode)> = Vec::new();
    let corner_of = |f: u32, v: u32| mesh.corner(f, v).expect("a corner of the face");
    let value_at = |state: &WedgeState, f: u32, v: u32| -> Option<CornerCode> {
        if f == NIL {
            return None;
        }
        mesh.corner(f, v).map(|k| state.corners[f as usize][k])
    };
    let push_distinct = |list: &mut Vec<CornerCode>, c: CornerCode| {
        if !list.contains(&c) {
            list.push(c);
        }
    };
    let candidates_of = |first: &[Option<CornerCode>], rest: &[CornerCode]| {
        let mut out: Vec<CornerCode> = Vec::new();
        for c in first.iter().flatten().chain(rest) {
            if !out.contains(c) {
                out.push(*c);
            }
        }
        out
    };
    let derived = spec.derived_normals;
    let encoding = truth.is_some();
    // With derived normals: the labels vs had, to which a split adds fresh ones only.
    let coarse_labels = if derived {
        labels_of(coarse.faces.iter().map(|c| c.codes[c.vs_corner]))
    } else {
        Vec::new()
    };
    let pool_with = |known: &[CornerCode]| -> Vec<u32> {
        if !derived {
            return Vec::new();
        }
        let mut pool = coarse_labels.clone();
        for l in labels_of(known.iter().copied()) {
            if !pool.contains(&l) {
                pool.push(l);
            }
        }
        pool
    };
    // Faces vs keeps, then faces that moved to vt.
    let fan_s: Vec<u32> = mesh.fan(fl, vs);
    let fan_t: Vec<u32> = mesh.fan(fl, vt);
    for (v, fan) in [(vs, &fan_s), (vt, &fan_t)] {
        for &g in fan.iter().filter(|&&g| g != fl && g != fr) {
            let k = corner_of(g, v);
            let c = coarse_of(g)
                .ok_or_else(|| malformed("a face of the split was not vs's"))?
                .codes[k];
            let (known, map) = if v == vs {
                (&mut known_s, &mut map_s)
            } else {
                (&mut known_t, &mut map_t)
            };
            let mapped = map.iter().find(|x| x.0 == c).map(|x| x.1);
            let first = if v == vs { mapped.or(Some(c)) } else { mapped };
            let corner = Corner {
                class: if v == vs {
                    Class::Survivor
                } else {
                    Class::Moved
                },
                candidates: candidates_of(&[first], known),
                chart: Some(c),
                at: mesh.positions[v as usize],
                coarse,
                labels: pool_with(known),
                encoding,
                mesh,
                vertex: v,
                face: fl,
            };
            let value = code_corner(symbols, contexts, spec, &corner, truth_of(g).0[k])?;
            if !map.iter().any(|x| x.0 == c) {
                map.push((c, value));
            }
            push_distinct(known, value);
            state.corners[g as usize][k] = value;
        }
    }
    // fl = (vs, vl, vt), fr = (vs, vt, vr): neighbours x across (vs, vl), f0 across (vl, vt);
    // fk across (vt, vr), y across (vr, vs).
    for f in [fl, fr] {
        if f == NIL {
            continue;
        }
        let face = mesh.faces[f as usize];
        let (beside_s, beside_t, other) = if f == fl {
            (face.nei[0], face.nei[1], face.v[1])
        } else {
            (face.nei[2], face.nei[1], face.v[2])
        };
        let chart = |g: u32| coarse_of(g).map(|c| c.codes[c.vs_corner]);
        let fallback = coarse.faces.first().map(|c| c.codes[c.vs_corner]);
        let chart_s = (beside_s != NIL)
            .then(|| chart(beside_s))
            .flatten()
            .or(fallback);
        let chart_t = (beside_t != NIL)
            .then(|| chart(beside_t))
            .flatten()
            .or(chart_s);
        let (truth_codes, truth_material) = truth_of(f);
        if let Some(materials) = state.materials.as_mut() {
            let around = [beside_s, beside_t].map(|g| (g != NIL).then(|| materials[g as usize]));
            let names = spec.materials.as_ref().map_or(0, |m| m.names.len());
            materials[f as usize] =
                code_material(symbols, contexts, &around, truth_material, names)?;
        }
        // A new value at vs or vt in fl / fr starts a wedge across a seam from the neighbour
        // beside it: it continues the chart on the other side (vs: the moved faces', vt: the
        // kept faces'). At vl / vr it is predicted from that vertex's value beside it.
        for (v, seam_chart) in [(vs, Some(chart_t)), (vt, Some(chart_s)), (other, None)] {
            let k = corner_of(f, v);
            let neighbour_s = value_at(state, beside_s, v);
            let neighbour_t = value_at(state, beside_t, v);
            let class_chart = seam_chart.unwrap_or_else(|| neighbour_s.or(neighbour_t).or(chart_s));
            let across = if f == fl {
                value_at(state, fr, v)
            } else {
                value_at(state, fl, v)
            };
            let rest: &[CornerCode] = if v == vs {
                &known_s
            } else if v == vt {
                &known_t
            } else {
                &[]
            };
            let first = if v == vt {
                [neighbour_t, neighbour_s, across]
            } else {
                [neighbour_s, neighbour_t, across]
            };
            let labels = if !derived {
                Vec::new()
            } else if v == other {
                // vl's (vr's) labels: those of its faces before the split.
                labels_of(
                    mesh.fan(f, v)
                        .into_iter()
                        .filter(|&g| g != fl && g != fr)
                        .filter_map(|g| value_at(state, g, v)),
                )
            } else {
                pool_with(rest)
            };
            let corner = Corner {
                class: Class::New,
                candidates: candidates_of(&first, rest),
                chart: class_chart,
                at: mesh.positions[v as usize],
                coarse,
                labels,
                encoding,
                mesh,
                vertex: v,
                face: if v == other { f } else { fl },
            };
            let value = code_corner(symbols, contexts, spec, &corner, truth_codes[k])?;
            state.corners[f as usize][k] = value;
            if v == vs {
                push_distinct(&mut known_s, value);
            } else if v == vt {
                push_distinct(&mut known_t, value);
            }
        }
    }
    let changed = coarse
        .faces
        .iter()
        .map(|c| (c.face, c.codes, state.corners[c.face as usize]))
        .collect();
    let created = (0..created)
        .map(|i| {
            let f = fl as usize + i;
            (
                state.corners[f],
                state.materials.as_ref().map_or(0, |m| m[f]),
            )
        })
        .collect();
    Ok(SplitWedges { changed, created })
}

fn code_material(
    symbols: &mut impl Symbols,
    contexts: &mut WedgeContexts,
    around: &[Option<u32>; 2],
    value: u32,
    names: usize,
) -> Result<u32> {
    let mut tried: Vec<u32> = Vec::new();
    for (i, m) in around.iter().flatten().enumerate() {
        if tried.contains(m) {
            continue;
        }
        tried.push(*m);
        if symbols.bit(
            &mut contexts.material_same[i],
            value == *m,
            WedgeField::Material.name(),
        )? {
            return Ok(*m);
        }
    }
    let id = symbols.uint(
        &mut contexts.material,
        value as u64,
        WedgeField::Material.name(),
    )?;
    if id >= names as u64 {
        return Err(malformed("material id beyond the names"));
    }
    Ok(id as u32)
}

/// Codes one corner's value: one of its candidates, or a new value predicted from its chart.
fn code_corner(
    symbols: &mut impl Symbols,
    contexts: &mut WedgeContexts,
    spec: &AppearanceSpec,
    corner: &Corner,
    value: CornerCode,
) -> Result<CornerCode> {
    let class = corner.class as usize;
    let candidates = &corner.candidates;
    // The encoder's labels become the decoder's before values are compared.
    let (value, own) = if spec.derived_normals && corner.encoding {
        let (value, own) = contexts.labels.translate(value);
        (value, Some(own))
    } else {
        (value, None)
    };
    for (i, &c) in candidates.iter().take(2).enumerate() {
        if symbols.bit(
            &mut contexts.same[class][i],
            value == c,
            WedgeField::Corners.name(),
        )? {
            return Ok(c);
        }
    }
    if candidates.len() > 2 {
        let rest = &candidates[2..];
        let index = rest.iter().position(|&c| c == value);
        if symbols.bit(
            &mut contexts.other[class],
            index.is_some(),
            WedgeField::Corners.name(),
        )? {
            let i = symbols.uint(
                &mut contexts.other_index,
                index.unwrap_or(0) as u64,
                WedgeField::Corners.name(),
            )?;
            return rest
                .get(i as usize)
                .copied()
                .ok_or_else(|| malformed("wedge index beyond the vertex's wedges"));
        }
    }
    let chart = corner.chart.unwrap_or_default();
    // A uv is predicted through the chart's fit; its contexts follow how far that moved it.
    let mut predicted = chart;
    let mut scale = 0;
    if let (Some(grid), Some(c)) = (spec.uv_grid, corner.chart) {
        let from = chart.uv.unwrap_or_default();
        let last = ((1u64 << grid.bits) - 1) as f64;
        let fitted = predict_uv(corner.coarse, c, corner.at).map_or(from, |t| {
            [t.x, t.y].map(|x| {
                if x.is_finite() {
                    x.round().clamp(0.0, last) as u32
                } else {
                    0
                }
            })
        });
        let moved = (0..2)
            .map(|a| fitted[a].abs_diff(from[a]))
            .max()
            .unwrap_or(0);
        scale = ((32 - moved.leading_zeros()) as usize).min(SCALES - 1);
        predicted.uv = Some(fitted);
    }
    // A normal is predicted by its vertex's faces, when the stream says so and they have area.
    if let (Some(bits), true) = (spec.normal_bits, spec.geometric_normals) {
        let n = corner.geometric_normal();
        if n != DVec3::ZERO {
            predicted.normal = Some(octahedral_code(n, bits));
        }
    }
    let residuals = Residuals {
        normal: &mut contexts.normal[class],
        uv: &mut contexts.uv[class][scale],
        colour: &mut contexts.colour[class],
        labels: &mut contexts.labels,
    };
    let choice = LabelChoice {
        pool: &corner.labels,
        predicted: corner.chart.map(label_of),
        class,
        own,
    };
    code_value(symbols, residuals, spec, predicted, value, &choice)
}

/// The contexts of one value's residuals.
struct Residuals<'a> {
    normal: &'a mut [IntContext; 5],
    uv: &'a mut [IntContext; 2],
    colour: &'a mut [IntContext; 4],
    labels: &'a mut Labels,
}

/// Codes `value` as its residuals from `predicted`, field by field as `spec` declares.
fn code_value(
    symbols: &mut impl Symbols,
    contexts: Residuals,
    spec: &AppearanceSpec,
    predicted: CornerCode,
    value: CornerCode,
    choice: &LabelChoice,
) -> Result<CornerCode> {
    let mut out = CornerCode::default();
    if spec.normal_bits.is_some() && spec.derived_normals {
        let label = contexts.labels.code(symbols, choice, label_of(value))?;
        out.normal = Some(label_code(label));
    } else if let Some(bits) = spec.normal_bits {
        let (p, t) = (
            predicted.normal.unwrap_or_default(),
            value.normal.unwrap_or_default(),
        );
        let max = octahedral_max(bits) as i64;
        let mut n = [0u32; 2];
        let mut first = 0i64;
        // Predicted from geometry: the second residual's contexts by the first's size, and the
        // value taken across an edge of the octahedral square when nearer the prediction there.
        let geometric = spec.geometric_normals;
        let truth = [t[0] as i64, t[1] as i64];
        let target = if geometric {
            nearest_image(truth, [p[0] as i64, p[1] as i64], max)
        } else {
            truth
        };
        let mut q = [0i64; 2];
        for axis in 0..2 {
            let c = if axis == 1 && geometric {
                1 + match first.unsigned_abs() {
                    0 => 0,
                    1 => 1,
                    2..=3 => 2,
                    _ => 3,
                }
            } else {
                axis
            };
            let d = symbols.int(
                &mut contexts.normal[c],
                target[axis] - p[axis] as i64,
                WedgeField::Normal.name(),
            )?;
            first = d;
            q[axis] = (p[axis] as i64).saturating_add(d);
        }
        if geometric {
            q = fold_into_square(q, max);
        }
        for axis in 0..2 {
            n[axis] = within(q[axis], max + 1, "normal")?;
        }
        out.normal = Some(n);
    }
    if let Some(grid) = spec.uv_grid {
        let (p, t) = (
            predicted.uv.unwrap_or_default(),
            value.uv.unwrap_or_default(),
        );
        let mut uv = [0u32; 2];
        for axis in 0..2 {
            let d = symbols.int(
                &mut contexts.uv[axis],
                t[axis] as i64 - p[axis] as i64,
                WedgeField::Uv.name(),
            )?;
            uv[axis] = within(p[axis] as i64 + d, 1i64 << grid.bits, "uv")?;
        }
        out.uv = Some(uv);
    }
    if spec.colours {
        let (p, t) = (
            predicted.colour.unwrap_or_default(),
            value.colour.unwrap_or_default(),
        );
        let mut rgba = [0u8; 4];
        for channel in 0..4 {
            let d = symbols.int(
                &mut contexts.colour[channel],
                t[channel].wrapping_sub(p[channel]) as i8 as i64,
                WedgeField::Colour.name(),
            )?;
            if !(-128..=127).contains(&d) {
                return Err(malformed("colour residual out of range"));
            }
            rgba[channel] = p[channel].wrapping_add(d as i8 as u8);
        }
        out.colour = Some(rgba);
    }
    Ok(out)
}

/// Of octahedral code `t` (in 0..=`max` on both coordinates) and its mirror images across the
/// square's four edges, the nearest to `p` (L1). The square continues across each edge into its
/// mirror image: (u, v) beyond u = max is (2 max − u, max − v), and likewise at the other edges.
/// Only images strictly outside the square count, so that [`fold_into_square`] undoes the choice.
fn nearest_image(t: [i64; 2], p: [i64; 2], max: i64) -> [i64; 2] {
    let [u, v] = t;
    let images = [
        (u < max).then_some([2 * max - u, max - v]),
        (u > 0).then_some([-u, max - v]),
        (v < max).then_some([max - u, 2 * max - v]),
        (v > 0).then_some([max - u, -v]),
    ];
    let cost = |q: [i64; 2]| (q[0] - p[0]).abs() + (q[1] - p[1]).abs();
    images
        .into_iter()
        .flatten()
        .fold(t, |best, q| if cost(q) < cost(best) { q } else { best })
}

/// The code inside the square that a point outside it in one coordinate mirrors (a point inside
/// is itself; one outside in both, which no encoder writes, is left for the range check).
fn fold_into_square(q: [i64; 2], max: i64) -> [i64; 2] {
    let mirror = |x: i64, to: i64| to.saturating_sub(x);
    if q[0] > max {
        [mirror(q[0], 2 * max), mirror(q[1], max)]
    } else if q[0] < 0 {
        [mirror(q[0], 0), mirror(q[1], max)]
    } else if q[1] > max {
        [mirror(q[0], max), mirror(q[1], 2 * max)]
    } else if q[1] < 0 {
        [mirror(q[0], max), mirror(q[1], 0)]
    } else {
        q
    }
}

/// The uv at `at` by the affine map that fits the coarse chart of `chart` around vs: the
/// corners of vs's coarse faces whose vs corner has that value.
fn predict_uv(coarse: &Coarse, chart: CornerCode, at: [i32; 3]) -> Option<DVec2> {
    let mut pairs: Vec<(DVec3, DVec2)> = Vec::with_capacity(2 * coarse.faces.len() + 1);
    let mut seen: Vec<u32> = Vec::with_capacity(pairs.capacity());
    let mut normal = DVec3::ZERO;
    for c in coarse
        .faces
        .iter()
        .filter(|c| c.codes[c.vs_corner] == chart)
    {
        let p = c.positions.map(point);
        normal += face_normal(p[0], p[1], p[2]);
        for ((&v, code), &at) in c.vertices.iter().zip(&c.codes).zip(&p) {
            if seen.contains(&v) {
                continue;
            }
            if let Some(t) = code.uv {
                seen.push(v);
                pairs.push((at, DVec2::new(t[0] as f64, t[1] as f64)));
            }
        }
    }
    uv_by_fit(point(at), normal, &pairs)
}

/// `value` when it lies in 0..`limit`; a malformed record otherwise.
fn within(value: i64, limit: i64, what: &str) -> Result<u32> {
    if value < 0 || value >= limit {
        return Err(malformed(&format!("{what} value {value} outside the grid")));
    }
    Ok(value as u32)
}

/// Codes the base mesh's corner values and materials (the encoder passes `truth`).
pub fn code_base(
    symbols: &mut impl Symbols,
    contexts: &mut WedgeContexts,
    mesh: &PmMesh,
    spec: &AppearanceSpec,
    truth: Option<&WedgeState>,
) -> Result<WedgeState> {
    let mut state = WedgeState {
        corners: Vec::with_capacity(mesh.faces.len()),
        materials: spec
            .materials
            .as_ref()
            .map(|_| Vec::with_capacity(mesh.faces.len())),
    };
    let mut known: Vec<Vec<CornerCode>> = vec![Vec::new(); mesh.positions.len()];
    let mut previous = CornerCode::default();
    let mut previous_material = None;
    for (f, face) in mesh.faces.iter().enumerate() {
        if let Some(materials) = state.materials.as_mut() {
            let value = truth.and_then(|t| t.materials.as_ref()).map_or(0, |m| m[f]);
            let names = spec.materials.as_ref().map_or(0, |m| m.names.len());
            let id = code_material(symbols, contexts, &[previous_material, None], value, names)?;
            materials.push(id);
            previous_material = Some(id);
        }
        let mut codes = [CornerCode::default(); 3];
        for (k, slot) in codes.iter_mut().enumerate() {
            let v = face.v[k] as usize;
            let value = truth.map_or(CornerCode::default(), |t| t.corners[f][k]);
            let (value, own) = match truth {
                Some(_) if spec.derived_normals => {
                    let (value, own) = contexts.labels.translate(value);
                    (value, Some(own))
                }
                _ => (value, None),
            };
            let index = known[v].iter().position(|&c| c == value);
            let code = if !known[v].is_empty()
                && symbols.bit(
                    &mut contexts.base_known,
                    index.is_some(),
                    WedgeField::Corners.name(),
                )? {
                let i = symbols.uint(
                    &mut contexts.base_index,
                    index.unwrap_or(0) as u64,
                    WedgeField::Corners.name(),
                )?;
                *known[v]
                    .get(i as usize)
                    .ok_or_else(|| malformed("base wedge index beyond the vertex's wedges"))?
            } else {
                let residuals = Residuals {
                    normal: &mut contexts.base_normal,
                    uv: &mut contexts.base_uv,
                    colour: &mut contexts.base_colour,
                    labels: &mut contexts.labels,
                };
                let pool = if spec.derived_normals {
                    labels_of(known[v].iter().copied())
                } else {
                    Vec::new()
                };
                let choice = LabelChoice {
                    pool: &pool,
                    predicted: None,
                    class: BASE_CLASS,
                    own,
                };
                let code = code_value(symbols, residuals, spec, previous, value, &choice)?;
                known[v].push(code);
                previous = code;
                code
            };
            *slot = code;
        }
        state.corners.push(codes);
    }
    Ok(state)
}

#[cfg(test)]
mod tests {
    use super::{fold_into_square, nearest_image};

    #[test]
    fn a_code_taken_across_the_octahedral_square_s_edge_folds_back_to_itself() {
        for max in [6i64, 254, 1022] {
            for u in 0..=max {
                for v in [0, 1, max / 2, max - 1, max] {
                    for p in [[0, 0], [max, 3], [2, max], [max / 2, max / 2], [max, max]] {
                        let image = nearest_image([u, v], p, max);
                        assert_eq!(fold_into_square(image, max), [u, v], "{u} {v} {p:?}");
                    }
                }
            }
        }
        // Near the right edge on the other side of the fold, the image is the nearer.
        assert_eq!(nearest_image([1021, 900], [1022, 120], 1022), [1023, 122]);
    }
}
