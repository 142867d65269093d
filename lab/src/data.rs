//! Test meshes on demand, as open3d.data or torchvision's datasets do: a bare name
//! (`experiment emc bunny`) is looked up in `$MESHCODEC_DATA`, `../shared/meshes` and the
//! per-user cache (`meshcodec::mesh::io::data_dirs`); a name the repository's manifest
//! (data/meshes.tsv) lists but none of these holds is downloaded into the cache — from
//! `$MESHCODEC_MIRROR` (a base URL holding the files by name) when set, else from its public
//! source at the commit the manifest names — with a progress bar, and kept only if its sha256
//! is the manifest's.

use crate::progress::Progress;
use anyhow::{anyhow, bail, Context, Result};
use meshcodec::mesh::io::{cache_dir, data_dirs, resolve as resolve_local};
use sha2::{Digest, Sha256};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The manifest, compiled in: one line a file.
const MANIFEST: &str = include_str!("../../data/meshes.tsv");

/// One mesh file of the manifest.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Entry {
    /// Its file name (`bunny.ply`); the stem is the name it is called by.
    pub file: String,
    /// Its sha256, lowercase hex.
    pub sha256: String,
    /// Where one file can be fetched from (`None`: only from a mirror).
    pub url: Option<String>,
    /// Its public source, as the manifest says it.
    pub source: String,
}

impl Entry {
    /// The name a user calls it by: the file's stem.
    pub fn name(&self) -> &str {
        self.file
            .rsplit_once('.')
            .map_or(&self.file, |(stem, _)| stem)
    }
}

/// Every file of the manifest.
pub fn manifest() -> Vec<Entry> {
    MANIFEST
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .filter_map(|l| {
            let mut cells = l.split('\t');
            let (file, sha256, url, source) =
                (cells.next()?, cells.next()?, cells.next()?, cells.next()?);
            Some(Entry {
                file: file.to_string(),
                sha256: sha256.to_string(),
                url: (url != "-").then(|| url.to_string()),
                source: source.to_string(),
            })
        })
        .collect()
}

/// The entry called `name` (a stem, or a file name).
pub fn entry(name: &str) -> Option<Entry> {
    manifest()
        .into_iter()
        .find(|e| e.file == name || e.name() == name)
}

/// Where `entry` lies in the data folders, if it does.
pub fn local(entry: &Entry) -> Option<PathBuf> {
    data_dirs()
        .into_iter()
        .map(|d| d.join(&entry.file))
        .find(|p| p.is_file())
}

/// A path or a bare name as a mesh file, downloading a manifest mesh no data folder holds.
pub fn resolve(name_or_path: &str) -> Result<PathBuf> {
    match resolve_local(name_or_path) {
        Ok(path) => Ok(path),
        Err(local_error) => match entry(name_or_path) {
            Some(e) if !name_or_path.contains('/') => {
                // A mesh that needs a companion file (the textured bunny's .mtl) gets it too.
                for companion in companions(&e) {
                    if local(&companion).is_none() {
                        fetch(&companion)?;
                    }
                }
                fetch(&e)
            }
            _ => Err(anyhow!(local_error)),
        },
    }
}

/// Files a mesh file names and the manifest holds (an OBJ's material library).
pub fn companions(entry: &Entry) -> Vec<Entry> {
    if entry.file == "bunny-10k-textured.obj" {
        return self::entry("bunny10k_textured.mtl").into_iter().collect();
    }
    Vec::new()
}

/// Where `entry` is fetched from: `$MESHCODEC_MIRROR/<file>`, else its own URL.
pub fn source_url(entry: &Entry) -> Result<String> {
    if let Some(mirror) = std::env::var("MESHCODEC_MIRROR")
        .ok()
        .filter(|m| !m.is_empty())
    {
        return Ok(format!("{}/{}", mirror.trim_end_matches('/'), entry.file));
    }
    entry.url.clone().ok_or_else(|| {
        anyhow!(
            "{} ({}) has no single file to download: set MESHCODEC_MIRROR to a folder of URLs holding it, or put it in {}",
            entry.file,
            entry.source,
            where_to_put()
        )
    })
}

/// Where a user may put a file by hand, for error messages.
fn where_to_put() -> String {
    match cache_dir() {
        Some(cache) => format!("$MESHCODEC_DATA, ../shared/meshes or {}", cache.display()),
        None => "$MESHCODEC_DATA or ../shared/meshes".to_string(),
    }
}

/// Downloads `entry` into the cache (atomically, after checking its sha256); its path.
pub fn fetch(entry: &Entry) -> Result<PathBuf> {
    let cache = cache_dir().ok_or_else(|| {
        anyhow!(
            "no cache folder for downloads: set MESHCODEC_CACHE (or HOME), or put {} in {}",
            entry.file,
            where_to_put()
        )
    })?;
    let url = source_url(entry)?;
    std::fs::create_dir_all(&cache).with_context(|| cache.display().to_string())?;
    let target = cache.join(&entry.file);
    let bytes = download(&url, &entry.file).map_err(|e| {
        anyhow!(
            "{}: cannot download {url} ({e}); put the file in {}",
            entry.file,
            where_to_put()
        )
    })?;
    let got = hex(&Sha256::digest(&bytes));
    if got != entry.sha256 {
        bail!(
            "{}: {url} sent {} bytes whose sha256 is {got}, not the manifest's {}; nothing kept",
            entry.file,
            bytes.len(),
            entry.sha256
        );
    }
    let partial = cache.join(format!(".{}.part", entry.file));
    let mut file =
        std::fs::File::create(&partial).with_context(|| partial.display().to_string())?;
    file.write_all(&bytes)?;
    file.sync_all()?;
    std::fs::rename(&partial, &target).with_context(|| target.display().to_string())?;
    Ok(target)
}

/// The bytes at `url`, with a progress bar on a terminal.
fn download(url: &str, what: &str) -> Result<Vec<u8>> {
    let agent: ureq::Agent = ureq::Agent::config_builder()
        .timeout_connect(Some(Duration::from_secs(15)))
        .timeout_per_read(Some(Duration::from_secs(60)))
        .build()
        .into();
    let response = agent.get(url).call().map_err(|e| anyhow!("{e}"))?;
    let body = response.into_body();
    let total = body.content_length().unwrap_or(0);
    let progress = Progress::on_terminal();
    progress.bytes(format!("downloading {what}"), total);
    let mut reader = body.into_reader();
    // At most 1 GiB, whatever the server says: the manifest's largest file is a few MB.
    let mut bytes = Vec::with_capacity(total.min(1 << 30) as usize);
    let mut chunk = vec![0u8; 1 << 16];
    loop {
        let n = reader.read(&mut chunk)?;
        if n == 0 {
            break;
        }
        bytes.extend_from_slice(&chunk[..n]);
        if bytes.len() > 1 << 30 {
            bail!("more than 1 GiB");
        }
        progress.at_byte(bytes.len() as u64);
    }
    progress.finish();
    Ok(bytes)
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Whether `path` holds exactly `entry`'s bytes.
pub fn verified(entry: &Entry, path: &Path) -> Result<bool> {
    let bytes = std::fs::read(path).with_context(|| path.display().to_string())?;
    Ok(hex(&Sha256::digest(&bytes)) == entry.sha256)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_manifest_lists_every_mesh_once_with_a_hash_and_a_source() {
        let entries = manifest();
        assert!(entries.len() >= 30);
        let mut files: Vec<&str> = entries.iter().map(|e| e.file.as_str()).collect();
        files.sort();
        files.dedup();
        assert_eq!(files.len(), entries.len());
        for e in &entries {
            assert_eq!(e.sha256.len(), 64, "{}", e.file);
            assert!(e.sha256.chars().all(|c| c.is_ascii_hexdigit()));
            assert!(!e.source.is_empty());
        }
        assert_eq!(entry("bunny").unwrap().file, "bunny.ply");
    }
}
