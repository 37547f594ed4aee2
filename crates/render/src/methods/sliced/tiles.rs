//! `sliced`'s air culling: the highest solid top of every 32 x 32 tile of
//! the map, taken over the tile and a one-texel margin around it, in a small
//! integer texture. Each slice is drawn as one quad per tile of the
//! footprint, and a tile whose maximum is below the slice's altitude is
//! dropped in the vertex shader: every fragment it would have made is air,
//! which the fragment test would discard. Without it, each pixel ran that
//! test once per slice between the eye's altitude and the ground.
//!
//! The margin: a fragment's point is recomputed from the pixel's ray, and
//! f32 can put it a hair across the tile's edge into a column of the next
//! tile; the margin covers that column, so culling removes only air.
//!
//! Edits rebuild the tiles their rectangles touch (margins included) from
//! the edited level and upload those tile rows before the next frame.

use crate::frame::Shared;
use strata_level::model::pair_is_dual;
use strata_level::{DirtyRect, Level};

/// log2 of the tile side, texels (smaller on a map narrower than that).
pub const TILE_LOG2: u32 = 5;

/// The tile maxima of a map, row-major, `width x height` tiles.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TileMaxima {
    /// log2 of the tile side in texels.
    pub log2: u32,
    /// Tiles across.
    pub width: u32,
    /// Tiles down.
    pub height: u32,
    /// Highest solid top of each tile and its one-texel margin (wrapping
    /// around the map, as the terrain does).
    pub data: Vec<u8>,
}

/// The top of each texel of row `y`: a dual pair's columns both reach the
/// slab's top (`high`, the odd texel's height); a single texel its height.
/// Branch-free over the pairs, so that it vectorises.
fn row_tops(level: &Level, y: u32, out: &mut Vec<u8>) {
    let (h, m) = level.row(y);
    out.clear();
    out.resize(h.len(), 0);
    for ((o, hp), mp) in out
        .chunks_exact_mut(2)
        .zip(h.chunks_exact(2))
        .zip(m.chunks_exact(2))
    {
        let keep_even = u8::from(!pair_is_dual(mp[0], mp[1])).wrapping_neg();
        o[0] = (hp[0] & keep_even) | (hp[1] & !keep_even);
        o[1] = hp[1];
    }
}

impl TileMaxima {
    /// Every tile of `level`.
    pub fn new(level: &Level) -> Self {
        Self::with_log2(level, TILE_LOG2)
    }

    /// Every tile of side `2^log2` (smaller on a map narrower than that) of
    /// `level`.
    pub fn with_log2(level: &Level, log2: u32) -> Self {
        let log2 = log2
            .min(level.width().trailing_zeros())
            .min(level.height().trailing_zeros());
        let (width, height) = (level.width() >> log2, level.height() >> log2);
        let mut t = TileMaxima {
            log2,
            width,
            height,
            data: vec![0; (width * height) as usize],
        };
        for ty in 0..height {
            t.rebuild_row(level, ty);
        }
        t
    }

    /// Tile row `ty` from `level`.
    fn rebuild_row(&mut self, level: &Level, ty: u32) {
        let side = 1i64 << self.log2;
        let (w, h) = (i64::from(level.width()), i64::from(level.height()));
        let row = &mut self.data[(ty * self.width) as usize..((ty + 1) * self.width) as usize];
        row.fill(0);
        let mut tops = Vec::with_capacity(w as usize);
        let y0 = i64::from(ty) * side - 1;
        for y in y0..=y0 + side + 1 {
            row_tops(level, y.rem_euclid(h) as u32, &mut tops);
            for (tx, (m, inner)) in row
                .iter_mut()
                .zip(tops.chunks_exact(side as usize))
                .enumerate()
            {
                let x0 = tx as i64 * side;
                let before = tops[(x0 - 1).rem_euclid(w) as usize];
                let after = tops[(x0 + side).rem_euclid(w) as usize];
                let inner = inner.iter().fold(0, |a, &b| a.max(b));
                *m = (*m).max(inner).max(before).max(after);
            }
        }
    }

    /// Tile `(tx, ty)` alone from `level`: the same value as a row rebuild,
    /// column by column (an edit touches a few tiles of a row).
    fn tile_max(&self, level: &Level, tx: u32, ty: u32) -> u8 {
        let side = 1i64 << self.log2;
        let (x0, y0) = (i64::from(tx) * side, i64::from(ty) * side);
        let mut m = 0;
        for y in y0 - 1..=y0 + side {
            for x in x0 - 1..=x0 + side {
                m = m.max(level.column(x, y).top());
            }
        }
        m
    }

    /// Rebuild the tiles whose inside or margin meets `rects` (already
    /// changed in `level`); returns their rows, ascending.
    pub fn update(&mut self, level: &Level, rects: &[DirtyRect]) -> Vec<u32> {
        let side = 1i64 << self.log2;
        let (w, h) = (i64::from(self.width), i64::from(self.height));
        // The tiles (wrapped) whose inside or one-texel margin holds texels
        // a..a + n along one axis of `count` tiles.
        let span = |a: u32, n: u32, count: i64| {
            let first = (i64::from(a) - 1).div_euclid(side);
            let last = (i64::from(a) + i64::from(n)).div_euclid(side);
            (first..=last.min(first + count - 1)).map(move |t| t.rem_euclid(count) as usize)
        };
        let mut dirty = vec![false; self.data.len()];
        for r in rects {
            for ty in span(r.y, r.height, h) {
                for tx in span(r.x, r.width, w) {
                    dirty[ty * w as usize + tx] = true;
                }
            }
        }
        let mut rows = Vec::new();
        for ty in 0..self.height {
            let mut any = false;
            for tx in 0..self.width {
                let i = (ty * self.width + tx) as usize;
                if dirty[i] {
                    self.data[i] = self.tile_max(level, tx, ty);
                    any = true;
                }
            }
            if any {
                rows.push(ty);
            }
        }
        rows
    }
}

/// Twin of `SliceTiles` in `sliced.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SliceTileParams {
    /// x, y: the first tile of the footprint (unwrapped tile coordinates);
    /// z, w: tiles across and down the footprint (z 0: no culling, one quad
    /// per slice over the whole footprint).
    pub grid: [i32; 4],
    /// x: log2 of the tile side; y, z: the map's tiles across and down - 1
    /// (wrapping masks); w: log2 of the block side ([`BLOCK_LOG2`], set by
    /// [`SliceTiles::prepare`]).
    pub tiles: [u32; 4],
}

/// More tiles per slice than this (a far plane far beyond any view) and the
/// slices are drawn whole, without culling: the vertex work would outgrow
/// what the culling saves.
pub const MAX_TILES_PER_SLICE: u64 = 1 << 14;

/// The tiles (side `2^log2`) over the footprint bound `[origin, origin +
/// extent)` in unwrapped texels, on a map of `map` tiles; whole slices when
/// there would be more than [`MAX_TILES_PER_SLICE`].
pub fn tile_grid(log2: u32, map: [u32; 2], origin: [i32; 2], extent: [u32; 2]) -> SliceTileParams {
    let tiles = [log2, map[0] - 1, map[1] - 1, 0];
    let span = |o: i32, e: u32| {
        let first = i64::from(o) >> log2;
        let last = (i64::from(o) + i64::from(e.max(1)) - 1) >> log2;
        (first, last - first + 1)
    };
    let (fx, nx) = span(origin[0], extent[0]);
    let (fy, ny) = span(origin[1], extent[1]);
    if (nx * ny) as u64 > MAX_TILES_PER_SLICE {
        return SliceTileParams {
            grid: [0; 4],
            tiles,
        };
    }
    SliceTileParams {
        grid: [fx as i32, fy as i32, nx as i32, ny as i32],
        tiles,
    }
}

/// log2 of the side of the finer blocks the slices' gap walks step over
/// (`sliced.wgsl::walk_gap`): a walk of up to 32 columns reads a few block
/// maxima where the air is open and walks columns only in blocks the ray
/// comes down to.
pub const BLOCK_LOG2: u32 = 3;

/// One set of maxima on the GPU: the CPU copy (kept for edits) and its
/// texture.
struct GpuMaxima {
    cpu: TileMaxima,
    texture: wgpu::Texture,
    view: wgpu::TextureView,
}

impl GpuMaxima {
    fn new(shared: &Shared, cpu: TileMaxima, label: &str) -> Self {
        let texture = shared.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: cpu.width,
                height: cpu.height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R8Uint,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let m = GpuMaxima { cpu, texture, view };
        m.upload_rows(shared, 0, m.cpu.height);
        m
    }

    /// Write tile rows `first..first + count` to the texture.
    fn upload_rows(&self, shared: &Shared, first: u32, count: u32) {
        let w = self.cpu.width;
        let data = &self.cpu.data[(first * w) as usize..((first + count) * w) as usize];
        shared.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &self.texture,
                mip_level: 0,
                origin: wgpu::Origin3d {
                    x: 0,
                    y: first,
                    z: 0,
                },
                aspect: wgpu::TextureAspect::All,
            },
            data,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(w),
                rows_per_image: Some(count),
            },
            wgpu::Extent3d {
                width: w,
                height: count,
                depth_or_array_layers: 1,
            },
        );
    }

    /// Rebuild the tiles `rects` touch and upload their rows.
    fn apply_edit(&mut self, shared: &Shared, level: &Level, rects: &[DirtyRect]) {
        for ty in self.cpu.update(level, rects) {
            self.upload_rows(shared, ty, 1);
        }
    }
}

/// The tile maxima on the GPU, the finer block maxima of the gap walks, and
/// the per-frame grid over the footprint.
pub struct SliceTiles {
    tiles: GpuMaxima,
    blocks: GpuMaxima,
    pub params: wgpu::Buffer,
}

impl SliceTiles {
    /// Build the maxima of `level` and upload them.
    pub fn new(shared: &Shared, level: &Level) -> Self {
        let params = shared.uniform_buffer(
            "sliced tiles",
            bytemuck::bytes_of(&SliceTileParams::default()),
        );
        SliceTiles {
            tiles: GpuMaxima::new(shared, TileMaxima::new(level), "sliced tile maxima"),
            blocks: GpuMaxima::new(
                shared,
                TileMaxima::with_log2(level, BLOCK_LOG2),
                "sliced block maxima",
            ),
            params,
        }
    }

    /// The tile maxima.
    pub fn view(&self) -> &wgpu::TextureView {
        &self.tiles.view
    }

    /// The block maxima.
    pub fn blocks_view(&self) -> &wgpu::TextureView {
        &self.blocks.view
    }

    /// Rebuild the tiles and blocks `rects` touch and upload their rows.
    pub fn apply_edit(&mut self, shared: &Shared, level: &Level, rects: &[DirtyRect]) {
        self.tiles.apply_edit(shared, level, rects);
        self.blocks.apply_edit(shared, level, rects);
    }

    /// The tile grid over the footprint bound `[origin, origin + extent)`
    /// (unwrapped texels), written for the next draw; returns the tiles per
    /// slice (1 when the slices are drawn whole).
    pub fn prepare(&self, shared: &Shared, origin: [i32; 2], extent: [u32; 2]) -> u32 {
        let cpu = &self.tiles.cpu;
        let mut p = tile_grid(cpu.log2, [cpu.width, cpu.height], origin, extent);
        p.tiles[3] = self.blocks.cpu.log2;
        shared
            .queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        if p.grid[2] == 0 {
            1
        } else {
            (p.grid[2] * p.grid[3]) as u32
        }
    }

    /// The tiles' side, texels.
    pub fn side(&self) -> u32 {
        1 << self.tiles.cpu.log2
    }

    /// GPU bytes: the textures and the uniform.
    pub fn gpu_bytes(&self) -> u64 {
        self.cpu_bytes() + std::mem::size_of::<SliceTileParams>() as u64
    }

    /// CPU bytes kept for edits: the maxima.
    pub fn cpu_bytes(&self) -> u64 {
        (self.tiles.cpu.data.len() + self.blocks.cpu.data.len()) as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use strata_level::MidRule;
    use strata_level::model::META_DOUBLE_LEVEL;

    /// 128 x 64 texels of sloping ground with dual pairs here and there.
    fn level() -> Level {
        let (w, h) = (128u32, 64u32);
        let mut heights = Vec::new();
        let mut metas = Vec::new();
        for y in 0..h {
            for x in 0..w {
                // A slope up in x and y, so a tile's margin is higher than
                // its inside, with some noise.
                let hash = (x * 7919 + y * 104_729) ^ (x * y * 31);
                heights.push(((x + y) % 190 + hash % 9) as u8);
                let dual = (x / 2 + y) % 5 == 0;
                metas.push(if dual { META_DOUBLE_LEVEL } else { 0 });
            }
        }
        Level::from_planes(w, h, heights, metas, MidRule::default()).unwrap()
    }

    /// Raise texel (x, y) (x even) to 255 and make its pair single: the
    /// edit's rectangle.
    fn raise_pair(level: &mut Level, x: u32, y: u32) -> DirtyRect {
        let i = (y * level.width() + x) as usize;
        let (heights, metas) = level.planes_mut();
        heights[i] = 255;
        metas[i] = 0;
        metas[i + 1] = 0;
        DirtyRect {
            x,
            y,
            width: 2,
            height: 1,
        }
    }

    fn check(level: &Level, t: &TileMaxima) {
        for ty in 0..t.height {
            for tx in 0..t.width {
                // The whole-map rows against the tile alone (the edits' path).
                assert_eq!(
                    t.data[(ty * t.width + tx) as usize],
                    t.tile_max(level, tx, ty),
                    "tile ({tx}, {ty})"
                );
            }
        }
    }

    #[test]
    fn maxima_cover_each_tile_and_its_margin() {
        let level = level();
        let t = TileMaxima::new(&level);
        assert_eq!((t.log2, t.width, t.height), (5, 4, 2));
        check(&level, &t);
        // The margin matters: some tile's maximum comes from outside it.
        let inner = |tx: u32, ty: u32| {
            let mut m = 0;
            for y in ty * 32..ty * 32 + 32 {
                for x in tx * 32..tx * 32 + 32 {
                    m = m.max(level.column(i64::from(x), i64::from(y)).top());
                }
            }
            m
        };
        assert!((0..8).any(|i| inner(i % 4, i / 4) < t.data[i as usize]));
    }

    #[test]
    fn an_edit_rebuilds_the_rows_it_touches() {
        let mut level = level();
        let mut t = TileMaxima::new(&level);
        // Raise texel (0, 40), one row into tile row 1 and on the map's left
        // edge: the margins wrap, so tiles in the last column change too.
        let h = level.height();
        let rect = raise_pair(&mut level, 0, 40);
        assert_eq!(t.update(&level, &[rect]), vec![1]);
        check(&level, &t);
        assert_eq!(t.data[(t.width + t.width - 1) as usize], 255);
        // A rectangle on a tile row's first texel row is in the margin of the
        // row above as well, wrapping at the top.
        let top = DirtyRect {
            x: 5,
            y: 0,
            width: 1,
            height: 1,
        };
        assert_eq!(t.update(&level, &[top]), vec![0, h / 32 - 1]);
        assert_eq!(t, TileMaxima::new(&level));
    }

    #[test]
    fn block_maxima_cover_each_block_and_follow_edits() {
        let mut level = level();
        let mut b = TileMaxima::with_log2(&level, BLOCK_LOG2);
        assert_eq!((b.log2, b.width, b.height), (3, 16, 8));
        check(&level, &b);
        let rect = raise_pair(&mut level, 40, 17);
        // Row 17 is inside block row 2 only (its margin rows are 15 and 24).
        assert_eq!(b.update(&level, &[rect]), vec![2]);
        assert_eq!(b, TileMaxima::with_log2(&level, BLOCK_LOG2));
        assert_eq!(b.data[(2 * b.width + 5) as usize], 255);
    }

    #[test]
    fn the_grid_covers_the_footprint_and_caps_its_tiles() {
        // [-5, 60) x [64, 65): tiles -1..=1 across, tile 2 down.
        let g = tile_grid(5, [4, 2], [-5, 64], [65, 1]);
        assert_eq!(g.grid, [-1, 2, 3, 1]);
        assert_eq!(g.tiles, [5, 3, 1, 0]);
        // Too many tiles: whole slices.
        let side = 1u32 << 5;
        let g = tile_grid(5, [4, 2], [0, 0], [side * 200, side * 200]);
        assert_eq!(g.grid, [0; 4]);
    }
}
