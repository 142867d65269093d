//! CAME's view-dependent refinement beside a view-independent simplifier: paper-tables/came-vd.md
//! from results/came/vd.json (`experiment came-vd`), results/came/flythrough.json (`experiment
//! came-fly`) and results/came/vd-meshoptimizer.json (experiments/meshopt_vd.py), all made by
//! `bash experiments/came-vd.sh`.

use crate::came::flythrough::{Flythrough, ORBIT_FRAMES};
use crate::came::vd::{stem, VdReport};
use crate::tables::thousands;
use meshcodec::error::{Error, Result};
use meshcodec::mesh::io::write_atomically;
use serde::Deserialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The command that makes every input of the table.
pub const COMMAND: &str = "bash experiments/came-vd.sh";
/// Faces against meshoptimizer's count the target allows.
const FACE_TARGET: f64 = 1.5;
/// Faces with the orientation guard against without it, the most the target allows.
const GUARD_TARGET: f64 = 1.25;

/// A rung of meshoptimizer's ladder chosen for a view or a fly-through frame.
#[derive(Deserialize, Clone, Default)]
struct Chosen {
    #[serde(default)]
    triangles: Option<usize>,
    #[serde(default)]
    hausdorff: Option<f64>,
    #[serde(default)]
    full_mesh: bool,
    /// Its error on the screen, measured as the view's or the frame's front is (0 for the full
    /// mesh; none in a file made before `meshcodec screen-distance` measured it).
    #[serde(default)]
    screen_max_px: Option<f64>,
    #[serde(default)]
    screen_mean_px: Option<f64>,
}

#[derive(Deserialize)]
struct MeshoptView {
    view: String,
    #[serde(flatten)]
    chosen: Chosen,
}

#[derive(Deserialize)]
struct MeshoptMesh {
    mesh: String,
    subdivisions: u32,
    views: Vec<MeshoptView>,
    #[serde(default)]
    flythrough_frames: Vec<Chosen>,
}

#[derive(Deserialize)]
struct Meshopt {
    meshoptimizer: String,
    simplify: String,
    distance: String,
    meshes: Vec<MeshoptMesh>,
}

fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| Error::Unsupported(format!("{}: {e}", path.display())))?;
    serde_json::from_str(&text).map_err(|e| Error::Unsupported(format!("{}: {e}", path.display())))
}

/// The `q`-quantile of `values` (nearest rank).
fn quantile(values: &[f64], q: f64) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    if sorted.is_empty() {
        return f64::NAN;
    }
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

/// Writes paper-tables/came-vd.md.
pub fn table(results: &Path, out: &Path) -> Result<PathBuf> {
    let folder = results.join("came");
    let vd: VdReport = read_json(&folder.join("vd.json"))?;
    let fly: Flythrough = read_json(&folder.join("flythrough.json"))?;
    let meshopt: Meshopt = read_json(&folder.join("vd-meshoptimizer.json"))?;
    let of_mesh = |name: &str, subdivisions: u32| {
        meshopt
            .meshes
            .iter()
            .find(|m| m.mesh == name && m.subdivisions == subdivisions)
    };
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# CAME view-dependent refinement beside meshoptimizer\n\n\
         Regenerate: `{COMMAND}`. Every `came` stream at {} bits, read from a file meta-node by \
         meta-node as the view asks, its index only as far as those meta-nodes; {}x{} pixels, {}° vertical field of view, τ = {} px, \
         two-sided (nothing left coarse for facing away), orientation guard on, each view from \
         a cold start.\n\n\
         **meshoptimizer** ({}): `{}`, the target error lowered a quarter octave at a time; a \
         view gets the fewest triangles of a rung whose Hausdorff distance to the full mesh \
         (`{}`) is within a pixel's size at the nearest point in view (the least depth of the \
         full mesh's vertices in the frustum). That mesh knows nothing of the view: it is \
         uniform, and within one pixel everywhere in view. Where no simplified mesh is within \
         it, the full mesh is its answer (\"full\").\n\n\
         **Measured error**: the adapted mesh against the full decode on the screen, both \
         ways, over every sample in the frustum (docs/CONTRACT.md §8); meshoptimizer's mesh \
         for each view and each fly-through frame is measured the same way (`meshcodec \
         screen-distance`).",
        vd.quant_bits,
        vd.width,
        vd.height,
        vd.fov_degrees,
        vd.tolerance_px,
        meshopt.meshoptimizer,
        meshopt.simplify,
        meshopt.distance
    );
    let _ = writeln!(
        md,
        "\n## Far, middle and near views\n\n\
         Far and middle: the eye at 20 and 1.5 bounding-box diagonals from the centre; near: \
         0.1 diagonals from the surface point farthest towards the eye, looking at it.\n\n\
         | mesh | view | tolerance (units) | faces | without guard | meshoptimizer | faces / meshoptimizer | max error px | mean error px | meshoptimizer's max / mean px | bytes read | of the stream | adapt ms | fetch wait ms |\n\
         |---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    let mut worst_ratio = 0.0f64;
    let mut worst_error = 0.0f64;
    // meshoptimizer's mean screen errors where it simplifies (not the full mesh).
    let mut simplifier_means: Vec<f64> = Vec::new();
    for mesh in &vd.meshes {
        let name = stem(&mesh.mesh, mesh.subdivisions);
        let theirs = of_mesh(&mesh.mesh, mesh.subdivisions);
        for view in &mesh.views {
            let chosen = theirs
                .and_then(|m| m.views.iter().find(|v| v.view == view.view))
                .map(|v| v.chosen.clone())
                .unwrap_or_default();
            let (count, ratio) = match chosen.triangles {
                Some(t) => {
                    let ratio = view.faces as f64 / t as f64;
                    worst_ratio = worst_ratio.max(ratio);
                    let label = if chosen.full_mesh {
                        format!("{} (full)", thousands(t))
                    } else {
                        format!(
                            "{} ({:.2e})",
                            thousands(t),
                            chosen.hausdorff.unwrap_or(f64::NAN)
                        )
                    };
                    (label, format!("{ratio:.2}"))
                }
                None => ("—".into(), "—".into()),
            };
            worst_error = worst_error.max(view.max_error_px);
            let theirs_on_screen = match (chosen.screen_max_px, chosen.screen_mean_px) {
                (Some(max), Some(mean)) => {
                    if !chosen.full_mesh {
                        simplifier_means.push(mean);
                    }
                    format!("{max:.2} / {mean:.3}")
                }
                _ => "—".into(),
            };
            let _ = writeln!(
                md,
                "| {name} | {} | {:.2e} | {} | {} | {count} | {ratio} | {:.2} | {:.3} | {theirs_on_screen} | {} | {:.1}% | {:.1} | {:.1} |",
                view.view,
                view.pixel_at_nearest,
                thousands(view.faces),
                thousands(view.faces_unguarded),
                view.max_error_px,
                view.mean_error_px,
                thousands(view.bytes_read as usize),
                100.0 * view.share_of_stream,
                view.adapt_ms,
                view.wait_ms
            );
        }
    }
    // The fly-through, summarised.
    let frames = &fly.frames;
    let theirs = of_mesh(&fly.mesh, fly.subdivisions)
        .map(|m| m.flythrough_frames.as_slice())
        .unwrap_or(&[]);
    let ratios: Vec<f64> = frames
        .iter()
        .zip(theirs)
        .filter_map(|(f, t)| t.triangles.map(|t| f.faces_two_sided as f64 / t as f64))
        .collect();
    let within = ratios.iter().filter(|&&r| r <= FACE_TARGET).count();
    let adapt: Vec<f64> = frames.iter().map(|f| f.front.adapt_ms).collect();
    // The same front without the guard, timed in the same run: how fast the machine was.
    let adapt_unguarded: Vec<f64> = frames.iter().map(|f| f.adapt_ms_unguarded).collect();
    let max_error = frames.iter().map(|f| f.max_error_px).fold(0.0, f64::max);
    let least_mean = frames
        .iter()
        .map(|f| f.mean_error_px)
        .fold(f64::INFINITY, f64::min);
    let per_frame: Vec<f64> = frames
        .iter()
        .scan(0u64, |before, f| {
            let read = f.front.bytes_fetched.saturating_sub(*before);
            *before = f.front.bytes_fetched;
            Some(read as f64)
        })
        .collect();
    let guard: Vec<f64> = frames
        .iter()
        .map(|f| f.front.faces as f64 / f.faces_unguarded.max(1) as f64)
        .collect();
    let _ = writeln!(
        md,
        "\n## The fly-through\n\n\
         {} frames around and into {} ×{} ({} triangles, a {}-byte stream), {}x{} pixels, {}° \
         (frames 0–{} orbit at 1.5 diagonals, then the camera flies in); the path's front is \
         one-sided and timed along the path alone, nothing else running between its frames; \
         a second front follows it two-sided for the faces and the measured error \
         (`cargo run --release --bin experiment -- came-fly`; BENCHMARKS.md has the figures \
         per frame).\n\n\
         | figure | median | 5% | 95% | min | max |\n|---|---:|---:|---:|---:|---:|",
        frames.len(),
        fly.mesh,
        4u32.pow(fly.subdivisions),
        thousands(fly.triangles),
        thousands(fly.stream_bytes as usize),
        fly.width,
        fly.height,
        fly.fov_degrees,
        ORBIT_FRAMES - 1
    );
    let row = |md: &mut String, label: &str, values: &[f64], digits: usize| {
        let min = values.iter().copied().fold(f64::INFINITY, f64::min);
        let max = values.iter().copied().fold(0.0, f64::max);
        let _ = writeln!(
            md,
            "| {label} | {:.digits$} | {:.digits$} | {:.digits$} | {min:.digits$} | {max:.digits$} |",
            quantile(values, 0.5),
            quantile(values, 0.05),
            quantile(values, 0.95)
        );
    };
    let two_sided: Vec<f64> = frames.iter().map(|f| f.faces_two_sided as f64).collect();
    let meshopt_counts: Vec<f64> = theirs
        .iter()
        .filter_map(|t| t.triangles.map(|t| t as f64))
        .collect();
    row(&mut md, "faces, two-sided", &two_sided, 0);
    row(
        &mut md,
        "meshoptimizer within a pixel at the nearest point",
        &meshopt_counts,
        0,
    );
    row(&mut md, "faces / meshoptimizer", &ratios, 2);
    row(&mut md, "faces with guard / without (one-sided)", &guard, 2);
    row(
        &mut md,
        "measured error, largest (px)",
        &frames.iter().map(|f| f.max_error_px).collect::<Vec<_>>(),
        2,
    );
    row(
        &mut md,
        "measured error, mean (px)",
        &frames.iter().map(|f| f.mean_error_px).collect::<Vec<_>>(),
        3,
    );
    let theirs_max: Vec<f64> = theirs.iter().filter_map(|t| t.screen_max_px).collect();
    let theirs_mean: Vec<f64> = theirs.iter().filter_map(|t| t.screen_mean_px).collect();
    if !theirs_mean.is_empty() {
        row(
            &mut md,
            "meshoptimizer's mesh, measured error, largest (px)",
            &theirs_max,
            2,
        );
        row(
            &mut md,
            "meshoptimizer's mesh, measured error, mean (px)",
            &theirs_mean,
            3,
        );
    }
    row(&mut md, "adaptation ms (fetch waits apart)", &adapt, 1);
    row(
        &mut md,
        "adaptation ms without the guard (same run)",
        &adapt_unguarded,
        1,
    );
    row(
        &mut md,
        "fetch wait ms",
        &frames.iter().map(|f| f.front.wait_ms).collect::<Vec<_>>(),
        1,
    );
    row(
        &mut md,
        "kB read in the frame",
        &per_frame.iter().map(|b| b / 1e3).collect::<Vec<_>>(),
        1,
    );
    let _ = writeln!(
        md,
        "\nThe first frame reads {:.1}% of the stream; frame {} alone, from a cold start ({:.1}% \
         of the surface in view), {:.1}%.",
        100.0 * frames.first().map_or(0, |f| f.front.bytes_fetched) as f64
            / fly.stream_bytes as f64,
        fly.tenth_of_surface.frame,
        100.0 * fly.tenth_of_surface.surface_in_view,
        100.0 * fly.tenth_of_surface.share_of_stream
    );
    if fly.fronts_differ > 0 {
        let _ = writeln!(
            md,
            "On {} frames the fronts flown again for the fold-overs settled a few faces from \
             the timed ones (a front numbers the nodes it takes in in the order the loader \
             thread finished them).",
            fly.fronts_differ
        );
    }
    // The targets, as they stand.
    let dragon_far = vd
        .meshes
        .iter()
        .find(|m| m.mesh == "dragon-50k")
        .and_then(|m| m.views.iter().find(|v| v.view == "far"));
    let large_middle = vd
        .meshes
        .iter()
        .find(|m| m.subdivisions > 0)
        .and_then(|m| m.views.iter().find(|v| v.view == "middle"));
    let met = |ok: bool| if ok { "met" } else { "**not met**" };
    // meshoptimizer's means beside ours: in the views, and frame by frame along the path,
    // whether a mesh within a pixel that knows nothing of the view reaches the target.
    let mut simplifier_evidence = Vec::new();
    if !simplifier_means.is_empty() {
        simplifier_evidence.push(format!(
            "in the views where they simplify: {:.3}–{:.3} px",
            simplifier_means
                .iter()
                .copied()
                .fold(f64::INFINITY, f64::min),
            simplifier_means.iter().copied().fold(0.0, f64::max)
        ));
    }
    let paired: Vec<(f64, f64)> = frames
        .iter()
        .zip(theirs)
        .filter_map(|(f, t)| t.screen_mean_px.map(|m| (f.mean_error_px, m)))
        .collect();
    if !paired.is_empty() {
        simplifier_evidence.push(format!(
            "along the fly-through: {:.3} px at most, 0 in the {} frames where only the full \
             mesh is within a pixel, and below ours in {} of {} frames",
            paired.iter().map(|p| p.1).fold(0.0, f64::max),
            theirs.iter().filter(|t| t.full_mesh).count(),
            paired.iter().filter(|p| p.1 < p.0).count(),
            paired.len()
        ));
    }
    let simplifier_mean = if simplifier_evidence.is_empty() {
        String::new()
    } else {
        format!(
            " (meshoptimizer's meshes within a pixel, {})",
            simplifier_evidence.join("; ")
        )
    };
    let views_guard = vd
        .meshes
        .iter()
        .flat_map(|m| &m.views)
        .map(|v| v.faces as f64 / v.faces_unguarded.max(1) as f64)
        .fold(0.0, f64::max);
    let frames_guard = guard.iter().copied().fold(0.0, f64::max);
    let _ = writeln!(
        md,
        "\n## Targets\n\n\
         | target | measured | |\n|---|---|---|\n\
         | faces at most {FACE_TARGET}× meshoptimizer's in every view and frame | views: up to {worst_ratio:.2}×; fly-through: {within} of {} frames, up to {:.2}× | {} |\n\
         | faces with the orientation guard at most {GUARD_TARGET}× without it in every view and frame | views up to {views_guard:.2}×, frames up to {frames_guard:.2}× | {} |\n\
         | measured error at most τ in every view and frame | views {worst_error:.2} px, frames {max_error:.2} px | {} |\n\
         | per-frame mean error at least τ/4 | least frame mean {least_mean:.3} px{simplifier_mean} | {} |\n\
         | far view of dragon-50k reads at most 5% of its stream | {} | {} |\n\
         | the million-triangle mesh whole at 1.5 diagonals reads at most 10% | {} | {} |\n\
         | fly-through adaptation: median at most 4 ms, 95th percentile at most 16 ms | {:.1} ms, {:.1} ms (without the guard, same run: {:.1} ms, {:.1} ms) | {} |",
        ratios.len(),
        ratios.iter().copied().fold(0.0, f64::max),
        met(worst_ratio <= FACE_TARGET && within == ratios.len() && !ratios.is_empty()),
        met(views_guard <= GUARD_TARGET && frames_guard <= GUARD_TARGET && !guard.is_empty()),
        met(worst_error <= vd.tolerance_px && max_error <= fly.tolerance_px),
        met(least_mean >= fly.tolerance_px / 4.0),
        dragon_far.map_or("—".into(), |v| format!("{:.1}%", 100.0 * v.share_of_stream)),
        met(dragon_far.is_some_and(|v| v.share_of_stream <= 0.05)),
        large_middle.map_or("—".into(), |v| format!("{:.1}%", 100.0 * v.share_of_stream)),
        met(large_middle.is_some_and(|v| v.share_of_stream <= 0.10)),
        quantile(&adapt, 0.5),
        quantile(&adapt, 0.95),
        quantile(&adapt_unguarded, 0.5),
        quantile(&adapt_unguarded, 0.95),
        met(quantile(&adapt, 0.5) <= 4.0 && quantile(&adapt, 0.95) <= 16.0)
    );
    // Renders.
    let _ = writeln!(
        md,
        "\n## What each mesh looks like\n\n\
         Ours (the adapted mesh) beside meshoptimizer's for the same tolerance, drawn by the \
         project's rasterizer from the view's camera; the far views are drawn from the middle \
         view's eye, where their faces can be told apart.\n\n\
         | view | ours | meshoptimizer |\n|---|---|---|"
    );
    for mesh in &vd.meshes {
        let name = stem(&mesh.mesh, mesh.subdivisions);
        for view in mesh.views.iter().filter(|v| v.view != "middle") {
            let theirs = format!("vd/{name}-{}-meshoptimizer.png", view.view);
            let _ = writeln!(
                md,
                "| {name} {} | ![ours](../results/came/{}) | ![meshoptimizer](../results/came/{theirs}) |",
                view.view, view.render
            );
        }
    }
    let path = out.join("came-vd.md");
    write_atomically(&path, md.as_bytes())?;
    Ok(path)
}
