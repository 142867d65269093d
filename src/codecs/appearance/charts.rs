//! What the faces of a coarse level show (docs/FORMAT.md §10.2): a vertex shows one wedge,
//! its representative's first, so a face whose corners stand for vertices on two sides of a
//! seam would stretch across the texture atlas. Each such face keeps the chart most of its
//! corners are in, and its other corners take the uv that chart's map gives their positions —
//! the local affine fit of the chart around a corner in it. Both sides work this out from the
//! level alone; it costs no bits.

use super::births::{faces_normal, in_chart, LevelView, Neighbours, RepValue};
use super::predict::uv_by_fit;
use super::Appearance;
use crate::mesh::attribute_quantization::UvGrid;
use crate::mesh::canonical_attributes::CornerCode;
use glam::{DVec2, DVec3};

/// Two corners share a chart when their uvs lie within this many times the uv distance
/// that the level's median stretch gives their positions (and a cell).
const SAME_CHART: f64 = 3.0;

/// The level's faces with wedges: each corner the wedge of its vertex (`values[v]`, then
/// `seams[v]`) that keeps the face's uvs closest together, and a face's corners still off its
/// chart carried into it. `materials`: each face's.
pub fn faces_in_charts(
    level: &LevelView,
    values: &[RepValue],
    seams: &[&[CornerCode]],
    uv_grid: Option<UvGrid>,
    materials: Option<Vec<u32>>,
) -> Appearance {
    let mut shown = Appearance {
        corners: level.faces.to_vec(),
        wedge_vertex: (0..values.len() as u32).collect(),
        codes: values.iter().map(|v| v.code).collect(),
        materials,
    };
    // A vertex's seam wedges follow the vertices' own.
    let mut seam_wedge = Vec::with_capacity(values.len());
    for (v, wedges) in seams.iter().enumerate() {
        seam_wedge.push(shown.codes.len() as u32);
        for &code in *wedges {
            shown.wedge_vertex.push(v as u32);
            shown.codes.push(code);
        }
    }
    let Some(grid) = uv_grid else {
        return shown;
    };
    // Each corner of a face at a vertex with seam wedges: the combination of wedges whose uv
    // triangle has the shortest perimeter.
    let uv_of = |w: u32, codes: &[CornerCode]| {
        let t = codes[w as usize].uv.unwrap_or_default();
        DVec2::new(t[0] as f64, t[1] as f64)
    };
    for f in 0..level.faces.len() {
        let face = level.faces[f];
        if face.iter().all(|&v| seams[v as usize].is_empty()) {
            continue;
        }
        let choices = face.map(|v| {
            let mut c: Vec<u32> = vec![v];
            c.extend((0..seams[v as usize].len() as u32).map(|j| seam_wedge[v as usize] + j));
            c
        });
        let mut best = (f64::INFINITY, [face[0], face[1], face[2]]);
        for &a in &choices[0] {
            for &b in &choices[1] {
                for &c in &choices[2] {
                    let t = [a, b, c].map(|w| uv_of(w, &shown.codes));
                    let perimeter =
                        (t[0] - t[1]).length() + (t[1] - t[2]).length() + (t[2] - t[0]).length();
                    if perimeter < best.0 {
                        best = (perimeter, [a, b, c]);
                    }
                }
            }
        }
        shown.corners[f] = best.1;
    }
    let uv = |v: u32| {
        let t = values[v as usize].code.uv.unwrap_or_default();
        DVec2::new(t[0] as f64, t[1] as f64)
    };
    let codes = shown.codes.clone();
    let corner_uv = |w: u32| uv_of(w, &codes);
    let p = |v: u32| level.positions[v as usize];
    let neighbours = Neighbours::build(level);
    // Each vertex's stretch: uv distance per unit of distance to its neighbours, the lower
    // quartile (a seam vertex's edges across the seam are the long ones in uv).
    let ratio = |a: u32, b: u32| {
        let d = (p(a) - p(b)).length();
        if d > 0.0 {
            (uv(a) - uv(b)).length() / d
        } else {
            0.0
        }
    };
    let stretch: Vec<f64> = (0..values.len() as u32)
        .map(|v| {
            let mut around: Vec<f64> = neighbours.of(v).iter().map(|&w| ratio(v, w)).collect();
            if around.is_empty() {
                return f64::INFINITY;
            }
            let quarter = around.len() / 4;
            *around.select_nth_unstable_by(quarter, f64::total_cmp).1
        })
        .collect();
    let same = |a: u32, b: u32| {
        let local = stretch[a as usize].max(stretch[b as usize]);
        (uv(a) - uv(b)).length() <= SAME_CHART * local * (p(a) - p(b)).length() + 1.0
    };
    // A vertex on a seam shows one side's wedge and disagrees with its neighbours on the
    // other: the share of neighbours it agrees with says how surely its chart is its faces'.
    let agreement: Vec<f64> = (0..values.len() as u32)
        .map(|v| {
            let around = neighbours.of(v);
            let agreeing = around.iter().filter(|&&w| same(v, w)).count();
            agreeing as f64 / around.len().max(1) as f64
        })
        .collect();
    let cells = 1u64 << grid.bits;
    let mut known = Vec::new();
    // Whether the corners' wedges `wa`, `wb` at vertices `a`, `b` share a chart.
    let same_corner = |a: u32, wa: u32, b: u32, wb: u32| {
        let local = stretch[a as usize].max(stretch[b as usize]);
        (corner_uv(wa) - corner_uv(wb)).length()
            <= SAME_CHART * local * (p(a) - p(b)).length() + 1.0
    };
    for f in 0..level.faces.len() {
        let vertices = level.faces[f];
        let wedges = shown.corners[f];
        let agree =
            |i: usize, j: usize| same_corner(vertices[i], wedges[i], vertices[j], wedges[j]);
        if agree(0, 1) && agree(1, 2) && agree(2, 0) {
            continue;
        }
        // The face keeps the chart of its surest corner; the corners off it are carried in.
        let home_corner = (0..3)
            .max_by(|&i, &j| {
                agreement[vertices[i] as usize]
                    .total_cmp(&agreement[vertices[j] as usize])
                    .then(j.cmp(&i))
            })
            .expect("three corners");
        let home = vertices[home_corner];
        let home_uv = corner_uv(wedges[home_corner]);
        let odd: Vec<usize> = (0..3).filter(|&k| !agree(home_corner, k)).collect();
        neighbours.known(level, home, |w| Some(values[w as usize]), &mut known);
        let with_uv: Vec<(DVec3, DVec2)> = std::iter::once((p(home), home_uv))
            .chain(known.iter().map(|(q, v)| {
                let t = v.code.uv.unwrap_or_default();
                (*q, DVec2::new(t[0] as f64, t[1] as f64))
            }))
            .collect();
        let chart = in_chart(&with_uv, p(home), home_uv);
        let normal = faces_normal(level, neighbours.faces_of(home));
        for k in odd {
            let v = vertices[k];
            // Too few neighbours in the chart: the home corner's uv.
            let carried = uv_by_fit(p(v), normal, &chart).unwrap_or(home_uv);
            let t = [carried.x, carried.y].map(|x| {
                if x.is_finite() {
                    x.round().clamp(0.0, (cells - 1) as f64) as u32
                } else {
                    0
                }
            });
            shown.corners[f][k] = shown.codes.len() as u32;
            shown.wedge_vertex.push(v);
            shown.codes.push(CornerCode {
                uv: Some(t),
                ..values[v as usize].code
            });
        }
    }
    shown
}
