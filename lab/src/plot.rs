//! Charts of results: rate-resolution (level vs bits/vertex, as EMC's Fig. 4) and
//! rate-distortion (cumulative bits vs Hausdorff error, log-log), as PNG and SVG.
//!
//! Charts are made from [`RunResult`]s — the contents of results/ — never by running a codec.
//! Log axes are drawn as linear axes over log10 of the data with tick labels in powers of ten,
//! which keeps one drawing path for both kinds of chart.

use crate::results::{LevelRow, RunResult};
use meshcodec::error::{Error, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    /// Points joined by a line.
    Line,
    /// Points only (single-rate codecs at several settings).
    Points,
}

/// One labelled curve.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Data points (in data units, not log).
    pub points: Vec<(f64, f64)>,
    /// How to draw it.
    pub mark: Mark,
}

/// A chart ready to draw.
#[derive(Clone, Debug)]
pub struct Chart {
    /// Caption.
    pub title: String,
    /// X axis description.
    pub x_desc: String,
    /// Y axis description.
    pub y_desc: String,
    /// Logarithmic x axis.
    pub x_log: bool,
    /// Logarithmic y axis.
    pub y_log: bool,
    /// Curves.
    pub series: Vec<Series>,
    /// Corner for the legend, away from where the curves run.
    pub legend: SeriesLabelPosition,
}

/// Rate-resolution chart: resolution level vs cumulative bits per vertex, one curve per run.
pub fn rate_resolution(runs: &[RunResult], title: &str) -> Chart {
    Chart {
        title: format!("Rate vs resolution — {title}"),
        x_desc: "resolution level".into(),
        y_desc: "cumulative bits per vertex".into(),
        x_log: false,
        y_log: false,
        legend: SeriesLabelPosition::UpperLeft,
        series: series(runs, |l| Some((l.level as f64, l.bits_per_vertex))),
    }
}

/// Rate-distortion chart: cumulative bits vs symmetric Hausdorff error, log-log.
pub fn rate_distortion(runs: &[RunResult], title: &str) -> Chart {
    Chart {
        title: format!("Rate vs distortion — {title}"),
        x_desc: "cumulative bits (log)".into(),
        y_desc: "Hausdorff error / bounding-box diagonal (log)".into(),
        x_log: true,
        y_log: true,
        legend: SeriesLabelPosition::UpperRight,
        series: series(runs, |l| Some((l.bits as f64, l.hausdorff?))),
    }
}

/// Rate-distortion chart of the RMS error: cumulative bits per vertex vs RMS error, log-log.
pub fn rate_rms(runs: &[RunResult], title: &str) -> Chart {
    Chart {
        title: title.into(),
        x_desc: "cumulative bits per vertex (log)".into(),
        y_desc: "RMS error / bounding-box diagonal (log)".into(),
        x_log: true,
        y_log: true,
        // The curves fall from the upper left to the lower right.
        legend: SeriesLabelPosition::LowerLeft,
        series: series(runs, |l| {
            Some((l.bits_per_vertex, l.rms?)).filter(|&(b, r)| b > 0.0 && r > 0.0)
        }),
    }
}

/// One series per run, of the points `point` gives for its levels; a single-level run (a
/// single-rate codec) is drawn as a point, not a line.
fn series(runs: &[RunResult], point: impl Fn(&LevelRow) -> Option<(f64, f64)>) -> Vec<Series> {
    runs.iter()
        .map(|r| Series {
            label: run_label(r, runs),
            points: r.levels.iter().filter_map(&point).collect(),
            mark: if r.levels.len() == 1 {
                Mark::Points
            } else {
                Mark::Line
            },
        })
        .collect()
}

/// Legend text of a run: the codec, plus what tells it apart from the other runs.
fn run_label(run: &RunResult, all: &[RunResult]) -> String {
    let meshes_differ = all.iter().any(|r| r.mesh != run.mesh);
    let quants_differ = all.iter().any(|r| r.quant_bits != run.quant_bits);
    let mut label = run.codec.clone();
    if meshes_differ {
        label.push_str(&format!(" {}", run.mesh));
    }
    if quants_differ {
        label.push_str(&format!(" q{}", run.quant_bits));
    }
    let rule = |r: &RunResult| r.appearance.as_ref().and_then(|a| a.in_levels.clone());
    if all.iter().any(|r| rule(r) != rule(run)) {
        label.push_str(&format!(" {}", rule(run).unwrap_or_else(|| "unit".into())));
    }
    label
}

/// Registers a sans-serif font with plotters once: DejaVu Sans from the system if present,
/// else the Ubuntu font shipped inside the `epaint_default_fonts` crate.
pub fn ensure_font() -> Result<()> {
    static REGISTERED: OnceLock<std::result::Result<(), String>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            let system = [
                "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
                "/usr/share/fonts/TTF/DejaVuSans.ttf",
                "/usr/share/fonts/dejavu/DejaVuSans.ttf",
            ]
            .iter()
            .find_map(|p| std::fs::read(p).ok());
            let bytes: &'static [u8] = match system {
                Some(b) => Box::leak(b.into_boxed_slice()),
                None => epaint_default_fonts::UBUNTU_LIGHT,
            };
            plotters::style::register_font("sans-serif", FontStyle::Normal, bytes)
                .map_err(|_| "no usable TrueType font for plots".to_string())
        })
        .clone()
        .map_err(Error::Unsupported)
}

/// Colour of the i-th series: a qualitative palette that stays readable when printed.
fn colour(i: usize) -> RGBColor {
    const PALETTE: [RGBColor; 8] = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(255, 127, 14),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(23, 190, 207),
    ];
    PALETTE[i % PALETTE.len()]
}

fn plot_error(e: impl std::fmt::Display) -> Error {
    Error::Io(std::io::Error::other(format!("plot: {e}")))
}

impl Chart {
    /// Draws `<stem>.png` (1200 × 800) and `<stem>.svg`; returns their paths.
    pub fn draw(&self, stem: &Path) -> Result<Vec<PathBuf>> {
        ensure_font()?;
        let png = stem.with_extension("png");
        let svg = stem.with_extension("svg");
        {
            let root = BitMapBackend::new(&png, (1200, 800)).into_drawing_area();
            self.draw_on(&root)?;
            root.present().map_err(plot_error)?;
        }
        {
            let root = SVGBackend::new(&svg, (1200, 800)).into_drawing_area();
            self.draw_on(&root)?;
            root.present().map_err(plot_error)?;
        }
        Ok(vec![png, svg])
    }

    /// Draws `charts` as panels of one figure, `columns` across, to `<stem>.png` and
    /// `<stem>.svg` (each panel 800 × 450); returns their paths.
    pub fn draw_panels(charts: &[Chart], columns: usize, stem: &Path) -> Result<Vec<PathBuf>> {
        ensure_font()?;
        let columns = columns.clamp(1, charts.len().max(1));
        let rows = charts.len().div_ceil(columns).max(1);
        let size = (800 * columns as u32, 450 * rows as u32);
        let png = stem.with_extension("png");
        let svg = stem.with_extension("svg");
        fn panels<DB: DrawingBackend>(
            charts: &[Chart],
            root: DrawingArea<DB, Shift>,
            rows: usize,
            columns: usize,
        ) -> Result<()>
        where
            DB::ErrorType: 'static,
        {
            root.fill(&WHITE).map_err(plot_error)?;
            for (chart, area) in charts.iter().zip(root.split_evenly((rows, columns))) {
                chart.draw_on(&area)?;
            }
            root.present().map_err(plot_error)
        }
        panels(
            charts,
            BitMapBackend::new(&png, size).into_drawing_area(),
            rows,
            columns,
        )?;
        panels(
            charts,
            SVGBackend::new(&svg, size).into_drawing_area(),
            rows,
            columns,
        )?;
        Ok(vec![png, svg])
    }

    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<()>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(plot_error)?;
        let tx = |v: f64| {
            if self.x_log {
                v.max(f64::MIN_POSITIVE).log10()
            } else {
                v
            }
        };
        let ty = |v: f64| if self.y_log { v.max(1e-12).log10() } else { v };
        let points: Vec<Vec<(f64, f64)>> = self
            .series
            .iter()
            .map(|s| {
                s.points
                    .iter()
                    .filter(|(x, y)| x.is_finite() && y.is_finite())
                    .filter(|(x, y)| (!self.x_log || *x > 0.0) && (!self.y_log || *y > 0.0))
                    .map(|&(x, y)| (tx(x), ty(y)))
                    .collect()
            })
            .collect();
        let (x_range, y_range) = padded_ranges(&points, self.x_log, self.y_log);
        let log_label = |v: &f64| {
            let value = 10f64.powf(*v);
            if (v - v.round()).abs() < 1e-9 {
                format!("1e{}", v.round() as i64)
            } else {
                format!("{value:.1e}")
            }
        };
        // Ticks are round numbers; printed with a few decimals at most, not float noise.
        let linear_label = |v: &f64| {
            let text = format!("{v:.3}");
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        };
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, ("sans-serif", 30))
            .margin(20)
            .x_label_area_size(60)
            .y_label_area_size(90)
            .build_cartesian_2d(x_range, y_range)
            .map_err(plot_error)?;
        let x_fmt: &dyn Fn(&f64) -> String = if self.x_log {
            &log_label
        } else {
            &linear_label
        };
        let y_fmt: &dyn Fn(&f64) -> String = if self.y_log {
            &log_label
        } else {
            &linear_label
        };
        chart
            .configure_mesh()
            .x_desc(&self.x_desc)
            .y_desc(&self.y_desc)
            .x_label_formatter(x_fmt)
            .y_label_formatter(y_fmt)
            .axis_desc_style(("sans-serif", 22))
            .label_style(("sans-serif", 18))
            .light_line_style(RGBColor(235, 235, 235))
            .bold_line_style(RGBColor(210, 210, 210))
            .draw()
            .map_err(plot_error)?;
        for (i, (series, pts)) in self.series.iter().zip(&points).enumerate() {
            let c = colour(i);
            if series.mark == Mark::Line {
                chart
                    .draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(3)))
                    .map_err(plot_error)?;
            }
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 4, c.filled())))
                .map_err(plot_error)?
                .label(&series.label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(3))
                });
        }
        chart
            .configure_series_labels()
            .label_font(("sans-serif", 20))
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(160, 160, 160))
            .position(self.legend.clone())
            .draw()
            .map_err(plot_error)?;
        Ok(())
    }
}

/// Axis ranges around all points with a margin. Linear axes that start at or above zero start
/// at zero; log axes (in log10 units) span at least one decade so their ticks differ.
fn padded_ranges(
    series: &[Vec<(f64, f64)>],
    x_log: bool,
    y_log: bool,
) -> (std::ops::Range<f64>, std::ops::Range<f64>) {
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in series.iter().flatten() {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if x0 > x1 {
        return (0.0..1.0, 0.0..1.0);
    }
    let pad = |lo: f64, hi: f64, log: bool| {
        if log {
            let centre = (lo + hi) / 2.0;
            let half = ((hi - lo) / 2.0 + 0.1).max(0.5);
            return centre - half..centre + half;
        }
        let span = (hi - lo).max(hi.abs() * 0.1).max(1e-9);
        let lo = if lo >= 0.0 { 0.0 } else { lo - 0.05 * span };
        lo..hi + 0.08 * span
    };
    (pad(x0, x1, x_log), pad(y0, y1, y_log))
}
