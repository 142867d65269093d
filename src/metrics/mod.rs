//! Metrics of docs/CONTRACT.md §5: surface sampling, exact point-to-surface distance through a BVH, and
//! the symmetric Hausdorff / RMS / paper measures of a decoded level against the original.

pub mod appearance;
pub mod distance;
pub mod sampling;

pub use distance::SurfaceIndex;
pub use sampling::{sample_faces, sample_surface, FacePoint, Samples};

use crate::codecs::LevelMesh;
use crate::mesh::TriMesh;
use serde::Serialize;

/// Samples per original triangle when the user does not say (docs/CONTRACT.md §5).
pub const DEFAULT_SAMPLES_PER_TRIANGLE: usize = 10;
/// Seed of the sampler, so that every run measures the same points.
pub const DEFAULT_SEED: u64 = 0x5eed_f3e5;

/// One direction of a comparison: distances from samples of one mesh to the other's surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct OneSided {
    /// Largest distance.
    pub max: f64,
    /// Mean distance.
    pub mean: f64,
    /// Root of the mean squared distance.
    pub rms: f64,
    /// Sum of squared distances (to combine directions).
    #[serde(skip)]
    pub sum_squares: f64,
    /// Number of samples.
    pub samples: usize,
}

impl OneSided {
    /// Statistics of `distances`.
    pub fn of(distances: &[f64]) -> OneSided {
        let n = distances.len().max(1) as f64;
        let sum: f64 = distances.iter().sum();
        let sum_squares: f64 = distances.iter().map(|d| d * d).sum();
        OneSided {
            max: distances.iter().copied().fold(0.0, f64::max),
            mean: sum / n,
            rms: (sum_squares / n).sqrt(),
            sum_squares,
            samples: distances.len(),
        }
    }
}

/// How far a decoded level is from the original, relative to the original's bounding-box
/// diagonal.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LevelDistance {
    /// Symmetric Hausdorff distance: max(h(original, level), h(level, original)).
    pub hausdorff: f64,
    /// RMS over the samples of both directions.
    pub rms: f64,
    /// EMC's measure: largest distance from an original vertex to the level's surface.
    pub hausdorff_paper: f64,
}

/// The original mesh prepared once for comparisons with many levels: its samples and its BVH.
pub struct Reference {
    /// Samples of the original (its vertices first).
    pub samples: Samples,
    /// Distance queries against the original's surface.
    pub index: SurfaceIndex,
    /// Length of the original's bounding-box diagonal.
    pub diagonal: f64,
    /// How many random samples to take on the other mesh.
    pub random_samples: usize,
    /// Seed for those samples.
    pub seed: u64,
}

impl Reference {
    /// Prepares `original` with `per_triangle` random samples per triangle.
    pub fn new(original: &TriMesh, per_triangle: usize, seed: u64) -> Reference {
        let random_samples = per_triangle * original.faces.len();
        let diagonal = original
            .referenced_bounds()
            .map(|b| b.diagonal())
            .filter(|d| *d > 0.0)
            .unwrap_or(1.0);
        Reference {
            samples: sample_surface(original, random_samples, seed),
            index: SurfaceIndex::of_mesh(original, &[]),
            diagonal,
            random_samples,
            seed,
        }
    }

    /// Distances both ways between the original and `level`, relative to the original's
    /// diagonal; `None` for a level with no vertex.
    pub fn compare(&self, level: &LevelMesh) -> Option<LevelDistance> {
        let m = self.measure(level)?;
        Some(LevelDistance {
            hausdorff: m.hausdorff() / self.diagonal,
            rms: m.rms() / self.diagonal,
            hausdorff_paper: m.paper / self.diagonal,
        })
    }

    /// Distances both ways in absolute units; `None` for a level with no vertex.
    pub fn measure(&self, level: &LevelMesh) -> Option<Measurement> {
        if level.mesh.positions.is_empty() {
            return None;
        }
        let level_index = SurfaceIndex::of_mesh(&level.mesh, &level.loose_edges);
        let to_level = level_index.distances(&self.samples.points);
        let paper = to_level[..self.samples.vertices]
            .iter()
            .copied()
            .fold(0.0, f64::max);
        let level_samples = sample_surface(&level.mesh, self.random_samples, self.seed ^ 1);
        let to_original = self.index.distances(&level_samples.points);
        Some(Measurement {
            forward: OneSided::of(&to_level),
            backward: OneSided::of(&to_original),
            paper,
            level_samples,
            to_level,
            to_original,
        })
    }
}

/// Both directions of a comparison, with the samples and distances behind them.
pub struct Measurement {
    /// Original samples → level surface.
    pub forward: OneSided,
    /// Level samples → original surface.
    pub backward: OneSided,
    /// Largest distance of an original vertex to the level (EMC's measure), absolute.
    pub paper: f64,
    /// The samples taken on the level.
    pub level_samples: Samples,
    /// Distance of each original sample to the level.
    pub to_level: Vec<f64>,
    /// Distance of each level sample to the original.
    pub to_original: Vec<f64>,
}

impl Measurement {
    /// Symmetric Hausdorff distance: the larger one-sided maximum.
    pub fn hausdorff(&self) -> f64 {
        self.forward.max.max(self.backward.max)
    }

    /// RMS over the samples of both directions together.
    pub fn rms(&self) -> f64 {
        let samples = (self.forward.samples + self.backward.samples).max(1) as f64;
        ((self.forward.sum_squares + self.backward.sum_squares) / samples).sqrt()
    }
}
