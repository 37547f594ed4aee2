//! A reference view on disk: pictures a person can look at (`sky.png`,
//! `distance.png`, `class.png`) and raw data (`distance.f32`, little-endian
//! row-major, `f32::INFINITY` = sky; `class.u8`; `terrain.u8`) described by
//! `reference.json` ([`ViewHeader`]).

use crate::{HitClass, Reference};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use strata_camera::Camera;
use strata_level::ViewSpec;

/// The JSON header ([`ViewHeader`]).
pub const HEADER_FILE: &str = "reference.json";
/// Distances, `width * height` little-endian `f32`, infinity for sky.
pub const DISTANCE_FILE: &str = "distance.f32";
/// Hit classes, one [`HitClass::code`] byte per pixel.
pub const CLASS_FILE: &str = "class.u8";
/// Terrain types (0..7, 0 for sky), one byte per pixel.
pub const TERRAIN_FILE: &str = "terrain.u8";

/// Sky in `distance.png` and `class.png`: white, which the ramp never reaches.
pub const SKY_RGB: [u8; 3] = [255, 255, 255];

/// `reference.json`: what the raw files hold and how they were made.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ViewHeader {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// The camera the view was traced with.
    pub camera: Camera,
    /// The view it was resolved from, when it came from one.
    pub view: Option<ViewSpec>,
    /// The level's content hash.
    pub level_hash: String,
    /// [`REFERENCE_VERSION`](crate::REFERENCE_VERSION) of the code that wrote it.
    pub reference_version: u32,
    /// Percent of pixels that are sky.
    pub sky_fraction: f64,
    /// Nearest hit, world units (`None` when all sky).
    pub distance_min: Option<f32>,
    /// Median hit distance ([`Reference::distance_summary`]).
    pub distance_median: Option<f32>,
    /// Farthest hit.
    pub distance_max: Option<f32>,
    /// Wall-clock seconds to compute (0 when read from the cache).
    pub seconds: f64,
    /// Whether the image came from the [`ReferenceCache`](crate::ReferenceCache).
    pub from_cache: bool,
    /// How to read the raw files, for a person opening the directory.
    pub format: String,
}

/// Why a view directory could not be written or read; each names the file.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// Reading or writing a file failed.
    #[error("{path}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// Encoding a picture failed.
    #[error("{path}")]
    Png {
        /// The picture.
        path: PathBuf,
        /// The encoder's error.
        source: image::ImageError,
    },
    /// `reference.json` is not a valid header.
    #[error("{path}")]
    Json {
        /// The header file.
        path: PathBuf,
        /// The parser's error.
        source: serde_json::Error,
    },
    /// A raw file has the wrong size or an unknown class code.
    #[error("{path}: {msg}")]
    Format {
        /// The raw file.
        path: PathBuf,
        /// What is wrong with it.
        msg: String,
    },
}

/// The text of [`ViewHeader::format`]: how to read the raw files.
pub const FORMAT_NOTE: &str = "distance.f32: width*height f32 little-endian, row-major, distance along the pixel ray from the eye, inf = sky; class.u8: 0 sky, 1 floor, 2 slab top, 3 cave ceiling, 4 wall; terrain.u8: terrain type 0..7 (0 for sky)";

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> OutputError + '_ {
    move |source| OutputError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// Write the pictures, the raw planes and the header into `dir` (created).
pub fn write_view(dir: &Path, header: &ViewHeader, r: &Reference) -> Result<(), OutputError> {
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let (w, h) = (r.width, r.height);
    let far = header.camera.far;
    let sky: Vec<u8> = r
        .distance
        .iter()
        .map(|d| if d.is_finite() { 0 } else { 255 })
        .collect();
    png(
        &dir.join("sky.png"),
        &sky,
        w,
        h,
        image::ExtendedColorType::L8,
    )?;
    let dist: Vec<u8> = r
        .distance
        .iter()
        .flat_map(|&d| distance_rgb(d, far))
        .collect();
    png(
        &dir.join("distance.png"),
        &dist,
        w,
        h,
        image::ExtendedColorType::Rgb8,
    )?;
    let class: Vec<u8> = r.class.iter().flat_map(|&c| class_rgb(c)).collect();
    png(
        &dir.join("class.png"),
        &class,
        w,
        h,
        image::ExtendedColorType::Rgb8,
    )?;
    let raw: Vec<u8> = r.distance.iter().flat_map(|d| d.to_le_bytes()).collect();
    write(&dir.join(DISTANCE_FILE), &raw)?;
    let codes: Vec<u8> = r.class.iter().map(|c| c.code()).collect();
    write(&dir.join(CLASS_FILE), &codes)?;
    write(&dir.join(TERRAIN_FILE), &r.terrain)?;
    let path = dir.join(HEADER_FILE);
    let json = serde_json::to_vec_pretty(header).map_err(|source| OutputError::Json {
        path: path.clone(),
        source,
    })?;
    write(&path, &json)
}

/// Read a directory written by [`write_view`].
pub fn read_view(dir: &Path) -> Result<(ViewHeader, Reference), OutputError> {
    let path = dir.join(HEADER_FILE);
    let text = std::fs::read(&path).map_err(io(&path))?;
    let header: ViewHeader = serde_json::from_slice(&text).map_err(|source| OutputError::Json {
        path: path.clone(),
        source,
    })?;
    let n = header.width as usize * header.height as usize;
    let dpath = dir.join(DISTANCE_FILE);
    let distance = read_f32(&dpath, n)?;
    let read_bytes = |name: &str| -> Result<Vec<u8>, OutputError> {
        let p = dir.join(name);
        let b = std::fs::read(&p).map_err(io(&p))?;
        if b.len() != n {
            return Err(OutputError::Format {
                path: p,
                msg: format!("{} bytes, expected {n}", b.len()),
            });
        }
        Ok(b)
    };
    let class = read_bytes(CLASS_FILE)?
        .into_iter()
        .map(|c| {
            HitClass::from_code(c).ok_or_else(|| OutputError::Format {
                path: dir.join(CLASS_FILE),
                msg: format!("unknown class code {c}"),
            })
        })
        .collect::<Result<_, _>>()?;
    let terrain = read_bytes(TERRAIN_FILE)?;
    let r = Reference {
        width: header.width,
        height: header.height,
        distance,
        class,
        terrain,
    };
    Ok((header, r))
}

/// Read a raw little-endian f32 file of exactly `n` values.
pub fn read_f32(path: &Path, n: usize) -> Result<Vec<f32>, OutputError> {
    let b = std::fs::read(path).map_err(io(path))?;
    if b.len() != 4 * n {
        return Err(OutputError::Format {
            path: path.to_path_buf(),
            msg: format!("{} bytes, expected {} ({n} f32 values)", b.len(), 4 * n),
        });
    }
    Ok(b.chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect())
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    std::fs::write(path, bytes).map_err(io(path))
}

fn png(
    path: &Path,
    buf: &[u8],
    w: u32,
    h: u32,
    kind: image::ExtendedColorType,
) -> Result<(), OutputError> {
    image::save_buffer(path, buf, w, h, kind).map_err(|source| OutputError::Png {
        path: path.to_path_buf(),
        source,
    })
}

/// Near is bright yellow, far is dark violet (viridis, reversed, on
/// `sqrt(d / far)` so the near field gets more of the ramp); sky is white.
pub fn distance_rgb(d: f32, far: f32) -> [u8; 3] {
    const STOPS: [[f32; 3]; 5] = [
        [253.0, 231.0, 37.0],
        [94.0, 201.0, 98.0],
        [33.0, 145.0, 140.0],
        [59.0, 82.0, 139.0],
        [68.0, 1.0, 84.0],
    ];
    if !d.is_finite() {
        return SKY_RGB;
    }
    let x = (d.max(0.0) / far.max(1e-6)).sqrt().min(1.0) * (STOPS.len() - 1) as f32;
    let k = (x as usize).min(STOPS.len() - 2);
    let f = x - k as f32;
    std::array::from_fn(|c| (STOPS[k][c] + (STOPS[k + 1][c] - STOPS[k][c]) * f).round() as u8)
}

/// One colour per class; sky white.
pub fn class_rgb(c: HitClass) -> [u8; 3] {
    match c {
        HitClass::Sky => SKY_RGB,
        HitClass::Floor => [70, 150, 60],
        HitClass::SlabTop => [235, 150, 40],
        HitClass::CaveCeiling => [200, 40, 40],
        HitClass::Wall => [80, 100, 170],
    }
}

/// `color.png`: the colour reference of a view.
pub const COLOR_FILE: &str = "color.png";

/// Write the colour reference as `dir/color.png`.
pub fn write_color(dir: &Path, color: &crate::ColorImage) -> Result<(), OutputError> {
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let path = dir.join(COLOR_FILE);
    image::save_buffer(
        &path,
        &color.rgb,
        color.width,
        color.height,
        image::ExtendedColorType::Rgb8,
    )
    .map_err(|source| OutputError::Png { path, source })
}
