//! How a PM stream codes the base mesh and the vertex split records: adaptive binary arithmetic
//! coding, one context set per field, contexts kept across levels (the coder is flushed per
//! level, the probabilities are not reset).

use crate::codecs::stats::PmField;
use crate::coding::arith::{ArithDecoder, ArithEncoder, BitContext, IntContext, UintContext};
use crate::coding::bits::index_bits;
use crate::coding::SyntaxClass::{Connectivity, Geometry};
use crate::hierarchy::pmesh::{Rotation, Vsplit};
use crate::hierarchy::simplify::vad_s_step;

/// Contexts of every vsplit field.
#[derive(Clone, Debug, Default)]
pub struct SplitContexts {
    delta_flclw: UintContext,
    vs_index: [BitContext; 2],
    vlr_rot: UintContext,
    ii: [BitContext; 2],
    /// vad_l: two tangential components, then the residual of the normal one.
    vad_l: [IntContext; 3],
    vad_s: [IntContext; 3],
    count: UintContext,
}

/// Share of the ring-centroid difference used as the vad_l prediction. Measured on
/// bunny-closed-35k (pm-reordered, bits of vad_l per split): 0 → 29.3, 0.45 → 27.5, 0.6 → 27.0,
/// 0.75 → 27.5, 1.0 → 29.1, 1.5 → 31.1. The ring centroids sit between the two vertices and
/// their far neighbours, so the full difference overshoots.
const RING_WEIGHT: f64 = 0.6;

/// How vad_l is predicted from what the decoder already has: the surface normal at vs. The
/// component along the axis nearest the normal is coded as its difference from the point on
/// vs's tangent plane above the other two (an integer prediction, so exactly invertible): the
/// new vertex lies near that plane.
#[derive(Clone, Copy, Debug, Default)]
pub struct Tangent {
    normal: [f64; 3],
    /// Predicted vad_l: the centroid of vt's future neighbours minus that of vs's remaining
    /// ones (each vertex sits near the middle of its ring).
    guess: [i64; 3],
}

impl Tangent {
    /// The tangent plane at the vertex `vs_index` of face `flclw` (area-weighted normal of its
    /// faces); no prediction if the face does not exist or the fan is flat-degenerate.
    pub fn at(mesh: &crate::hierarchy::pmesh::PmMesh, split: &Vsplit) -> Tangent {
        let (flclw, vs_index) = (split.flclw, split.vs_index);
        let Some(face) = mesh.faces.get(flclw as usize) else {
            return Tangent::default();
        };
        let vs = face.v[(vs_index as usize).min(2)];
        let mut guess = [0i64; 3];
        if let Some((_, ring_t, ring_s)) = mesh.split_rings(split) {
            let mean = |ring: &[u32]| {
                let mut m = [0f64; 3];
                for &v in ring {
                    let p = mesh.positions[v as usize];
                    for a in 0..3 {
                        m[a] += p[a] as f64 / ring.len() as f64;
                    }
                }
                m
            };
            if !ring_t.is_empty() && !ring_s.is_empty() {
                let (mt, ms) = (mean(&ring_t), mean(&ring_s));
                guess = [0, 1, 2].map(|a| (RING_WEIGHT * (mt[a] - ms[a])).round() as i64);
            }
        }
        let mut n = [0f64; 3];
        for f in mesh.fan(flclw, vs) {
            let [a, b, c] = mesh.faces[f as usize]
                .v
                .map(|v| mesh.positions[v as usize].map(|x| x as f64));
            let (u, w) = (
                [0, 1, 2].map(|k| b[k] - a[k]),
                [0, 1, 2].map(|k| c[k] - a[k]),
            );
            n[0] += u[1] * w[2] - u[2] * w[1];
            n[1] += u[2] * w[0] - u[0] * w[2];
            n[2] += u[0] * w[1] - u[1] * w[0];
        }
        Tangent { normal: n, guess }
    }

    /// (first tangential axis, second, normal axis).
    fn axes(&self) -> (usize, usize, usize) {
        let n = self.normal.map(f64::abs);
        let k = if n[0] >= n[1] && n[0] >= n[2] {
            0
        } else if n[1] >= n[2] {
            1
        } else {
            2
        };
        ((k + 1) % 3, (k + 2) % 3, k)
    }

    /// Predicted normal-axis component for tangential components (di, dj).
    fn predict(&self, di: i32, dj: i32) -> i64 {
        let (i, j, k) = self.axes();
        let nk = self.normal[k];
        if nk == 0.0 || !nk.is_finite() {
            return 0;
        }
        let p = -(self.normal[i] * di as f64 + self.normal[j] * dj as f64) / nk;
        p.round().clamp(-(1i64 << 40) as f64, (1i64 << 40) as f64) as i64
    }
}

/// Which optional parts a record has, from the stream's parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// How flclw is written.
    pub flclw: FlclwCoding,
    /// Whether vad_s is present (zero otherwise).
    pub with_vad_s: bool,
}

/// How `flclw` is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FlclwCoding {
    /// As a face index: ⌈log2 F⌉ bits at probability ½ (Table 3).
    Index,
    /// As the difference to the previous record's, modulo F (Table 4, after reordering).
    Delta,
}

fn rotation_symbol(r: Rotation) -> u64 {
    match r {
        Rotation::ToBoundary => 0,
        Rotation::Empty => 1,
        Rotation::EmptyAcrossGap => 2,
        Rotation::Faces(k) => 3 + k as u64,
    }
}

fn rotation_of(symbol: u64) -> Option<Rotation> {
    Some(match symbol {
        0 => Rotation::ToBoundary,
        1 => Rotation::Empty,
        2 => Rotation::EmptyAcrossGap,
        k => Rotation::Faces(u32::try_from(k - 3).ok()?),
    })
}

/// Writes the number of splits in a level.
pub fn put_count(enc: &mut ArithEncoder, ctx: &mut SplitContexts, n: u64) {
    enc.uint(&mut ctx.count, n, Connectivity, PmField::Count.name());
}

/// Reads the number of splits in a level.
pub fn get_count(dec: &mut ArithDecoder, ctx: &mut SplitContexts) -> Option<u64> {
    dec.uint(&mut ctx.count)
}

/// Writes one vsplit; `faces` is the face count before it, `previous` the last record's flclw.
pub fn put_split(
    enc: &mut ArithEncoder,
    ctx: &mut SplitContexts,
    s: &Vsplit,
    faces: u32,
    previous: u32,
    layout: Layout,
    tangent: Tangent,
) {
    match layout.flclw {
        FlclwCoding::Index => enc.raw(
            s.flclw as u64,
            index_bits(faces as u64),
            Connectivity,
            PmField::Flclw.name(),
        ),
        FlclwCoding::Delta => {
            let delta = (s.flclw as u64 + faces as u64 - previous.min(faces) as u64) % faces as u64;
            enc.uint(
                &mut ctx.delta_flclw,
                delta,
                Connectivity,
                PmField::Flclw.name(),
            );
        }
    }
    enc.bit(
        &mut ctx.vs_index[0],
        s.vs_index == 0,
        Connectivity,
        PmField::VsIndex.name(),
    );
    if s.vs_index != 0 {
        enc.bit(
            &mut ctx.vs_index[1],
            s.vs_index == 1,
            Connectivity,
            PmField::VsIndex.name(),
        );
    }
    enc.uint(
        &mut ctx.vlr_rot,
        rotation_symbol(s.vlr_rot),
        Connectivity,
        PmField::VlrRot.name(),
    );
    enc.bit(&mut ctx.ii[0], s.ii == 2, Geometry, PmField::Ii.name());
    if s.ii != 2 {
        enc.bit(&mut ctx.ii[1], s.ii == 0, Geometry, PmField::Ii.name());
    }
    let (i, j, k) = tangent.axes();
    enc.int(
        &mut ctx.vad_l[0],
        s.vad_l[i] as i64 - tangent.guess[i],
        Geometry,
        PmField::VadL.name(),
    );
    enc.int(
        &mut ctx.vad_l[1],
        s.vad_l[j] as i64 - tangent.guess[j],
        Geometry,
        PmField::VadL.name(),
    );
    let residual = s.vad_l[k] as i64 - tangent.predict(s.vad_l[i], s.vad_l[j]);
    enc.int(&mut ctx.vad_l[2], residual, Geometry, PmField::VadL.name());
    if layout.with_vad_s {
        let step = vad_s_step(s.vad_l);
        for a in 0..3 {
            enc.int(
                &mut ctx.vad_s[a],
                (s.vad_s[a] / step) as i64,
                Geometry,
                PmField::VadS.name(),
            );
        }
    }
}

/// Reads one vsplit (see [`put_split`]); `None` when the bits are exhausted or out of range.
pub fn get_split(
    dec: &mut ArithDecoder,
    ctx: &mut SplitContexts,
    faces: u32,
    previous: u32,
    layout: Layout,
    tangent: impl Fn(&Vsplit) -> Tangent,
) -> Option<Vsplit> {
    let flclw = match layout.flclw {
        FlclwCoding::Index => dec.raw(index_bits(faces as u64))?.min(u32::MAX as u64),
        FlclwCoding::Delta => {
            let delta = dec.uint(&mut ctx.delta_flclw)?;
            (previous as u64).checked_add(delta)? % (faces as u64).max(1)
        }
    };
    let vs_index = if dec.bit(&mut ctx.vs_index[0])? {
        0
    } else if dec.bit(&mut ctx.vs_index[1])? {
        1
    } else {
        2
    };
    let vlr_rot = rotation_of(dec.uint(&mut ctx.vlr_rot)?)?;
    let ii = if dec.bit(&mut ctx.ii[0])? {
        2
    } else if dec.bit(&mut ctx.ii[1])? {
        0
    } else {
        1
    };
    let located = Vsplit {
        flclw: u32::try_from(flclw).ok()?,
        vs_index,
        vlr_rot,
        ii,
        vad_l: [0; 3],
        vad_s: [0; 3],
    };
    let tangent = tangent(&located);
    let (i, j, k) = tangent.axes();
    let mut vad_l = [0i32; 3];
    vad_l[i] = i32::try_from(dec.int(&mut ctx.vad_l[0])?.checked_add(tangent.guess[i])?).ok()?;
    vad_l[j] = i32::try_from(dec.int(&mut ctx.vad_l[1])?.checked_add(tangent.guess[j])?).ok()?;
    let residual = dec.int(&mut ctx.vad_l[2])?;
    vad_l[k] = i32::try_from(residual.checked_add(tangent.predict(vad_l[i], vad_l[j]))?).ok()?;
    let mut vad_s = [0i32; 3];
    if layout.with_vad_s {
        let step = vad_s_step(vad_l);
        for (value, context) in vad_s.iter_mut().zip(ctx.vad_s.iter_mut()) {
            *value = i32::try_from(dec.int(context)?).ok()?.checked_mul(step)?;
        }
    }
    Some(Vsplit {
        flclw: u32::try_from(flclw).ok()?,
        vs_index,
        vlr_rot,
        ii,
        vad_l,
        vad_s,
    })
}
