//! `strata convert`: a Vangers world directory to a Strata store (Zarr v3)
//! and back. Vangers -> store -> Vangers gives the same decoded level, and
//! the files Strata wrote come back byte for byte.

use anyhow::Context;
use std::path::PathBuf;
use std::time::Instant;
use strata_store::Layout;
use strata_store::fs::{DirKind, dir_kind, to_store, to_vangers};

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
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// What to write; default: the other kind than `--level`.
    #[arg(long, value_enum)]
    to: Option<To>,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let from = dir_kind(&args.level)?;
    let to = args.to.unwrap_or(match from {
        DirKind::Vangers => To::Store,
        DirKind::Store => To::Vangers,
    });
    let t = Instant::now();
    match to {
        To::Store => {
            to_store(&args.level, &args.out, &Layout::default())
                .with_context(|| format!("writing the store {}", args.out.display()))?;
        }
        To::Vangers => to_vangers(&args.level, &args.out)
            .with_context(|| format!("writing the Vangers world {}", args.out.display()))?,
    }
    println!(
        "wrote {} ({to:?}) from {} in {:.2} s",
        args.out.display(),
        args.level.display(),
        t.elapsed().as_secs_f64()
    );
    Ok(())
}
