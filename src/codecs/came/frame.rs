//! A meta-node's coordinate frame for `came-paper` (Grabner §3.3.1): the principal axes of its
//! difference vectors, the constant c bounding the normalized vectors d̃ = c·2^(l/2)·d, and the
//! uniform quantizer of their components.
//!
//! The paper gives the frame and c no coding of their own, so they are sent as they are: e1, e2,
//! e3 as nine 32-bit floats and 1/c as one (rounded up, so that |d̃| ≤ 1 holds), used as decoded
//! so that encoder and decoder project alike. (Table 3's coordinate column, 2.62M bits for the
//! bunny's 69,668 difference vectors, is 37.6 bits a vector against 15 for the components
//! alone: a per-meta-node cost of this order.) The "maximum number of bits per component" B is
//! the first axis's: an axis whose components all lie within 2^−k gets B − k bits over
//! [−2^−k, 2^−k], so every axis keeps the same step 2/2^B.

use crate::coding::BitSource;
use glam::DVec3;

/// Bits of each axis's range exponent k.
const RANGE_BITS: u32 = 4;
/// Bits a frame takes in the stream: nine floats for the axes, one for 1/c, three ranges.
pub const FRAME_BITS: u32 = 10 * 32 + 3 * RANGE_BITS;

/// A decoded frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// e1, e2, e3 (orthonormal to float precision).
    pub axes: [DVec3; 3],
    /// 1/c.
    scale: f32,
    /// Per axis: its components lie within 2^−k.
    range: [u32; 3],
}

/// The eigenvectors of a symmetric 3×3 matrix, largest eigenvalue first (cyclic Jacobi).
pub fn principal_axes(m: [[f64; 3]; 3]) -> [DVec3; 3] {
    let mut a = m;
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..32 {
        let off = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
        if off <= 1e-30 * (a[0][0].powi(2) + a[1][1].powi(2) + a[2][2].powi(2)) || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← Jᵀ A J, V ← V J for the rotation J in the (p, q) plane.
            for row in &mut a {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (rp, rq) = (a[p], a[q]);
            a[p] = [0, 1, 2].map(|k| c * rp[k] - s * rq[k]);
            a[q] = [0, 1, 2].map(|k| s * rp[k] + c * rq[k]);
            for row in &mut v {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| a[j][j].total_cmp(&a[i][i]));
    let column = |i: usize| DVec3::new(v[0][i], v[1][i], v[2][i]).normalize_or(DVec3::X);
    let e1 = column(order[0]);
    let e2 = column(order[1]);
    // The third axis closes a right-handed frame.
    let e2 = (e2 - e1 * e1.dot(e2)).normalize_or(e1.any_orthonormal_vector());
    [e1, e2, e1.cross(e2)]
}

impl Frame {
    /// The frame of a meta-node's difference vectors `d`, each with its depth l below the
    /// meta-node's root, for `bits` bits per component.
    pub fn fit(vectors: &[(DVec3, u8)], bits: u8) -> Frame {
        let mut m = [[0.0; 3]; 3];
        for &(d, _) in vectors {
            let d = d.to_array();
            for (i, row) in m.iter_mut().enumerate() {
                for (j, x) in row.iter_mut().enumerate() {
                    *x += d[i] * d[j];
                }
            }
        }
        let axes = principal_axes(m).map(|e| e.as_vec3().as_dvec3());
        // 1/c: the longest normalized vector, rounded up to a float (and kept above zero).
        let longest = vectors
            .iter()
            .map(|&(d, l)| d.length() * normalization(l))
            .fold(f64::MIN_POSITIVE, f64::max);
        let mut scale = longest as f32;
        if (scale as f64) < longest {
            scale = f32::from_bits(scale.to_bits() + 1);
        }
        let scale = scale.max(f32::MIN_POSITIVE);
        let mut range = [0u32; 3];
        for (axis, k) in range.iter_mut().enumerate() {
            let widest = vectors
                .iter()
                .map(|&(d, l)| (d.dot(axes[axis]) * normalization(l) / scale as f64).abs())
                .fold(0.0, f64::max);
            let free = if widest > 0.0 {
                (-widest.log2()).floor()
            } else {
                64.0
            };
            *k = free.clamp(0.0, (bits as f64 - 1.0).max(0.0)) as u32;
        }
        Frame { axes, scale, range }
    }

    /// The frame's fields as (bits, value), in stream order ([`FRAME_BITS`] bits in all).
    pub fn fields(&self) -> Vec<(u32, u32)> {
        let floats = self
            .axes
            .iter()
            .flat_map(|e| e.to_array())
            .map(|x| x as f32)
            .chain([self.scale]);
        floats
            .map(|x| (32, x.to_bits()))
            .chain(self.range.map(|k| (RANGE_BITS, k)))
            .collect()
    }

    /// Reads a frame for `bits` bits per component; `None` when the bits run out, an axis is
    /// no unit vector, 1/c is no positive number or an axis's range leaves it no bit.
    pub fn read(source: &mut BitSource, bits: u8) -> Option<Frame> {
        let mut axes = [DVec3::ZERO; 3];
        for e in &mut axes {
            for x in [&mut e.x, &mut e.y, &mut e.z] {
                *x = f32::from_bits(source.get(32)?) as f64;
            }
            if !e.is_finite() || (e.length() - 1.0).abs() > 1e-3 {
                return None;
            }
        }
        let scale = f32::from_bits(source.get(32)?);
        if !(scale.is_finite() && scale > 0.0) {
            return None;
        }
        let mut range = [0u32; 3];
        for k in &mut range {
            *k = source.get(RANGE_BITS)?;
            if *k >= bits as u32 {
                return None;
            }
        }
        Some(Frame { axes, scale, range })
    }

    /// Bits of each axis's components.
    pub fn component_bits(&self, bits: u8) -> [u32; 3] {
        self.range.map(|k| bits as u32 - k)
    }

    /// The quantized components of difference vector `d` at depth `l`.
    pub fn quantize(&self, d: DVec3, l: u8, bits: u8) -> [u32; 3] {
        let to_unit = normalization(l) / self.scale as f64;
        let step = 2.0 / (1u64 << bits) as f64;
        let widths = self.component_bits(bits);
        [0, 1, 2].map(|axis| {
            let half = 2f64.powi(-(self.range[axis] as i32));
            let x = d.dot(self.axes[axis]) * to_unit;
            let top = (1u64 << widths[axis]) - 1;
            ((x + half) / step).floor().clamp(0.0, top as f64) as u32
        })
    }

    /// The difference vector that quantized components `q` at depth `l` stand for.
    pub fn dequantize(&self, q: [u32; 3], l: u8, bits: u8) -> DVec3 {
        let to_grid = self.scale as f64 / normalization(l);
        let step = 2.0 / (1u64 << bits) as f64;
        (0..3)
            .map(|axis| {
                let half = 2f64.powi(-(self.range[axis] as i32));
                self.axes[axis] * ((-half + (q[axis] as f64 + 0.5) * step) * to_grid)
            })
            .sum()
    }
}

/// 2^(l/2): the paper's normalization of a difference vector l levels below the meta-node's root.
pub fn normalization(l: u8) -> f64 {
    2f64.powf(l as f64 / 2.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coding::{BitSink, SyntaxClass};

    #[test]
    fn principal_axes_are_found_largest_first() {
        // Vectors spread mostly along (1, 1, 0), less along z, least along (1, −1, 0).
        let a = DVec3::new(1.0, 1.0, 0.0).normalize();
        let b = DVec3::Z;
        let c = DVec3::new(1.0, -1.0, 0.0).normalize();
        let mut m = [[0.0; 3]; 3];
        for (v, w) in [(a, 9.0), (b, 4.0), (c, 1.0)] {
            for i in 0..3 {
                for j in 0..3 {
                    m[i][j] += w * v[i] * v[j];
                }
            }
        }
        let [e1, e2, e3] = principal_axes(m);
        assert!(e1.dot(a).abs() > 0.999_999, "{e1}");
        assert!(e2.dot(b).abs() > 0.999_999, "{e2}");
        assert!(e3.dot(c).abs() > 0.999_999, "{e3}");
        assert!((e1.cross(e2).dot(e3) - 1.0).abs() < 1e-9);
    }

    #[test]
    fn quantized_vectors_come_back_within_half_a_step_per_axis() {
        let vectors: Vec<(DVec3, u8)> = (0..60)
            .map(|i| {
                let t = i as f64 * 0.37;
                let l = (i % 8) as u8;
                let d = DVec3::new(t.sin() * 9.0, t.cos() * 4.0, (t * 3.0).sin() * 0.2);
                (d / normalization(l), l)
            })
            .collect();
        for bits in [3u8, 5, 8] {
            let frame = Frame::fit(&vectors, bits);
            let mut sink = BitSink::default();
            for (width, value) in frame.fields() {
                sink.put(SyntaxClass::Geometry, width, value);
            }
            let (bytes, ledger) = sink.finish();
            assert_eq!(ledger.total(), FRAME_BITS as u64);
            let read = Frame::read(&mut BitSource::new(&bytes), bits).unwrap();
            assert_eq!(read, frame);
            // The flat third axis gets fewer bits than the first.
            let widths = frame.component_bits(bits);
            assert!(widths[2] < widths[0], "{widths:?}");
            let step = 2.0 / (1u64 << bits) as f64 * frame.scale as f64;
            for &(d, l) in &vectors {
                let back = frame.dequantize(frame.quantize(d, l, bits), l, bits);
                for axis in 0..3 {
                    let error = (back - d).dot(frame.axes[axis]).abs() * normalization(l);
                    assert!(
                        error <= step / 2.0 + 1e-5,
                        "{bits} bits: {error} > {step}/2"
                    );
                }
            }
        }
    }
}
