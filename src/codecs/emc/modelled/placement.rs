//! Where a level shows its vertices: inside each vertex's cell, where the coder's own
//! prediction expects it, rather than at the cell's centre. It costs no bits: both sides already
//! know each vertex's neighbours and its cell, and the stream is the same.
//!
//! Along each axis the prediction of [`super::walk::estimate`] (the neighbours' regression
//! plane, or their mean) comes with an expected squared error σ². Taking the vertex's place as
//! normally distributed about the prediction, and knowing only that it lies inside its cell
//! [c − w, c + w], the place that minimizes the expected squared error is the mean of that
//! normal distribution truncated to the cell. A sure prediction (σ ≪ w) puts the vertex at the
//! prediction, kept inside the cell; an unsure one (σ ≫ w) leaves it near the centre. The full
//! level is exact and shows the decoded cells' centres, as before.
//!
//! σ² is the contexts' estimate, made to rank predictions rather than to be a variance. Scaled
//! by [`TRUST`] × (how far the neighbours reach, in half-widths, at least 1) it fits the errors
//! measured on bunny.ply and armadillo-43k.obj at 12 bits: where the neighbours lie within a
//! cell or two (coarse levels, clusters) the prediction is better than σ² says; where they lie
//! many cells away (the finest levels) it is worse. On bunny.ply this lowers the RMS error of
//! levels 4–11, by 1.13–1.46× at levels 4–9 and 1.01–1.05× at levels 10–11 (`cargo run
//! --release --example emc_placement`; docs/notes/benchmarks-history.md, "Intermediate levels").

use super::walk::{estimate, Walker};
// The same exponential on every platform (the `libm` crate's, not the C library's, whose last
// bit differs between glibc and the WebAssembly build): a level shows the same positions
// wherever it is decoded (web/test/decode.test.mjs compares them bit for bit).
use crate::mesh::Grid;
use glam::DVec3;
use libm::exp;
use rayon::prelude::*;

/// How much the prediction's expected squared error is trusted, per half-width that the
/// neighbours reach (see the module docs).
const TRUST: f64 = 0.25;

/// How far out towards its cell's faces a vertex may be shown, in half-widths.
const INSIDE: f64 = 0.999;

/// Along an axis on which a cell is still an eighth of the grid or more (the first three
/// levels), the neighbours span a large part of the model and their plane says little of where
/// the vertex lies: it stays at its cell's centre (placed there, levels 1–2 of bunny.ply had
/// 1.2–1.5× the RMS error of the centres, level 3 of porsche and dragon-res3 1.09–1.15×).
const COARSE_LEVELS: u8 = 3;

impl Walker {
    /// Every vertex's shown position: its expected place inside its cell along each axis
    /// (see the module docs), in the grid's coordinates.
    pub fn shown_positions(&self, grid: &Grid) -> Vec<DVec3> {
        let origin = DVec3::from(grid.origin);
        // The centres are in half cells of the full grid.
        let unit = DVec3::from(grid.cell) * 0.5;
        let levels = self.state.order.levels;
        (0..self.state.len())
            .into_par_iter()
            .map(|v| {
                let (centre, shifts) = self.cell_of(v);
                let mut place = centre.map(|c| c as f64);
                if let Some(m) = self.moments(v) {
                    // Root mean square distance of the neighbours from the centre.
                    let reach = (0..3)
                        .map(|a| m.cov[a][a] + m.mean[a] * m.mean[a])
                        .sum::<f64>()
                        .max(0.0)
                        .sqrt();
                    for (axis, p) in place.iter_mut().enumerate() {
                        if shifts[axis] + COARSE_LEVELS >= levels {
                            continue;
                        }
                        let (prediction, variance) = estimate(&m, axis, shifts);
                        // Strictly inside the cell, so that quantizing a shown position on
                        // the level's grid finds its cell.
                        let half_width = (1u64 << shifts[axis]) as f64 * INSIDE;
                        let scale = TRUST * (reach / half_width).max(1.0);
                        *p += truncated_normal_mean(prediction, scale * variance, half_width);
                    }
                }
                origin + DVec3::from(place) * unit
            })
            .collect()
    }
}

/// Mean of the normal distribution N(`mean`, `variance`) restricted to [−`w`, `w`].
fn truncated_normal_mean(mean: f64, variance: f64, w: f64) -> f64 {
    if mean.is_nan() {
        return 0.0;
    }
    let sigma = variance.max(0.0).sqrt();
    if sigma.is_nan() || sigma <= 1e-9 * w {
        return mean.clamp(-w, w);
    }
    if sigma > 0.5 * w {
        // Wide against the cell: the closed form below would subtract nearly equal
        // probabilities; the density is smooth over the cell, so integrate it.
        return w * wide_truncated_mean(mean / w, sigma / w);
    }
    let (a, b) = ((-w - mean) / sigma, (w - mean) / sigma);
    let mass = normal_cdf(b) - normal_cdf(a);
    if mass < 1e-6 {
        // All but nothing of the distribution lies inside: its nearest edge.
        return mean.clamp(-w, w);
    }
    let offset = mean + sigma * (normal_pdf(a) - normal_pdf(b)) / mass;
    offset.clamp(-w, w)
}

/// Mean over [−1, 1] of the density exp(−(t − m)² / 2s²), s > ½: by 8-point Gauss–Legendre
/// quadrature (the exponent taken relative to its largest value in the interval) while the
/// exponent changes by at most 16 across the interval, else as an exponential tail from the
/// nearer edge (its slope there is at least 7, so the rest of the interval weighs nothing).
fn wide_truncated_mean(m: f64, s: f64) -> f64 {
    let across = 2.0 * m.abs() / (s * s);
    if across > 16.0 {
        let slope = (m.abs() - 1.0) / (s * s);
        return (1.0 - 1.0 / slope).copysign(m);
    }
    const NODES: [f64; 4] = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    const WEIGHTS: [f64; 4] = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    let peak = m.clamp(-1.0, 1.0);
    let density = |t: f64| exp(((peak - m).powi(2) - (t - m).powi(2)) / (2.0 * s * s));
    let (mut mass, mut moment) = (0.0, 0.0);
    for (x, weight) in NODES.into_iter().zip(WEIGHTS) {
        for t in [-x, x] {
            let d = weight * density(t);
            mass += d;
            moment += d * t;
        }
    }
    (moment / mass).clamp(-1.0, 1.0)
}

fn normal_pdf(x: f64) -> f64 {
    exp(-0.5 * x * x) * 0.398_942_280_401_432_7
}

fn normal_cdf(x: f64) -> f64 {
    0.5 * (1.0 + erf(x * std::f64::consts::FRAC_1_SQRT_2))
}

/// The error function, within 1.5e-7 (Abramowitz and Stegun 7.1.26).
fn erf(x: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.327_591_1 * x.abs());
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let y = 1.0 - poly * exp(-x * x);
    y.copysign(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erf_matches_known_values() {
        for (x, want) in [
            (0.0, 0.0),
            (0.5, 0.520_499_877_813_046_5),
            (1.0, 0.842_700_792_949_714_9),
            (2.0, 0.995_322_265_018_952_7),
            (-1.0, -0.842_700_792_949_714_9),
        ] {
            assert!((erf(x) - want).abs() < 2e-7, "erf({x}) = {}", erf(x));
        }
    }

    #[test]
    fn a_sure_prediction_is_kept_inside_the_cell_and_an_unsure_one_goes_to_the_centre() {
        assert!((truncated_normal_mean(0.3, 1e-8, 1.0) - 0.3).abs() < 1e-6);
        assert_eq!(truncated_normal_mean(5.0, 0.0, 1.0), 1.0);
        assert!(truncated_normal_mean(0.9, 1e6, 1.0).abs() < 1e-3);
        // Symmetric about the centre, and between the prediction and the centre.
        let m = truncated_normal_mean(0.6, 0.25, 1.0);
        assert!(m > 0.0 && m < 0.6, "{m}");
        assert!((truncated_normal_mean(-0.6, 0.25, 1.0) + m).abs() < 1e-12);
        // Far outside: at the nearest edge, never past it.
        assert_eq!(truncated_normal_mean(40.0, 0.01, 1.0), 1.0);
        let tail = truncated_normal_mean(40.0, 1.0, 1.0);
        assert!(tail > 0.97 && tail < 0.98, "{tail}"); // 1 − 1/39
        assert!(truncated_normal_mean(1e9, 1e12, 1.0) <= 1.0);
    }

    #[test]
    fn the_quadrature_agrees_with_the_closed_form_where_both_hold() {
        for mean in [-2.0, -0.7, 0.0, 0.3, 1.5] {
            for sigma in [0.5, 0.6, 0.9] {
                let (a, b) = ((-1.0 - mean) / sigma, (1.0 - mean) / sigma);
                let mass = normal_cdf(b) - normal_cdf(a);
                let closed = mean + sigma * (normal_pdf(a) - normal_pdf(b)) / mass;
                let quadrature = wide_truncated_mean(mean, sigma);
                assert!(
                    (closed - quadrature).abs() < 1e-4,
                    "{mean} {sigma}: {closed} {quadrature}"
                );
            }
        }
        // Very wide: nearly uniform over the cell, leaning towards the mean.
        let m = wide_truncated_mean(3.0, 1e4);
        assert!(m > 0.0 && m < 1e-6, "{m}");
    }
}
