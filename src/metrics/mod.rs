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
/// Most random samples a direction when the user does not say (docs/CONTRACT.md §5): enough
/// that a level's Hausdorff and RMS distances on the 1.1M-triangle mesh are within 2% of what
/// ten samples a triangle give (BENCHMARKS.md), so that measuring does not grow with the mesh.
pub const DEFAULT_MAX_SAMPLES: usize = 1_000_000;

/// How many random samples a comparison takes on each surface: `per_triangle` for every
/// triangle of the original, at most `max`. Each mesh's vertices are sampled besides.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleBudget {
    /// Random samples per original triangle.
    pub per_triangle: usize,
    /// Most random samples a direction.
    pub max: usize,
}

impl Default for SampleBudget {
    fn default() -> Self {
        SampleBudget {
            per_triangle: DEFAULT_SAMPLES_PER_TRIANGLE,
            max: DEFAULT_MAX_SAMPLES,
        }
    }
}

impl SampleBudget {
    /// `per_triangle` a triangle, capped at the default maximum.
    pub fn per_triangle(per_triangle: usize) -> SampleBudget {
        SampleBudget {
            per_triangle,
            ..SampleBudget::default()
        }
    }

    /// Random samples a direction for an original of `triangles` triangles.
    pub fn count(&self, triangles: usize) -> usize {
        self.per_triangle.saturating_mul(triangles).min(self.max)
    }
}
/// Seed of the sampler, so that every run measures the same points.
pub const DEFAULT_SEED: u64 = 0x5eed_f3e5;

/// One direction of a comparison: distances from samples of one mesh to the other's surface.
///
/// The samples are a mesh's vertices and random points; when the budget capped the random
/// points, each stands for several (`random_weight`), so that mean and RMS estimate what the
/// uncapped count would give (docs/CONTRACT.md §5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct OneSided {
    /// Largest distance.
    pub max: f64,
    /// Mean distance.
    pub mean: f64,
    /// Root of the mean squared distance.
    pub rms: f64,
    /// Weighted sum of squared distances (to combine directions).
    #[serde(skip)]
    pub sum_squares: f64,
    /// Total weight of the samples: the vertices, and the random points as many as they stand
    /// for.
    #[serde(skip)]
    pub weight: f64,
    /// Weighted variance of the random points' squared distances over the total weight
    /// squared, times their count: the random part's share of the mean square's variance.
    #[serde(skip)]
    pub random_variance: f64,
    /// Largest distance over the vertices and every second random sample: how much the
    /// maximum still grew from half the samples to all of them.
    #[serde(skip)]
    pub half_max: f64,
    /// Number of samples.
    pub samples: usize,
}

impl OneSided {
    /// Statistics of `distances`, of which the first `vertices` are a mesh's vertices and the
    /// rest random samples, each of those standing for `random_weight` samples (1 when the
    /// budget did not cap them).
    pub fn of(distances: &[f64], vertices: usize, random_weight: f64) -> OneSided {
        let vertices = vertices.min(distances.len());
        let (at_vertices, random) = distances.split_at(vertices);
        let squares = |d: &[f64]| d.iter().map(|d| d * d).sum::<f64>();
        let w = random_weight;
        let weight = vertices as f64 + w * random.len() as f64;
        let norm = weight.max(1.0);
        let sum = at_vertices.iter().sum::<f64>() + w * random.iter().sum::<f64>();
        let random_squares = squares(random);
        let sum_squares = squares(at_vertices) + w * random_squares;
        // The vertices are fixed points; only the random ones vary from seed to seed.
        let random_variance = if random.len() > 1 {
            let n = random.len() as f64;
            let mean_square = random_squares / n;
            let mean_fourth = random.iter().map(|d| (d * d) * (d * d)).sum::<f64>() / n;
            let spread = (mean_fourth - mean_square * mean_square).max(0.0);
            // Var(Σ w d²) = w² n Var(d²).
            w * w * n * spread
        } else {
            0.0
        };
        let half_max = at_vertices
            .iter()
            .chain(random.iter().step_by(2))
            .copied()
            .fold(0.0, f64::max);
        OneSided {
            max: distances.iter().copied().fold(0.0, f64::max),
            mean: sum / norm,
            rms: (sum_squares / norm).sqrt(),
            sum_squares,
            weight,
            random_variance,
            half_max,
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
    /// How far the figures may be from the surfaces' own, from the samples (§5).
    pub uncertainty: Uncertainty,
}

/// How precisely a comparison's samples pin its figures down (docs/CONTRACT.md §5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Uncertainty {
    /// Samples taken: original → level, level → original (vertices included).
    pub samples: [usize; 2],
    /// Relative standard error of the RMS distance, as if the random samples were independent
    /// (the stratified samples are closer than that).
    pub rms: f64,
    /// What the Hausdorff distance gained from half the random samples to all of them,
    /// relative to it: about what doubling them would still add.
    pub hausdorff: f64,
}

/// The original mesh prepared once for comparisons with many levels: its samples and its BVH.
pub struct Reference {
    /// Samples of the original (its vertices first).
    pub samples: Samples,
    /// Distance queries against the original's surface.
    pub index: SurfaceIndex,
    /// Length of the original's bounding-box diagonal.
    pub diagonal: f64,
    /// How many random samples to take on the other mesh (as many as on the original).
    pub random_samples: usize,
    /// How many random samples a direction would take without the budget's cap: each sample
    /// taken stands for `uncapped_samples / random_samples`.
    pub uncapped_samples: usize,
    /// Seed for those samples.
    pub seed: u64,
}

impl Reference {
    /// Prepares `original` with the random samples `budget` gives its triangles.
    pub fn new(original: &TriMesh, budget: SampleBudget, seed: u64) -> Reference {
        let random_samples = budget.count(original.faces.len());
        let uncapped_samples = budget.per_triangle.saturating_mul(original.faces.len());
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
            uncapped_samples,
            seed,
        }
    }

    /// How many random samples each one taken stands for.
    fn random_weight(&self) -> f64 {
        if self.random_samples == 0 {
            1.0
        } else {
            (self.uncapped_samples as f64 / self.random_samples as f64).max(1.0)
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
            uncertainty: m.uncertainty(),
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
            forward: OneSided::of(&to_level, self.samples.vertices, self.random_weight()),
            backward: OneSided::of(&to_original, level_samples.vertices, self.random_weight()),
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

    /// RMS over the samples of both directions together (the random ones weighing what they
    /// stand for).
    pub fn rms(&self) -> f64 {
        let weight = (self.forward.weight + self.backward.weight).max(1.0);
        ((self.forward.sum_squares + self.backward.sum_squares) / weight).sqrt()
    }

    /// How precisely the samples pin the Hausdorff and RMS distances down.
    pub fn uncertainty(&self) -> Uncertainty {
        let weight = (self.forward.weight + self.backward.weight).max(1.0);
        let mean_square = (self.forward.sum_squares + self.backward.sum_squares) / weight;
        // The mean square's standard error, carried to its root (δ√m = δm / (2√m)), relative.
        let variance =
            (self.forward.random_variance + self.backward.random_variance) / (weight * weight);
        let rms = if mean_square > 0.0 {
            variance.sqrt() / (2.0 * mean_square)
        } else {
            0.0
        };
        let hausdorff = self.hausdorff();
        let half = self.forward.half_max.max(self.backward.half_max);
        Uncertainty {
            samples: [self.forward.samples, self.backward.samples],
            rms,
            hausdorff: if hausdorff > 0.0 {
                (hausdorff - half) / hausdorff
            } else {
                0.0
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    fn level(mesh: TriMesh) -> LevelMesh {
        LevelMesh {
            mesh,
            ..LevelMesh::default()
        }
    }

    #[test]
    fn the_budget_caps_the_samples_and_below_the_cap_changes_nothing() {
        let budget = SampleBudget {
            per_triangle: 10,
            max: 1000,
        };
        assert_eq!(budget.count(50), 500);
        assert_eq!(budget.count(5000), 1000);
        let original = generate::terrain(40, 3);
        let coarse = level(generate::terrain(8, 3));
        let uncapped = SampleBudget {
            per_triangle: 10,
            max: usize::MAX,
        };
        let under = SampleBudget {
            per_triangle: 10,
            max: 10 * original.faces.len(),
        };
        let a = Reference::new(&original, uncapped, 7)
            .compare(&coarse)
            .unwrap();
        let b = Reference::new(&original, under, 7)
            .compare(&coarse)
            .unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn a_capped_budget_estimates_what_the_uncapped_one_measures() {
        // Vertices weigh the same share whatever the cap: the random samples stand for the
        // uncapped count.
        let original = generate::terrain(3000, 5);
        let coarse = level(generate::terrain(30, 5));
        let full = Reference::new(&original, SampleBudget::per_triangle(10), 3)
            .measure(&coarse)
            .unwrap();
        let capped = SampleBudget {
            per_triangle: 10,
            max: original.faces.len(),
        };
        let reference = Reference::new(&original, capped, 3);
        assert_eq!(reference.random_samples, original.faces.len());
        let part = reference.measure(&coarse).unwrap();
        let uncertainty = part.uncertainty();
        assert_eq!(
            uncertainty.samples,
            [part.forward.samples, part.backward.samples]
        );
        assert!(
            uncertainty.rms > 0.0 && uncertainty.rms < 0.01,
            "{uncertainty:?}"
        );
        let off = (part.rms() / full.rms() - 1.0).abs();
        assert!(off < 5.0 * uncertainty.rms + 1e-3, "{off} {uncertainty:?}");
        // A tenth of the samples finds a maximum a little lower (or, at other points, about the
        // same), and the half-sample gap says that more samples would raise it.
        let gap = 1.0 - part.hausdorff() / full.hausdorff();
        assert!((-0.005..0.03).contains(&gap), "{gap} {uncertainty:?}");
        assert!(uncertainty.hausdorff > 0.0, "{uncertainty:?}");
        assert!((0.0..1.0).contains(&uncertainty.hausdorff));
    }
}
