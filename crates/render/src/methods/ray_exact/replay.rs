//! A CPU replay of `ray-exact`'s frame (issue 36, item 1: the bound on
//! paper): the same traversal as the WGSL, step for step in f32
//! (`ray_exact_core.wgsl::exact_march` with the compute pipelines' constants,
//! `EXACT_LOG_RATIO` 2 and `EXACT_CLIMB` 1, over the pyramid they build), run
//! for the three passes of the deferred frame, counting per ray what the GPU
//! does:
//!
//! 1. **march** (`cs_exact_march_hits`, one ray per pixel): iterations of the
//!    traversal loop, pyramid words read (`maxmip_get`), terrain texels read
//!    (`decode_column`), the hit and the 8x8 shadow blocks it stamps;
//! 2. **shadow** (`cs_exact_shadow_blocks`, one ray per texel of every
//!    stamped block): the same march along the light;
//! 3. **shade** (`cs_exact_shade`, one per hit pixel): the column and its four
//!    neighbours (`surface_normal_at`) and the shadow map's 4-tap PCF where
//!    the point is not under a slab.
//!
//! Bytes: every read and write the passes issue (terrain texels are 4 bytes,
//! pyramid reads one 4-byte word, shadow and depth texels 4 bytes, colour 4),
//! and the distinct bytes each resource had read (the least that must come
//! from memory once). f32 on the CPU rounds as IEEE; the GPU may fuse a
//! multiply-add or divide less exactly, so a ray can differ by a step at a
//! boundary it grazes (the tests bound that).

use crate::frame::Globals;
use crate::options::TexelWalk;
use glam::{IVec2, Vec2, Vec3};
use strata_level::Level;
use strata_maxmip::{CavePyramid, Pyramid, TexelTops};

mod beam;
mod counts;
pub use crate::options::BeamSearch;
pub use beam::{BEAM_CAP, BEAM_TILE, BeamCount, SHADOW_BEAM_LANES, WIDE_LANES, WIDE_ROUNDS};
use counts::PassAcc;
pub use counts::{FrameCount, PassCount, Spread};

/// `EXACT_LOG_RATIO` of the compute pipelines ([`crate::options::ExactOptions`]).
pub const LOG_RATIO: u32 = 2;
const BASE_TILE: f32 = 256.0;
const BIG: f32 = 3.0e38;
const MAX_ALTITUDE: f32 = 255.0;
const MARK_BLOCK: i32 = 8;
/// `CAVE_MARGIN` of `ray_exact_core.wgsl`.
const CAVE_MARGIN: f32 = 0.015625;
const SHADOW_BLOCK_TEXELS: u64 = (MARK_BLOCK * MARK_BLOCK) as u64;

/// Bytes of one read or write of each resource.
const TERRAIN_TEXEL_BYTES: u64 = 4;
const PYRAMID_WORD_BYTES: u64 = 4;
const TEXEL_BYTES: u64 = 4;

/// What one march did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MarchCount {
    /// Hit: ray parameter and column (absolute texels).
    pub hit: Option<(f32, IVec2)>,
    /// Traversal loop iterations (`ExactHit::iterations`).
    pub iterations: u32,
    /// Pyramid words read.
    pub pyramid_reads: u32,
    /// Terrain texels read.
    pub terrain_reads: u32,
    /// Iterations whose test waited on a read (a tile's maximum, a texel's
    /// column), and the texel plane's block reads
    /// ([`Traversal::texel_walk`]): the ray's chain of dependent fetches.
    pub waits: u32,
    /// Iterations that went down a level.
    pub descents: u32,
    /// Levels climbed after steps that left the parent tile.
    pub climbs: u32,
}

/// Traversal knobs to try on paper; [`Traversal::GPU`] is what the compute
/// pipelines run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Traversal {
    /// Most levels climbed after a step leaves its parent tile
    /// (`EXACT_CLIMB`).
    pub climb: u32,
    /// The visited level (0 = texels, top = 256-texel tiles) camera and
    /// shadow rays start at (`None`: the top).
    pub start: Option<u32>,
    /// Camera rays start where their 8x8-pixel tile's beam first may meet
    /// the ground (`cs_exact_beam`, [`Replay::beam`]), else at the near
    /// plane; shadow rays where their 8x8-texel block's does
    /// ([`Replay::shadow_beam`]), else at altitude 255.
    pub beam: bool,
    /// How the beams are searched (`EXACT_BEAM_SEARCH`).
    pub search: BeamSearch,
    /// Most rounds of a shadow block's wide search (`EXACT_SHADOW_ROUNDS`).
    pub shadow_rounds: u32,
    /// The visited level camera and shadow rays start at from their beam
    /// (`EXACT_BEAM_LEVEL`).
    pub beam_level: u32,
    /// A descent into the texels tests the texel in the same iteration
    /// (`EXACT_FUSED_DESCENT`).
    pub fused_descent: bool,
    /// A tile a camera ray passes between the floors and slabs of is
    /// skipped (`EXACT_CAVE_SKIP`, [`CavePyramid`]); the camera tiles' beams
    /// likewise. Shadow rays come down from above the map and never pass
    /// under a slab: their pipeline leaves the test out.
    pub cave_skip: bool,
    /// The beams test a box no wider than a texel against the texels that
    /// hold it rather than against 4-texel tiles (`EXACT_BEAM_TEXELS`).
    pub beam_texels: bool,
    /// How a 4x4 tile's texels are walked: from the terrain, or from the
    /// texel plane (`EXACT_TEXEL_BLOCKS`, [`TexelTops`]).
    pub texel_walk: TexelWalk,
}

impl Traversal {
    /// The whole map's compute pipelines' traversal (`START_LEVEL`).
    pub const GPU: Traversal = Traversal {
        climb: 1,
        start: Some(super::START_LEVEL / LOG_RATIO),
        beam: true,
        search: crate::options::ExactOptions::DEFAULT.beam_search,
        shadow_rounds: crate::options::ExactOptions::DEFAULT.shadow_rounds,
        beam_level: super::BEAM_LEVEL / LOG_RATIO,
        fused_descent: crate::options::ExactOptions::DEFAULT.fused_descent,
        cave_skip: crate::options::ExactOptions::DEFAULT.cave_skip,
        beam_texels: crate::options::ExactOptions::DEFAULT.beam_texels,
        texel_walk: crate::options::ExactOptions::DEFAULT.texel_walk,
    };

    /// Starting at the 256-texel tiles (the GPU's before `START_LEVEL`).
    pub const FROM_TOP: Traversal = Traversal {
        climb: 1,
        start: None,
        beam: false,
        search: BeamSearch::Serial,
        shadow_rounds: WIDE_ROUNDS,
        beam_level: super::BEAM_LEVEL / LOG_RATIO,
        fused_descent: false,
        cave_skip: false,
        beam_texels: false,
        texel_walk: TexelWalk::Terrain,
    };
}

/// Distinct elements read of one resource (a bit per element).
#[derive(Clone, Debug)]
struct Touched {
    bits: Vec<u64>,
    count: u64,
}

impl Touched {
    fn new(elements: u64) -> Self {
        Touched {
            bits: vec![0; elements.div_ceil(64) as usize],
            count: 0,
        }
    }

    fn clear(&mut self) {
        self.bits.fill(0);
        self.count = 0;
    }

    fn touch(&mut self, i: u64) {
        let (w, b) = ((i / 64) as usize, 1u64 << (i % 64));
        if self.bits[w] & b == 0 {
            self.bits[w] |= b;
            self.count += 1;
        }
    }
}

/// The world the replay reads: the level, its pyramid as the compute
/// pipelines build it, and what was read of them.
pub struct Replay<'a> {
    level: &'a Level,
    pyramid: &'a Pyramid,
    top: u32,
    /// The traversal replayed ([`Traversal::GPU`] unless changed).
    pub traversal: Traversal,
    /// The cave pyramid beside `pyramid` (built with the replay).
    caves: CavePyramid,
    /// The texel plane (built when a traversal first walks it).
    texels: Option<TexelTops>,
    terrain_touched: Touched,
    pyramid_touched: Touched,
}

/// The pyramid `ray-exact`'s compute pipelines read.
pub fn compute_pyramid(level: &Level) -> Pyramid {
    Pyramid::with_step(level, LOG_RATIO)
}

/// `texel_after` of `column_segment.wgsl`.
fn texel_after(p: Vec2, d: Vec2) -> IVec2 {
    let f = p.floor();
    let on = |a: f32, b: f32, dd: f32| i32::from(a == b && dd < 0.0);
    IVec2::new(
        f.x as i32 - on(f.x, p.x, d.x),
        f.y as i32 - on(f.y, p.y, d.y),
    )
}

/// `column_entry` of `column_segment.wgsl`: the first t in [t0, t1] at which
/// `oz + t dz` is solid, or -1.
fn column_entry(c: &strata_level::model::Column, oz: f32, dz: f32, t0: f32, t1: f32) -> f32 {
    let low = f32::from(c.low);
    let mut best = -1.0f32;
    if dz < 0.0 {
        let e = t0.max((low - oz) / dz);
        if e <= t1 {
            best = e;
        }
    } else if oz + dz * t0 <= low {
        best = t0;
    }
    if c.dual {
        let (mid, high) = (f32::from(c.mid), f32::from(c.high));
        let (mut lo, mut hi) = (t0, t1);
        if dz == 0.0 {
            if oz < mid || oz > high {
                (lo, hi) = (1.0, 0.0);
            }
        } else {
            let (ta, tb) = ((mid - oz) / dz, (high - oz) / dz);
            lo = t0.max(ta.min(tb));
            hi = t1.min(ta.max(tb));
        }
        if lo <= hi && (best < 0.0 || lo < best) {
            best = lo;
        }
    }
    best
}

/// `exact_base` of `ray_exact_core.wgsl`.
fn exact_base(p: Vec2) -> IVec2 {
    (p / BASE_TILE).floor().as_ivec2() * BASE_TILE as i32
}

/// `exact_clip` of `ray_exact_core.wgsl`: empty (x > y) when the segment
/// stays above 255.
fn exact_clip(o: Vec3, d: Vec3, t0: f32, t1: f32) -> (f32, f32) {
    let (mut a, mut b) = (t0, t1);
    if d.z < 0.0 {
        a = a.max((MAX_ALTITUDE - o.z) / d.z);
    } else if o.z > MAX_ALTITUDE {
        return (1.0, 0.0);
    } else if d.z > 0.0 {
        b = b.min((MAX_ALTITUDE - o.z) / d.z);
    }
    (a, b)
}

/// A ray's walk over a grid of tiles (relative to its base): the
/// direction's signs and reciprocals, as `exact_march_at` sets them up.
struct RayGrid {
    o: Vec3,
    d: Vec3,
    step: IVec2,
    far_side: IVec2,
    still: [bool; 2],
    inv: Vec2,
}

impl RayGrid {
    fn new(o: Vec3, d: Vec3) -> Self {
        let pos = [d.x > 0.0, d.y > 0.0];
        let still = [d.x == 0.0, d.y == 0.0];
        RayGrid {
            o,
            d,
            step: IVec2::new(if pos[0] { 1 } else { -1 }, if pos[1] { 1 } else { -1 }),
            far_side: IVec2::new(i32::from(pos[0]), i32::from(pos[1])),
            still,
            inv: Vec2::new(
                if still[0] { 0.0 } else { 1.0 / d.x },
                if still[1] { 0.0 } else { 1.0 / d.y },
            ),
        }
    }

    /// The texel holding the ray's point at `t`.
    fn texel_at(&self, t: f32) -> IVec2 {
        texel_after(self.o.truncate() + self.d.truncate() * t, self.d.truncate())
    }

    /// Tile `cell` of side `2^shift`: where the ray crosses its far x and y
    /// lines (`tb`), its exit (`t_exit`) and the ray's end in it (`t_out`).
    fn bounds(&self, cell: IVec2, shift: u32, t1: f32) -> (Vec2, f32, f32) {
        let edge = (cell + self.far_side).as_vec2() * (1u32 << shift) as f32;
        let tb = (edge - self.o.truncate()) * self.inv;
        let tb = Vec2::new(
            if self.still[0] { BIG } else { tb.x },
            if self.still[1] { BIG } else { tb.y },
        );
        let t_exit = tb.x.min(tb.y);
        (tb, t_exit, t_exit.min(t1))
    }

    /// The next cell after `cell`, whose far lines the ray crosses at `tb`.
    fn next(&self, mut cell: IVec2, tb: Vec2) -> IVec2 {
        if tb.x <= tb.y {
            cell.x += self.step.x;
        }
        if tb.y <= tb.x {
            cell.y += self.step.y;
        }
        cell
    }
}

impl<'a> Replay<'a> {
    /// A replay over `level` and its compute pyramid ([`compute_pyramid`]).
    pub fn new(level: &'a Level, pyramid: &'a Pyramid) -> Self {
        let pairs = u64::from(level.width() / 2) * u64::from(level.height());
        Replay {
            level,
            pyramid,
            top: pyramid.top(),
            traversal: Traversal::GPU,
            caves: CavePyramid::with_step(level, pyramid.layout.step),
            texels: None,
            terrain_touched: Touched::new(pairs),
            pyramid_touched: Touched::new(u64::from(pyramid.layout.bytes / 4)),
        }
    }

    /// `decode_column` (one terrain texel: the pair holding (x, y)).
    fn column(&mut self, x: i32, y: i32) -> strata_level::model::Column {
        let (w, h) = (self.level.width() as i32, self.level.height() as i32);
        let pair = ((x & (w - 1)) >> 1) as u64 + (y & (h - 1)) as u64 * (w / 2) as u64;
        self.terrain_touched.touch(pair);
        self.level.column(i64::from(x), i64::from(y))
    }

    /// `maxmip_get` (one word).
    fn maxmip(&mut self, k: u32, tx: i32, ty: i32) -> f32 {
        let i = self
            .pyramid
            .layout
            .level(k)
            .index(i64::from(tx), i64::from(ty));
        self.pyramid_touched.touch((i / 4) as u64);
        f32::from(self.pyramid.data[i])
    }

    /// `cave_clear` of `exact_levels.wgsl` (the cave word, counted as a
    /// pyramid read by the caller).
    fn cave_clear(&self, k: u32, tx: i32, ty: i32, z_lo: f32, z_hi: f32) -> bool {
        let (floor, bottom) = self.caves.get(k, i64::from(tx), i64::from(ty));
        z_lo > f32::from(floor) + CAVE_MARGIN && z_hi < f32::from(bottom) - CAVE_MARGIN
    }

    /// `exact_march` of `ray_exact_core.wgsl` on the whole map (level of
    /// detail 0), counting.
    pub fn march(&mut self, o: Vec3, base: IVec2, d: Vec3, t0: f32, t1: f32) -> MarchCount {
        self.march_at(o, base, d, (t0, t1), self.traversal.start)
    }

    /// `exact_march_at`: [`Replay::march`] from visited level `start`
    /// (`None`: the top).
    fn march_at(
        &mut self,
        o: Vec3,
        base: IVec2,
        d: Vec3,
        (t0, t1): (f32, f32),
        start: Option<u32>,
    ) -> MarchCount {
        let mut r = MarchCount::default();
        if t1 < t0 {
            return r;
        }
        let ratio = LOG_RATIO;
        let grid = RayGrid::new(o, d);
        let top = self.top / ratio;
        let mut lvl = start.map_or(top, |s| s.min(top));
        let mut t = t0;
        let mut cell = grid.texel_at(t) >> (lvl * ratio) as i32;
        loop {
            if r.iterations >= super::ITERATION_CAP {
                return r;
            }
            r.iterations += 1;
            let shift = lvl * ratio;
            let (mut tb, mut t_exit, mut t_out) = grid.bounds(cell, shift, t1);
            let mut test_column = lvl == 0;
            if lvl > 0 {
                let (z_a, z_b) = (o.z + d.z * t, o.z + d.z * t_out);
                let z_min = z_a.min(z_b);
                let tile = (base >> shift as i32) + cell;
                r.pyramid_reads += 1;
                r.waits += 1;
                let under = z_min <= self.maxmip(shift, tile.x, tile.y);
                // EXACT_CAVE_SKIP: the cave word, read beside the maximum
                // (its test matters only under the maximum).
                if self.traversal.cave_skip {
                    r.pyramid_reads += 1;
                }
                let between = under
                    && self.traversal.cave_skip
                    && self.cave_clear(shift, tile.x, tile.y, z_min, z_a.max(z_b));
                let block = self.traversal.texel_walk.reads_plane() && shift == 2;
                if block && self.traversal.texel_walk == TexelWalk::PlaneBeside {
                    // The block's words beside the maximum: no wait of
                    // their own.
                    r.pyramid_reads += 4;
                }
                if under && !between && block {
                    // EXACT_TEXEL_BLOCKS: the tile's texels from the plane.
                    r.descents += 1;
                    match self.texel_block(&mut r, &grid, base, t1, &mut t, cell) {
                        Some((c, l)) => {
                            cell = c;
                            lvl = l;
                            continue;
                        }
                        None => return r,
                    }
                }
                if under && !between {
                    r.descents += 1;
                    lvl -= 1;
                    let child = grid.texel_at(t) >> (shift - ratio) as i32;
                    let first = cell << ratio as i32;
                    cell = child.clamp(first, first + IVec2::splat((1 << ratio) - 1));
                    if !self.traversal.fused_descent || lvl > 0 {
                        continue;
                    }
                    // EXACT_FUSED_DESCENT: the texel in this iteration.
                    (tb, t_exit, t_out) = grid.bounds(cell, 0, t1);
                    test_column = true;
                }
            }
            if test_column {
                let column = base + cell;
                r.terrain_reads += 1;
                r.waits += 1;
                let c = self.column(column.x, column.y);
                let e = column_entry(&c, o.z, d.z, t, t_out);
                if e >= 0.0 {
                    r.hit = Some((e, column));
                    return r;
                }
            }
            if t_exit >= t1 {
                return r;
            }
            t = t_exit;
            let old = cell;
            (cell, lvl) = self.climb(&mut r, old, grid.next(cell, tb), lvl);
        }
    }

    /// `exact_climb`: after a step from `was` to `cell` at visited level
    /// `lvl`, the cell and level (EXACT_CLIMB).
    fn climb(
        &self,
        r: &mut MarchCount,
        mut was: IVec2,
        mut cell: IVec2,
        mut lvl: u32,
    ) -> (IVec2, u32) {
        let ratio = LOG_RATIO as i32;
        for _ in 0..self.traversal.climb {
            if lvl >= self.top / LOG_RATIO || (was >> ratio) == (cell >> ratio) {
                break;
            }
            was >>= ratio;
            cell >>= ratio;
            lvl += 1;
            r.climbs += 1;
        }
        (cell, lvl)
    }

    /// The texel walk of `exact_march_at` over the 4x4 tile `cell` (level
    /// 2, relative to `base`) from the texel plane, from `t` on: `None`
    /// when the ray ends in it (hit, or `t1`), else the cell and visited
    /// level after it leaves the tile (`t` its exit).
    fn texel_block(
        &mut self,
        r: &mut MarchCount,
        grid: &RayGrid,
        base: IVec2,
        t1: f32,
        t: &mut f32,
        cell: IVec2,
    ) -> Option<(IVec2, u32)> {
        let level = self.level;
        let texels = self.texels.get_or_insert_with(|| TexelTops::new(level));
        let first = cell << 2;
        if self.traversal.texel_walk == TexelWalk::Plane {
            // The block's four row words, side by side: one wait.
            r.pyramid_reads += 4;
            r.waits += 1;
        }
        let mut texel = grid.texel_at(*t).clamp(first, first + IVec2::splat(3));
        loop {
            if r.iterations >= super::ITERATION_CAP {
                return None;
            }
            r.iterations += 1;
            let (tb, t_exit, t_out) = grid.bounds(texel, 0, t1);
            let column = base + texel;
            let byte = texels.get(i64::from(column.x), i64::from(column.y));
            let c = if byte == strata_maxmip::TEXEL_DECODE {
                r.terrain_reads += 1;
                r.waits += 1;
                let (w, h) = (level.width() as i32, level.height() as i32);
                let pair = ((column.x & (w - 1)) >> 1) as u64
                    + (column.y & (h - 1)) as u64 * (w / 2) as u64;
                self.terrain_touched.touch(pair);
                level.column(i64::from(column.x), i64::from(column.y))
            } else {
                // A single floor (its terrain type is not needed to test it).
                strata_level::model::Column {
                    low: byte,
                    mid: byte,
                    high: byte,
                    dual: false,
                    lower_type: 0,
                    upper_type: 0,
                }
            };
            let e = column_entry(&c, grid.o.z, grid.d.z, *t, t_out);
            if e >= 0.0 {
                r.hit = Some((e, column));
                return None;
            }
            if t_exit >= t1 {
                return None;
            }
            *t = t_exit;
            let was = texel;
            texel = grid.next(texel, tb);
            if (texel >> 2) != cell {
                return Some(self.climb(r, was, texel, 0));
            }
        }
    }

    /// `exact_pixel_hit` of `ray_exact_pixel.wgsl` (the eye's tile as base):
    /// the ray and what its march did.
    pub fn pixel(&mut self, g: &Globals, px: f32, py: f32) -> (Vec3, MarchCount) {
        self.pixel_from(g, px, py, None)
    }

    /// `exact_pixel_hit_from`: the march of pixel (px, py) from no earlier
    /// than `start` (its tile's beam, [`Replay::tile_beam`]), from visited
    /// level [`Traversal::beam_level`] then; `None`: as
    /// [`Replay::pixel`].
    pub fn pixel_from(
        &mut self,
        g: &Globals,
        px: f32,
        py: f32,
        start: Option<f32>,
    ) -> (Vec3, MarchCount) {
        let eye = Vec3::from_slice(&g.eye[..3]);
        let d = camera_ray(g, px, py);
        let focal = g.eye[3];
        let (a, b) = exact_clip(eye, d, g.forward[3] / focal, g.right[3] / focal);
        let base = exact_base(eye.truncate());
        let o = (eye.truncate() - base.as_vec2()).extend(eye.z);
        let level = match start {
            Some(_) => Some(self.traversal.beam_level),
            None => self.traversal.start,
        };
        let a = start.map_or(a, |t| a.max(t));
        (d, self.march_at(o, base, d, (a, b), level))
    }

    /// `cast_texel` of `ray_exact_shadow.wgsl`: shadow texel (i, j).
    pub fn shadow_texel(&mut self, g: &Globals, i: u32, j: u32) -> MarchCount {
        self.shadow_texel_from(g, i, j, None)
    }

    /// `exact_shadow_ray` of `ray_exact_core.wgsl`: where shadow texel
    /// (i, j)'s ray comes down to altitude 255, and the ray parameter it
    /// leaves the map at below 0.
    fn shadow_start(&self, g: &Globals, i: u32, j: u32) -> (Vec3, f32) {
        // `shadow_texel_centre` of `frame.wgsl`: from the texel's lattice index.
        let texel = g.shadow_origin[3];
        let at = |n: u32, first: i32| (first.wrapping_add(n as i32) as f32 + 0.5) * texel;
        let o = Vec3::from_slice(&g.shadow_anchor[..3])
            + Vec3::from_slice(&g.shadow_u[..3]) * at(i, g.shadow_lattice[0])
            + Vec3::from_slice(&g.shadow_v[..3]) * at(j, g.shadow_lattice[1]);
        let d = Vec3::from_slice(&g.light_dir[..3]);
        let t_in = (MAX_ALTITUDE - o.z) / d.z;
        let t_out = (-1.0 - o.z) / d.z;
        (o + d * t_in, t_out - t_in)
    }

    /// `cast_texel` from no earlier than `start` (its block's beam).
    pub fn shadow_texel_from(
        &mut self,
        g: &Globals,
        i: u32,
        j: u32,
        start: Option<f32>,
    ) -> MarchCount {
        self.without_caves(|replay| replay.shadow_texel_march(g, i, j, start))
    }

    /// Run `f` with the cave skip off (the shadow pipeline's constant).
    pub(super) fn without_caves<T>(&mut self, f: impl FnOnce(&mut Self) -> T) -> T {
        let keep = std::mem::replace(&mut self.traversal.cave_skip, false);
        let out = f(self);
        self.traversal.cave_skip = keep;
        out
    }

    fn shadow_texel_march(
        &mut self,
        g: &Globals,
        i: u32,
        j: u32,
        start: Option<f32>,
    ) -> MarchCount {
        let d = Vec3::from_slice(&g.light_dir[..3]);
        let (p, span) = self.shadow_start(g, i, j);
        let base = exact_base(p.truncate());
        let rel = (p.truncate() - base.as_vec2()).extend(p.z);
        match start {
            None => self.march(rel, base, d, 0.0, span),
            Some(t) => {
                let level = Some(self.traversal.beam_level);
                self.march_at(rel, base, d, (t.max(0.0), span), level)
            }
        }
    }
}

/// `camera_ray` of `frame.wgsl`.
pub fn camera_ray(g: &Globals, px: f32, py: f32) -> Vec3 {
    let sx = px - g.screen[0] * 0.5;
    let sy = g.screen[1] * 0.5 - py;
    Vec3::from_slice(&g.forward[..3]) * g.eye[3] - Vec3::from_slice(&g.right[..3]) * sx
        + Vec3::from_slice(&g.up[..3]) * sy
}

/// `mark_shadow_blocks` of `ray_exact_deferred.wgsl`: the blocks shading
/// point `p` can read.
fn shadow_blocks_of(g: &Globals, p: Vec3, out: &mut impl FnMut(u32)) {
    let texel = g.shadow_origin[3];
    let rel = p - Vec3::from_slice(&g.shadow_origin[..3]);
    let uv = Vec2::new(
        rel.dot(Vec3::from_slice(&g.shadow_u[..3])),
        rel.dot(Vec3::from_slice(&g.shadow_v[..3])),
    ) / texel;
    let side = g.shadow_u[3] as i32;
    let lo = (uv - Vec2::splat(2.5)).floor().as_ivec2();
    let hi = (uv + Vec2::splat(2.5)).floor().as_ivec2();
    if hi.x < 0 || hi.y < 0 || lo.x >= side || lo.y >= side {
        return;
    }
    let blocks = side / MARK_BLOCK;
    let b0 = lo.clamp(IVec2::ZERO, IVec2::splat(side - 1)) / MARK_BLOCK;
    let b1 = hi.clamp(IVec2::ZERO, IVec2::splat(side - 1)) / MARK_BLOCK;
    for by in b0.y..=b1.y {
        for bx in b0.x..=b1.x {
            out((by * blocks + bx) as u32);
        }
    }
}

/// Whether the shading of a hit at `p` in column `c` reads the shadow map
/// (`shade_with_normal`: not under a slab or on its underside), and how many
/// of its four taps fall on the map.
fn shadow_taps(g: &Globals, p: Vec3, c: &strata_level::model::Column, d: Vec3) -> u64 {
    if g.light_dir[3] == 0.0 {
        return 0;
    }
    let (z, low, mid, high) = (p.z, f32::from(c.low), f32::from(c.mid), f32::from(c.high));
    // `surface_kind`.
    let floor = !c.dual || z < 0.5 * (low + mid);
    let ceiling = !floor && d.z > 0.0 && z - mid < high - z;
    if c.dual && (z < mid || ceiling) {
        return 0;
    }
    // The taps lie within 2 texels of p's own map coordinates; all four are
    // on the map except at its very edge, where the count is a bound.
    4
}

/// Check the beams on every pixel of a frame and every texel of the shadow
/// blocks its hits stamp: march each ray from the near plane (altitude 255)
/// and from its tile's (block's) beam ([`Replay::tile_beam`],
/// [`Replay::shadow_beam`]); the rays whose hits differ (t to the bit, or
/// the column) and those whose hit lies before their beam (both must be 0).
pub fn beam_disagreements(replay: &mut Replay<'_>, g: &Globals) -> (u64, u64) {
    let (w, h) = (g.screen[0] as u32, g.screen[1] as u32);
    let (mut differ, mut early) = (0, 0);
    let bits = |hit: Option<(f32, IVec2)>| hit.map(|(t, c)| (t.to_bits(), c));
    let mut blocks = std::collections::BTreeSet::new();
    for ty in 0..h.div_ceil(BEAM_TILE) {
        for tx in 0..w.div_ceil(BEAM_TILE) {
            let start = replay.tile_start(g, tx, ty).t;
            for y in ty * BEAM_TILE..((ty + 1) * BEAM_TILE).min(h) {
                for x in tx * BEAM_TILE..((tx + 1) * BEAM_TILE).min(w) {
                    let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                    let (d, old) = replay.pixel(g, px, py);
                    let new = replay.pixel_from(g, px, py, Some(start)).1.hit;
                    differ += u64::from(bits(old.hit) != bits(new));
                    early += u64::from(old.hit.is_some_and(|(t, _)| t < start));
                    if let Some((t, _)) = old.hit
                        && g.light_dir[3] != 0.0
                    {
                        let p = Vec3::from_slice(&g.eye[..3]) + d * t;
                        shadow_blocks_of(g, p, &mut |b| {
                            blocks.insert(b);
                        });
                    }
                }
            }
        }
    }
    // The shadow blocks the hits stamp, every texel.
    let across = g.shadow_u[3] as u32 / MARK_BLOCK as u32;
    for b in blocks {
        let (bx, by) = (b % across * 8, b / across * 8);
        let start = replay.shadow_block_start(g, bx, by).t;
        for j in 0..MARK_BLOCK as u32 {
            for i in 0..MARK_BLOCK as u32 {
                let old = replay.shadow_texel(g, bx + i, by + j).hit;
                let new = replay.shadow_texel_from(g, bx + i, by + j, Some(start)).hit;
                differ += u64::from(bits(old) != bits(new));
                early += u64::from(old.is_some_and(|(t, _)| t < start));
            }
        }
    }
    (differ, early)
}

/// Warps of 8x8 workgroups over a w x h grid of invocations: 8x4 each, as
/// indices into the grid's row-major order.
fn warps_of(w: u32, h: u32) -> impl Iterator<Item = Vec<usize>> {
    (0..h.div_ceil(4)).flat_map(move |wy| {
        (0..w.div_ceil(8)).map(move |wx| {
            (wy * 4..(wy * 4 + 4).min(h))
                .flat_map(|y| (wx * 8..(wx * 8 + 8).min(w)).map(move |x| (y * w + x) as usize))
                .collect()
        })
    })
}

/// Replay `ray-exact`'s deferred frame for globals `g` (shadows as `g` says).
pub fn replay_frame(replay: &mut Replay<'_>, g: &Globals) -> FrameCount {
    replay.terrain_touched.clear();
    replay.pyramid_touched.clear();
    let (w, h) = (g.screen[0] as u32, g.screen[1] as u32);
    let shadows = g.light_dir[3] != 0.0;
    let side = g.shadow_u[3] as u32;
    let mut march = PassAcc::default();
    let mut hits = Vec::new();
    let mut stamped = vec![false; ((side / MARK_BLOCK as u32).pow(2)) as usize];
    let mut listed = Vec::new();
    // The beams: one per 8x8 tile, one thread each, in 8x8 workgroups of
    // tiles (a warp: 8x4 tiles).
    let tiles = (w.div_ceil(BEAM_TILE), h.div_ceil(BEAM_TILE));
    let mut beam = PassAcc::default();
    let mut starts = vec![None; (tiles.0 * tiles.1) as usize];
    if replay.traversal.beam {
        for ty in 0..tiles.1 {
            for tx in 0..tiles.0 {
                let b = replay.tile_start(g, tx, ty);
                starts[(ty * tiles.0 + tx) as usize] = Some(b.t);
                beam.add(&MarchCount {
                    iterations: b.iterations,
                    pyramid_reads: b.pyramid_reads,
                    ..MarchCount::default()
                });
            }
        }
    }
    // The wide search in the march writes and reads no starts.
    let wide = replay.traversal.search == BeamSearch::Wide;
    let beam = if replay.traversal.beam {
        let mut p = beam.finish(warps_of(tiles.0, tiles.1));
        // The serial pre-pass writes one f32 per tile; the wide search
        // happens in the march's workgroup and writes nothing.
        p.bytes_written = if wide {
            0
        } else {
            u64::from(tiles.0 * tiles.1) * 4
        };
        p
    } else {
        PassCount::default()
    };
    for y in 0..h {
        for x in 0..w {
            let start = starts[((y / BEAM_TILE) * tiles.0 + x / BEAM_TILE) as usize];
            let (d, m) = replay.pixel_from(g, x as f32 + 0.5, y as f32 + 0.5, start);
            march.add(&m);
            if let Some((t, column)) = m.hit {
                let p = Vec3::from_slice(&g.eye[..3]) + d * t;
                if shadows {
                    shadow_blocks_of(g, p, &mut |b| {
                        if !std::mem::replace(&mut stamped[b as usize], true) {
                            listed.push(b);
                        }
                    });
                }
                hits.push((p, d, column));
            }
        }
    }
    let pixels = u64::from(w) * u64::from(h);
    let mut march = march.finish(warps_of(w, h));
    // hits (column and t, 8 B each pixel), stamps and list.
    march.bytes_written = pixels * 2 * TEXEL_BYTES + listed.len() as u64 * 8;
    if replay.traversal.beam && !wide {
        // Each pixel reads its tile's start.
        march.bytes_read += pixels * 4;
    }
    let most_iterations = march.iterations.max;

    let mut shadow = PassAcc::default();
    let mut shadow_beams = 0u64;
    if shadows {
        let across = side / MARK_BLOCK as u32;
        for &b in &listed {
            let (bx, by) = (b % across, b / across);
            let start = replay
                .traversal
                .beam
                .then(|| replay.shadow_block_start(g, bx * 8, by * 8));
            if let Some(s) = start {
                shadow_beams += u64::from(s.iterations);
            }
            for j in 0..MARK_BLOCK as u32 {
                for i in 0..MARK_BLOCK as u32 {
                    let t = start.map(|s| s.t);
                    shadow.add(&replay.shadow_texel_from(g, bx * 8 + i, by * 8 + j, t));
                }
            }
        }
    }
    // Each listed block is a workgroup, its texels in rows: two warps.
    let rays = shadow.rays();
    let mut shadow = shadow.finish((0..rays / 32).map(|k| (k * 32..k * 32 + 32).collect()));
    shadow.bytes_read += listed.len() as u64 * 4;
    shadow.bytes_written = listed.len() as u64 * SHADOW_BLOCK_TEXELS * TEXEL_BYTES;
    let shadow_most_iterations = shadow.iterations.max;

    // Shading: the column's pair (it holds one row neighbour too), the pair
    // of the other row neighbour, the column neighbours, the taps.
    let mut shade_terrain = Vec::with_capacity(hits.len());
    let mut taps = 0;
    for &(p, d, column) in &hits {
        let c = replay.column(column.x, column.y);
        let across = if column.x & 1 == 1 { 1 } else { -1 };
        for (dx, dy) in [(across, 0), (0, 1), (0, -1)] {
            replay.column(column.x + dx, column.y + dy);
        }
        shade_terrain.push(4);
        taps += shadow_taps(g, p, &c, d);
    }
    let terrain = Spread::of(shade_terrain);
    let shade = PassCount {
        rays: hits.len() as u64,
        terrain_reads: terrain,
        shadow_reads: taps,
        // hits for every pixel (8 B) and the taps for the hits.
        bytes_read: pixels * 2 * TEXEL_BYTES
            + terrain.total * TERRAIN_TEXEL_BYTES
            + taps * TEXEL_BYTES,
        // colour and depth of every pixel.
        bytes_written: pixels * 2 * TEXEL_BYTES,
        ..PassCount::default()
    };
    FrameCount {
        size: [w, h],
        hits: hits.len() as u64,
        beam,
        beam_lanes: if replay.traversal.search.is_wide() {
            WIDE_LANES
        } else {
            1
        },
        march,
        shadow,
        shadow_beam_iterations: shadow_beams,
        shade,
        shadow_blocks: listed.len() as u64,
        terrain_bytes_touched: replay.terrain_touched.count * TERRAIN_TEXEL_BYTES,
        pyramid_bytes_touched: replay.pyramid_touched.count * PYRAMID_WORD_BYTES,
        most_iterations,
        shadow_most_iterations,
    }
}
