//! Bad input through the binaries: every fault exits 1 with one line on stderr naming the file,
//! writes no output file, and never panics (docs/CONTRACT.md §7).

use std::path::{Path, PathBuf};
use std::process::Command;

struct Outcome {
    code: Option<i32>,
    stdout: String,
    stderr: String,
}

fn run(bin: &str, args: &[&str], dir: &Path) -> Outcome {
    let out = Command::new(bin)
        .args(args)
        .current_dir(dir)
        .env(
            "MESHCODEC_DATA",
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes"),
        )
        .output()
        .expect("binary runs");
    Outcome {
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

fn assert_clean_failure(outcome: &Outcome, mentions: &str) {
    assert_eq!(outcome.code, Some(1), "stderr: {}", outcome.stderr);
    assert_eq!(
        outcome.stderr.lines().count(),
        1,
        "stderr: {}",
        outcome.stderr
    );
    assert!(outcome.stderr.starts_with("error: "), "{}", outcome.stderr);
    assert!(
        outcome.stderr.contains(mentions),
        "'{mentions}' not in {}",
        outcome.stderr
    );
}

fn scratch() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

const EXPERIMENT: &str = env!("CARGO_BIN_EXE_experiment");
const MESHCODEC: &str = env!("CARGO_BIN_EXE_meshcodec");

/// A camera that sees bunny whole, 320 pixels wide.
const BUNNY_CAMERA: [&str; 6] = [
    "--eye",
    "-0.05,0.15,1.0",
    "--target",
    "-0.02,0.1,0",
    "--size",
    "320x240",
];

/// Runs `meshcodec` with `args` in `dir`, which must succeed; returns what it printed.
fn succeed(args: &[&str], dir: &Path) -> String {
    let out = run(MESHCODEC, args, dir);
    assert_eq!(out.code, Some(0), "{:?}: {}", args, out.stderr);
    out.stdout
}

#[test]
fn bad_meshes_fail_cleanly_and_leave_no_results() {
    let dir = scratch();
    let d = dir.path();
    let bunny =
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes/bunny.ply"))
            .unwrap();
    let cases: Vec<(PathBuf, &str)> = vec![
        (d.join("missing.ply"), "missing.ply"),
        (
            write(
                d,
                "nan.off",
                b"OFF\n3 1 0\n0 0 0\nnan 1 0\n0 1 1\n3 0 1 2\n",
            ),
            "non-finite",
        ),
        (
            write(d, "range.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
            "range.obj",
        ),
        (
            write(
                d,
                "range.off",
                b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
            ),
            "out of range",
        ),
        (write(d, "empty.off", b"OFF\n0 0 0\n"), "empty mesh"),
        (write(d, "empty.obj", b"# nothing\n"), "empty.obj"),
        (
            write(d, "trunc.ply", &bunny[..bunny.len() / 3]),
            "trunc.ply",
        ),
        (write(d, "cut.stl", &[0u8; 120]), "cut.stl"),
    ];
    for (path, mentions) in &cases {
        let p = path.to_str().unwrap();
        assert_clean_failure(
            &run(EXPERIMENT, &["raw", p, "--out", "results"], d),
            mentions,
        );
        assert!(!d.join("results").exists(), "{p} left results behind");
        assert_clean_failure(
            &run(MESHCODEC, &["encode", "--codec", "raw", p, "out.mc"], d),
            mentions,
        );
        assert!(!d.join("out.mc").exists(), "{p} left a stream behind");
    }
}

#[test]
fn unknown_names_list_what_is_known() {
    let dir = scratch();
    let outcome = run(EXPERIMENT, &["raw", "no-such-mesh"], dir.path());
    assert_clean_failure(&outcome, "known names");
    assert!(outcome.stderr.contains("bunny"));
    // An unknown codec: one error line, then the codecs a line each
    // (encode_defaults_to_emc_and_the_binaries_list_every_codec).
    let outcome = run(EXPERIMENT, &["nocodec", "bunny"], dir.path());
    assert_eq!(outcome.code, Some(1));
    let first = outcome.stderr.lines().next().unwrap_or_default();
    assert!(
        first.starts_with("error: ") && first.contains("codecs: raw"),
        "{}",
        outcome.stderr
    );
}

#[test]
fn garbage_and_cut_streams_fail_cleanly() {
    let dir = scratch();
    let d = dir.path();
    let mut noise = Vec::new();
    let mut x: u32 = 12345;
    for _ in 0..4000 {
        x = x.wrapping_mul(1_103_515_245).wrapping_add(12345);
        noise.push((x >> 16) as u8);
    }
    write(d, "garbage.mc", &noise);
    for args in [
        &["decode", "garbage.mc", "out.ply"][..],
        &["info", "garbage.mc"][..],
        &["info", "garbage.mc", "--json"][..],
    ] {
        assert_clean_failure(&run(MESHCODEC, args, d), "garbage.mc");
        assert!(!d.join("out.ply").exists());
    }
    let encoded = run(
        MESHCODEC,
        &["encode", "--codec", "raw", "beethoven", "b.mc"],
        d,
    );
    assert_eq!(encoded.code, Some(0), "{}", encoded.stderr);
    let stream = std::fs::read(d.join("b.mc")).unwrap();
    // raw has one level: every cut short of the whole stream holds no complete level.
    for cut in [0, 3, 20, 60, stream.len() / 2, stream.len() - 1] {
        write(d, "cut.mc", &stream[..cut]);
        assert_clean_failure(
            &run(MESHCODEC, &["decode", "cut.mc", "out.obj"], d),
            "cut.mc",
        );
        assert!(!d.join("out.obj").exists());
    }
    let whole = run(MESHCODEC, &["decode", "b.mc", "out.obj"], d);
    assert_eq!(whole.code, Some(0), "{}", whole.stderr);
    assert!(d.join("out.obj").exists());
}

/// `stream` with its index replaced by `edit` of it.
fn with_index(stream: &[u8], edit: impl Fn(&mut meshcodec::container::Index)) -> Vec<u8> {
    let (header, mut index, payload_start) =
        meshcodec::container::read_header_and_index(stream).unwrap();
    edit(&mut index);
    let mut out = Vec::new();
    header.write(&mut out);
    index.write(&mut out);
    out.extend_from_slice(&stream[payload_start..]);
    out
}

/// `stream` with its last unit's index entry claiming `children` units (its last byte, a
/// one-byte count of 0 in every stream of this build).
fn with_children_of_the_last_unit(stream: &[u8], children: u8) -> Vec<u8> {
    let (_, _, payload_start) = meshcodec::container::read_header_and_index(stream).unwrap();
    let mut out = stream.to_vec();
    assert_eq!(out[payload_start - 1], 0);
    out[payload_start - 1] = children;
    out
}

#[test]
fn foreign_versions_lying_indexes_and_impossible_stops_fail_cleanly() {
    let dir = scratch();
    let d = dir.path();
    let encoded = run(MESHCODEC, &["encode", "--codec", "emc", "eight", "e.mc"], d);
    assert_eq!(encoded.code, Some(0), "{}", encoded.stderr);
    let stream = std::fs::read(d.join("e.mc")).unwrap();
    let mut old = stream.clone();
    old[4] = 1;
    let past = with_index(&stream, |index| index.units[11].length += 1000);
    let childless = with_children_of_the_last_unit(&stream, 1);
    let cases: [(&str, &[u8], &str); 3] = [
        ("old.mc", &old, "format version 1"),
        ("past.mc", &past, "runs past"),
        (
            "children.mc",
            &childless,
            "unit 11 has 1 children, 0 units follow",
        ),
    ];
    for (name, bytes, mentions) in cases {
        write(d, name, bytes);
        for args in [
            &["decode", name, "out.ply"][..],
            &["info", name][..],
            &["info", name, "--json"][..],
        ] {
            assert_clean_failure(&run(MESHCODEC, args, d), mentions);
            assert!(!d.join("out.ply").exists());
        }
    }
    // Stops the stream or the codec cannot honour are refused, not approximated.
    assert_clean_failure(
        &run(
            MESHCODEC,
            &["decode", "e.mc", "out.ply", "--level", "13"],
            d,
        ),
        "the stream has 12 levels",
    );
    let raw = run(MESHCODEC, &["encode", "--codec", "raw", "eight", "r.mc"], d);
    assert_eq!(raw.code, Some(0), "{}", raw.stderr);
    assert_clean_failure(
        &run(
            MESHCODEC,
            &["decode", "r.mc", "out.ply", "--passes", "2"],
            d,
        ),
        "cannot stop inside a level",
    );
    assert!(!d.join("out.ply").exists());
}

#[test]
fn emc_commands_work_on_every_shared_mesh() {
    let dir = scratch();
    let d = dir.path();
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&shared)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let ext = p
                .extension()
                .map(|e| e.to_string_lossy().to_string())
                .unwrap_or_default();
            meshcodec::mesh::io::EXTENSIONS.contains(&ext.as_str())
        })
        .collect();
    files.sort();
    assert!(files.len() >= 30);
    // Each coder at its default quantization.
    for (file, (codec, bits)) in files
        .iter()
        .flat_map(|f| [(f, ("emc", 12)), (f, ("emc-paper", 24))])
    {
        let f = file.to_str().unwrap();
        let ok = |args: &[&str]| {
            let out = run(MESHCODEC, args, d);
            assert_eq!(out.code, Some(0), "{args:?}: {}", out.stderr);
        };
        // Their geometry: some also hold normals, colours or texture coordinates.
        ok(&["encode", "--codec", codec, "--drop-attributes", f, "m.mc"]);
        let info = Command::new(MESHCODEC)
            .args(["info", "m.mc", "--json"])
            .current_dir(d)
            .output()
            .unwrap();
        assert!(info.status.success());
        let json: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
        assert_eq!(json["codec"], codec);
        assert_eq!(json["levels"], bits, "{f}");
        assert_eq!(
            json["level_sizes"].as_array().unwrap().len(),
            bits as usize,
            "{f}"
        );
        assert_eq!(json["quant_bits"], bits);
        assert_eq!(json["cell"].as_array().unwrap().len(), 3);
        assert!(json["vertex_copies"].is_null(), "{f}: only pm cuts");
        ok(&["decode", "m.mc", "full.ply"]);
        ok(&["decode", "m.mc", "level8.obj", "--level", "8"]);
        ok(&[
            "decode",
            "m.mc",
            "half.ply",
            "--bytes",
            &(std::fs::metadata(d.join("m.mc")).unwrap().len() / 2).to_string(),
        ]);
        let full = meshcodec::mesh::io::read_mesh(&d.join("full.ply")).unwrap();
        assert_eq!(
            full.vertex_count() as u64,
            json["vertices"].as_u64().unwrap(),
            "{f}"
        );
        assert_eq!(
            full.face_count() as u64,
            json["triangles"].as_u64().unwrap(),
            "{f}"
        );
        let coarse = meshcodec::mesh::io::read_mesh(&d.join("level8.obj")).unwrap();
        assert!(coarse.vertex_count() <= full.vertex_count());
    }
}

#[test]
fn a_reader_that_goes_away_is_no_panic() {
    // `meshcodec distance --json | head -1`: the reader closes the pipe before the output ends.
    let dir = scratch();
    for _ in 0..5 {
        let mut child = Command::new(MESHCODEC)
            .args(["distance", "--json", "--samples", "2", "eight", "eight"])
            .current_dir(dir.path())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{:?}: {stderr}", out.status);
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}

#[test]
fn view_adapts_a_came_stream_reading_what_it_needs_and_refuses_other_streams() {
    let dir = scratch();
    let d = dir.path();
    let ok = |args: &[&str]| {
        succeed(args, d);
    };
    ok(&["encode", "--codec", "came", "bunny", "b.mc"]);
    ok(&["encode", "--codec", "emc", "bunny", "e.mc"]);
    let camera = BUNNY_CAMERA;
    let with = |extra: &[&'static str]| -> Vec<&str> {
        let mut args = vec!["view", "b.mc", "v.ply"];
        args.extend_from_slice(&camera);
        args.extend_from_slice(extra);
        args
    };
    ok(&with(&["--png", "v.png"]));
    let full = meshcodec::mesh::io::read_mesh(&d.join("v.ply")).unwrap();
    // From afar, only some meta-nodes are read.
    let mut far = vec![
        "view",
        "b.mc",
        "far.ply",
        "--eye",
        "-0.05,0.15,5",
        "--target",
        "-0.02,0.1,0",
    ];
    far.extend_from_slice(&["--size", "320x240"]);
    let out = run(MESHCODEC, &far, d);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    let read = out.stdout.lines().find(|l| l.starts_with("read ")).unwrap();
    let numbers: Vec<u64> = read
        .split(|c: char| !c.is_ascii_digit())
        .filter_map(|w| w.parse().ok())
        .collect();
    assert!(numbers[0] < numbers[1], "{read}");
    assert!(out
        .stdout
        .contains("orientation: every face in view turns as its full-mesh triangle does"));
    far.push("--allow-fold-overs");
    let out = run(MESHCODEC, &far, d);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    assert!(
        out.stdout.contains("orientation: not guarded"),
        "{}",
        out.stdout
    );
    assert!(full.face_count() > 100 && d.join("v.png").is_file());
    ok(&with(&["--faces", "500"]));
    let budgeted = meshcodec::mesh::io::read_mesh(&d.join("v.ply")).unwrap();
    assert!(budgeted.face_count() <= 500 && budgeted.face_count() < full.face_count());

    // info lists every meta-node's byte range, the last one ending with the file.
    let info = Command::new(MESHCODEC)
        .args(["info", "b.mc", "--json"])
        .current_dir(d)
        .output()
        .unwrap();
    let report: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    assert_eq!(report["layered"], false);
    let metas = report["units"].as_array().unwrap();
    assert!(metas.len() > 1 && metas.iter().all(|m| m["present"] == true));
    assert_eq!(metas.last().unwrap()["end_byte"], report["bytes"]);
    assert!(metas
        .windows(2)
        .all(|w| w[0]["end_byte"] == w[1]["first_byte"]));

    let mut args = vec!["view", "e.mc", "w.ply"];
    args.extend_from_slice(&camera);
    assert_clean_failure(&run(MESHCODEC, &args, d), "e.mc");
    // A stream cut after some meta-nodes: those past the cut are refused, each for its own
    // branch, and the rest adapts (cut early: this view of bunny 320 pixels wide reads only
    // coarse bands, and cut at half the stream it lost none).
    let stream = std::fs::read(d.join("b.mc")).unwrap();
    write(d, "cut.mc", &stream[..stream.len() / 20]);
    let mut args = vec!["view", "cut.mc", "w.ply"];
    args.extend_from_slice(&camera);
    let out = run(MESHCODEC, &args, d);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    assert!(out.stderr.lines().count() > 1, "{}", out.stderr);
    assert!(out
        .stderr
        .lines()
        .all(|l| l.starts_with("warning: meta-node ") && l.contains("past the stream's end")));
    let cut = meshcodec::mesh::io::read_mesh(&d.join("w.ply")).unwrap();
    assert!(cut.face_count() > 100 && cut.face_count() < full.face_count());
    // Cut inside its index, it cannot be read at all.
    write(d, "head.mc", &stream[..40]);
    let mut args = vec!["view", "head.mc", "x.ply"];
    args.extend_from_slice(&camera);
    assert_clean_failure(&run(MESHCODEC, &args, d), "head.mc");
    assert!(!d.join("x.ply").exists());
}

#[test]
fn screen_distance_measures_a_view_in_pixels_and_refuses_an_empty_frustum() {
    let dir = scratch();
    let d = dir.path();
    let ok = |args: &[&str]| succeed(args, d);
    let camera = BUNNY_CAMERA;
    ok(&["encode", "--codec", "came", "bunny", "b.mc"]);
    ok(&["decode", "b.mc", "full.ply"]);
    ok(&[&["view", "b.mc", "v.ply", "--two-sided"][..], &camera].concat());
    let measure = |b: &str, camera: &[&str]| -> serde_json::Value {
        let out = ok(&[&["screen-distance", "full.ply", b, "--json"][..], camera].concat());
        serde_json::from_str(&out).unwrap()
    };
    // The adapted mesh keeps its promise (one pixel), and is no copy of the full one.
    let adapted = measure("v.ply", &camera);
    let (max, mean) = (
        adapted["max_px"].as_f64().unwrap(),
        adapted["mean_px"].as_f64().unwrap(),
    );
    assert!(max > 0.0 && max <= 1.0 && mean < max, "{adapted}");
    // (A mesh against itself: the distance search's rounding, millionths of a pixel.)
    let itself = measure("full.ply", &camera)["max_px"].as_f64().unwrap();
    assert!(itself < 1e-4, "{itself}");
    // Looking away from the mesh: nothing to measure.
    let away = ["--eye", "0,0,5", "--target", "0,0,10"];
    let out = run(
        MESHCODEC,
        &[&["screen-distance", "full.ply", "v.ply"][..], &away].concat(),
        d,
    );
    assert_clean_failure(&out, "frustum");
}

#[test]
fn a_codec_that_cannot_carry_appearance_refuses_it_unless_told_to_drop_it() {
    let dir = scratch();
    let d = dir.path();
    // The shared textured bunny: 6,451 texture coordinates and a material; came-paper's full
    // level is lossy, so it has no appearance unit.
    let out = run(
        MESHCODEC,
        &[
            "encode",
            "--codec",
            "came-paper",
            "bunny-10k-textured",
            "t.mc",
        ],
        d,
    );
    assert_clean_failure(&out, "bunny-10k-textured.obj");
    assert!(
        out.stderr.contains("6451 texture coordinates") && out.stderr.contains("--drop-attributes"),
        "{}",
        out.stderr
    );
    assert!(!d.join("t.mc").exists());
    let out = run(
        MESHCODEC,
        &[
            "encode",
            "--codec",
            "emc",
            "--drop-attributes",
            "bunny-10k-textured",
            "t.mc",
        ],
        d,
    );
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    assert!(
        out.stderr.starts_with("note: ") && out.stderr.contains("dropped"),
        "{}",
        out.stderr
    );
    assert!(d.join("t.mc").is_file());
    // A file of geometry alone encodes without a word.
    let out = run(MESHCODEC, &["encode", "--codec", "emc", "bunny", "b.mc"], d);
    assert_eq!((out.code, out.stderr.as_str()), (Some(0), ""));
}

#[test]
fn convert_keeps_appearance_and_distance_measures_it() {
    let dir = scratch();
    let d = dir.path();
    // OBJ with seams → glTF (vertices split at every seam) → welded back into the same wedges.
    let out = run(MESHCODEC, &["convert", "bunny-10k-textured", "b.glb"], d);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    assert!(out.stdout.contains("6451 wedges"), "{}", out.stdout);
    let out = run(
        MESHCODEC,
        &["distance", "bunny-10k-textured", "b.glb", "--json"],
        d,
    );
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    let report: serde_json::Value = serde_json::from_str(&out.stdout).unwrap();
    let uv = report["appearance"]["uv_texels"].as_f64().unwrap();
    assert!(uv < 1e-3, "{uv}");
    // A decode of 12-bit uvs is measured off by a fraction of a texel, not zero.
    let out = run(MESHCODEC, &["encode", "--codec", "emc", "spot", "s.mc"], d);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    let out = run(MESHCODEC, &["decode", "s.mc", "s.obj"], d);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    let out = run(MESHCODEC, &["distance", "spot", "s.obj", "--json"], d);
    let report: serde_json::Value = serde_json::from_str(&out.stdout).unwrap();
    let uv = report["appearance"]["uv_texels"].as_f64().unwrap();
    assert!(uv > 0.0 && uv < 1.0, "{uv}");
    // A format that cannot be written is one line, and no file.
    let out = run(MESHCODEC, &["convert", "spot", "s.xyz"], d);
    assert_clean_failure(&out, "s.xyz");
    assert!(!d.join("s.xyz").exists());
}

#[test]
fn pm_encodes_a_mesh_that_is_no_manifold_and_info_says_it_was_cut() {
    let dir = scratch();
    let d = dir.path();
    let mesh = meshcodec::mesh::io::resolve("bunny-res4").unwrap();
    let mesh = mesh.to_str().unwrap();
    for codec in ["pm", "pm-reordered"] {
        let out = run(MESHCODEC, &["encode", "--codec", codec, mesh, "b.mc"], d);
        assert_eq!(out.code, Some(0), "{}", out.stderr);
        let text = run(MESHCODEC, &["info", "b.mc"], d);
        assert!(
            text.stdout
                .contains("cut to an oriented 2-manifold: 175 vertex copies"),
            "{}",
            text.stdout
        );
        let json = run(MESHCODEC, &["info", "b.mc", "--json"], d);
        let json: serde_json::Value = serde_json::from_str(&json.stdout).unwrap();
        assert_eq!(json["vertex_copies"], 175);
        // A level before the last holds the copies; the last is the mesh itself.
        let levels = json["level_sizes"].as_array().unwrap();
        assert_eq!(levels.last().unwrap()["vertices"], json["vertices"]);
        assert!(levels
            .iter()
            .any(|l| l["vertices"].as_u64() > json["vertices"].as_u64()));
        let out = run(MESHCODEC, &["decode", "b.mc", "full.ply"], d);
        assert_eq!(out.code, Some(0), "{}", out.stderr);
    }
}

#[test]
fn a_mesh_name_and_a_resolved_path_work_from_any_working_directory() {
    // No data folder beside the scratch folder and none in the environment (nor any lookup
    // through the folder the binary was built in): the name is found in the per-user cache,
    // and `resolve`'s path names the file from anywhere.
    let dir = scratch();
    let d = dir.path();
    let cache = tempfile::tempdir().unwrap();
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes");
    std::fs::copy(
        shared.join("bunny-res4.ply"),
        cache.path().join("bunny-res4.ply"),
    )
    .unwrap();
    let out = Command::new(MESHCODEC)
        .args(["encode", "--codec", "raw", "bunny-res4", "named.mc"])
        .current_dir(d)
        .env_remove("MESHCODEC_DATA")
        .env("MESHCODEC_CACHE", cache.path())
        .env("MESHCODEC_MIRROR", "http://127.0.0.1:1")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let path = meshcodec::mesh::io::resolve("bunny-res4").unwrap();
    assert!(path.is_absolute(), "{}", path.display());
    let out = run(
        MESHCODEC,
        &[
            "encode",
            "--codec",
            "raw",
            path.to_str().unwrap(),
            "path.mc",
        ],
        d,
    );
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    assert_eq!(
        std::fs::read(d.join("named.mc")).unwrap(),
        std::fs::read(d.join("path.mc")).unwrap()
    );
}

#[test]
fn encode_defaults_to_emc_and_the_binaries_list_every_codec() {
    let dir = scratch();
    let d = dir.path();
    let out = run(MESHCODEC, &["encode", "bunny-res4", "b.mc"], d);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    let info = run(MESHCODEC, &["info", "b.mc", "--json"], d);
    let json: serde_json::Value = serde_json::from_str(&info.stdout).unwrap();
    assert_eq!(json["codec"], "emc");
    let listed = |text: &str| {
        for codec in meshcodec::codecs::registry() {
            assert!(
                text.lines()
                    .any(|l| l.contains(codec.name()) && l.contains(codec.summary())),
                "{} not listed in {text}",
                codec.name()
            );
        }
    };
    let help = run(MESHCODEC, &["encode", "--help"], d);
    assert_eq!(help.code, Some(0));
    listed(&help.stdout);
    assert!(help.stdout.contains("(default)"), "{}", help.stdout);
    let help = run(EXPERIMENT, &["--help"], d);
    assert_eq!(help.code, Some(0));
    listed(&help.stdout);
    // An unknown name: the error line, then the codecs.
    for (bin, args) in [
        (
            MESHCODEC,
            vec!["encode", "--codec", "zip", "bunny-res4", "z.mc"],
        ),
        (EXPERIMENT, vec!["zip", "bunny-res4", "--out", "r"]),
    ] {
        let out = run(bin, &args, d);
        assert_eq!(out.code, Some(1), "{}", out.stderr);
        let first = out.stderr.lines().next().unwrap_or_default();
        assert!(
            first.starts_with("error: ") && first.contains("unknown codec 'zip'"),
            "{}",
            out.stderr
        );
        listed(&out.stderr);
        assert!(!d.join("z.mc").exists() && !d.join("r").exists());
    }
}

#[test]
fn a_format_that_cannot_hold_the_appearance_is_refused_naming_those_that_can() {
    let dir = scratch();
    let d = dir.path();
    // bunny-10k-textured has materials, which PLY cannot hold.
    let out = run(MESHCODEC, &["encode", "bunny-10k-textured", "t.mc"], d);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    for args in [
        vec!["decode", "t.mc", "t.ply"],
        vec!["convert", "bunny-10k-textured", "t.ply"],
    ] {
        let out = run(MESHCODEC, &args, d);
        assert_clean_failure(&out, "t.ply");
        for named in ["materials", ".obj", ".glb", ".gltf", "--drop-attributes"] {
            assert!(out.stderr.contains(named), "{named}: {}", out.stderr);
        }
        assert!(!out.stderr.contains(".ply,"), "{}", out.stderr);
        assert!(!d.join("t.ply").exists());
        let mut dropping = args.clone();
        dropping.push("--drop-attributes");
        let out = run(MESHCODEC, &dropping, d);
        assert_eq!(out.code, Some(0), "{}", out.stderr);
        let mesh = meshcodec::mesh::io::read_attributed(&d.join("t.ply")).unwrap();
        assert!(mesh.attributes.is_empty());
        std::fs::remove_file(d.join("t.ply")).unwrap();
    }
    // The format that holds it all still takes it.
    let out = run(MESHCODEC, &["decode", "t.mc", "t.obj"], d);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    let mesh = meshcodec::mesh::io::read_attributed(&d.join("t.obj")).unwrap();
    assert!(mesh.attributes.materials.is_some());
}

#[test]
fn render_draws_a_mesh_or_a_stream_and_refuses_bad_cameras() {
    let dir = scratch();
    let d = dir.path();
    let camera = [
        "--eye",
        "0,0.1,0.4",
        "--target",
        "0,0.1,0",
        "--size",
        "64x48",
    ];
    let ok = |args: &[&str]| {
        let out = run(MESHCODEC, args, d);
        assert_eq!(out.code, Some(0), "{args:?}: {}", out.stderr);
    };
    ok(&[&["render", "bunny-res4", "mesh.png"][..], &camera].concat());
    ok(&["encode", "bunny-res4", "b.mc"]);
    ok(&[
        &["render", "b.mc", "level.png", "--level", "3"][..],
        &camera,
    ]
    .concat());
    for png in ["mesh.png", "level.png"] {
        let bytes = std::fs::read(d.join(png)).unwrap();
        assert!(bytes.starts_with(b"\x89PNG"), "{png}");
    }
    let out = run(
        MESHCODEC,
        &[&["render", "b.mc", "x.png", "--fov", "0"][..], &camera].concat(),
        d,
    );
    assert_clean_failure(&out, "--fov 0");
    write(d, "junk.mc", b"MshC\x06\x04\x01 not a stream");
    let out = run(
        MESHCODEC,
        &[&["render", "junk.mc", "x.png"][..], &camera].concat(),
        d,
    );
    assert_clean_failure(&out, "junk.mc");
    assert!(!d.join("x.png").exists());
}

/// `info` on a `came` stream of one meta-node (its index is trivially layered, but its levels
/// are depths, not units) lists its levels; it once indexed the units by level and panicked.
#[test]
fn info_lists_the_levels_of_a_came_stream_of_one_meta_node() {
    let dir = scratch();
    let d = dir.path();
    let encoded = run(
        MESHCODEC,
        &["encode", "--codec", "came", "eight", "c.mc"],
        d,
    );
    assert_eq!(encoded.code, Some(0), "{}", encoded.stderr);
    for args in [&["info", "c.mc"][..], &["info", "c.mc", "--json"][..]] {
        let info = run(MESHCODEC, args, d);
        assert_eq!(info.code, Some(0), "{}", info.stderr);
        assert!(info.stdout.contains("766"), "{}", info.stdout);
    }
}

/// `info` on a mesh file describes the mesh (what a user checks before encoding); on a packed
/// glTF scene, each primitive's stream; on a `.mc` file that is none, the stream's error.
#[test]
fn info_describes_a_mesh_file_and_a_packed_scene() {
    let dir = scratch();
    let d = dir.path();
    let info = run(MESHCODEC, &["info", "spot.obj"], d);
    assert_eq!(info.code, Some(0), "{}", info.stderr);
    assert!(
        info.stdout.contains("2,930 vertices, 5,856 triangles; uvs"),
        "{}",
        info.stdout
    );
    assert!(info.stdout.contains("boundary edges 0"), "{}", info.stdout);
    let json = run(MESHCODEC, &["info", "bunny", "--json"], d);
    assert_eq!(json.code, Some(0), "{}", json.stderr);
    let report: serde_json::Value = serde_json::from_str(&json.stdout).unwrap();
    assert_eq!(report["primitives"][0]["triangles"], 69_451);
    assert_eq!(report["primitives"][0]["topology"]["boundary_edges"], 223);
    let packed = run(MESHCODEC, &["pack", "spot", "spot.glb"], d);
    assert_eq!(packed.code, Some(0), "{}", packed.stderr);
    let info = run(MESHCODEC, &["info", "spot.glb"], d);
    assert_eq!(info.code, Some(0), "{}", info.stderr);
    assert!(
        info.stdout.contains("stream of codec emc") && info.stdout.contains("5,856 triangles"),
        "{}",
        info.stdout
    );
    write(d, "not-a-stream.mc", b"hello");
    assert_clean_failure(
        &run(MESHCODEC, &["info", "not-a-stream.mc"], d),
        "bad magic",
    );
}
