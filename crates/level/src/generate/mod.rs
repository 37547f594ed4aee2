//! The built-in Vangers-like world: terraced plateaus with vertical cliffs,
//! a river valley at sea level 80, roads that ramp between levels, districts
//! of pits, furrows, pillared halls and hangars, slabs (bridges, arches,
//! overhangs, roofs) and ten named landmarks with twelve default views.
//!
//! Every texel is a pure function of (seed, size, x, y), evaluated row by row
//! in parallel, so the bytes are the same at any thread count. Nothing needs
//! the whole map: [`generate`] makes worlds that fit in memory (up to 2^28
//! texels), [`Chunked`] any rectangle of a world up to 65536x65536 on its
//! own (what `strata generate --to store` writes chunk by chunk), the same
//! bytes wherever both apply.

mod assets;
pub mod chunked;
pub mod knobs;
// The generator's designs, public only between its own modules.
#[doc(hidden)]
pub mod landmarks;
mod noise;
pub mod preview;
#[doc(hidden)]
pub mod terrain;

use crate::World;
use crate::model::{
    Level, META_DELTA_MASK, META_DOUBLE_LEVEL, META_TERRAIN_SHIFT, MidRule, ShapeError,
};
use rayon::prelude::*;

pub use assets::{BEGIN_COLORS, END_COLORS, palette, world_config};
pub use chunked::{Chunked, MAX_CHUNKED_SIDE, check_chunked_size};
pub use knobs::{Knobs, MAX_DUAL_FRACTION, MAX_FLOOR_ROUGHNESS};
pub use terrain::SEA;

/// Bumped whenever the output for a given seed and size changes (cache key).
pub const GENERATOR_VERSION: u32 = 4;
/// Smallest side the generator accepts (the landmarks need the room).
pub const MIN_SIDE: u32 = 256;
/// Largest side (the `world.ini` reader refuses map powers above 15).
pub const MAX_SIDE: u32 = 1 << 15;
/// Largest map, in texels (two bytes each in memory).
pub const MAX_TEXELS: u64 = 1 << 28;

/// Which world to generate: the same parameters give the same bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GenerateParams {
    /// Any value; each seed is a different world.
    pub seed: u64,
    /// Map width, texels ([`check_size`] says which sizes are accepted).
    pub width: u32,
    /// Map height, texels.
    pub height: u32,
}

impl Default for GenerateParams {
    /// The built-in default world: Fostral's size, a fixed seed.
    fn default() -> Self {
        GenerateParams {
            seed: 1997,
            width: 2048,
            height: 16384,
        }
    }
}

/// Why a world cannot be generated.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum GenerateError {
    /// The size fails [`check_size`].
    #[error("map size {width}x{height}: {reason}")]
    Size {
        /// Width asked for, texels.
        width: u32,
        /// Height asked for, texels.
        height: u32,
        /// Which rule it breaks.
        reason: String,
    },
    /// [`parse_size`] got text that is not `WIDTHxHEIGHT` (the text).
    #[error("size `{0}` is not WIDTHxHEIGHT (e.g. 2048x16384)")]
    SizeSyntax(String),
    /// The landmarks do not all fit on the map (a valid but cramped size).
    #[error("map {width}x{height} has no room left for the `{landmark}` landmark")]
    NoRoom {
        /// Map width, texels.
        width: u32,
        /// Map height, texels.
        height: u32,
        /// The landmark that did not fit.
        landmark: &'static str,
    },
    /// A [`Knobs`] value is outside its range.
    #[error("{name} {value} is outside its range {range}")]
    Knob {
        /// The knob.
        name: &'static str,
        /// The value given.
        value: String,
        /// The accepted range.
        range: String,
    },
    /// [`Chunked::fill`] or [`Chunked::patch`] was asked for a rectangle it
    /// cannot make.
    #[error("rectangle {cols}x{rows} at ({x0}, {y0}): {reason}")]
    Rect {
        /// Left column asked for.
        x0: u32,
        /// Top row asked for.
        y0: u32,
        /// Columns asked for.
        cols: u32,
        /// Rows asked for.
        rows: u32,
        /// Which rule it breaks.
        reason: String,
    },
    /// The planes could not form a [`Level`] (a bug if it happens: sizes are checked first).
    #[error(transparent)]
    Shape(#[from] ShapeError),
}

/// Parse `WIDTHxHEIGHT`; the size itself is checked by [`check_size`].
pub fn parse_size(text: &str) -> Result<(u32, u32), GenerateError> {
    let bad = || GenerateError::SizeSyntax(text.to_string());
    let (w, h) = text.trim().split_once(['x', 'X']).ok_or_else(bad)?;
    Ok((
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    ))
}

/// Powers of two from 256 to 32768 a side, at most 2^28 texels.
pub fn check_size(width: u32, height: u32) -> Result<(), GenerateError> {
    let err = |reason: &str| GenerateError::Size {
        width,
        height,
        reason: reason.to_string(),
    };
    if !width.is_power_of_two() || !height.is_power_of_two() {
        return Err(err("each side must be a power of two"));
    }
    if width < MIN_SIDE || height < MIN_SIDE {
        return Err(err("each side must be at least 256"));
    }
    if width > MAX_SIDE || height > MAX_SIDE {
        return Err(err("each side must be at most 32768"));
    }
    if u64::from(width) * u64::from(height) > MAX_TEXELS {
        return Err(err("at most 2^28 texels"));
    }
    Ok(())
}

/// An overhead solid layer over a texel: wanted cave ceiling and slab top.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Slab {
    /// Wanted cave ceiling (`mid`), altitude; encoded as the nearest multiple
    /// of 8 above the floor at or below it (the gap codes' steps).
    pub ceiling: i32,
    /// Wanted slab top (`high`), altitude; clamped to 0..=255.
    pub high: i32,
    /// Terrain type of the slab, 0..8.
    pub ty: u8,
}

/// What the generator wants at one texel, before pair encoding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Texel {
    /// Wanted floor (`low`), altitude; clamped to 0..=255.
    pub floor: i32,
    /// Terrain type of the floor, 0..8.
    pub ty: u8,
    /// The layer over a cave, if any.
    pub slab: Option<Slab>,
}

impl Texel {
    /// A texel without a slab.
    #[inline]
    pub fn single(floor: i32, ty: u8) -> Self {
        Texel {
            floor,
            ty,
            slab: None,
        }
    }

    /// This texel with a slab from `ceiling` to `high` of type `ty` over it.
    #[inline]
    pub fn with_slab(self, ceiling: i32, high: i32, ty: u8) -> Self {
        Texel {
            slab: Some(Slab { ceiling, high, ty }),
            ..self
        }
    }
}

#[inline]
fn byte(v: i32) -> u8 {
    v.clamp(0, 255) as u8
}

/// Encode a horizontal texel pair (DESIGN §1). A slab wanted by either texel
/// makes the pair dual; the gap code rounds the ceiling down to the 8-unit
/// steps of the original mid rule, so every cave is at least 8 tall, and a
/// slab too thin to keep a cave and 2 units of roof is dropped.
#[inline]
fn encode_pair(a: Texel, b: Texel, heights: &mut [u8], metas: &mut [u8]) {
    let carrier = if a.slab.is_some() {
        Some(a)
    } else if b.slab.is_some() {
        Some(b)
    } else {
        None
    };
    if let Some(t) = carrier {
        let s = t.slab.expect("carrier has a slab");
        let low = byte(t.floor);
        let high = byte(s.high);
        let want = s.ceiling - i32::from(low);
        let code = (want / 8 - 1).clamp(0, 15) as u8;
        let mid = i32::from(low) + MidRule::Original.gap(code) as i32;
        if i32::from(high) - mid >= 2 {
            heights[0] = low;
            heights[1] = high;
            metas[0] = META_DOUBLE_LEVEL | ((t.ty & 7) << META_TERRAIN_SHIFT) | (code >> 2);
            metas[1] =
                META_DOUBLE_LEVEL | ((s.ty & 7) << META_TERRAIN_SHIFT) | (code & META_DELTA_MASK);
            return;
        }
    }
    for (i, t) in [a, b].into_iter().enumerate() {
        heights[i] = byte(t.floor);
        metas[i] = (t.ty & 7) << META_TERRAIN_SHIFT;
    }
}

/// Generate the world for `params`.
pub fn generate(params: &GenerateParams) -> Result<World, GenerateError> {
    generate_with(params, &Knobs::default())
}

/// Generate the world for `params` with `knobs` turned (checked first).
pub fn generate_with(params: &GenerateParams, knobs: &Knobs) -> Result<World, GenerateError> {
    let mut generation = Generation::with_knobs(params, knobs)?;
    let Generation {
        terrain,
        layout,
        mask,
        heights,
        metas,
        ..
    } = &mut generation;
    let w = params.width as usize;
    heights
        .par_chunks_mut(w)
        .zip(metas.par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, (hrow, mrow))| {
            fill_row(terrain, layout, mask.as_ref(), y as u32, hrow, mrow)
        });
    generation.next_row = params.height;
    generation.finish()
}

/// [`generate`] a band of rows at a time, for a caller that must stay
/// responsive meanwhile (the browser page, which has one thread): the same
/// rows, so the same world byte for byte.
pub struct Generation {
    params: GenerateParams,
    knobs: Knobs,
    terrain: terrain::Terrain,
    layout: landmarks::Layout,
    mask: Option<knobs::SlabMask>,
    heights: Vec<u8>,
    metas: Vec<u8>,
    next_row: u32,
}

impl Generation {
    /// Set up the terrain and place the landmarks (no rows yet).
    pub fn new(params: &GenerateParams) -> Result<Self, GenerateError> {
        Self::with_knobs(params, &Knobs::default())
    }

    /// [`new`](Self::new) with `knobs` turned (checked first).
    pub fn with_knobs(params: &GenerateParams, knobs: &Knobs) -> Result<Self, GenerateError> {
        check_size(params.width, params.height)?;
        knobs.check()?;
        let mut terrain = terrain::Terrain::new(params.seed, params.width, params.height);
        if let Some(r) = knobs.floor_roughness {
            terrain.set_fine_scale(r as f32);
        }
        let mask = knobs
            .dual_fraction
            .map(|f| knobs::SlabMask::new(terrain.seed, params.width, params.height, f));
        let layout = landmarks::place(&terrain)?;
        let texels = params.width as usize * params.height as usize;
        Ok(Generation {
            params: *params,
            knobs: *knobs,
            terrain,
            layout,
            mask,
            heights: vec![0u8; texels],
            metas: vec![0u8; texels],
            next_row: 0,
        })
    }

    /// Generate up to `rows` more rows; true when every row is done.
    pub fn step(&mut self, rows: u32) -> bool {
        let w = self.params.width as usize;
        let end = (self.next_row + rows).min(self.params.height);
        for y in self.next_row..end {
            let span = y as usize * w..(y as usize + 1) * w;
            fill_row(
                &self.terrain,
                &self.layout,
                self.mask.as_ref(),
                y,
                &mut self.heights[span.clone()],
                &mut self.metas[span],
            );
        }
        self.next_row = end;
        self.is_done()
    }

    /// Whether every row is generated.
    pub fn is_done(&self) -> bool {
        self.next_row >= self.params.height
    }

    /// Fraction of the rows done, 0..=1.
    pub fn progress(&self) -> f32 {
        self.next_row as f32 / self.params.height as f32
    }

    /// The world, once every row is done (generating any left first).
    pub fn finish(mut self) -> Result<World, GenerateError> {
        self.step(u32::MAX - self.next_row);
        let GenerateParams {
            seed,
            width,
            height,
        } = self.params;
        let level = Level::from_planes(width, height, self.heights, self.metas, MidRule::Original)?;
        let config = world_config(width, height)?;
        let sections = crate::vpr::VprLayout::of(&config).sections();
        Ok(World {
            name: format!("generated-{seed}{}", self.knobs.name_suffix()),
            config,
            palette: palette(),
            water: Some(vec![SEA; sections]),
            views: self.layout.views(&self.terrain),
            edit: Some(self.layout.edit_site()),
            level,
            source: Default::default(),
        })
    }
}

/// One row of the map: landmarks where they cover it, the terrain elsewhere.
fn fill_row(
    terrain: &terrain::Terrain,
    layout: &landmarks::Layout,
    mask: Option<&knobs::SlabMask>,
    y: u32,
    hrow: &mut [u8],
    mrow: &mut [u8],
) {
    fill_span(terrain, layout, mask, y, 0, hrow, mrow);
}

/// Texels `x0 .. x0 + hrow.len()` of row `y` (`x0` and the length even:
/// whole pairs), the same bytes as that part of [`fill_row`].
fn fill_span(
    terrain: &terrain::Terrain,
    layout: &landmarks::Layout,
    mask: Option<&knobs::SlabMask>,
    y: u32,
    x0: u32,
    hrow: &mut [u8],
    mrow: &mut [u8],
) {
    debug_assert!(x0.is_multiple_of(2) && hrow.len().is_multiple_of(2) && hrow.len() == mrow.len());
    let x1 = x0 + hrow.len() as u32;
    let sites: Vec<&landmarks::Landmark> = layout
        .list
        .iter()
        .filter(|l| l.covers_row(y) && l.x0 < x1 && x0 < l.x0 + l.w)
        .collect();
    let row = terrain.row(y);
    let texel = |x: u32| {
        let t = match sites.iter().find(|l| l.covers_x(x)) {
            Some(site) => site.texel(terrain, x, y),
            None => terrain.texel(x, &row),
        };
        match mask {
            Some(m) => m.apply(t, x, y),
            None => t,
        }
    };
    for (i, x) in (x0..x1).step_by(2).enumerate() {
        let i = 2 * i;
        encode_pair(
            texel(x),
            texel(x + 1),
            &mut hrow[i..i + 2],
            &mut mrow[i..i + 2],
        );
    }
}

/// The landmarks of the world `params` would generate: name, description,
/// centre, without generating the map.
pub fn landmark_list(
    params: &GenerateParams,
) -> Result<Vec<(String, String, u32, u32)>, GenerateError> {
    check_size(params.width, params.height)?;
    let terrain = terrain::Terrain::new(params.seed, params.width, params.height);
    let layout = landmarks::place(&terrain)?;
    Ok(layout
        .list
        .iter()
        .map(|l| {
            (
                l.kind.name().to_string(),
                l.kind.describe().to_string(),
                l.x0 + l.w / 2,
                l.y0 + l.h / 2,
            )
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_checked() {
        assert_eq!(parse_size("512x2048"), Ok((512, 2048)));
        assert!(parse_size("512").is_err());
        assert!(parse_size("ax2").is_err());
        assert!(check_size(300, 512).is_err());
        assert!(check_size(128, 512).is_err());
        assert!(check_size(256, 256).is_ok());
        assert!(check_size(65536, 65536).is_err());
    }

    #[test]
    fn pair_encoding_keeps_caves_at_least_8_tall() {
        let (mut h, mut m) = ([0u8; 2], [0u8; 2]);
        let a = Texel::single(100, 2).with_slab(103, 140, 5);
        encode_pair(a, Texel::single(100, 2), &mut h, &mut m);
        let c = crate::model::decode_column(&h, &m, 0, MidRule::Original);
        assert!(c.dual && c.low == 100 && c.mid == 108 && c.high == 140);
        assert_eq!((c.lower_type, c.upper_type), (2, 5));
        // Too thin: dropped, both texels single.
        let thin = Texel::single(100, 2).with_slab(104, 108, 5);
        encode_pair(thin, Texel::single(90, 1), &mut h, &mut m);
        assert_eq!(
            (h, m[0] & META_DOUBLE_LEVEL, m[1] & META_DOUBLE_LEVEL),
            ([100, 90], 0, 0)
        );
    }
}
