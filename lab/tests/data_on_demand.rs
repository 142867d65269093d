//! Meshes on demand (lab/src/data.rs): from a folder with no ../shared beside it and no data
//! folder, `experiment emc bunny` downloads bunny.ply from a `MESHCODEC_MIRROR` served here on
//! loopback into the cache, checks its sha256 and runs; a mirror that sends other bytes leaves
//! nothing in the cache; an unreachable mirror with an empty cache ends in one line and a
//! non-zero exit.

use std::io::{BufRead, BufReader, Write};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn shared_meshes() -> PathBuf {
    std::env::var_os("MESHCODEC_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes"))
}

/// An HTTP server on loopback answering every GET of `/<file>` with `body(file)` (404 when
/// `None`), until the test ends; its base URL.
fn mirror(body: impl Fn(&str) -> Option<Vec<u8>> + Send + 'static) -> String {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let url = format!("http://{}", listener.local_addr().unwrap());
    std::thread::spawn(move || {
        for stream in listener.incoming() {
            let Ok(mut stream) = stream else { continue };
            let mut reader = BufReader::new(stream.try_clone().unwrap());
            let mut request = String::new();
            if reader.read_line(&mut request).is_err() {
                continue;
            }
            // The headers, up to the blank line.
            let mut line = String::new();
            while reader.read_line(&mut line).is_ok_and(|n| n > 2) {
                line.clear();
            }
            let file = request
                .split_whitespace()
                .nth(1)
                .unwrap_or("/")
                .trim_start_matches('/')
                .to_string();
            let _ = match body(&file) {
                Some(bytes) => stream
                    .write_all(
                        format!(
                            "HTTP/1.1 200 OK\r\nContent-Length: {}\r\nConnection: close\r\n\r\n",
                            bytes.len()
                        )
                        .as_bytes(),
                    )
                    .and_then(|_| stream.write_all(&bytes)),
                None => stream.write_all(
                    b"HTTP/1.1 404 Not Found\r\nContent-Length: 0\r\nConnection: close\r\n\r\n",
                ),
            };
        }
    });
    url
}

/// `bin` run in a scratch folder with no data folder, `cache` as the cache, `mirror` as the
/// mirror.
fn run(bin: &str, args: &[&str], scratch: &Path, cache: &Path, mirror: &str) -> Output {
    let work = scratch.join("work");
    let empty = scratch.join("empty");
    std::fs::create_dir_all(&work).unwrap();
    std::fs::create_dir_all(&empty).unwrap();
    Command::new(bin)
        .args(args)
        .current_dir(&work)
        .env("MESHCODEC_DATA", &empty)
        .env("MESHCODEC_CACHE", cache)
        .env("MESHCODEC_MIRROR", mirror)
        .output()
        .expect("binary runs")
}

#[test]
fn a_mesh_no_data_folder_holds_is_fetched_from_the_mirror_checked_and_run() {
    let scratch = tempfile::tempdir().unwrap();
    let cache = scratch.path().join("cache");
    let served = mirror(|file| std::fs::read(shared_meshes().join(file)).ok());
    let out = run(
        env!("CARGO_BIN_EXE_experiment"),
        &["emc", "bunny", "--out", "results"],
        scratch.path(),
        &cache,
        &served,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read(cache.join("bunny.ply")).unwrap(),
        std::fs::read(shared_meshes().join("bunny.ply")).unwrap()
    );
    assert!(scratch.path().join("work/results/emc/bunny.json").is_file());
}

#[test]
fn other_bytes_are_refused_and_an_unreachable_mirror_is_one_line() {
    let scratch = tempfile::tempdir().unwrap();
    let cache = scratch.path().join("cache");
    let meshcodec = env!("CARGO_BIN_EXE_meshcodec");
    let liar = mirror(|_| Some(b"solid nothing\nendsolid\n".to_vec()));
    let out = run(meshcodec, &["info", "eight"], scratch.path(), &cache, &liar);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("sha256"), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(!cache.join("eight.off").exists());
    // Nothing listens on port 1.
    let out = run(
        meshcodec,
        &["info", "eight"],
        scratch.path(),
        &cache,
        "http://127.0.0.1:1",
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("http://127.0.0.1:1/eight.off") && stderr.contains("put the file in"),
        "{stderr}"
    );
    // `data fetch` with the real mirror, then `info` finds it in the cache with no mirror.
    let served = mirror(|file| std::fs::read(shared_meshes().join(file)).ok());
    let out = run(
        meshcodec,
        &["data", "fetch", "eight"],
        scratch.path(),
        &cache,
        &served,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = run(
        meshcodec,
        &["info", "eight"],
        scratch.path(),
        &cache,
        "http://127.0.0.1:1",
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("766 vertices"));
}
