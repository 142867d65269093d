//! How appearance attributes are quantized (docs/CONTRACT.md §2.1): texture coordinates on a
//! square grid of 2^Qt cells over their bounding box, normals as octahedral codes of Qn bits a
//! coordinate, colours on 8 bits a channel.
//!
//! Glossary: Qt (`uv_bits`) bits per uv axis; Qn (`normal_bits`) bits per octahedral
//! coordinate; an **octahedral code** is the pair (a, b), each in 0 ..= 2^Qn − 2, of the point
//! where the normal meets the octahedron |x| + |y| + |z| = 1, the lower half folded out over the
//! upper half's square (Meyer et al. 2010, as Draco). One code is kept out of the 2^Qn so that
//! the square has a centre cell: the axis directions are exact.

use crate::error::{Error, Result};
use glam::{DVec2, DVec3};

/// Default bits per uv axis (Qt).
pub const DEFAULT_UV_BITS: u8 = 12;
/// Default bits per octahedral normal coordinate (Qn).
pub const DEFAULT_NORMAL_BITS: u8 = 10;
/// Most bits per uv axis.
pub const MAX_UV_BITS: u8 = 24;
/// Fewest and most bits per octahedral coordinate.
pub const NORMAL_BITS_RANGE: std::ops::RangeInclusive<u8> = 2..=16;

/// The bits attributes are quantized to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AttributeBits {
    /// Qt: bits per uv axis.
    pub uv: u8,
    /// Qn: bits per octahedral normal coordinate.
    pub normal: u8,
    /// Normals derived from the positions over each normal wedge (the input's normals say only
    /// where creases are; [`super::derived_normals`]) instead of the input's own.
    pub derive_normals: bool,
}

impl Default for AttributeBits {
    fn default() -> Self {
        AttributeBits {
            uv: DEFAULT_UV_BITS,
            normal: DEFAULT_NORMAL_BITS,
            derive_normals: false,
        }
    }
}

impl AttributeBits {
    /// Refuses bit counts outside what the format holds.
    pub fn check(&self) -> Result<()> {
        if self.uv == 0 || self.uv > MAX_UV_BITS {
            return Err(Error::Unsupported(format!(
                "uv quantization of {} bits (1 to {MAX_UV_BITS} are supported)",
                self.uv
            )));
        }
        if !NORMAL_BITS_RANGE.contains(&self.normal) {
            return Err(Error::Unsupported(format!(
                "normal quantization of {} bits ({} to {} are supported)",
                self.normal,
                NORMAL_BITS_RANGE.start(),
                NORMAL_BITS_RANGE.end()
            )));
        }
        Ok(())
    }
}

/// The grid texture coordinates are quantized on: square cells, 2^bits along the longer side
/// of the uvs' bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvGrid {
    /// Bits per axis (Qt).
    pub bits: u8,
    /// The box's minimum corner.
    pub origin: [f64; 2],
    /// The side of a cell.
    pub cell: f64,
}

impl UvGrid {
    /// The grid of `bits` over `uvs` (all finite), or `None` when there are none.
    pub fn fit(uvs: impl IntoIterator<Item = DVec2>, bits: u8) -> Result<Option<UvGrid>> {
        let mut bounds: Option<(DVec2, DVec2)> = None;
        for t in uvs {
            if !t.is_finite() {
                return Err(Error::mesh(format!(
                    "texture coordinate ({}, {}) is not finite",
                    t.x, t.y
                )));
            }
            bounds = Some(match bounds {
                None => (t, t),
                Some((lo, hi)) => (lo.min(t), hi.max(t)),
            });
        }
        let Some((lo, hi)) = bounds else {
            return Ok(None);
        };
        let side = (hi - lo).max_element();
        // A single uv value still needs a positive cell to divide by.
        let side = if side > 0.0 { side } else { 1.0 };
        Ok(Some(UvGrid {
            bits,
            origin: lo.to_array(),
            cell: side / (1u64 << bits) as f64,
        }))
    }

    /// Whether the grid's numbers are usable (finite, positive cell, far corner finite).
    pub fn is_valid(&self) -> bool {
        self.bits >= 1
            && self.bits <= MAX_UV_BITS
            && self.origin.iter().all(|o| o.is_finite())
            && self.cell.is_finite()
            && self.cell > 0.0
            && self
                .origin
                .iter()
                .all(|o| (o + self.cell * (1u64 << self.bits) as f64).is_finite())
    }

    /// The cell of `t`, clamped to the grid.
    pub fn quantize(&self, t: DVec2) -> [u32; 2] {
        let last = ((1u64 << self.bits) - 1) as f64;
        let axis = |x: f64, o: f64| ((x - o) / self.cell).floor().clamp(0.0, last) as u32;
        [axis(t.x, self.origin[0]), axis(t.y, self.origin[1])]
    }

    /// The centre of cell `q`.
    pub fn dequantize(&self, q: [u32; 2]) -> DVec2 {
        DVec2::new(
            self.origin[0] + (q[0] as f64 + 0.5) * self.cell,
            self.origin[1] + (q[1] as f64 + 0.5) * self.cell,
        )
    }
}

/// The largest octahedral coordinate on `bits` bits: codes run 0 ..= this (an even number, so
/// the centre `max / 2` exists).
pub fn octahedral_max(bits: u8) -> u32 {
    (1u32 << bits) - 2
}

/// The octahedral code of normal `n` on `bits` bits a coordinate: the canonical one, so that
/// `octahedral_code(octahedral_normal(c)) == c` for every code this returns. A normal of zero
/// length or with a non-finite coordinate has no direction; it is coded as +z.
pub fn octahedral_code(n: DVec3, bits: u8) -> [u32; 2] {
    let first = raw_code(n, bits);
    // Points on the square's border stand for one normal twice (the fold); decoding and
    // coding again picks one of them, and that one is a fixed point.
    raw_code(octahedral_normal(first, bits), bits)
}

fn raw_code(n: DVec3, bits: u8) -> [u32; 2] {
    let l1 = n.x.abs() + n.y.abs() + n.z.abs();
    let n = if l1 > 0.0 && l1.is_finite() {
        n / l1
    } else {
        DVec3::Z
    };
    let sign = |x: f64| if x < 0.0 { -1.0 } else { 1.0 };
    let (u, v) = if n.z >= 0.0 {
        (n.x, n.y)
    } else {
        ((1.0 - n.y.abs()) * sign(n.x), (1.0 - n.x.abs()) * sign(n.y))
    };
    let max = octahedral_max(bits) as f64;
    let half = max / 2.0;
    let coordinate = |x: f64| (x * half + half).round().clamp(0.0, max) as u32;
    [coordinate(u), coordinate(v)]
}

/// The unit normal of octahedral code `c` on `bits` bits.
pub fn octahedral_normal(c: [u32; 2], bits: u8) -> DVec3 {
    let half = (octahedral_max(bits) / 2) as f64;
    let u = c[0] as f64 / half - 1.0;
    let v = c[1] as f64 / half - 1.0;
    let z = 1.0 - u.abs() - v.abs();
    let sign = |x: f64| if x < 0.0 { -1.0 } else { 1.0 };
    let (x, y) = if z >= 0.0 {
        (u, v)
    } else {
        ((1.0 - v.abs()) * sign(u), (1.0 - u.abs()) * sign(v))
    };
    DVec3::new(x, y, z).normalize()
}

/// A colour channel in [0, 1] on 8 bits (values outside are clamped; NaN is 0).
pub fn colour_code(c: [f64; 4]) -> [u8; 4] {
    c.map(|x| {
        if x.is_nan() {
            0
        } else {
            (x.clamp(0.0, 1.0) * 255.0).round() as u8
        }
    })
}

/// The colour of an 8-bit code.
pub fn colour_value(c: [u8; 4]) -> [f64; 4] {
    c.map(|x| x as f64 / 255.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_canonical_octahedral_code_is_a_fixed_point() {
        for bits in [2u8, 3, 4, 5, 8, 10] {
            let max = octahedral_max(bits);
            for a in 0..=max {
                for b in 0..=max {
                    let c = octahedral_code(octahedral_normal([a, b], bits), bits);
                    let again = octahedral_code(octahedral_normal(c, bits), bits);
                    assert_eq!(c, again, "bits {bits}, code {a} {b}");
                }
            }
        }
    }

    #[test]
    fn octahedral_codes_are_close_and_axes_exact() {
        let bits = 10;
        for n in [
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_Z,
        ] {
            let back = octahedral_normal(octahedral_code(n, bits), bits);
            assert!((back - n).length() < 1e-12, "{n} came back as {back}");
        }
        // 10 bits: the worst angle is well under half a degree.
        let mut worst: f64 = 0.0;
        for i in 0..2000 {
            let t = i as f64 * 0.618_033_988_7;
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / 2000.0;
            let r = (1.0 - z * z).sqrt();
            let n = DVec3::new(
                r * (t * std::f64::consts::TAU).cos(),
                r * (t * std::f64::consts::TAU).sin(),
                z,
            );
            let back = octahedral_normal(octahedral_code(n, bits), bits);
            worst = worst.max(n.angle_between(back));
        }
        assert!(worst.to_degrees() < 0.5, "{}", worst.to_degrees());
        assert_eq!(
            octahedral_code(DVec3::ZERO, bits),
            octahedral_code(DVec3::Z, bits)
        );
    }

    #[test]
    fn uv_cells_and_colours_requantize_exactly() {
        let uvs = [
            DVec2::new(0.1, 0.2),
            DVec2::new(0.9, 0.4),
            DVec2::new(0.5, 0.25),
        ];
        let grid = UvGrid::fit(uvs, 12).unwrap().unwrap();
        assert!(grid.is_valid());
        for t in uvs {
            let q = grid.quantize(t);
            assert_eq!(grid.quantize(grid.dequantize(q)), q);
            assert!((grid.dequantize(q) - t).abs().max_element() <= grid.cell);
        }
        for k in 0..=255u8 {
            assert_eq!(colour_code(colour_value([k, 0, k, 255])), [k, 0, k, 255]);
        }
        assert!(UvGrid::fit([DVec2::new(f64::NAN, 0.0)], 12).is_err());
        assert_eq!(UvGrid::fit([], 12).unwrap(), None);
    }
}
