//! The generator without the whole map: any rectangle of a world on
//! demand, in memory proportional to the rectangle, for worlds far larger
//! than memory (a 65536x65536 store is 8 GiB of planes).
//!
//! Nothing of the world is global but what is cheap to know everywhere:
//! the landmarks are placed from the river alone (an analytic curve), the
//! views and the edit site from the landmarks, the water level is one
//! constant, and the `--dual-fraction` threshold comes from a sparse
//! sample of its noise. Each rectangle takes a [`Terrain::window`] holding
//! the coarse fields and districts its texels read, so the bytes of a
//! rectangle are those of the same texels of [`super::generate_with`] at
//! every size both accept.

use super::terrain::{SEA, Terrain};
use super::{
    GenerateError, GenerateParams, Knobs, MIN_SIDE, assets, fill_span, knobs::SlabMask, landmarks,
    palette,
};
use crate::World;
use crate::model::{Level, MidRule};

/// Largest side of a world generated chunk by chunk (into a store).
pub const MAX_CHUNKED_SIDE: u32 = 1 << 16;

/// Sizes [`Chunked`] accepts: powers of two from 256 to 65536 a side.
pub fn check_chunked_size(width: u32, height: u32) -> Result<(), GenerateError> {
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
    if width > MAX_CHUNKED_SIDE || height > MAX_CHUNKED_SIDE {
        return Err(err("each side must be at most 65536"));
    }
    Ok(())
}

/// A world to be generated a rectangle at a time (see the module docs).
pub struct Chunked {
    params: GenerateParams,
    knobs: Knobs,
    terrain: Terrain,
    layout: landmarks::Layout,
    mask: Option<SlabMask>,
}

impl Chunked {
    /// Check the size ([`check_chunked_size`]) and knobs, place the
    /// landmarks; no texel yet. Takes well under a second at any size.
    pub fn new(params: &GenerateParams, knobs: &Knobs) -> Result<Self, GenerateError> {
        check_chunked_size(params.width, params.height)?;
        knobs.check()?;
        let (w, h) = (params.width, params.height);
        let mut terrain = Terrain::lazy(params.seed, w, h);
        if let Some(r) = knobs.floor_roughness {
            terrain.set_fine_scale(r as f32);
        }
        let mask = knobs
            .dual_fraction
            .map(|f| SlabMask::new(terrain.seed, w, h, f));
        let layout = landmarks::place(&terrain)?;
        Ok(Chunked {
            params: *params,
            knobs: *knobs,
            terrain,
            layout,
            mask,
        })
    }

    /// The world's seed and size.
    pub fn params(&self) -> &GenerateParams {
        &self.params
    }

    /// Everything of the world but its planes: name, `world.ini`, palette,
    /// water, views and edit site, as [`super::generate_with`] gives them.
    /// Its `level` is a 2x1 stand-in, not the map (what a writer that
    /// takes the planes chunk by chunk wants, e.g. a store's).
    pub fn world_without_planes(&self) -> World {
        let GenerateParams {
            seed,
            width,
            height,
        } = self.params;
        let config = assets::config_of(width, height);
        let sections = crate::vpr::VprLayout::of(&config).sections();
        World {
            name: format!("generated-{seed}{}", self.knobs.name_suffix()),
            config,
            palette: palette(),
            water: Some(vec![SEA; sections]),
            views: self.layout.views(&self.terrain),
            edit: Some(self.layout.edit_site()),
            level: Level::flat(2, 1, 0, 0).expect("a 2x1 level is valid"),
            source: Default::default(),
        }
    }

    /// The landmarks: name, description, centre (as [`super::landmark_list`]).
    pub fn landmarks(&self) -> Vec<(String, String, u32, u32)> {
        self.layout
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
            .collect()
    }

    /// Generate texels `x0 .. x0 + cols` of rows `y0 .. y0 + rows` into
    /// `heights` and `metas` (row-major, `cols` a row). The rectangle must
    /// lie inside the map, `x0` and `cols` even (whole pairs); one thread
    /// (callers run rectangles in parallel).
    pub fn fill(
        &self,
        (x0, y0, cols, rows): (u32, u32, u32, u32),
        heights: &mut [u8],
        metas: &mut [u8],
    ) -> Result<(), GenerateError> {
        let (w, h) = (self.params.width, self.params.height);
        let n = cols as usize * rows as usize;
        let inside = u64::from(x0) + u64::from(cols) <= u64::from(w)
            && u64::from(y0) + u64::from(rows) <= u64::from(h);
        if !inside
            || !x0.is_multiple_of(2)
            || !cols.is_multiple_of(2)
            || heights.len() != n
            || metas.len() != n
        {
            return Err(GenerateError::Rect {
                x0,
                y0,
                cols,
                rows,
                reason: format!(
                    "must lie inside the {w}x{h} map, start on an even column, cover whole pairs, and the buffers hold {n} bytes each (they hold {} and {})",
                    heights.len(),
                    metas.len()
                ),
            });
        }
        if n == 0 {
            return Ok(());
        }
        let terrain = self.terrain.window(x0, y0, cols, rows);
        for (r, (hrow, mrow)) in heights
            .chunks_exact_mut(cols as usize)
            .zip(metas.chunks_exact_mut(cols as usize))
            .enumerate()
        {
            fill_span(
                &terrain,
                &self.layout,
                self.mask.as_ref(),
                y0 + r as u32,
                x0,
                hrow,
                mrow,
            );
        }
        Ok(())
    }

    /// A `cols x rows` level (powers of two, at most the map's sides) cut
    /// from the world at (`x0`, `y0`) (any integers: they wrap, `x0`
    /// rounded down to even): a piece of a huge world to look at (e.g. a
    /// preview) without the rest. It wraps at its own edges, not the map's.
    pub fn patch(&self, x0: i64, y0: i64, cols: u32, rows: u32) -> Result<Level, GenerateError> {
        let (w, h) = (self.params.width, self.params.height);
        if !cols.is_power_of_two() || !rows.is_power_of_two() || cols < 2 || cols > w || rows > h {
            return Err(GenerateError::Rect {
                x0: x0.rem_euclid(w.into()) as u32,
                y0: y0.rem_euclid(h.into()) as u32,
                cols,
                rows,
                reason: format!(
                    "a patch's sides must be powers of two from 2 to the map's {w}x{h}"
                ),
            });
        }
        let px = (x0.rem_euclid(w.into()) as u32) & !1;
        let py = y0.rem_euclid(h.into()) as u32;
        let (cw, ch) = (cols as usize, rows as usize);
        let mut heights = vec![0u8; cw * ch];
        let mut metas = vec![0u8; cw * ch];
        // Up to two pieces each way where the patch crosses the map's seam.
        let split = |start: u32, len: u32, side: u32| {
            let first = len.min(side - start);
            [(start, 0, first), (0, first, len - first)]
        };
        for (sy, dy, ny) in split(py, rows, h) {
            for (sx, dx, nx) in split(px, cols, w) {
                if nx == 0 || ny == 0 {
                    continue;
                }
                let n = nx as usize * ny as usize;
                let (mut hb, mut mb) = (vec![0u8; n], vec![0u8; n]);
                self.fill((sx, sy, nx, ny), &mut hb, &mut mb)?;
                for r in 0..ny as usize {
                    let dst = (dy as usize + r) * cw + dx as usize;
                    let src = r * nx as usize..(r + 1) * nx as usize;
                    heights[dst..dst + nx as usize].copy_from_slice(&hb[src.clone()]);
                    metas[dst..dst + nx as usize].copy_from_slice(&mb[src]);
                }
            }
        }
        Ok(Level::from_planes(
            cols,
            rows,
            heights,
            metas,
            MidRule::Original,
        )?)
    }
}
