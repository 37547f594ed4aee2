//! A disk cache of references, so the harness never recomputes one it has.
//! Key: SHA-256 of the reference version, the level's content hash, every
//! camera field and the image size. File: a 20-byte header then the three
//! planes (distance f32 LE, class u8, terrain u8): 6 bytes per pixel.

use crate::pyramid::Pyramid;
use crate::raycast::Tracer;
use crate::shading::{ColorImage, TerrainRamps, render_color};
use crate::{COLOR_VERSION, HitClass, REFERENCE_VERSION, Reference, ReferenceSettings};
use sha2::{Digest, Sha256};
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use strata_camera::Camera;
use strata_level::Level;

const MAGIC: &[u8; 8] = b"STRATARF";
const COLOR_MAGIC: &[u8; 8] = b"STRATACL";

/// `$STRATA_CACHE_DIR/reference`, else `$XDG_CACHE_HOME/strata/reference`,
/// else `~/.cache/strata/reference`, else `./.strata-cache/reference`.
pub fn default_cache_dir() -> PathBuf {
    let env = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    if let Some(dir) = env("STRATA_CACHE_DIR") {
        return dir.join("reference");
    }
    if let Some(dir) = env("XDG_CACHE_HOME") {
        return dir.join("strata").join("reference");
    }
    if let Some(home) = env("HOME") {
        return home.join(".cache").join("strata").join("reference");
    }
    PathBuf::from(".strata-cache").join("reference")
}

/// Why the cache could not store an entry.
#[derive(Debug, thiserror::Error)]
pub enum CacheError {
    /// Creating the cache directory or writing an entry failed.
    #[error("reference cache {path}")]
    Io {
        /// The file or directory written.
        path: PathBuf,
        /// The operating system's error.
        source: io::Error,
    },
}

/// Reference images on disk, keyed by level content hash, camera, size and
/// [`REFERENCE_VERSION`] (colour entries also by
/// colours and [`COLOR_VERSION`]). A missing or
/// unreadable entry is a miss, never an error.
pub struct ReferenceCache {
    dir: PathBuf,
    /// The pyramid of the last level computed, by content hash, so that
    /// `get_or_compute` over many views of one level builds it once.
    last_pyramid: Mutex<Option<(String, Arc<Pyramid>)>>,
}

impl ReferenceCache {
    /// A cache in `dir` (created on first store).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        ReferenceCache {
            dir: dir.into(),
            last_pyramid: Mutex::new(None),
        }
    }

    /// The cache's directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The cache key of a level (by content hash) and camera.
    pub fn key(level_hash: &str, camera: &Camera) -> String {
        let mut h = Sha256::new();
        h.update(b"strata-reference");
        h.update(REFERENCE_VERSION.to_le_bytes());
        h.update(level_hash.as_bytes());
        for v in [
            camera.position.x,
            camera.position.y,
            camera.position.z,
            camera.yaw_deg,
            camera.pitch_deg,
            camera.focal_px,
            camera.near,
            camera.far,
        ] {
            h.update(v.to_le_bytes());
        }
        h.update(camera.width.to_le_bytes());
        h.update(camera.height.to_le_bytes());
        h.finalize().iter().map(|b| format!("{b:02x}")).collect()
    }

    fn path(&self, key: &str) -> PathBuf {
        self.dir.join(format!("{key}.ref"))
    }

    /// The cached reference, or `None` when absent or unreadable (a damaged
    /// file is treated as a miss and overwritten by the next store).
    pub fn get(&self, level_hash: &str, camera: &Camera) -> Option<Reference> {
        let bytes = std::fs::read(self.path(&Self::key(level_hash, camera))).ok()?;
        decode(&bytes).filter(|r| r.width == camera.width && r.height == camera.height)
    }

    /// Store a reference; written to a temporary file and renamed, so a
    /// concurrent reader never sees half a file.
    pub fn put(&self, level_hash: &str, camera: &Camera, r: &Reference) -> Result<(), CacheError> {
        let io_err = |path: &Path| {
            let path = path.to_path_buf();
            move |source| CacheError::Io { path, source }
        };
        std::fs::create_dir_all(&self.dir).map_err(io_err(&self.dir))?;
        let path = self.path(&Self::key(level_hash, camera));
        let tmp = path.with_extension(format!("tmp{}", std::process::id()));
        std::fs::write(&tmp, encode(r)).map_err(io_err(&tmp))?;
        std::fs::rename(&tmp, &path).map_err(io_err(&path))
    }

    /// The reference of `level` through `camera`, from the cache or computed
    /// (and stored). Hashes the level on each call: for many views of one
    /// level use [`get_or_compute_traced`](Self::get_or_compute_traced).
    pub fn get_or_compute(&self, level: &Level, camera: &Camera) -> Result<Reference, CacheError> {
        let hash = level.content_hash();
        if let Some(r) = self.get(&hash, camera) {
            return Ok(r);
        }
        let mut last = self.last_pyramid.lock().unwrap_or_else(|e| e.into_inner());
        let tracer = match &*last {
            Some((h, p)) if *h == hash => Tracer::with_pyramid(level, p.clone()),
            _ => {
                let t = Tracer::new(level);
                if let Some(p) = t.pyramid() {
                    *last = Some((hash.clone(), p.clone()));
                }
                t
            }
        };
        drop(last);
        let r = tracer.render(camera, &ReferenceSettings::default());
        self.put(&hash, camera, &r)?;
        Ok(r)
    }

    /// Like [`get_or_compute`](Self::get_or_compute) with a prepared tracer
    /// and the level's content hash. Returns the reference and whether it
    /// came from the cache.
    pub fn get_or_compute_traced(
        &self,
        tracer: &Tracer,
        level_hash: &str,
        camera: &Camera,
    ) -> Result<(Reference, bool), CacheError> {
        if let Some(r) = self.get(level_hash, camera) {
            return Ok((r, true));
        }
        let r = tracer.render(camera, &ReferenceSettings::default());
        // A source that failed to read gives no reference to keep (the
        // caller finds the error in `tracer.error()`).
        if tracer.error().is_none() {
            self.put(level_hash, camera, &r)?;
        }
        Ok((r, false))
    }
}

impl ReferenceCache {
    /// The cache key of a colour reference: the distance reference's key,
    /// the colours, the shadow switch and the colour version.
    pub fn color_key(
        level_hash: &str,
        camera: &Camera,
        ramps: &TerrainRamps,
        shadows: bool,
    ) -> String {
        let mut h = Sha256::new();
        h.update(b"strata-color");
        h.update(COLOR_VERSION.to_le_bytes());
        h.update(Self::key(level_hash, camera).as_bytes());
        h.update(ramps.key_bytes());
        h.update([u8::from(shadows)]);
        h.finalize().iter().map(|b| format!("{b:02x}")).collect()
    }

    fn color_path(
        &self,
        level_hash: &str,
        camera: &Camera,
        ramps: &TerrainRamps,
        shadows: bool,
    ) -> PathBuf {
        self.dir.join(format!(
            "{}.rgb",
            Self::color_key(level_hash, camera, ramps, shadows)
        ))
    }

    /// The cached colour reference, or `None` when absent or unreadable.
    pub fn get_color(
        &self,
        level_hash: &str,
        camera: &Camera,
        ramps: &TerrainRamps,
        shadows: bool,
    ) -> Option<ColorImage> {
        let bytes = std::fs::read(self.color_path(level_hash, camera, ramps, shadows)).ok()?;
        decode_color(&bytes).filter(|c| c.width == camera.width && c.height == camera.height)
    }

    /// The colour reference of `camera`'s view (shadows on or off), from the
    /// cache or computed and stored. Returns it and whether it was cached.
    pub fn get_or_compute_color(
        &self,
        tracer: &Tracer,
        level_hash: &str,
        camera: &Camera,
        ramps: &TerrainRamps,
        shadows: bool,
    ) -> Result<(ColorImage, bool), CacheError> {
        if let Some(c) = self.get_color(level_hash, camera, ramps, shadows) {
            return Ok((c, true));
        }
        let path = self.color_path(level_hash, camera, ramps, shadows);
        let c = render_color(tracer, ramps, camera, shadows);
        if tracer.error().is_some() {
            return Ok((c, false));
        }
        let io_err = |path: &Path| {
            let path = path.to_path_buf();
            move |source| CacheError::Io { path, source }
        };
        std::fs::create_dir_all(&self.dir).map_err(io_err(&self.dir))?;
        let tmp = path.with_extension(format!("tmp{}", std::process::id()));
        let mut bytes = COLOR_MAGIC.to_vec();
        bytes.extend_from_slice(&c.width.to_le_bytes());
        bytes.extend_from_slice(&c.height.to_le_bytes());
        bytes.extend_from_slice(&c.rgb);
        std::fs::write(&tmp, bytes).map_err(io_err(&tmp))?;
        std::fs::rename(&tmp, &path).map_err(io_err(&path))?;
        Ok((c, false))
    }
}

fn decode_color(bytes: &[u8]) -> Option<ColorImage> {
    let u32_at = |k: usize| Some(u32::from_le_bytes(bytes.get(k..k + 4)?.try_into().ok()?));
    if bytes.get(..8)? != COLOR_MAGIC {
        return None;
    }
    let (width, height) = (u32_at(8)?, u32_at(12)?);
    let rgb = bytes[16..].to_vec();
    (rgb.len() == 3 * width as usize * height as usize).then_some(ColorImage { width, height, rgb })
}

fn encode(r: &Reference) -> Vec<u8> {
    let n = r.pixel_count();
    let mut out = Vec::with_capacity(20 + 6 * n);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&REFERENCE_VERSION.to_le_bytes());
    out.extend_from_slice(&r.width.to_le_bytes());
    out.extend_from_slice(&r.height.to_le_bytes());
    for d in &r.distance {
        out.extend_from_slice(&d.to_le_bytes());
    }
    out.extend(r.class.iter().map(|c| c.code()));
    out.extend_from_slice(&r.terrain);
    out
}

fn decode(bytes: &[u8]) -> Option<Reference> {
    let u32_at = |k: usize| Some(u32::from_le_bytes(bytes.get(k..k + 4)?.try_into().ok()?));
    if bytes.get(..8)? != MAGIC || u32_at(8)? != REFERENCE_VERSION {
        return None;
    }
    let (width, height) = (u32_at(12)?, u32_at(16)?);
    let n = (width as usize).checked_mul(height as usize)?;
    let body = &bytes[20..];
    if body.len() != n.checked_mul(6)? {
        return None;
    }
    let (dist, rest) = body.split_at(4 * n);
    let (class, terrain) = rest.split_at(n);
    Some(Reference {
        width,
        height,
        distance: dist
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect(),
        class: class
            .iter()
            .map(|&c| HitClass::from_code(c))
            .collect::<Option<_>>()?,
        terrain: terrain.to_vec(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn tmp_dir(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("strata-ref-cache-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    #[test]
    fn round_trip_hit_and_keys() {
        let level = Level::flat(64, 64, 10, 3).unwrap();
        let cam = Camera::new(Vec3::new(5.0, 5.0, 40.0), 10.0, -30.0, 24, 16).unwrap();
        let dir = tmp_dir("rt");
        let cache = ReferenceCache::new(&dir);
        let hash = level.content_hash();
        assert!(cache.get(&hash, &cam).is_none());
        let a = cache.get_or_compute(&level, &cam).unwrap();
        let stored = cache.get(&hash, &cam).expect("stored after compute");
        assert_eq!(stored, a);
        assert!(a.distance.iter().any(|d| d.is_finite()));
        // Any camera field, the size or the level changes the key.
        let mut other = cam;
        other.yaw_deg += 0.01;
        assert_ne!(
            ReferenceCache::key(&hash, &cam),
            ReferenceCache::key(&hash, &other)
        );
        let mut bigger = cam;
        bigger.width += 1;
        assert_ne!(
            ReferenceCache::key(&hash, &cam),
            ReferenceCache::key(&hash, &bigger)
        );
        let other_level = Level::flat(64, 64, 11, 3).unwrap();
        assert!(cache.get(&other_level.content_hash(), &cam).is_none());
        // The remembered pyramid belongs to the first level: not reused here.
        let other = cache.get_or_compute(&other_level, &cam).unwrap();
        assert_eq!(other, crate::render_reference(&other_level, &cam));
        assert_ne!(other, a);
        // A damaged file is a miss, then repaired.
        let path = cache.path(&ReferenceCache::key(&hash, &cam));
        std::fs::write(&path, b"STRATARF garbage").unwrap();
        assert!(cache.get(&hash, &cam).is_none());
        assert_eq!(cache.get_or_compute(&level, &cam).unwrap(), a);
        assert!(cache.get(&hash, &cam).is_some());
        // The colour reference: computed once, then served, per shadow switch.
        let ramps = crate::TerrainRamps {
            palette: std::array::from_fn(|i| [i as u8; 3]),
            begin: [0; 8],
            end: [255; 8],
        };
        let tracer = Tracer::new(&level);
        let (c, hit) = cache
            .get_or_compute_color(&tracer, &hash, &cam, &ramps, true)
            .unwrap();
        assert!(!hit);
        let (again, hit) = cache
            .get_or_compute_color(&tracer, &hash, &cam, &ramps, true)
            .unwrap();
        assert!(hit);
        assert_eq!(again, c);
        let (_, hit) = cache
            .get_or_compute_color(&tracer, &hash, &cam, &ramps, false)
            .unwrap();
        assert!(!hit);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
