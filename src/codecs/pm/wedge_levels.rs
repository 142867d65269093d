//! The encoder's corner values at every level of a progressive mesh: from the full mesh's, the
//! splits undone in reverse, each collapse giving vs's corners their coarse values by the rule
//! [`AttributeFit`] names. The decoder needs no rule: each split codes the fine values against
//! the coarse ones it holds ([`super::wedges`]).
//!
//! A collapse merges the wedges that continue across the collapsed edge: in fl, vt's wedge
//! joins vs's; in fr likewise. `Keep` gives the merged wedge the survivor's values (the
//! fast-QEM paper's rule: the survivor's uvs). `Fit` interpolates them along the edge to
//! where the collapse put vs — vt's values when vs moved onto vt, their mean at the midpoint —
//! so that a texture stays where the surface went; it costs the bits of re-coding vs's
//! values at the split.

use super::wedges::{label_code, label_of, SplitTruth, WedgeState};
use crate::codecs::AttributeFit;
use crate::container::AppearanceSpec;
use crate::hierarchy::pmesh::{PmMesh, Vsplit, NIL};
use crate::mesh::attribute_quantization::{octahedral_code, octahedral_normal};
use crate::mesh::canonical_attributes::CornerCode;
use glam::DVec3;

/// The base mesh's values and, split by split, the fine values the encoder codes.
pub struct WedgeLevels {
    /// Values of M⁰.
    pub base: WedgeState,
    /// For each split, every face at vs and vt after it with its values and material.
    pub truths: Vec<SplitTruth>,
}

fn point(c: [i32; 3]) -> DVec3 {
    DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64)
}

/// The values of the merged wedge of `a` (vs's) and `b` (vt's), `t` of the way from a to b.
fn mix(a: CornerCode, b: CornerCode, t: f64, spec: &AppearanceSpec) -> CornerCode {
    if t <= 0.0 {
        return a;
    }
    if t >= 1.0 {
        // A label of derived normals stays vs's (see `derive`).
        return CornerCode {
            normal: if spec.derived_normals {
                a.normal
            } else {
                b.normal
            },
            ..b
        };
    }
    let lerp = |x: u32, y: u32| (x as f64 * (1.0 - t) + y as f64 * t).round() as u32;
    CornerCode {
        normal: match (a.normal, b.normal, spec.normal_bits) {
            // A label of derived normals names a group, which does not blend.
            _ if spec.derived_normals => a.normal,
            (Some(x), Some(y), Some(bits)) => {
                let n = octahedral_normal(x, bits) * (1.0 - t) + octahedral_normal(y, bits) * t;
                Some(if n.length_squared() > 1e-12 {
                    octahedral_code(n, bits)
                } else {
                    x
                })
            }
            (n, _, _) => n,
        },
        uv: match (a.uv, b.uv) {
            (Some(x), Some(y)) => Some([lerp(x[0], y[0]), lerp(x[1], y[1])]),
            (uv, _) => uv,
        },
        colour: match (a.colour, b.colour) {
            (Some(x), Some(y)) => Some(std::array::from_fn(|i| {
                lerp(x[i] as u32, y[i] as u32).min(255) as u8
            })),
            (c, _) => c,
        },
    }
}

/// The values of every level, from `full` (Mⁿ, the splits all applied) and its values `state`.
pub fn derive(
    full: &PmMesh,
    mut state: WedgeState,
    splits: &[Vsplit],
    fit: AttributeFit,
    spec: &AppearanceSpec,
) -> WedgeLevels {
    let mut mesh = full.clone();
    let mut truths = Vec::with_capacity(splits.len());
    for split in splits.iter().rev() {
        let vt = mesh.positions.len() as u32 - 1;
        let created = if split.vlr_rot.has_fr() { 2 } else { 1 };
        let fl = mesh.faces.len() as u32 - created;
        let fr = if created == 2 { fl + 1 } else { NIL };
        let vs = mesh.faces[fl as usize].v[0];
        let fan_s = mesh.fan(fl, vs);
        let fan_t = mesh.fan(fl, vt);
        let mut truth: SplitTruth = Vec::with_capacity(fan_s.len() + fan_t.len());
        for &f in fan_s.iter().chain(&fan_t) {
            if truth.iter().all(|x| x.0 != f) {
                let material = state.materials.as_ref().map_or(0, |m| m[f as usize]);
                truth.push((f, state.corners[f as usize], material));
            }
        }
        truths.push(truth);
        // The wedges that merge: (vt's, vs's) in fl, then in fr.
        let mut merging = vec![(state.corners[fl as usize][2], state.corners[fl as usize][0])];
        // Normal labels that continue across the edge, each set named by vs's label in it.
        let mut label_sets: Vec<Vec<u32>> = Vec::new();
        if spec.derived_normals {
            let mut across = vec![merging[0]];
            if fr != NIL {
                across.push((state.corners[fr as usize][1], state.corners[fr as usize][0]));
            }
            for (b, a) in across {
                let (b, a) = (label_of(b), label_of(a));
                match label_sets
                    .iter_mut()
                    .find(|s| s.contains(&a) || s.contains(&b))
                {
                    Some(set) => set.extend([a, b]),
                    None => label_sets.push(vec![a, b]),
                }
            }
        }
        if fr != NIL {
            let pair = (state.corners[fr as usize][1], state.corners[fr as usize][0]);
            if merging.iter().all(|m| m.0 != pair.0 && m.1 != pair.1) {
                merging.push(pair);
            }
        }
        let (ps, pt) = (
            point(mesh.positions[vs as usize]),
            point(mesh.positions[vt as usize]),
        );
        mesh.ecol(split);
        let t = match fit {
            AttributeFit::Keep => 0.0,
            AttributeFit::Fit => {
                let d = pt - ps;
                let length2 = d.length_squared();
                if length2 > 0.0 {
                    ((point(mesh.positions[vs as usize]) - ps).dot(d) / length2).clamp(0.0, 1.0)
                } else {
                    0.0
                }
            }
        };
        let merged: Vec<(CornerCode, CornerCode, CornerCode)> = merging
            .iter()
            .map(|&(b, a)| (b, a, mix(a, b, t, spec)))
            .collect();
        for &f in fan_t.iter().filter(|&&f| f != fl && f != fr) {
            let k = mesh.corner(f, vs).expect("a moved face holds vs again");
            let value = &mut state.corners[f as usize][k];
            if let Some(m) = merged.iter().find(|m| m.0 == *value) {
                *value = m.2;
            }
        }
        for &f in fan_s.iter().filter(|&&f| f != fl && f != fr) {
            let k = mesh.corner(f, vs).expect("a face of vs");
            let value = &mut state.corners[f as usize][k];
            if let Some(m) = merged.iter().find(|m| m.1 == *value) {
                *value = m.2;
            }
        }
        // The normal groups that continue across the edge merge whatever their other values,
        // under vs's label: a label stays at one vertex, so that the decoder can tell a group
        // it holds from a new one.
        for &f in fan_s.iter().chain(&fan_t).filter(|&&f| f != fl && f != fr) {
            let k = mesh.corner(f, vs).expect("a face of vs");
            let value = &mut state.corners[f as usize][k];
            if let Some(set) = label_sets.iter().find(|s| s.contains(&label_of(*value))) {
                value.normal = Some(label_code(set[0]));
            }
        }
        for _ in 0..created {
            state.corners.pop();
            if let Some(m) = state.materials.as_mut() {
                m.pop();
            }
        }
    }
    truths.reverse();
    WedgeLevels {
        base: state,
        truths,
    }
}
