//! The values a coarse level shows (docs/FORMAT.md §10.1): every vertex of a level stands for
//! one vertex of the full mesh, its **representative**, and shows that vertex's first wedge.
//! A representative's values are coded once, in the level that gives it a vertex of its own
//! (its **birth**), predicted from the neighbours the level mesh gives it whose values are
//! already known; they are exact from then on. Written once for both directions, as
//! [`super::coder`] is.

use super::coder::Symbols;
use super::predict::{face_normal, uv_by_fit};
use crate::coding::arith::{BitContext, IntContext, UintContext};
use crate::container::AppearanceSpec;
use crate::error::{Error, Result};
use crate::mesh::attribute_quantization::{octahedral_code, octahedral_max};
use crate::mesh::canonical_attributes::CornerCode;
use glam::{DVec2, DVec3};

/// A representative's values: its first wedge's codes and the material of the face that
/// wedge is first met on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RepValue {
    /// Quantized normal, uv and colour (the uv at the centre of the cell its coded bits
    /// name).
    pub code: CornerCode,
    /// Material id, when the stream declares materials.
    pub material: Option<u32>,
    /// Low bits of each uv axis left uncoded, for the full appearance.
    pub uv_low_bits: u8,
    /// Whether the values are a sketch (docs/FORMAT.md §10.1): which of its neighbours'
    /// charts each wedge lies in, its values those the chart predicts; the full appearance
    /// codes them again.
    pub sketched: bool,
}

/// A level as the births see it: where its vertices are shown and which of them share an edge.
pub struct LevelView<'a> {
    /// Shown position of every vertex.
    pub positions: &'a [DVec3],
    /// The level's faces.
    pub faces: &'a [[u32; 3]],
    /// The level's edges on no face.
    pub loose_edges: &'a [[u32; 2]],
}

/// The uv predictions scored against each other: the nearest neighbour's uv, the fitted
/// affine map, the inliers' mean, and the mean of the first two.
const UV_PREDICTIONS: usize = 4;

/// Context sets for uv residuals by how far apart the neighbours' uvs lie (log2 buckets).
const UV_SCALES: usize = 12;

/// A neighbour's uv is in the chart of the nearest one when it lies within this many times
/// the uv distance that the neighbourhood's median stretch gives its 3D distance.
const CHART_REACH: f64 = 3.0;

/// What both sides keep from level to level: the contexts, the predictions' recent errors and
/// every representative's values.
pub struct Births {
    /// Values by representative (`None` until its birth).
    pub values: Vec<Option<RepValue>>,
    /// A uv is coded to this many bits below the spread of its neighbours' uvs, the rest
    /// left to the full appearance; `None`: exactly.
    pub uv_precision: Option<u8>,
    contexts: Box<Contexts>,
    uv_scores: [f64; UV_PREDICTIONS],
    previous: RepValue,
    /// By representative: its other wedges (across seams), in the order the settling level
    /// meets them.
    pub seams: Vec<Seams>,
}

/// A representative's wedges after its first.
pub type Seams = smallvec::SmallVec<[CornerCode; 1]>;

/// Most wedges a representative may have past its first.
const MAX_SEAM_WEDGES: u64 = 64;

/// Context sets for a sketch's chart choice, by how many charts there are to choose from.
const SKETCH_CHOICES: usize = 4;

#[derive(Default)]
struct Contexts {
    /// A sketched wedge's chart: [charts to choose from, 1 to 4 or more].
    sketch_chart: [UintContext; SKETCH_CHOICES],
    /// A sketch's wedges past the first: [charts left, 0 to 3 or more].
    sketch_seams: [UintContext; SKETCH_CHOICES],
    /// Wedges past the first: [a neighbour lies off the first wedge's chart].
    seam_count: [UintContext; 2],
    /// A seam wedge's uv: [predicted from a neighbour off the charts so far][axis].
    seam_uv: [[IntContext; 2]; 2],
    /// A seam wedge's normal and colour about the first wedge's.
    seam_normal: [IntContext; 2],
    seam_colour: [IntContext; 4],
    /// [a neighbour is known]
    material_same: [BitContext; 2],
    material: UintContext,
    /// [basis: neighbours, nearest only, none][scale][axis]
    uv: [[[IntContext; 2]; UV_SCALES]; 3],
    /// [the vertex has faces][axis]
    normal: [[IntContext; 2]; 2],
    /// [spread of the known neighbours' colours][channel]
    colour: [[IntContext; 4]; 5],
}

impl Births {
    /// Nothing known yet, for a mesh of `vertices` representatives.
    pub fn new(vertices: usize) -> Births {
        Births {
            values: vec![None; vertices],
            uv_precision: None,
            contexts: Box::default(),
            uv_scores: [0.0; UV_PREDICTIONS],
            previous: RepValue::default(),
            seams: vec![Seams::new(); vertices],
        }
    }

    /// Codes (with `truth`, each representative's true values) or reads the values of the
    /// representatives born in `level`, those of the vertices `born`, in that order; `token(v)`
    /// names the representative vertex v stands for.
    pub fn code(
        &mut self,
        symbols: &mut impl Symbols,
        level: &LevelView,
        born: &[u32],
        token: impl Fn(u32) -> u32,
        spec: &AppearanceSpec,
        truth: Option<(&[RepValue], &[Seams])>,
    ) -> Result<()> {
        let neighbours = Neighbours::build(level);
        let mut known = Vec::new();
        for &v in born {
            let t = token(v) as usize;
            if t >= self.values.len() || self.values[t].is_some() {
                return Err(Error::malformed(
                    0,
                    0,
                    "appearance: a representative is born twice",
                ));
            }
            neighbours.known(level, v, |w| self.values[token(w) as usize], &mut known);
            let normal = faces_normal(level, neighbours.faces_of(v));
            let prediction = self.predict(level.positions[v as usize], normal, &known, spec);
            let first = truth.map(|(values, _)| values[t]).unwrap_or_default();
            let value = self.code_one(symbols, &prediction, spec, first)?;
            let seams = truth.map(|(_, seams)| &seams[t][..]).unwrap_or_default();
            let p = level.positions[v as usize];
            self.seams[t] = self.code_seams(symbols, p, normal, &value, &known, spec, seams)?;
            self.values[t] = Some(value);
            self.previous = value;
        }
        Ok(())
    }

    /// Codes or reads a sketch of the representatives born in `level` (those of the vertices
    /// `born`, in order): for each, which of the charts its neighbours' wedges lie in holds
    /// its first wedge, how many more wedges it has and in which of the other charts. Each
    /// wedge's uv is what its chart's fit predicts; its other values what the neighbours
    /// predict. `truth`: the encoder's values, as for [`Self::code`].
    pub fn sketch(
        &mut self,
        symbols: &mut impl Symbols,
        level: &LevelView,
        born: &[u32],
        token: impl Fn(u32) -> u32,
        spec: &AppearanceSpec,
        truth: Option<(&[RepValue], &[Seams])>,
    ) -> Result<()> {
        let neighbours = Neighbours::build(level);
        let mut known = Vec::new();
        for &v in born {
            let t = token(v) as usize;
            if t >= self.values.len() || self.values[t].is_some() {
                return Err(Error::malformed(
                    0,
                    0,
                    "appearance: a representative is born twice",
                ));
            }
            neighbours.known(level, v, |w| self.values[token(w) as usize], &mut known);
            let p = level.positions[v as usize];
            let normal = faces_normal(level, neighbours.faces_of(v));
            let mut value = self.predict(p, normal, &known, spec).value(spec);
            value.sketched = true;
            let mut seams = Seams::new();
            if let Some(grid) = spec.uv_grid {
                let cells = 1u64 << grid.bits;
                // Every wedge of the neighbours, nearest first, grouped by chart.
                let at = |q: [u32; 2]| DVec2::new(q[0] as f64, q[1] as f64);
                let mut wedges: Vec<(DVec3, DVec2)> = Vec::new();
                for &w in neighbours.of(v) {
                    let tw = token(w) as usize;
                    if let Some(known) = self.values[tw] {
                        let q = level.positions[w as usize];
                        wedges.extend(known.code.uv.map(|t| (q, at(t))));
                        wedges.extend(
                            self.seams[tw]
                                .iter()
                                .filter_map(|c| c.uv.map(|t| (q, at(t)))),
                        );
                    }
                }
                wedges.sort_by(|a, b| {
                    (a.0 - p)
                        .length_squared()
                        .total_cmp(&(b.0 - p).length_squared())
                });
                let mut charts: Vec<[u32; 2]> = Vec::new();
                while let Some(&(q0, t0)) = wedges.first() {
                    let chart = in_chart(&wedges, q0, t0);
                    let fitted = uv_by_fit(p, normal_or_z(normal), &chart).unwrap_or(t0);
                    charts.push(clamp_cell(fitted, cells));
                    wedges.retain(|w| !chart.contains(w));
                }
                if !charts.is_empty() {
                    let first = truth.map(|(values, _)| values[t].code.uv.unwrap_or_default());
                    let nearest = |target: [u32; 2], among: &[usize]| {
                        among
                            .iter()
                            .position(|&i| {
                                let d = |c: [u32; 2]| at(c).distance_squared(at(target));
                                among.iter().all(|&j| d(charts[i]) <= d(charts[j]))
                            })
                            .unwrap_or(0)
                    };
                    let mut left: Vec<usize> = (0..charts.len()).collect();
                    let c = &mut *self.contexts;
                    let choices = |n: usize| n.clamp(1, SKETCH_CHOICES) - 1;
                    let pick = symbols.uint(
                        &mut c.sketch_chart[choices(left.len())],
                        first.map_or(0, |f| nearest(f, &left)) as u64,
                        "sketch",
                    )? as usize;
                    let chosen = *left.get(pick).ok_or_else(|| {
                        Error::malformed(0, 0, "appearance: a sketch's chart past those there are")
                    })?;
                    value.code.uv = Some(charts[chosen]);
                    left.remove(pick);
                    let truth_seams = truth.map(|(_, seams)| &seams[t][..]).unwrap_or_default();
                    let count = symbols.uint(
                        &mut c.sketch_seams[left.len().min(SKETCH_CHOICES - 1)],
                        truth_seams.len().min(left.len()) as u64,
                        "sketch",
                    )? as usize;
                    if count > left.len() {
                        return Err(Error::malformed(
                            0,
                            0,
                            "appearance: a sketch with more wedges than charts",
                        ));
                    }
                    for j in 0..count {
                        let target = truth_seams.get(j).and_then(|c| c.uv).unwrap_or_default();
                        let pick = symbols.uint(
                            &mut c.sketch_chart[choices(left.len())],
                            nearest(target, &left) as u64,
                            "sketch",
                        )? as usize;
                        let chosen = *left.get(pick).ok_or_else(|| {
                            Error::malformed(
                                0,
                                0,
                                "appearance: a sketch's chart past those there are",
                            )
                        })?;
                        left.remove(pick);
                        seams.push(CornerCode {
                            uv: Some(charts[chosen]),
                            ..value.code
                        });
                    }
                }
            }
            self.values[t] = Some(value);
            self.seams[t] = seams;
        }
        Ok(())
    }

    /// What each vertex of `level` shows: its representative's values where they are known,
    /// else the values its neighbours' predict for it, uncoded (vertices in order, a vertex
    /// once a neighbour has values, until none is left that has such a neighbour).
    pub fn shown(
        &self,
        level: &LevelView,
        token: impl Fn(u32) -> u32,
        spec: &AppearanceSpec,
    ) -> Vec<RepValue> {
        let n = level.positions.len();
        let mut shown: Vec<Option<RepValue>> = (0..n as u32)
            .map(|v| self.values.get(token(v) as usize).copied().flatten())
            .collect();
        let neighbours = Neighbours::build(level);
        let mut known = Vec::new();
        let mut left: Vec<u32> = (0..n as u32)
            .filter(|&v| shown[v as usize].is_none())
            .collect();
        while !left.is_empty() {
            let before = left.len();
            left.retain(|&v| {
                neighbours.known(level, v, |w| shown[w as usize], &mut known);
                if known.is_empty() {
                    return true;
                }
                let normal = faces_normal(level, neighbours.faces_of(v));
                let prediction = self.predict(level.positions[v as usize], normal, &known, spec);
                shown[v as usize] = Some(prediction.value(spec));
                false
            });
            if left.len() == before {
                break;
            }
        }
        shown
            .into_iter()
            .map(|v| v.unwrap_or(self.previous))
            .collect()
    }

    /// The prediction of the values of a vertex at `p` whose faces' area-weighted normal is
    /// `normal`, from `known`, its neighbours with values (nearest first).
    fn predict(
        &self,
        p: DVec3,
        normal: DVec3,
        known: &[(DVec3, RepValue)],
        spec: &AppearanceSpec,
    ) -> Prediction {
        let nearest = known.first().map(|(_, v)| *v);
        let material = nearest
            .and_then(|v| v.material)
            .or(self.previous.material)
            .unwrap_or(0);
        let has_faces = normal.length_squared() > 0.0;
        let normal_code = match spec.normal_bits {
            Some(bits) if has_faces => octahedral_code(normal, bits),
            _ => nearest
                .and_then(|v| v.code.normal)
                .or(self.previous.code.normal)
                .unwrap_or_default(),
        };
        let uv = spec.uv_grid.map(|grid| {
            let cells = 1u64 << grid.bits;
            let at = |q: [u32; 2]| DVec2::new(q[0] as f64, q[1] as f64);
            let with_uv: Vec<(DVec3, DVec2)> = known
                .iter()
                .filter_map(|(q, v)| v.code.uv.map(|t| (*q, at(t))))
                .collect();
            match with_uv.first() {
                None => UvPrediction {
                    basis: 2,
                    scale: 0,
                    cell: self.previous.code.uv.unwrap_or([cells as u32 / 2; 2]),
                    choices: None,
                },
                Some(&(q0, t0)) => {
                    let chart = in_chart(&with_uv, q0, t0);
                    let spread = chart
                        .iter()
                        .map(|(_, t)| (*t - t0).abs().max_element())
                        .fold(0.0f64, f64::max);
                    let scale = rounded_log2(spread as u64).min(UV_SCALES - 1);
                    if chart.len() < 2 {
                        UvPrediction {
                            basis: 1,
                            scale,
                            cell: clamp_cell(t0, cells),
                            choices: None,
                        }
                    } else {
                        let mean =
                            chart.iter().map(|(_, t)| *t).sum::<DVec2>() / chart.len() as f64;
                        let fitted = uv_by_fit(p, normal_or_z(normal), &chart).unwrap_or(mean);
                        let choices = [t0, fitted, mean, (t0 + fitted) * 0.5];
                        let best = (0..UV_PREDICTIONS)
                            .min_by(|&i, &j| self.uv_scores[i].total_cmp(&self.uv_scores[j]))
                            .expect("choices");
                        UvPrediction {
                            basis: 0,
                            scale,
                            cell: clamp_cell(choices[best], cells),
                            choices: Some(choices),
                        }
                    }
                }
            }
        });
        let colours: Vec<[u8; 4]> = known.iter().filter_map(|(_, v)| v.code.colour).collect();
        let (colour, spread) = match colours.len() {
            0 => (self.previous.code.colour.unwrap_or_default(), 256),
            n => {
                let mean = std::array::from_fn(|i| {
                    let sum: u32 = colours.iter().map(|c| c[i] as u32).sum();
                    ((sum + n as u32 / 2) / n as u32) as u8
                });
                let spread = (0..4)
                    .map(|i| {
                        let lo = colours.iter().map(|c| c[i]).min().unwrap_or(0);
                        let hi = colours.iter().map(|c| c[i]).max().unwrap_or(0);
                        (hi - lo) as u32
                    })
                    .max()
                    .unwrap_or(0);
                (mean, if n == 1 { 256 } else { spread })
            }
        };
        Prediction {
            neighbour: nearest.is_some(),
            material,
            has_faces,
            normal: normal_code,
            uv,
            colour,
            colour_spread: match spread {
                0 => 0,
                1..=3 => 1,
                4..=15 => 2,
                16..=255 => 3,
                _ => 4,
            },
        }
    }

    /// Codes or reads the wedges of a representative past its `first` (those across seams):
    /// their count, then each one's values, its uv predicted from the chart of the nearest
    /// neighbour in `known` off the charts of the wedges before it.
    #[allow(clippy::too_many_arguments)]
    fn code_seams(
        &mut self,
        symbols: &mut impl Symbols,
        p: DVec3,
        normal: DVec3,
        first: &RepValue,
        known: &[(DVec3, RepValue)],
        spec: &AppearanceSpec,
        truth: &[CornerCode],
    ) -> Result<Seams> {
        let at = |q: [u32; 2]| DVec2::new(q[0] as f64, q[1] as f64);
        let with_uv: Vec<(DVec3, DVec2)> = known
            .iter()
            .filter_map(|(q, v)| v.code.uv.map(|t| (*q, at(t))))
            .collect();
        // The neighbours off the chart of every wedge so far, nearest first.
        let off_charts = |wedges: &[CornerCode]| -> Vec<(DVec3, DVec2)> {
            let mut charts: Vec<(DVec3, DVec2)> = Vec::new();
            for w in wedges {
                if let Some(t) = w.uv {
                    let mut around = vec![(p, at(t))];
                    around.extend(&with_uv);
                    charts.extend(in_chart(&around, p, at(t)));
                }
            }
            with_uv
                .iter()
                .filter(|(q, t)| !charts.iter().any(|(r, u)| r == q && u == t))
                .copied()
                .collect()
        };
        let mut wedges: Vec<CornerCode> = vec![first.code];
        let outside = spec.uv_grid.is_some() && !off_charts(&wedges).is_empty();
        let c = &mut *self.contexts;
        let count = symbols.uint(
            &mut c.seam_count[outside as usize],
            truth.len() as u64,
            "seam_wedges",
        )?;
        if count > MAX_SEAM_WEDGES {
            return Err(Error::malformed(
                0,
                0,
                "appearance: a representative with too many wedges",
            ));
        }
        let mut seams = Seams::new();
        for j in 0..count as usize {
            let value = truth.get(j).copied().unwrap_or_default();
            let mut code = first.code;
            if let Some(bits) = spec.normal_bits {
                let max = octahedral_max(bits);
                let predicted = first.code.normal.unwrap_or_default();
                let mut n = [0u32; 2];
                for axis in 0..2 {
                    let d = symbols.int(
                        &mut c.seam_normal[axis],
                        value.normal.unwrap_or_default()[axis] as i64 - predicted[axis] as i64,
                        "normal",
                    )?;
                    n[axis] = in_range(predicted[axis] as i64 + d, max as u64 + 1, "normal")?;
                }
                code.normal = Some(n);
            }
            if let Some(grid) = spec.uv_grid {
                let cells = 1u64 << grid.bits;
                let off = off_charts(&wedges);
                let predicted = match off.first() {
                    Some(&(q0, t0)) => {
                        let chart = in_chart(&off, q0, t0);
                        let t = uv_by_fit(p, normal_or_z(normal), &chart).unwrap_or(t0);
                        clamp_cell(t, cells)
                    }
                    None => first.code.uv.unwrap_or_default(),
                };
                let mut t = [0u32; 2];
                for axis in 0..2 {
                    let d = symbols.int(
                        &mut c.seam_uv[off.is_empty() as usize][axis],
                        value.uv.unwrap_or_default()[axis] as i64 - predicted[axis] as i64,
                        "uv_seam",
                    )?;
                    t[axis] = in_range(predicted[axis] as i64 + d, cells, "uv")?;
                }
                code.uv = Some(t);
            }
            if spec.colours {
                let predicted = first.code.colour.unwrap_or_default();
                let mut rgba = [0u8; 4];
                for channel in 0..4 {
                    let d = symbols.int(
                        &mut c.seam_colour[channel],
                        value.colour.unwrap_or_default()[channel].wrapping_sub(predicted[channel])
                            as i8 as i64,
                        "colour",
                    )?;
                    if !(-128..=127).contains(&d) {
                        return Err(Error::malformed(0, 0, "appearance: colour out of range"));
                    }
                    rgba[channel] = predicted[channel].wrapping_add(d as i8 as u8);
                }
                code.colour = Some(rgba);
            }
            wedges.push(code);
            seams.push(code);
        }
        Ok(seams)
    }

    /// Codes or reads one representative's values about `prediction`.
    fn code_one(
        &mut self,
        symbols: &mut impl Symbols,
        prediction: &Prediction,
        spec: &AppearanceSpec,
        truth: RepValue,
    ) -> Result<RepValue> {
        let c = &mut *self.contexts;
        let mut out = RepValue::default();
        if let Some(names) = &spec.materials {
            let value = truth.material.unwrap_or(0);
            let same = symbols.bit(
                &mut c.material_same[prediction.neighbour as usize],
                value == prediction.material,
                "material",
            )?;
            let id = if same {
                prediction.material
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
            out.material = Some(id);
        }
        if let Some(bits) = spec.normal_bits {
            let max = octahedral_max(bits);
            let predicted = prediction.normal;
            let value = truth.code.normal.unwrap_or_default();
            let mut n = [0u32; 2];
            for axis in 0..2 {
                let d = symbols.int(
                    &mut c.normal[prediction.has_faces as usize][axis],
                    value[axis] as i64 - predicted[axis] as i64,
                    "normal",
                )?;
                n[axis] = in_range(predicted[axis] as i64 + d, max as u64 + 1, "normal")?;
            }
            out.code.normal = Some(n);
        }
        if let (Some(grid), Some(uv)) = (spec.uv_grid, &prediction.uv) {
            let cells = 1u64 << grid.bits;
            // Bits below the neighbourhood's spread by more than the precision wait for
            // the full appearance, where the mesh's own faces predict them better.
            let low = match (self.uv_precision, uv.basis) {
                (Some(precision), 0 | 1) => (uv.scale as u32 + 1)
                    .saturating_sub(precision as u32)
                    .min(grid.bits as u32),
                _ => 0,
            };
            let value = truth.code.uv.unwrap_or_default();
            let mut t = [0u32; 2];
            for axis in 0..2 {
                let d = symbols.int(
                    &mut c.uv[uv.basis][uv.scale][axis],
                    (value[axis] >> low) as i64 - (uv.cell[axis] >> low) as i64,
                    "uv_born",
                )?;
                let coarse = in_range((uv.cell[axis] >> low) as i64 + d, cells >> low, "uv")?;
                t[axis] = ((coarse << low) + (1 << low >> 1)).min(cells as u32 - 1);
            }
            out.uv_low_bits = low as u8;
            if let Some(choices) = uv.choices {
                let at = DVec2::new(t[0] as f64, t[1] as f64);
                for (score, choice) in self.uv_scores.iter_mut().zip(choices) {
                    *score = *score * 0.97 + (at - choice).abs().element_sum();
                }
            }
            out.code.uv = Some(t);
        }
        if spec.colours {
            let predicted = prediction.colour;
            let value = truth.code.colour.unwrap_or_default();
            let mut rgba = [0u8; 4];
            for channel in 0..4 {
                let d = symbols.int(
                    &mut c.colour[prediction.colour_spread][channel],
                    value[channel].wrapping_sub(predicted[channel]) as i8 as i64,
                    "colour",
                )?;
                if !(-128..=127).contains(&d) {
                    return Err(Error::malformed(0, 0, "appearance: colour out of range"));
                }
                rgba[channel] = predicted[channel].wrapping_add(d as i8 as u8);
            }
            out.code.colour = Some(rgba);
        }
        Ok(out)
    }
}

/// What a vertex's neighbours predict of its values.
struct Prediction {
    /// Whether it has a neighbour with values.
    neighbour: bool,
    material: u32,
    /// Whether it lies on a face of the level (its normal is the faces').
    has_faces: bool,
    normal: [u32; 2],
    uv: Option<UvPrediction>,
    colour: [u8; 4],
    colour_spread: usize,
}

struct UvPrediction {
    /// Neighbours in the chart, the nearest alone, none.
    basis: usize,
    /// log2 of the chart's neighbours' uv spread.
    scale: usize,
    cell: [u32; 2],
    /// The predictions scored (see [`UV_PREDICTIONS`]).
    choices: Option<[DVec2; UV_PREDICTIONS]>,
}

impl Prediction {
    /// The values predicted, uncoded.
    fn value(&self, spec: &AppearanceSpec) -> RepValue {
        RepValue {
            code: CornerCode {
                normal: spec.normal_bits.map(|_| self.normal),
                uv: self.uv.as_ref().map(|uv| uv.cell),
                colour: spec.colours.then_some(self.colour),
            },
            material: spec.materials.as_ref().map(|_| self.material),
            uv_low_bits: 0,
            sketched: false,
        }
    }
}

/// The neighbours in `with_uv` (nearest first, the nearest at `q0` with uv `t0`) whose uv
/// lies where the neighbourhood's median stretch puts it from the nearest one's: those in its
/// chart, the nearest included.
pub(super) fn in_chart(with_uv: &[(DVec3, DVec2)], q0: DVec3, t0: DVec2) -> Vec<(DVec3, DVec2)> {
    let mut stretch: Vec<f64> = with_uv[1..]
        .iter()
        .filter_map(|(q, t)| {
            let d = (*q - q0).length();
            (d > 0.0).then(|| (*t - t0).length() / d)
        })
        .collect();
    if stretch.is_empty() {
        return with_uv[..1].to_vec();
    }
    stretch.sort_by(f64::total_cmp);
    let median = stretch[stretch.len() / 2];
    with_uv
        .iter()
        .filter(|(q, t)| (*t - t0).length() <= CHART_REACH * median * (*q - q0).length() + 1.0)
        .copied()
        .collect()
}

/// The area-weighted normal of `faces` of `level` (zero without faces).
pub(super) fn faces_normal(level: &LevelView, faces: &[u32]) -> DVec3 {
    faces
        .iter()
        .map(|&f| {
            let [a, b, c] = level.faces[f as usize].map(|v| level.positions[v as usize]);
            face_normal(a, b, c)
        })
        .sum()
}

fn normal_or_z(n: DVec3) -> DVec3 {
    if n.length_squared() > 0.0 {
        n
    } else {
        DVec3::Z
    }
}

/// Each vertex's neighbours (over faces and loose edges) and faces, as compressed rows.
pub(super) struct Neighbours {
    start: Vec<u32>,
    list: Vec<u32>,
    face_start: Vec<u32>,
    face_list: Vec<u32>,
}

impl Neighbours {
    pub(super) fn build(level: &LevelView) -> Neighbours {
        let n = level.positions.len();
        // Each vertex's row holds its faces' other corners and its loose edges' other ends,
        // then is sorted and deduplicated on its own (short rows, not one long sort).
        let mut start = vec![0u32; n + 1];
        for f in level.faces {
            for &v in f {
                start[v as usize + 1] += 2;
            }
        }
        for &[a, b] in level.loose_edges {
            start[a as usize + 1] += 1;
            start[b as usize + 1] += 1;
        }
        for i in 1..start.len() {
            start[i] += start[i - 1];
        }
        let mut fill = start.clone();
        let mut list = vec![0u32; start[n] as usize];
        let mut put = |v: u32, w: u32| {
            list[fill[v as usize] as usize] = w;
            fill[v as usize] += 1;
        };
        for f in level.faces {
            for k in 0..3 {
                let (v, a, b) = (f[k], f[(k + 1) % 3], f[(k + 2) % 3]);
                put(v, a);
                put(v, b);
            }
        }
        for &[a, b] in level.loose_edges {
            put(a, b);
            put(b, a);
        }
        // Compacted in place, row by row.
        let mut kept = 0usize;
        let mut row_start = vec![0u32; n + 1];
        for v in 0..n {
            let row = &mut list[start[v] as usize..start[v + 1] as usize];
            row.sort_unstable();
            let mut last = None;
            for i in start[v] as usize..start[v + 1] as usize {
                let w = list[i];
                if last != Some(w) {
                    list[kept] = w;
                    kept += 1;
                    last = Some(w);
                }
            }
            row_start[v + 1] = kept as u32;
        }
        list.truncate(kept);
        let mut face_start = vec![0u32; n + 1];
        for f in level.faces {
            for &v in f {
                face_start[v as usize + 1] += 1;
            }
        }
        for i in 1..face_start.len() {
            face_start[i] += face_start[i - 1];
        }
        let mut fill = face_start.clone();
        let mut face_list = vec![0u32; level.faces.len() * 3];
        for (i, f) in level.faces.iter().enumerate() {
            for &v in f {
                face_list[fill[v as usize] as usize] = i as u32;
                fill[v as usize] += 1;
            }
        }
        Neighbours {
            start: row_start,
            list,
            face_start,
            face_list,
        }
    }

    pub(super) fn of(&self, v: u32) -> &[u32] {
        &self.list[self.start[v as usize] as usize..self.start[v as usize + 1] as usize]
    }

    /// `v`'s neighbours that `value` gives values, with their positions, nearest first (the
    /// neighbour most likely in the vertex's chart), into `out`.
    pub(super) fn known(
        &self,
        level: &LevelView,
        v: u32,
        value: impl Fn(u32) -> Option<RepValue>,
        out: &mut Vec<(DVec3, RepValue)>,
    ) {
        let p = level.positions[v as usize];
        out.clear();
        for &w in self.of(v) {
            if let Some(value) = value(w) {
                out.push((level.positions[w as usize], value));
            }
        }
        out.sort_by(|a, b| {
            (a.0 - p)
                .length_squared()
                .total_cmp(&(b.0 - p).length_squared())
        });
    }

    pub(super) fn faces_of(&self, v: u32) -> &[u32] {
        &self.face_list
            [self.face_start[v as usize] as usize..self.face_start[v as usize + 1] as usize]
    }
}

/// log2(`s`) rounded to the nearest integer (0 for 0 and 1), in integers, so that every
/// platform buckets alike.
fn rounded_log2(s: u64) -> usize {
    if s <= 1 {
        return 0;
    }
    let k = 63 - s.leading_zeros();
    // log2(s) ≥ k + ½ exactly when s² ≥ 2^(2k + 1).
    k as usize + ((s as u128) * (s as u128) >= 1u128 << (2 * k + 1)) as usize
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
