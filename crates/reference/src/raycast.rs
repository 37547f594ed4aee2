//! The exact ray cast: a hierarchical 2D grid traversal over the max-height
//! pyramid, and an analytic intersection of the ray's segment inside each
//! texel column with the column's solid intervals `[0, low]` and `[mid, high]`.
//!
//! Arithmetic is in f64: the map is up to 16384 texels long, where f32 keeps
//! only ~0.002 of a unit, and these are the numbers every renderer is scored by.

use crate::pyramid::{LOG_RATIO, Pyramid};
use crate::tiled::{TileCursor, TiledGrid};
use crate::{HitClass, Reference, ReferenceSettings};
use glam::DVec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use strata_camera::Camera;
use strata_level::ray;
use strata_level::source::{ColumnSource, SourceError};
use strata_level::{Column, Level};

/// Where a ray first meets solid terrain.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RayHit {
    /// Distance along the (unit) ray from its origin.
    pub distance: f64,
    /// Which interval, entered through which face.
    pub class: HitClass,
    /// Terrain type (0..7) of the interval hit (the floor's lower type, the
    /// slab's upper type).
    pub terrain: u8,
    /// The texel column hit (a wall hit lies on its texel line, where the
    /// point alone does not say which side's column it was).
    pub column: [i64; 2],
}

/// A map prepared for ray casting (its max-height pyramid built once, or,
/// for a map read through a [`ColumnSource`], built per tile as tiles are
/// read). Build one per map and reuse it for every view.
pub struct Tracer<'a> {
    inner: Inner<'a>,
    /// The first read error of a tiled source (rays stop once there is one).
    error: Arc<ErrorSlot>,
}

enum Inner<'a> {
    /// A level in memory with a whole-map pyramid: the fast path.
    Memory(MemoryGrid<'a>),
    /// A source read a tile at a time (a store's chunk cache).
    Tiled(TiledGrid<'a>),
}

/// Where a tiled tracer's first read error is kept.
#[derive(Default)]
pub(crate) struct ErrorSlot {
    failed: AtomicBool,
    first: Mutex<Option<SourceError>>,
}

impl ErrorSlot {
    pub(crate) fn record(&self, e: SourceError) {
        let mut first = self.first.lock().unwrap_or_else(|p| p.into_inner());
        first.get_or_insert(e);
        self.failed.store(true, Ordering::Release);
    }
    #[inline]
    pub(crate) fn failed(&self) -> bool {
        self.failed.load(Ordering::Acquire)
    }
    pub(crate) fn get(&self) -> Option<SourceError> {
        self.first.lock().unwrap_or_else(|p| p.into_inner()).clone()
    }
}

impl<'a> Tracer<'a> {
    /// A tracer with the max-height pyramid of `level` built (in parallel),
    /// which lets rays skip tiles they pass above.
    pub fn new(level: &'a Level) -> Self {
        Self::with_pyramid(level, Arc::new(Pyramid::new(level)))
    }

    /// A tracer that builds nothing first and visits every texel column a
    /// ray crosses: exact like the others, and cheaper for a few short rays
    /// (a viewer's pick) than building the pyramid over the whole map.
    pub fn unaccelerated(level: &'a Level) -> Self {
        Self::with_pyramid(level, Arc::new(Pyramid::none()))
    }

    /// A tracer for `level` reusing a pyramid built for identical content.
    pub(crate) fn with_pyramid(level: &'a Level, pyramid: Arc<Pyramid>) -> Self {
        Tracer {
            inner: Inner::Memory(MemoryGrid { level, pyramid }),
            error: Arc::default(),
        }
    }

    /// A tracer over any column source: a [`Level`] takes the fast path of
    /// [`Tracer::new`]; otherwise nothing is built for the whole map. The
    /// coarsest level of the max-height pyramid is the source's tile tops
    /// (a store's chunk summaries), the finer levels are built per tile
    /// when a ray first descends into it and kept with the tile while the
    /// source keeps it, so memory stays within the source's budget. Results
    /// are bit-identical to the in-memory tracer's. Errors reading the tile
    /// tops are returned; errors reading tiles later stop the rays and are
    /// returned by [`Tracer::try_render`] / [`Tracer::error`].
    pub fn over(source: &'a dyn ColumnSource) -> Result<Self, SourceError> {
        if let Some(level) = source.as_level() {
            return Ok(Self::new(level));
        }
        Ok(Tracer {
            inner: Inner::Tiled(TiledGrid::new(source, true)?),
            error: Arc::default(),
        })
    }

    /// [`Tracer::over`] without any pyramid (every texel column a ray
    /// crosses is read): for a few short rays.
    pub fn over_unaccelerated(source: &'a dyn ColumnSource) -> Result<Self, SourceError> {
        if let Some(level) = source.as_level() {
            return Ok(Self::unaccelerated(level));
        }
        Ok(Tracer {
            inner: Inner::Tiled(TiledGrid::new(source, false)?),
            error: Arc::default(),
        })
    }

    pub(crate) fn pyramid(&self) -> Option<&Arc<Pyramid>> {
        match &self.inner {
            Inner::Memory(m) => Some(&m.pyramid),
            Inner::Tiled(_) => None,
        }
    }

    /// The level it traces, when it traces one in memory.
    pub fn level(&self) -> Option<&'a Level> {
        match &self.inner {
            Inner::Memory(m) => Some(m.level),
            Inner::Tiled(_) => None,
        }
    }

    /// The columns it traces.
    pub fn source(&self) -> &'a dyn ColumnSource {
        match &self.inner {
            Inner::Memory(m) => m.level,
            Inner::Tiled(t) => t.source,
        }
    }

    pub(crate) fn error_slot(&self) -> &Arc<ErrorSlot> {
        &self.error
    }

    /// The first error reading the source (a tiled source only): rays traced
    /// after it found nothing, so images rendered since are not the reference.
    pub fn error(&self) -> Option<SourceError> {
        self.error.get()
    }

    /// [`Tracer::render`], failing when the source could not be read.
    pub fn try_render(
        &self,
        camera: &Camera,
        settings: &ReferenceSettings,
    ) -> Result<Reference, SourceError> {
        let r = self.render(camera, settings);
        match self.error() {
            Some(e) => Err(e),
            None => Ok(r),
        }
    }

    /// Render the reference of one camera, parallel over rows.
    pub fn render(&self, camera: &Camera, settings: &ReferenceSettings) -> Reference {
        let (w, h) = (camera.width as usize, camera.height as usize);
        let n = w * h;
        let mut distance = vec![f32::INFINITY; n];
        let mut class = vec![HitClass::Sky; n];
        let mut terrain = vec![0u8; n];
        let origin = camera.position.as_dvec3();
        let focal = f64::from(camera.focal_px);
        let far = f64::from(camera.far);
        distance
            .par_chunks_mut(w)
            .zip(class.par_chunks_mut(w))
            .zip(terrain.par_chunks_mut(w))
            .enumerate()
            .for_each(|(j, ((dist_row, class_row), terrain_row))| {
                let mut state = self.ray_state();
                for i in 0..w {
                    let dir = camera
                        .image_direction(i as f32 + 0.5, j as f32 + 0.5)
                        .as_dvec3();
                    // Far is along the view axis: the ray's length to it
                    // grows with its angle off the axis.
                    let t_max = far * dir.length() / focal;
                    let unit = dir.normalize();
                    if let Some(hit) = self.trace_in(&mut state, origin, unit, t_max, settings) {
                        dist_row[i] = hit.distance as f32;
                        class_row[i] = hit.class;
                        terrain_row[i] = hit.terrain;
                    }
                }
            });
        Reference {
            width: camera.width,
            height: camera.height,
            distance,
            class,
            terrain,
        }
    }

    /// The decoded column at texel (x, y), wrapping; `None` when a tiled
    /// source failed to read it (the error is kept, see [`Tracer::error`]).
    pub fn column(&self, x: i64, y: i64) -> Option<Column> {
        match &self.inner {
            Inner::Memory(m) => Some(m.level.column(x, y)),
            Inner::Tiled(t) => match t.source.column(x, y) {
                Ok(c) => Some(c),
                Err(e) => {
                    self.error.record(e);
                    None
                }
            },
        }
    }

    /// The first solid point along `origin + t dir`, `t` in `[0, t_max]`.
    /// `dir` must be a unit vector for `distance` to be a distance. The
    /// origin is assumed outside solid terrain (a camera guarantees it).
    pub fn trace(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        settings: &ReferenceSettings,
    ) -> Option<RayHit> {
        self.trace_in(&mut self.ray_state(), origin, dir, t_max, settings)
    }

    /// State kept between the rays of one thread (the tile being read):
    /// consecutive rays mostly stay in the same chunks, so keeping it saves
    /// a cache lookup (a lock) per ray.
    pub(crate) fn ray_state(&self) -> RayState<'a> {
        match &self.inner {
            Inner::Memory(_) => RayState::Memory,
            Inner::Tiled(_) => RayState::Tiled(TileCursor::default()),
        }
    }

    /// [`Tracer::trace`] with a thread's [`RayState`].
    #[inline]
    pub(crate) fn trace_in(
        &self,
        state: &mut RayState<'a>,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        settings: &ReferenceSettings,
    ) -> Option<RayHit> {
        match (&self.inner, state) {
            (Inner::Memory(m), _) => march(m, &mut (), origin, dir, t_max, settings),
            (Inner::Tiled(t), state) => {
                if self.error.failed() {
                    return None;
                }
                if let RayState::Memory = state {
                    // A state made for another tracer: start a cursor.
                    *state = RayState::Tiled(TileCursor::default());
                }
                let RayState::Tiled(cursor) = state else {
                    return None;
                };
                let hit = march(t, cursor, origin, dir, t_max, settings);
                if let Some(e) = cursor.error.take() {
                    self.error.record(e);
                    return None;
                }
                hit
            }
        }
    }
}

/// What one thread keeps between rays (see [`Tracer::ray_state`]).
pub(crate) enum RayState<'a> {
    /// Nothing: a level in memory.
    Memory,
    /// The tile being read.
    Tiled(TileCursor<'a>),
}

/// What the traversal reads: the pyramid's levels and the columns. `None`
/// means the data could not be read (the cursor keeps why).
pub(crate) trait Grid {
    /// Per-ray state (the tile being read).
    type Cursor;
    /// The coarsest pyramid level (0: none).
    fn top_level(&self) -> usize;
    /// Highest solid altitude anywhere on the map.
    fn global_max(&self) -> u8;
    /// Max top of tile (cx, cy) of pyramid level `level` (1..=top), wrapping.
    fn tile_max(&self, cur: &mut Self::Cursor, level: usize, cx: i64, cy: i64) -> Option<u8>;
    /// The column at texel (x, y), wrapping.
    fn column(&self, cur: &mut Self::Cursor, x: i64, y: i64) -> Option<Column>;
}

/// A level in memory and its whole-map pyramid.
struct MemoryGrid<'a> {
    level: &'a Level,
    pyramid: Arc<Pyramid>,
}

impl Grid for MemoryGrid<'_> {
    type Cursor = ();
    #[inline]
    fn top_level(&self) -> usize {
        self.pyramid.top_level()
    }
    #[inline]
    fn global_max(&self) -> u8 {
        self.pyramid.global_max()
    }
    #[inline]
    fn tile_max(&self, _: &mut (), level: usize, cx: i64, cy: i64) -> Option<u8> {
        Some(self.pyramid.get(level, cx, cy))
    }
    #[inline]
    fn column(&self, _: &mut (), x: i64, y: i64) -> Option<Column> {
        Some(self.level.column(x, y))
    }
}

/// The traversal: a hierarchical 2D grid walk over `grid`'s pyramid,
/// intersecting the ray with each texel column it crosses.
#[inline(never)]
fn march<G: Grid>(
    grid: &G,
    cur: &mut G::Cursor,
    origin: DVec3,
    dir: DVec3,
    t_max: f64,
    settings: &ReferenceSettings,
) -> Option<RayHit> {
    let (o, d) = (origin, dir);
    if !(o.is_finite() && d.is_finite() && t_max.is_finite()) || d == DVec3::ZERO {
        return None;
    }
    // Above the highest column nothing is solid: start where the ray
    // comes down to it and stop where it rises above it.
    let ceiling = f64::from(grid.global_max());
    let mut t = 0.0f64;
    let mut t_end = t_max;
    if o.z > ceiling {
        if d.z >= 0.0 {
            return None;
        }
        t = (ceiling - o.z) / d.z;
    }
    if d.z > 0.0 {
        t_end = t_end.min((ceiling - o.z) / d.z);
    }
    if t > t_end {
        return None;
    }
    // The start point is not a column entry: being on a surface there
    // (the ray starts exactly at the highest top) is a floor, not a wall.
    let t_start = t;
    let top = if settings.accelerate && grid.top_level() > 0 {
        grid.top_level()
    } else {
        0
    };
    let step_x: i64 = if d.x > 0.0 { 1 } else { -1 };
    let step_y: i64 = if d.y > 0.0 { 1 } else { -1 };
    let (tx0, ty0) = texel_after(o + d * t, d);
    let mut lvl = top;
    let mut cx = tx0 >> (LOG_RATIO as usize * lvl);
    let mut cy = ty0 >> (LOG_RATIO as usize * lvl);
    loop {
        let shift = LOG_RATIO as usize * lvl;
        let size = (1i64 << shift) as f64;
        let tx = ray::boundary_t(o.x, d.x, cx, size);
        let ty = ray::boundary_t(o.y, d.y, cy, size);
        let t_exit = tx.min(ty);
        let t_out = t_exit.min(t_end);
        if lvl > 0 {
            let z_min = (o.z + d.z * t).min(o.z + d.z * t_out);
            if z_min <= f64::from(grid.tile_max(cur, lvl, cx, cy)?) {
                // The ray may touch something in this tile: descend to the
                // child tile it is in at `t`.
                lvl -= 1;
                let (ax, ay) = texel_after(o + d * t, d);
                let child_shift = shift - LOG_RATIO as usize;
                let first = |c: i64| c << LOG_RATIO;
                let last = |c: i64| (c << LOG_RATIO) + (1 << LOG_RATIO) - 1;
                cx = (ax >> child_shift).clamp(first(cx), last(cx));
                cy = (ay >> child_shift).clamp(first(cy), last(cy));
                continue;
            }
        } else {
            let column = grid.column(cur, cx, cy)?;
            let mut hit = if settings.subdivision <= 1 {
                column_hit(&column, o, d, t, t_out, t > t_start)
            } else {
                subdivided_hit(
                    &column,
                    o,
                    d,
                    t,
                    t_out,
                    (cx, cy),
                    t > t_start,
                    settings.subdivision,
                )
            };
            if let Some(hit) = &mut hit {
                hit.column = [cx, cy];
                return Some(*hit);
            }
        }
        if t_exit >= t_end {
            return None;
        }
        t = t_exit;
        let (old_x, old_y) = (cx, cy);
        if tx <= ty {
            cx += step_x;
        }
        if ty <= tx {
            cy += step_y;
        }
        // Crossed into another parent tile: go back up to skip more.
        if lvl < top
            && (old_x >> LOG_RATIO != cx >> LOG_RATIO || old_y >> LOG_RATIO != cy >> LOG_RATIO)
        {
            lvl += 1;
            cx >>= LOG_RATIO;
            cy >>= LOG_RATIO;
        }
    }
}

/// The texel containing `p + eps * d`: a point exactly on a texel line
/// belongs to the side the ray is moving into.
#[inline]
fn texel_after(p: DVec3, d: DVec3) -> (i64, i64) {
    (ray::texel_after(p.x, d.x), ray::texel_after(p.y, d.y))
}

/// First point of the segment `[t0, t1]` inside one of the column's solid
/// intervals, classified by how the ray got there. `entry` says `t0` is where
/// the ray entered the column (so being solid there means a wall).
#[inline]
fn column_hit(c: &Column, o: DVec3, d: DVec3, t0: f64, t1: f64, entry: bool) -> Option<RayHit> {
    let slab = c.dual.then_some((c.mid, c.high));
    let (t, is_slab) = ray::column_entry(c.low, slab, o.z, d.z, t0, t1)?;
    let class = if entry && t <= t0 {
        HitClass::Wall
    } else if !is_slab {
        HitClass::Floor
    } else if d.z < 0.0 {
        HitClass::SlabTop
    } else {
        HitClass::CaveCeiling
    };
    Some(RayHit {
        distance: t,
        class,
        terrain: if is_slab { c.upper_type } else { c.lower_type },
        // Filled in by the traversal, which knows the column's coordinates.
        column: [0, 0],
    })
}

/// [`column_hit`] over the segment cut at every `1/sub` texel line: the
/// convergence test's "half step". Only the first piece starts at the
/// column's entry.
#[allow(clippy::too_many_arguments)] // the ray and one column's segment
fn subdivided_hit(
    c: &Column,
    o: DVec3,
    d: DVec3,
    t0: f64,
    t1: f64,
    (cx, cy): (i64, i64),
    mut entry: bool,
    sub: u32,
) -> Option<RayHit> {
    let sub = i64::from(sub.next_power_of_two().min(64));
    let size = 1.0 / sub as f64;
    let p = o + d * t0;
    let inside = |v: f64, dv: f64, texel: i64| {
        let f = (v * sub as f64).floor();
        let s = if f == v * sub as f64 && dv < 0.0 {
            f as i64 - 1
        } else {
            f as i64
        };
        s.clamp(texel * sub, texel * sub + sub - 1)
    };
    let (mut sx, mut sy) = (inside(p.x, d.x, cx), inside(p.y, d.y, cy));
    let mut t = t0;
    loop {
        let tx = ray::boundary_t(o.x, d.x, sx, size);
        let ty = ray::boundary_t(o.y, d.y, sy, size);
        let t_exit = tx.min(ty);
        if let Some(hit) = column_hit(c, o, d, t, t_exit.min(t1), entry) {
            return Some(hit);
        }
        if t_exit >= t1 {
            return None;
        }
        entry = false;
        t = t_exit;
        if tx <= ty {
            sx += if d.x > 0.0 { 1 } else { -1 };
        }
        if ty <= tx {
            sy += if d.y > 0.0 { 1 } else { -1 };
        }
    }
}
