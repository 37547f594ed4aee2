/// What can go wrong exporting.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// `--region` text that is not four integers.
    #[error("region {0:?}: expected X0,Y0,X1,Y1 (texels, X0 < X1, Y0 < Y1)")]
    RegionSyntax(String),
    /// A region that is empty, negative or larger than the map.
    #[error(
        "region {text:?}: {why} (the map is {width}x{height} texels and wraps: X0,Y0 must lie in it, X1,Y1 may pass its edge by at most one map size)"
    )]
    RegionBounds {
        /// The region as given.
        text: String,
        /// What is wrong with it.
        why: &'static str,
        /// Map width.
        width: u32,
        /// Map height.
        height: u32,
    },
    /// A quality outside `[0, 1]`.
    #[error("quality {0} is outside [0, 1]")]
    Quality(f64),
    /// An unknown format name.
    #[error("format {0:?}: expected glb, gltf or obj")]
    Format(String),
    /// The region holds no triangles.
    #[error("the region holds no triangles")]
    Empty,
    /// The map could not be read (a store's chunk missing or corrupt).
    #[error("reading the map: {0}")]
    Source(#[from] strata_level::SourceError),
}
