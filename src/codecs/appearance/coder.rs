//! The appearance unit's syntax, written once for both directions (docs/FORMAT.md §9): the
//! encoder passes the true value of every decision, the decoder reads it, and both then update
//! the same state.

use super::predict::{face_normal, uv_by_fit, uv_by_unfolding, uv_from_triangle, winding};
use super::traversal::Traversal;
use crate::codecs::appearance::Appearance;
use crate::coding::arith::{ArithDecoder, ArithEncoder, BitContext, IntContext, UintContext};
use crate::coding::SyntaxClass;
use crate::container::AppearanceSpec;
use crate::error::{Error, Result};
use crate::mesh::attribute_quantization::{octahedral_code, octahedral_max};
use crate::mesh::canonical_attributes::CornerCode;
use crate::mesh::TriMesh;
use glam::{DVec2, DVec3};

/// One decision at a time, both ways.
pub trait Symbols {
    /// Codes or reads a bit; `value` is the encoder's (the decoder ignores it).
    fn bit(&mut self, context: &mut BitContext, value: bool, field: &'static str) -> Result<bool>;
    /// Codes or reads an unsigned integer.
    fn uint(&mut self, context: &mut UintContext, value: u64, field: &'static str) -> Result<u64>;
    /// Codes or reads a signed integer.
    fn int(&mut self, context: &mut IntContext, value: i64, field: &'static str) -> Result<i64>;
}

impl Symbols for ArithEncoder {
    fn bit(&mut self, context: &mut BitContext, value: bool, field: &'static str) -> Result<bool> {
        ArithEncoder::bit(self, context, value, SyntaxClass::Geometry, field);
        Ok(value)
    }
    fn uint(&mut self, context: &mut UintContext, value: u64, field: &'static str) -> Result<u64> {
        ArithEncoder::uint(self, context, value, SyntaxClass::Geometry, field);
        Ok(value)
    }
    fn int(&mut self, context: &mut IntContext, value: i64, field: &'static str) -> Result<i64> {
        ArithEncoder::int(self, context, value, SyntaxClass::Geometry, field);
        Ok(value)
    }
}

/// The decoder's side: an arithmetic decoder and where its unit starts, for errors.
pub struct Reader {
    /// The range decoder over the unit.
    pub coder: ArithDecoder,
    /// The unit's number and first byte in the stream.
    pub unit: usize,
    /// First byte of the unit.
    pub start: usize,
}

impl Reader {
    fn ended(&self) -> Error {
        Error::malformed(
            self.unit,
            self.start,
            "appearance unit ends before its last wedge",
        )
    }
}

impl Symbols for Reader {
    fn bit(&mut self, context: &mut BitContext, _: bool, _: &'static str) -> Result<bool> {
        self.coder.bit(context).ok_or_else(|| self.ended())
    }
    fn uint(&mut self, context: &mut UintContext, _: u64, _: &'static str) -> Result<u64> {
        self.coder.uint(context).ok_or_else(|| self.ended())
    }
    fn int(&mut self, context: &mut IntContext, _: i64, _: &'static str) -> Result<i64> {
        self.coder.int(context).ok_or_else(|| self.ended())
    }
}

/// A vertex's first wedge as its representative showed it (docs/FORMAT.md §10): its values,
/// but for the `uv_low_bits` lowest bits of each uv axis, left to the full appearance.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FirstValue {
    /// The values; the uv's low bits are zero.
    pub code: CornerCode,
    /// uv bits (per axis) still to code.
    pub uv_low_bits: u8,
}

/// The wedges of a vertex known before the full appearance, in the order its corners meet
/// them (docs/FORMAT.md §10).
pub type Known = smallvec::SmallVec<[FirstValue; 1]>;

/// Context sets for the low uv bits a representative left out, by their count.
const UV_LOW_SETS: usize = 8;

/// What the encoder knows: every decoded face's corners' values and material.
pub struct Truth<'a> {
    /// Quantized values of each corner, per face of the decoded mesh.
    pub corners: &'a [[CornerCode; 3]],
    /// Material id of each face of the decoded mesh.
    pub materials: Option<&'a [u32]>,
}

const NONE: u32 = u32::MAX;
/// The uv predictions scored against each other: unfolded, similar, their mean, fitted, the mean
/// of unfolded and fitted.
const UV_PREDICTIONS: usize = 5;

/// Context sets for uv residuals by the predicting edge's length in cells (log2 buckets).
const UV_SCALES: usize = 10;

/// How a new wedge's uv is predicted: from two corners of its face, one, or none.
#[derive(Clone, Copy)]
enum UvBasis {
    Unfolded = 0,
    Triangle = 1,
    Corner = 2,
    Previous = 3,
}

#[derive(Default)]
struct Contexts {
    /// Continues the candidate wedge: [which candidate][the edge's other end: unknown, continued,
    /// seam][wedges at the vertex: one, more].
    same: [[[BitContext; 2]; 3]; 2],
    /// A new wedge rather than one not met across an edge: [no candidate at all].
    new: [BitContext; 2],
    other: UintContext,
    material_same: [BitContext; 2],
    material: UintContext,
    /// [basis][scale][axis]
    uv: [[[IntContext; 2]; UV_SCALES]; 4],
    /// The low uv bits a representative left out: [their count][scale][axis].
    uv_low: [[[IntContext; 2]; UV_SCALES]; UV_LOW_SETS],
    /// [first wedge at its vertex][axis]
    normal: [[IntContext; 2]; 2],
    /// [spread of the known corners' colours][channel]
    colour: [[IntContext; 4]; 5],
}

/// Runs the unit's syntax over `mesh` (the decoded full level), coding `truth` when given.
/// With `first`, the values of each vertex's first wedge are known already (`first[v]`, the
/// level appearance of §10): a wedge that a vertex starts with takes them uncoded, but for the
/// low bits of its uv that its representative left out, coded here.
pub fn run(
    symbols: &mut impl Symbols,
    mesh: &TriMesh,
    spec: &AppearanceSpec,
    truth: Option<&Truth>,
    first: Option<&[Known]>,
) -> Result<Appearance> {
    let traversal = Traversal::new(mesh);
    let faces = &mesh.faces;
    let mut c = Contexts::default();
    let mut out = Appearance {
        corners: vec![[NONE; 3]; faces.len()],
        wedge_vertex: Vec::new(),
        codes: Vec::new(),
        materials: spec.materials.as_ref().map(|_| vec![0; faces.len()]),
    };
    // Wedges of each vertex as a list through `next_wedge`, newest first.
    let mut first_wedge = vec![NONE; mesh.positions.len()];
    // Wedges made at each vertex so far: the n-th takes the n-th known one.
    let mut wedges_at = vec![
        0u8;
        if first.is_some() {
            mesh.positions.len()
        } else {
            0
        }
    ];
    let mut next_wedge: Vec<u32> = Vec::new();
    let mut previous_uv = [0u32; 2];
    let mut previous_colour = [0u8; 4];
    let mut last_winding = 1.0;
    // Recent errors of the uv predictions (see `UV_PREDICTIONS`).
    let mut uv_scores = [0.0f64; UV_PREDICTIONS];
    let mut previous_material = 0u32;
    let normal_max = spec.normal_bits.map(octahedral_max);
    let uv_cells = spec.uv_grid.map(|g| 1u64 << g.bits);
    // The fitted uv prediction's corners and their wedges, kept between wedges to spare an
    // allocation each.
    let mut pairs: Vec<(DVec3, DVec2)> = Vec::new();
    let mut seen: Vec<u32> = Vec::new();
    for &f in &traversal.order {
        let fu = f as usize;
        let face = faces[fu];
        let across: [Option<u32>; 3] =
            std::array::from_fn(|j| traversal.before_across(f, face[j], face[(j + 1) % 3]));
        if let (Some(materials), Some(names)) = (out.materials.as_mut(), &spec.materials) {
            let neighbour = across.iter().flatten().next();
            let predicted = neighbour.map_or(previous_material, |&g| materials[g as usize]);
            let value = truth.and_then(|t| t.materials).map_or(0, |m| m[fu]);
            let same = symbols.bit(
                &mut c.material_same[neighbour.is_some() as usize],
                value == predicted,
                "material",
            )?;
            let id = if same {
                predicted
            } else {
                let id = symbols.uint(&mut c.material, value as u64, "material")?;
                if id >= names.names.len() as u64 {
                    return Err(Error::malformed(
                        0,
                        0,
                        format!("appearance: material {id} of {}", names.names.len()),
                    ));
                }
                id as u32
            };
            materials[fu] = id;
            previous_material = id;
        }
        // Which wedge each corner takes.
        let mut edge_continued: [Option<bool>; 3] = [None; 3];
        let mut born = [false; 3];
        let mut partial: [Option<FirstValue>; 3] = [None; 3];
        for k in 0..3 {
            let v = face[k] as usize;
            let truth_code = truth.map(|t| t.corners[fu][k]);
            let wedge_at = |g: Option<u32>| {
                g.and_then(|g| {
                    let gf = faces[g as usize];
                    (0..3)
                        .find(|&i| gf[i] as usize == v)
                        .map(|i| out.corners[g as usize][i])
                })
            };
            // Candidates: across the edge to the next corner, then across the edge from the
            // previous one.
            let mut candidates: Vec<(usize, u32)> = Vec::with_capacity(2);
            for edge in [k, (k + 2) % 3] {
                if let Some(w) = wedge_at(across[edge]) {
                    if candidates.iter().all(|&(_, x)| x != w) {
                        candidates.push((edge, w));
                    }
                }
            }
            let mut chosen = NONE;
            if first_wedge[v] != NONE {
                let several = next_wedge[first_wedge[v] as usize] != NONE;
                for (slot, &(edge, w)) in candidates.iter().enumerate() {
                    let partner = match edge_continued[edge] {
                        None => 0,
                        Some(true) => 1,
                        Some(false) => 2,
                    };
                    let value = truth_code == Some(out.codes[w as usize]);
                    let same = symbols.bit(
                        &mut c.same[slot][partner][several as usize],
                        value,
                        "wedge",
                    )?;
                    edge_continued[edge].get_or_insert(same);
                    if same {
                        chosen = w;
                        break;
                    }
                }
                if chosen == NONE {
                    let mut others = Vec::new();
                    let mut w = first_wedge[v];
                    while w != NONE {
                        if candidates.iter().all(|&(_, x)| x != w) {
                            others.push(w);
                        }
                        w = next_wedge[w as usize];
                    }
                    if !others.is_empty() {
                        let matching = others
                            .iter()
                            .position(|&w| truth_code == Some(out.codes[w as usize]));
                        let new = symbols.bit(
                            &mut c.new[candidates.is_empty() as usize],
                            matching.is_none(),
                            "wedge",
                        )?;
                        if !new {
                            let index = if others.len() > 1 {
                                symbols.uint(&mut c.other, matching.unwrap_or(0) as u64, "wedge")?
                            } else {
                                0
                            };
                            chosen = *others.get(index as usize).ok_or_else(|| {
                                Error::malformed(0, 0, "appearance: wedge index out of range")
                            })?;
                        }
                    }
                }
            }
            if chosen == NONE {
                chosen = out.wedge_vertex.len() as u32;
                out.wedge_vertex.push(v as u32);
                let known_first = first.and_then(|f| {
                    let n = wedges_at[v];
                    wedges_at[v] = n.saturating_add(1);
                    f[v].get(n as usize).copied()
                });
                out.codes
                    .push(known_first.map(|f| f.code).unwrap_or_default());
                next_wedge.push(first_wedge[v]);
                first_wedge[v] = chosen;
                // A first wedge whose uv is whole is known; one with low bits left goes
                // through the values below for those alone.
                born[k] = known_first.is_none_or(|f| f.uv_low_bits > 0);
                partial[k] = known_first.filter(|f| f.uv_low_bits > 0);
            }
            out.corners[fu][k] = chosen;
        }
        // The new wedges' values, those with the most known corners in the face first.
        let mut known = born.map(|b| !b);
        while let Some(k) = (0..3)
            .filter(|&k| !known[k])
            .max_by_key(|&k| (known[(k + 1) % 3] as u8 + known[(k + 2) % 3] as u8, 3 - k))
        {
            let w = out.corners[fu][k] as usize;
            let v = face[k];
            let truth_code = truth.map(|t| t.corners[fu][k]).unwrap_or_default();
            let mut code = CornerCode::default();
            let others = [(k + 1) % 3, (k + 2) % 3];
            let known_code = |j: usize| known[j].then(|| out.codes[out.corners[fu][j] as usize]);
            if let Some(shown) = partial[k] {
                code = shown.code;
            }
            if let (Some(bits), Some(max), None) = (spec.normal_bits, normal_max, partial[k]) {
                let first_at_vertex = next_wedge[w] == NONE;
                let p = |i: usize| mesh.positions[face[i] as usize];
                let direction = if first_at_vertex {
                    traversal
                        .faces_at(v)
                        .iter()
                        .map(|&g| {
                            let gf = faces[g as usize];
                            let q = |i: usize| mesh.positions[gf[i] as usize];
                            face_normal(q(0), q(1), q(2))
                        })
                        .sum()
                } else {
                    face_normal(p(0), p(1), p(2))
                };
                let predicted = octahedral_code(direction, bits);
                let value = truth_code.normal.unwrap_or_default();
                let mut n = [0u32; 2];
                for axis in 0..2 {
                    let d = symbols.int(
                        &mut c.normal[first_at_vertex as usize][axis],
                        value[axis] as i64 - predicted[axis] as i64,
                        "normal",
                    )?;
                    n[axis] = in_range(predicted[axis] as i64 + d, max as u64 + 1, "normal")?;
                }
                code.normal = Some(n);
            }
            if let Some(cells) = uv_cells {
                let uv = |j: usize| known_code(j).and_then(|c| c.uv);
                let at = |q: [u32; 2]| DVec2::new(q[0] as f64, q[1] as f64);
                let mut scored = None;
                // How far the predictions fall apart: when they disagree the residual is large.
                let mut disagreement: Option<f64> = None;
                let (basis, predicted) = match (uv(others[0]), uv(others[1])) {
                    (Some(ta), Some(tb)) => {
                        let p = |i: usize| mesh.positions[face[i] as usize];
                        // The face across the known edge, when it continues both wedges.
                        let [ea, eb] = others.map(|j| out.corners[fu][j]);
                        let unfolded = across[others[0]].and_then(|g| {
                            let gf = faces[g as usize];
                            let gw = out.corners[g as usize];
                            let at_vertex = |v| (0..3).find(|&i| gf[i] == v);
                            let (ia, ib) =
                                (at_vertex(face[others[0]])?, at_vertex(face[others[1]])?);
                            if gw[ia] != ea || gw[ib] != eb {
                                return None;
                            }
                            let ic = 3 - ia - ib;
                            let tc = out.codes[gw[ic] as usize].uv?;
                            uv_by_unfolding(
                                p(k),
                                [p(others[0]), p(others[1]), mesh.positions[gf[ic] as usize]],
                                [at(ta), at(tb), at(tc)],
                            )
                        });
                        let similar = uv_from_triangle(
                            p(k),
                            p(others[0]),
                            p(others[1]),
                            at(ta),
                            at(tb),
                            last_winding,
                        );
                        // The chart's corners around the known edge: every corner of the
                        // faces visited so far at either end that continue its wedge there.
                        pairs.clear();
                        seen.clear();
                        let mut plane_normal = face_normal(p(0), p(1), p(2));
                        for (end, wedge) in [(face[others[0]], ea), (face[others[1]], eb)] {
                            for &g in traversal.faces_at(end) {
                                let gw = out.corners[g as usize];
                                if g == f || gw[0] == NONE || !gw.contains(&wedge) {
                                    continue;
                                }
                                let gf = faces[g as usize];
                                let q = |i: usize| mesh.positions[gf[i] as usize];
                                plane_normal += face_normal(q(0), q(1), q(2));
                                for (i, &w) in gw.iter().enumerate() {
                                    if seen.contains(&w) {
                                        continue;
                                    }
                                    if let Some(t) = out.codes[w as usize].uv {
                                        seen.push(w);
                                        pairs.push((q(i), at(t)));
                                    }
                                }
                            }
                        }
                        let fitted = uv_by_fit(p(k), plane_normal, &pairs);
                        // Of these predictions, the one that has erred least lately (both
                        // sides score them all once the value is known).
                        let t = match unfolded {
                            Some(u) => {
                                let fit = fitted.unwrap_or(u);
                                let choices =
                                    [u, similar, (u + similar) * 0.5, fit, (u + fit) * 0.5];
                                let best = (0..UV_PREDICTIONS)
                                    .min_by(|&i, &j| uv_scores[i].total_cmp(&uv_scores[j]))
                                    .expect("choices");
                                scored = Some(choices);
                                disagreement = Some(
                                    (u - fit).abs().element_sum()
                                        + (u - similar).abs().element_sum(),
                                );
                                choices[best]
                            }
                            None => similar,
                        };
                        let basis = if unfolded.is_some() {
                            UvBasis::Unfolded
                        } else {
                            UvBasis::Triangle
                        };
                        (basis, clamp_cell(t, cells))
                    }
                    (Some(t), None) | (None, Some(t)) => (UvBasis::Corner, t),
                    (None, None) => (UvBasis::Previous, previous_uv),
                };
                // Residuals grow with the triangle's size in uv (its known edge) and with how
                // far the predictions fall apart: the geometric mean of the two picks the
                // contexts.
                let scale = match (uv(others[0]), uv(others[1])) {
                    (Some(ta), Some(tb)) if disagreement.is_some() => {
                        let d = disagreement.unwrap_or(0.0).max(1.0);
                        let span = (at(ta) - at(tb)).abs().max_element().max(1.0);
                        (((d * span).log2() * 0.5).round().max(0.0) as usize).min(UV_SCALES - 1)
                    }
                    (Some(ta), Some(tb)) => {
                        let span = (at(ta) - at(tb)).abs().max_element() as u64;
                        (64 - span.leading_zeros() as usize).min(UV_SCALES - 1)
                    }
                    _ => 0,
                };
                let value = truth_code.uv.unwrap_or_default();
                let mut t = [0u32; 2];
                for axis in 0..2 {
                    t[axis] = match partial[k] {
                        // The representative's high bits hold: the prediction is taken
                        // into their cell, and the low bits coded from there.
                        Some(shown) => {
                            let low = shown.uv_low_bits.min(31);
                            let base = shown.code.uv.unwrap_or_default()[axis] >> low << low;
                            let top = base as i64 + (1i64 << low) - 1;
                            let guess = (predicted[axis] as i64).clamp(base as i64, top);
                            let d = symbols.int(
                                &mut c.uv_low[(low as usize - 1).min(UV_LOW_SETS - 1)][scale][axis],
                                value[axis] as i64 - guess,
                                "uv_low",
                            )?;
                            let x = guess + d;
                            if x < base as i64 || x > top {
                                return Err(Error::malformed(
                                    0,
                                    0,
                                    "appearance: uv low bits outside the representative's cell",
                                ));
                            }
                            in_range(x, cells, "uv")?
                        }
                        None => {
                            let d = symbols.int(
                                &mut c.uv[basis as usize][scale][axis],
                                value[axis] as i64 - predicted[axis] as i64,
                                ["uv_unfolded", "uv_triangle", "uv_corner", "uv_previous"]
                                    [basis as usize],
                            )?;
                            in_range(predicted[axis] as i64 + d, cells, "uv")?
                        }
                    };
                }
                if let Some(choices) = scored {
                    let actual = at(t);
                    for (score, choice) in uv_scores.iter_mut().zip(choices) {
                        *score = *score * 0.97 + (actual - choice).abs().element_sum();
                    }
                }
                code.uv = Some(t);
                previous_uv = t;
            }
            if spec.colours && partial[k].is_none() {
                let known_colours: Vec<[u8; 4]> = others
                    .iter()
                    .filter_map(|&j| known_code(j).and_then(|c| c.colour))
                    .collect();
                // The mean of the face's known corners; the spread between them picks the
                // contexts (a smooth region predicts well, an edge in the colours does not).
                let (predicted, spread): ([u8; 4], u32) = match known_colours[..] {
                    [a, b] => (
                        std::array::from_fn(|i| (a[i] as u16 + b[i] as u16).div_ceil(2) as u8),
                        a.iter()
                            .zip(b)
                            .map(|(x, y)| x.abs_diff(y) as u32)
                            .max()
                            .unwrap_or(0),
                    ),
                    [a] => (a, 256),
                    _ => (previous_colour, 256),
                };
                let spread_context = match spread {
                    0 => 0,
                    1..=3 => 1,
                    4..=15 => 2,
                    16..=255 => 3,
                    _ => 4,
                };
                let value = truth_code.colour.unwrap_or_default();
                let mut rgba = [0u8; 4];
                for channel in 0..4 {
                    let d = symbols.int(
                        &mut c.colour[spread_context][channel],
                        value[channel].wrapping_sub(predicted[channel]) as i8 as i64,
                        "colour",
                    )?;
                    if !(-128..=127).contains(&d) {
                        return Err(Error::malformed(0, 0, "appearance: colour out of range"));
                    }
                    rgba[channel] = predicted[channel].wrapping_add(d as i8 as u8);
                }
                code.colour = Some(rgba);
                previous_colour = rgba;
            }
            out.codes[w] = code;
            known[k] = true;
        }
        if spec.uv_grid.is_some() {
            let t = out.corners[fu].map(|w| {
                let q = out.codes[w as usize].uv.unwrap_or_default();
                DVec2::new(q[0] as f64, q[1] as f64)
            });
            last_winding = winding(t);
        }
    }
    Ok(out)
}

/// `value` when it lies in 0..`limit`; a malformed stream otherwise.
fn in_range(value: i64, limit: u64, what: &str) -> Result<u32> {
    if value < 0 || value as u64 >= limit {
        return Err(Error::malformed(
            0,
            0,
            format!("appearance: {what} value {value} outside the grid"),
        ));
    }
    Ok(value as u32)
}

fn clamp_cell(t: DVec2, cells: u64) -> [u32; 2] {
    let last = (cells - 1) as f64;
    let axis = |x: f64| {
        if x.is_finite() {
            x.round().clamp(0.0, last) as u32
        } else {
            0
        }
    };
    [axis(t.x), axis(t.y)]
}
