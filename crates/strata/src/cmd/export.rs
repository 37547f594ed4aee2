//! `strata export`: the fitted mesh with terrain colours as glTF or OBJ.

use crate::world_arg::{Opened, check_whole_world, whole_world_limit};
use anyhow::Context;
use std::path::PathBuf;
use strata_export::{Format, Region, TerrainSoup};

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    world: crate::world_arg::WorldArgs,
    /// Output format: glb (binary glTF), gltf (glTF JSON, buffer embedded) or obj.
    /// Default: what --out's extension says.
    #[arg(long, value_name = "NAME")]
    format: Option<String>,
    /// Texels X0,Y0,X1,Y1 (half-open); X1/Y1 may pass the map edge (it wraps; the piece stays whole). Default: the whole map.
    #[arg(long, value_name = "X0,Y0,X1,Y1")]
    region: Option<String>,
    /// Mesh quality q in [0, 1] (max vertical error 2^(4(1-q))).
    #[arg(long, value_name = "Q", default_value_t = 0.5)]
    quality: f64,
    /// Output file: `.glb`, `.gltf` or `.obj`.
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
}

/// The format `--format` names, checked against `--out`'s extension (a file
/// named `.gltf` holds JSON by convention, so GLB bytes there are refused),
/// or the one the extension says.
fn format_for(format: Option<&str>, out: &std::path::Path) -> anyhow::Result<Format> {
    let by_extension = Format::from_extension(out);
    match (format, by_extension) {
        (Some(name), ext) => {
            let format: Format = name.parse()?;
            if let Some(ext) = ext
                && ext != format
            {
                anyhow::bail!(
                    "--format {} but {} is named `.{}`: name the file `.{}` or pass --format {}",
                    format.name(),
                    out.display(),
                    ext.name(),
                    format.name(),
                    ext.name()
                );
            }
            Ok(format)
        }
        (None, Some(ext)) => Ok(ext),
        (None, None) => anyhow::bail!(
            "cannot tell the format from {}: name it `.glb`, `.gltf` or `.obj`, or pass --format",
            out.display()
        ),
    }
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let format = format_for(args.format.as_deref(), &args.out)?;
    // A store is read through its chunk cache: only the chunks under the
    // region. The whole map of a store is a mesh as large as the map, so a
    // store too large to load is refused without --region.
    let opened = args.world.open()?;
    let source = opened.source();
    let (w, h) = source.size();
    let region = match &args.region {
        Some(text) => Region::parse_in(text, w, h)?,
        None => {
            if let Opened::Store(s) = &opened {
                check_whole_world(s.store.dir(), s.store.store(), whole_world_limit())
                    .context("export of the whole map (give --region X0,Y0,X1,Y1)")?;
            }
            Region::whole_of(w, h)
        }
    };
    // Open the file first: an unwritable path fails before the fit.
    let file = std::fs::File::create(&args.out)
        .with_context(|| format!("cannot write the export to {}", args.out.display()))?;
    let soup = TerrainSoup::build_from(source, opened.world(), region, args.quality)?;
    let mut out = std::io::BufWriter::new(file);
    soup.write(format, &mut out)
        .with_context(|| format!("writing {}", args.out.display()))?;
    drop(out);
    let bytes = std::fs::metadata(&args.out).map(|m| m.len()).unwrap_or(0);
    println!(
        "{}: {} vertices, {} triangles, max error {}, {:.1} MiB",
        args.out.display(),
        soup.positions.len(),
        soup.triangles.len(),
        soup.max_error,
        bytes as f64 / (1 << 20) as f64
    );
    Ok(())
}
