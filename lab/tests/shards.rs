//! `experiment run SET --shard I/N` + `experiment merge` write exactly what one run writes:
//! every file byte for byte, except the wall-clock timings in the results JSON (encode and
//! decode times, PM's iteration rates).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

const EXPERIMENT: &str = env!("CARGO_BIN_EXE_experiment");

fn experiment(args: &[&str], dir: &Path) -> String {
    let out = Command::new(EXPERIMENT)
        .args(args)
        .current_dir(dir)
        .env(
            "MESHCODEC_DATA",
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes"),
        )
        .output()
        .expect("experiment runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "experiment {args:?}: {stderr}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Wall-clock figures (`…_seconds`, `…_per_second`, as encode and decode times and PM's
/// iteration rates) set to null, wherever they sit.
fn blank_timings(value: &mut serde_json::Value) {
    match value {
        serde_json::Value::Object(map) => {
            for (key, v) in map.iter_mut() {
                if key.ends_with("_seconds") || key.ends_with("_per_second") {
                    *v = serde_json::Value::Null;
                } else {
                    blank_timings(v);
                }
            }
        }
        serde_json::Value::Array(items) => items.iter_mut().for_each(blank_timings),
        _ => {}
    }
}

/// Every file under `root` by relative path; results JSON with the timings blanked.
fn tree(root: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            let mut bytes = std::fs::read(&path).unwrap();
            if path.extension().is_some_and(|e| e == "json") {
                let mut value: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
                blank_timings(&mut value);
                bytes = serde_json::to_vec(&value).unwrap();
            }
            files.insert(path.strip_prefix(root).unwrap().to_path_buf(), bytes);
        }
    }
    files
}

#[test]
fn three_shards_merged_are_one_run() {
    let dir = tempfile::tempdir().unwrap();
    let set = dir.path().join("tiny.toml");
    // 2 meshes × 3 codecs × 2 quantizations = 12 jobs; spot's uvs in the levels are for pm
    // alone: raw and emc refuse them.
    std::fs::write(
        &set,
        r#"description = "sharding test"
codecs = ["raw", "emc", "pm"]
meshes = ["bunny-res4", "spot"]
quant = [10, 12]
samples = 2
keep_streams = true
appearance = true
attributes = ["fit"]
"#,
    )
    .unwrap();
    let set = set.to_str().unwrap();
    let one = experiment(&["run", set, "--out", "one"], dir.path());
    assert!(one.contains("emc refused spot"), "{one}");
    for i in 1..=3 {
        let shard = format!("{i}/3");
        let out = format!("shard{i}");
        let said = experiment(&["run", set, "--shard", &shard, "--out", &out], dir.path());
        assert!(
            said.contains(&format!("shard {i}/3: 4 of the set's 12 jobs")),
            "{said}"
        );
        assert!(!said.contains("comparison charts"), "{said}");
    }
    let merged = experiment(
        &[
            "merge", set, "shard3", "shard1", "shard2", "--out", "merged",
        ],
        dir.path(),
    );
    assert!(merged.contains("merged 12 jobs"), "{merged}");
    let (one_files, merged_files) = (
        tree(&dir.path().join("one")),
        tree(&dir.path().join("merged")),
    );
    assert_eq!(
        one_files.keys().collect::<Vec<_>>(),
        merged_files.keys().collect::<Vec<_>>()
    );
    for (path, bytes) in &one_files {
        assert!(bytes == &merged_files[path], "{} differs", path.display());
    }
    for expected in [
        "compare/tiny/spot-rate-distortion.png",
        "emc/spot.refused.txt",
        "pm/bunny-res4-q10.mc",
        "pm/spot-q10-appearance-fit.mc",
    ] {
        assert!(
            one_files.contains_key(Path::new(expected)),
            "{expected}: {:?}",
            one_files.keys()
        );
    }
    // The summary tables agree too.
    let table = |text: &str| text[text.find("\ncodec").unwrap()..].to_string();
    assert_eq!(table(&one), table(&merged));

    // A shard short: the merge names it and writes nothing.
    let out = Command::new(EXPERIMENT)
        .args(["merge", set, "shard1", "shard3", "--out", "partial"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("shard 2/3 is missing"));
    assert!(!dir.path().join("partial").exists());
}
