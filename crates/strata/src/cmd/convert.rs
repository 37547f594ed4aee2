//! `strata convert`: a Vangers world directory to a Strata store (Zarr v3)
//! and back. Vangers -> store -> Vangers gives the same decoded level, and
//! the files Strata wrote come back byte for byte.

use anyhow::Context;
use std::path::PathBuf;
use std::time::Instant;
use strata_store::fs::{DirKind, dir_kind, to_store, to_vangers};
use strata_store::{DirStore, Layout};

/// What a world directory is written as.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum To {
    /// A Strata store: a chunked Zarr v3 group (`zarr.json`).
    Store,
    /// A Vangers world directory (`world.ini`, `.vmc`, …).
    Vangers,
}

#[derive(clap::Args)]
pub struct Args {
    /// The world to convert: a Vangers world or a store (told apart by its files).
    #[arg(long, value_name = "DIR")]
    level: PathBuf,
    /// Directory to write (must not exist, or be empty).
    #[arg(long, value_name = "DIR", required_unless_present = "add_lod")]
    out: Option<PathBuf>,
    /// What to write; default: the other kind than `--level`.
    #[arg(long, value_enum)]
    to: Option<To>,
    /// Write the levels of detail (`lod/`) of the store `--level` in place,
    /// for a store made before they existed; nothing else changes.
    #[arg(long, conflicts_with_all = ["out", "to"])]
    add_lod: bool,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let from = dir_kind(&args.level)?;
    let t = Instant::now();
    if args.add_lod {
        if from != DirKind::Store {
            anyhow::bail!(
                "--add-lod writes a store's levels of detail; {} is a Vangers world (convert it with --to store, which writes them)",
                args.level.display()
            );
        }
        let store = DirStore::build_lods(&args.level, &|_, _| {})
            .with_context(|| format!("writing the levels of detail of {}", args.level.display()))?;
        println!(
            "wrote {} levels of detail into {} in {:.2} s",
            store.store().lod_levels(),
            args.level.display(),
            t.elapsed().as_secs_f64()
        );
        return Ok(());
    }
    let out = args.out.clone().expect("clap requires --out");
    let to = args.to.unwrap_or(match from {
        DirKind::Vangers => To::Store,
        DirKind::Store => To::Vangers,
    });
    match to {
        To::Store => {
            to_store(&args.level, &out, &Layout::default())
                .with_context(|| format!("writing the store {}", out.display()))?;
            DirStore::build_lods(&out, &|_, _| {})
                .with_context(|| format!("writing the levels of detail of {}", out.display()))?;
        }
        To::Vangers => to_vangers(&args.level, &out)
            .with_context(|| format!("writing the Vangers world {}", out.display()))?,
    }
    println!(
        "wrote {} ({to:?}) from {} in {:.2} s",
        out.display(),
        args.level.display(),
        t.elapsed().as_secs_f64()
    );
    Ok(())
}
