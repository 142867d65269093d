//! Experiment sets split over machines: `experiment run SET.toml --shard I/N` runs every N-th
//! job of the set (a job is one codec on one mesh at one quantization, numbered in the set's
//! order: meshes, then codecs, then quantizations) and leaves a manifest of what it wrote;
//! `experiment merge SET.toml DIR…` checks that the shards' manifests cover every job once and
//! copies their files into one results folder, where the comparison charts are drawn as a
//! single run draws them.

use meshcodec::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Shard `index` (from 1) of `count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// Which shard, from 1.
    pub index: usize,
    /// How many shards.
    pub count: usize,
}

impl Shard {
    /// Parses "I/N" (1 ≤ I ≤ N): what a Slurm job array hands over as
    /// `${SLURM_ARRAY_TASK_ID}/N`.
    pub fn parse(text: &str) -> std::result::Result<Shard, String> {
        let bad = || format!("shard '{text}' is not I/N with 1 <= I <= N");
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let (index, count) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// Whether job `job` (numbered from 0 in the set's order) is this shard's: jobs are dealt
    /// round-robin, so neighbouring jobs (often the same mesh) spread over the shards.
    pub fn owns(&self, job: usize) -> bool {
        job % self.count == self.index - 1
    }

    /// The shard that runs job `job`.
    pub fn of_job(job: usize, count: usize) -> Shard {
        Shard {
            index: job % count + 1,
            count,
        }
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// One job of a set, as its manifest records it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct JobRecord {
    /// Number of the job in the set's order, from 0.
    pub job: usize,
    /// Codec name.
    pub codec: String,
    /// Mesh name (file stem).
    pub mesh: String,
    /// Quantization asked for (none: the codec's default).
    pub quant: Option<u8>,
    /// Whether the codec refused the mesh (its reason is the one file).
    pub refused: bool,
    /// Files the job wrote, relative to the shard's results folder.
    pub files: Vec<PathBuf>,
}

/// What one shard ran and wrote.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardManifest {
    /// The set's name (its file stem).
    pub set: String,
    /// Which shard.
    pub shard: Shard,
    /// Jobs in the set in all.
    pub jobs_in_set: usize,
    /// The jobs this shard ran, in order.
    pub jobs: Vec<JobRecord>,
}

/// Where shard `shard` of set `set` leaves its manifest in its results folder.
pub fn manifest_path(out: &Path, set: &str, shard: Shard) -> PathBuf {
    out.join(format!(
        "{set}.shard-{}-of-{}.json",
        shard.index, shard.count
    ))
}

/// Every job of set `set` (of `jobs_in_set` jobs), found in exactly one of the shard folders
/// `dirs`: each job with the folder holding its files, in the set's order. Refuses a missing
/// shard or job, a job found twice, or manifests of another split of the set.
pub fn collect(
    set: &str,
    jobs_in_set: usize,
    dirs: &[PathBuf],
) -> Result<Vec<(JobRecord, PathBuf)>> {
    let mut manifests = Vec::new();
    for dir in dirs {
        let prefix = format!("{set}.shard-");
        let entries = std::fs::read_dir(dir)
            .map_err(|e| Error::Unsupported(format!("{}: {e}", dir.display())))?;
        let mut found = false;
        for entry in entries {
            let path = entry?.path();
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if !(name.starts_with(&prefix) && name.ends_with(".json")) {
                continue;
            }
            let text = std::fs::read_to_string(&path)?;
            let manifest: ShardManifest = serde_json::from_str(&text).map_err(|e| {
                Error::Unsupported(format!("{}: not a shard manifest: {e}", path.display()))
            })?;
            manifests.push((manifest, dir.clone()));
            found = true;
        }
        if !found {
            return Err(Error::Unsupported(format!(
                "{}: no manifest of set {set} (experiment run … --shard I/N writes one)",
                dir.display()
            )));
        }
    }
    let count = manifests
        .first()
        .map(|(m, _)| m.shard.count)
        .ok_or_else(|| Error::Unsupported("no shard folder given".into()))?;
    let mut seen = vec![false; count];
    let mut jobs: Vec<Option<(JobRecord, PathBuf)>> = vec![None; jobs_in_set];
    for (manifest, dir) in manifests {
        if manifest.shard.count != count || manifest.jobs_in_set != jobs_in_set {
            return Err(Error::Unsupported(format!(
                "{}: shard {} of a {}-job set, but the others are of {count} shards and the set has {jobs_in_set} jobs",
                dir.display(),
                manifest.shard,
                manifest.jobs_in_set
            )));
        }
        let i = manifest.shard.index - 1;
        if std::mem::replace(&mut seen[i], true) {
            return Err(Error::Unsupported(format!(
                "shard {} is given twice (again in {})",
                manifest.shard,
                dir.display()
            )));
        }
        for record in manifest.jobs {
            let slot = jobs.get_mut(record.job).ok_or_else(|| {
                Error::Unsupported(format!(
                    "{}: job {} is not in the set",
                    dir.display(),
                    record.job
                ))
            })?;
            if slot.is_some() || !manifest.shard.owns(record.job) {
                return Err(Error::Unsupported(format!(
                    "{}: job {} ({} on {}) does not belong to shard {}",
                    dir.display(),
                    record.job,
                    record.codec,
                    record.mesh,
                    manifest.shard
                )));
            }
            *slot = Some((record, dir.clone()));
        }
    }
    if let Some(missing) = seen.iter().position(|s| !s) {
        return Err(Error::Unsupported(format!(
            "shard {}/{count} is missing: its folder was not given or it did not finish",
            missing + 1
        )));
    }
    jobs.into_iter()
        .enumerate()
        .map(|(job, found)| {
            found.ok_or_else(|| {
                Error::Unsupported(format!(
                    "job {job} is in no manifest: shard {} stopped before it",
                    Shard::of_job(job, count)
                ))
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_deal_every_job_to_exactly_one() {
        assert_eq!(Shard::parse("2/3"), Ok(Shard { index: 2, count: 3 }));
        for bad in ["0/3", "4/3", "3", "a/b", "1/0", ""] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
        for job in 0..20 {
            let owners: Vec<usize> = (1..=3)
                .filter(|&i| Shard { index: i, count: 3 }.owns(job))
                .collect();
            assert_eq!(owners, vec![Shard::of_job(job, 3).index]);
        }
    }

    #[test]
    fn collecting_refuses_missing_and_doubled_jobs() {
        let dir = tempfile::tempdir().unwrap();
        let write = |name: &str, shard: Shard, jobs: Vec<usize>| {
            let folder = dir.path().join(name);
            std::fs::create_dir_all(&folder).unwrap();
            let manifest = ShardManifest {
                set: "s".into(),
                shard,
                jobs_in_set: 4,
                jobs: jobs
                    .into_iter()
                    .map(|job| JobRecord {
                        job,
                        codec: "raw".into(),
                        mesh: "m".into(),
                        quant: None,
                        refused: false,
                        files: vec![],
                    })
                    .collect(),
            };
            std::fs::write(
                manifest_path(&folder, "s", shard),
                serde_json::to_string(&manifest).unwrap(),
            )
            .unwrap();
            folder
        };
        let a = write("a", Shard { index: 1, count: 2 }, vec![0, 2]);
        let b = write("b", Shard { index: 2, count: 2 }, vec![1, 3]);
        let jobs = collect("s", 4, &[b.clone(), a.clone()]).unwrap();
        assert_eq!(
            jobs.iter().map(|(r, _)| r.job).collect::<Vec<_>>(),
            [0, 1, 2, 3]
        );
        assert!(collect("s", 4, std::slice::from_ref(&a))
            .unwrap_err()
            .to_string()
            .contains("shard 2/2 is missing"));
        let short = write("short", Shard { index: 2, count: 2 }, vec![1]);
        assert!(collect("s", 4, &[a.clone(), short])
            .unwrap_err()
            .to_string()
            .contains("job 3 is in no manifest"));
        let wrong = write("wrong", Shard { index: 2, count: 2 }, vec![1, 2]);
        assert!(collect("s", 4, &[a.clone(), wrong])
            .unwrap_err()
            .to_string()
            .contains("does not belong"));
        assert!(collect("s", 4, &[a.clone(), a]).is_err());
    }
}
