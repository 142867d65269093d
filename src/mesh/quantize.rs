//! The quantization grid of docs/CONTRACT.md §1.
//!
//! Cell index q = min(floor((x − origin) / c), 2^Q − 1) per axis; a decoded vertex sits at the
//! cell centre origin + (q + ½)c, so decoded positions re-quantize to the same cell.

use super::{Aabb, TriMesh};
use crate::error::{Error, Result};
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// Largest number of bits per axis a grid may have: cell indices fit a `u32` with room to spare.
pub const MAX_QUANT_BITS: u8 = 30;

/// How the cell size is chosen from the bounding box.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum GridShape {
    /// One cell size on every axis: (largest extent) / 2^Q, as Draco (the default: docs/CONTRACT.md §1).
    #[default]
    Cubic,
    /// Each axis divided into 2^Q cells of its own extent (EMC's box).
    PerAxis,
}

/// A quantization grid: origin, cell size per axis, and bits per axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Grid {
    /// Smallest corner of the grid.
    pub origin: [f64; 3],
    /// Cell size on each axis.
    pub cell: [f64; 3],
    /// Bits per axis (Q): 2^Q cells along each axis.
    pub bits: u8,
}

impl Grid {
    /// The grid of `shape` with `bits` per axis over the referenced vertices of `mesh`.
    pub fn fit(mesh: &TriMesh, bits: u8, shape: GridShape) -> Result<Grid> {
        let bounds = mesh
            .referenced_bounds()
            .ok_or_else(|| Error::mesh("empty mesh: no vertices"))?;
        Grid::over(bounds, bits, shape)
    }

    /// The grid of `shape` with `bits` per axis over `bounds`.
    pub fn over(bounds: Aabb, bits: u8, shape: GridShape) -> Result<Grid> {
        if bits == 0 || bits > MAX_QUANT_BITS {
            return Err(Error::Unsupported(format!(
                "quantization of {bits} bits (1 to {MAX_QUANT_BITS} are supported)"
            )));
        }
        let cells = (1u64 << bits) as f64;
        let extent = bounds.extent();
        // A flat or point-like mesh still needs a positive cell size to divide by.
        let positive = |e: f64, fallback: f64| if e > 0.0 { e } else { fallback };
        let largest = positive(extent.max_element(), 1.0);
        let cell = match shape {
            GridShape::Cubic => DVec3::splat(largest / cells),
            GridShape::PerAxis => DVec3::new(
                positive(extent.x, largest) / cells,
                positive(extent.y, largest) / cells,
                positive(extent.z, largest) / cells,
            ),
        };
        Ok(Grid {
            origin: bounds.min.to_array(),
            cell: cell.to_array(),
            bits,
        })
    }

    /// Number of cells along each axis.
    pub fn cells_per_axis(&self) -> u32 {
        1u32 << self.bits
    }

    /// The cell that contains `p`.
    pub fn quantize(&self, p: DVec3) -> [u32; 3] {
        let top = (self.cells_per_axis() - 1) as f64;
        let q = (p - DVec3::from(self.origin)) / DVec3::from(self.cell);
        let axis = |v: f64| v.floor().clamp(0.0, top) as u32;
        [axis(q.x), axis(q.y), axis(q.z)]
    }

    /// The centre of cell `q`.
    pub fn dequantize(&self, q: [u32; 3]) -> DVec3 {
        let q = DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64);
        DVec3::from(self.origin) + (q + 0.5) * DVec3::from(self.cell)
    }

    /// Centre of a cell of a coarser level: `q` indexes cells `2^shift` times larger than ours on
    /// each axis (shift per axis), as an octree node at depth `bits − shift` sees them.
    pub fn coarse_centre(&self, q: [u32; 3], shift: [u8; 3]) -> DVec3 {
        let origin = DVec3::from(self.origin);
        let cell = DVec3::from(self.cell);
        let axis = |i: usize| {
            let size = cell[i] * (1u64 << shift[i]) as f64;
            origin[i] + (q[i] as f64 + 0.5) * size
        };
        DVec3::new(axis(0), axis(1), axis(2))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centres_requantize_to_their_cell() {
        let bounds = Aabb {
            min: DVec3::new(-1.3, 0.2, 5.0),
            max: DVec3::new(2.1, 0.9, 5.5),
        };
        for bits in [1u8, 7, 12, 24, 30] {
            let grid = Grid::over(bounds, bits, GridShape::Cubic).unwrap();
            let top = grid.cells_per_axis() - 1;
            for q in [[0, 0, 0], [top, top / 2, 1], [top / 3, top, top]] {
                assert_eq!(grid.quantize(grid.dequantize(q)), q, "bits {bits}");
            }
        }
    }

    #[test]
    fn largest_corner_falls_in_the_last_cell() {
        let bounds = Aabb {
            min: DVec3::ZERO,
            max: DVec3::new(4.0, 2.0, 1.0),
        };
        let grid = Grid::over(bounds, 3, GridShape::Cubic).unwrap();
        assert_eq!(grid.quantize(bounds.max), [7, 4, 2]);
        let per_axis = Grid::over(bounds, 3, GridShape::PerAxis).unwrap();
        assert_eq!(per_axis.quantize(bounds.max), [7, 7, 7]);
    }

    #[test]
    fn rejects_zero_and_too_many_bits() {
        let bounds = Aabb {
            min: DVec3::ZERO,
            max: DVec3::ONE,
        };
        assert!(Grid::over(bounds, 0, GridShape::Cubic).is_err());
        assert!(Grid::over(bounds, 31, GridShape::Cubic).is_err());
    }
}
