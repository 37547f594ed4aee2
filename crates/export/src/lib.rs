//! Export the fitted terrain mesh (issue 18) for Blender and engines: glTF
//! 2.0 as binary `.glb` or as `.gltf` JSON (buffer embedded), or Wavefront
//! OBJ, with terrain colours as vertex colours.
//!
//! ```
//! use strata_export::{Format, Region, TerrainSoup};
//! let world = strata_level::generate::generate(&strata_level::generate::GenerateParams {
//!     width: 256,
//!     height: 256,
//!     ..Default::default()
//! })
//! .unwrap();
//! let region = Region::parse("0,0,128,128", &world.level).unwrap();
//! let soup = TerrainSoup::build(&world, region, 0.5).unwrap();
//! let mut bytes = Vec::new();
//! soup.write(Format::Glb, &mut bytes).unwrap();
//! assert_eq!(&bytes[..4], b"glTF");
//! ```
//!
//! Frame: glTF is y-up, so the terrain's (x, y, z-up) texel frame is
//! written as glTF `(x, z, -y)` (right-handed both ways; Blender's glTF and
//! OBJ importers turn it back into z-up). One unit is one texel, altitude in
//! height units. Vertices stand at texel centres, like the renderer's.
//!
//! Stability: [`Region`], [`Format`], [`TerrainSoup`] and [`ExportError`]
//! are the stable surface.

#![warn(missing_docs)]

mod color;
mod error;
mod gltf;
mod obj;
mod region;
mod soup;

pub use error::ExportError;
pub use region::Region;
pub use soup::TerrainSoup;

/// An output file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// glTF 2.0 binary (`.glb`): positions, `COLOR_0` (RGBA8), u32 indices.
    Glb,
    /// glTF 2.0 JSON (`.gltf`): the same document, its buffer embedded as a
    /// base64 data URI, so the one file is complete.
    Gltf,
    /// Wavefront OBJ with `v x y z r g b` vertex colours.
    Obj,
}

impl Format {
    /// The name `--format` takes, which is also the file extension.
    pub fn name(self) -> &'static str {
        match self {
            Format::Glb => "glb",
            Format::Gltf => "gltf",
            Format::Obj => "obj",
        }
    }

    /// The format a file name's extension says (`.glb`, `.gltf`, `.obj`, any case).
    pub fn from_extension(path: &std::path::Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        ext.parse().ok()
    }
}

impl std::str::FromStr for Format {
    type Err = ExportError;
    fn from_str(s: &str) -> Result<Self, ExportError> {
        match s {
            "glb" => Ok(Format::Glb),
            "gltf" => Ok(Format::Gltf),
            "obj" => Ok(Format::Obj),
            other => Err(ExportError::Format(other.to_string())),
        }
    }
}

impl TerrainSoup {
    /// Write the mesh in `format`.
    pub fn write(&self, format: Format, out: &mut impl std::io::Write) -> std::io::Result<()> {
        match format {
            Format::Glb => gltf::write_binary(self, out),
            Format::Gltf => gltf::write_json(self, out),
            Format::Obj => obj::write(self, out),
        }
    }
}
