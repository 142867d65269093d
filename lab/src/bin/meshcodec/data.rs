//! `meshcodec data list` and `meshcodec data fetch NAME|--all`: the test meshes of the
//! repository's manifest (meshcodec_lab::data), where they are, and downloading them.

use anyhow::{bail, Result};
use clap::Subcommand;
use meshcodec_lab::data::{companions, entry, fetch, local, manifest, verified};

#[derive(Subcommand)]
pub enum DataAction {
    /// Every mesh of the manifest: its name, where it is found (or "not here"), its source.
    List,
    /// Download meshes into the per-user cache, each checked against its sha256 (those
    /// already in a data folder with the right bytes are left as they are).
    Fetch {
        /// Mesh names (`bunny`) or file names (`bunny.ply`).
        names: Vec<String>,
        /// Every mesh of the manifest.
        #[arg(long, conflicts_with = "names")]
        all: bool,
    },
}

pub fn run(action: DataAction) -> Result<()> {
    match action {
        DataAction::List => {
            let mut text = String::new();
            for e in manifest() {
                let place = local(&e).map_or("not here".to_string(), |p| p.display().to_string());
                text.push_str(&format!(
                    "{:<24} {place}\n{:<24} from {}\n",
                    e.name(),
                    "",
                    e.source
                ));
            }
            meshcodec_lab::cli::write_stdout(&text)?;
        }
        DataAction::Fetch { names, all } => {
            let entries = if all {
                manifest()
            } else {
                if names.is_empty() {
                    bail!("name the meshes to fetch, or --all (`meshcodec data list` lists them)");
                }
                names
                    .iter()
                    .map(|n| {
                        entry(n).ok_or_else(|| {
                            anyhow::anyhow!(
                                "{n}: not a mesh of the manifest (`meshcodec data list`)"
                            )
                        })
                    })
                    .collect::<Result<Vec<_>>>()?
                    .into_iter()
                    .flat_map(|e| {
                        let mut with = companions(&e);
                        with.insert(0, e);
                        with
                    })
                    .collect()
            };
            for e in entries {
                if let Some(path) = local(&e) {
                    if verified(&e, &path)? {
                        eprintln!("{}: already in {}", e.file, path.display());
                        continue;
                    }
                }
                let path = fetch(&e)?;
                eprintln!("{}: fetched into {}", e.file, path.display());
            }
        }
    }
    Ok(())
}
