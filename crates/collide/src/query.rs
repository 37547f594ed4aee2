//! Queries against the terrain collider: ray cast, box contact, box cast.
//!
//! Coordinates are unwrapped world units (texels in x and y, altitude in z);
//! the map is a torus, so a query anywhere sees the map repeated. Ray casts
//! walk the columns in f64 (`ray.rs`); box queries run against the
//! contact surfaces ([`crate::surface`]) built over the box's footprint, in
//! a frame centred near the box so f32 stays exact however far the map
//! extends.

use crate::ray::Face;
use crate::terrain::TerrainCollider;
use parry3d::math::{Pose, Rotation, Vector};
use parry3d::query::{self, ShapeCastOptions};
use parry3d::shape::Cuboid;

/// Where a ray first meets the terrain collider.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// Distance along the unit ray from its origin.
    pub distance: f64,
    /// The hit point (unwrapped world coordinates).
    pub point: [f64; 3],
    /// The unit normal of the face hit: up on a floor or slab top, down
    /// under a slab, horizontal on a column's side (towards the ray).
    pub normal: [f32; 3],
    /// The chunk (row-major index) of the column hit.
    pub chunk: usize,
    /// The texel column hit (unwrapped: wrap it with the map's size).
    pub column: [i64; 2],
    /// Which face of the column.
    pub face: Face,
    /// Terrain type (0..7) of the interval hit.
    pub terrain: u8,
}

/// The closest contact between a box and the terrain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxContact {
    /// Signed distance: negative when the box penetrates the terrain.
    pub distance: f32,
    /// Contact point on the terrain (unwrapped world coordinates).
    pub point: [f64; 3],
    /// Unit normal pointing from the terrain towards the box.
    pub normal: [f32; 3],
}

/// Where a moving box first touches the terrain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxCastHit {
    /// Distance travelled along the unit direction before touching.
    pub distance: f64,
    /// The touching point on the terrain (unwrapped world coordinates).
    pub point: [f64; 3],
    /// Unit normal of the terrain there, towards the box.
    pub normal: [f32; 3],
}

/// An oriented box: centre (world), half extents and a unit quaternion
/// `[x, y, z, w]` for its rotation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxShape {
    /// Centre in unwrapped world coordinates.
    pub centre: [f64; 3],
    /// Half extents along the box's own axes.
    pub half_extents: [f32; 3],
    /// Rotation as a unit quaternion `[x, y, z, w]`.
    pub rotation: [f32; 4],
}

impl BoxShape {
    /// An axis-aligned box.
    pub fn axis_aligned(centre: [f64; 3], half_extents: [f32; 3]) -> Self {
        BoxShape {
            centre,
            half_extents,
            rotation: [0.0, 0.0, 0.0, 1.0],
        }
    }

    /// Finite centre, positive finite half extents, a finite non-zero
    /// rotation.
    fn is_valid(&self) -> bool {
        self.centre.iter().all(|v| v.is_finite() && v.abs() <= FAR)
            && self.half_extents.iter().all(|v| v.is_finite() && *v > 0.0)
            && self.rotation.iter().all(|v| v.is_finite())
            && self.rotation.iter().any(|v| *v != 0.0)
    }

    fn radius(&self) -> f64 {
        let [a, b, c] = self.half_extents;
        f64::from((a * a + b * b + c * c).sqrt())
    }
}

/// Coordinates beyond this (in x or y) are refused: the traversal counts
/// texels in `i64` and a map repeats long before.
const FAR: f64 = (1u64 << 40) as f64;
/// Longest ray searched: a ray along a rational direction can run along
/// the torus for ever without meeting anything.
const T_LIMIT: f64 = 1e7;
/// Widest box query footprint per height-field piece, samples.
const PIECE: i64 = 128;

impl TerrainCollider {
    /// The first point of the terrain along `origin + t dir`, `t` in
    /// `[0, t_max]` (`t_max` is capped at 10^7). `dir` need not be
    /// normalised (it is). A zero or non-finite ray, or an origin farther
    /// than 2^40 from the map's origin, hits nothing. An origin inside solid
    /// terrain hits at distance 0. Exact to the texel model: the CPU
    /// reference's hit, column for column.
    pub fn cast_ray(&self, origin: [f64; 3], dir: [f64; 3], t_max: f64) -> Option<RayHit> {
        let len = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        if !(len > 0.0 && len.is_finite() && t_max >= 0.0)
            || origin.iter().any(|v| !v.is_finite())
            || origin[0].abs() > FAR
            || origin[1].abs() > FAR
        {
            return None;
        }
        let d = [dir[0] / len, dir[1] / len, dir[2] / len];
        let hit = self.columns.cast(origin, d, t_max.min(T_LIMIT))?;
        let t = hit.t;
        let normal = match hit.face {
            Face::Floor | Face::SlabTop => [0.0, 0.0, 1.0],
            Face::Ceiling => [0.0, 0.0, -1.0],
            Face::Wall { across_x: true } => [-(d[0].signum() as f32), 0.0, 0.0],
            Face::Wall { across_x: false } => [0.0, -(d[1].signum() as f32), 0.0],
        };
        let (nx, ny) = (
            i64::from(self.layout.chunks_x),
            i64::from(self.layout.chunks_y),
        );
        let chunk = self.layout.index(
            hit.column[0]
                .div_euclid(i64::from(self.layout.size_x))
                .rem_euclid(nx) as u32,
            hit.column[1]
                .div_euclid(i64::from(self.layout.size_y))
                .rem_euclid(ny) as u32,
        );
        Some(RayHit {
            distance: t,
            point: [
                origin[0] + d[0] * t,
                origin[1] + d[1] * t,
                origin[2] + d[2] * t,
            ],
            normal,
            chunk,
            column: hit.column,
            face: hit.face,
            terrain: hit.terrain,
        })
    }

    /// Call `f` with the contact surfaces over every piece of the samples
    /// whose cells meet `[x_lo, x_hi] x [y_lo, y_hi]` (world), and the pose
    /// of the pieces in the frame centred at `frame`.
    fn for_each_piece(
        &self,
        [x_lo, x_hi, y_lo, y_hi]: [f64; 4],
        frame: [f64; 3],
        mut f: impl FnMut(&crate::surface::Surfaces, Pose),
    ) {
        // Samples stand at texel centres: cells between samples s and s + 1
        // span [s + 0.5, s + 1.5].
        let (sx0, sx1) = ((x_lo - 1.5).floor() as i64, (x_hi + 0.5).ceil() as i64);
        let (sy0, sy1) = ((y_lo - 1.5).floor() as i64, (y_hi + 0.5).ceil() as i64);
        let mut y = sy0;
        while y < sy1 {
            let ny = (sy1 - y).min(PIECE);
            let mut x = sx0;
            while x < sx1 {
                let nx = (sx1 - x).min(PIECE);
                let s = self.columns.surfaces(x, y, nx as u32, ny as u32, 1);
                let pose = s.pose(frame);
                f(&s, pose);
                x += nx;
            }
            y += ny;
        }
    }

    /// The box's pose in the frame centred at `frame`.
    fn box_pose(b: &BoxShape, frame: [f64; 3]) -> Pose {
        let [x, y, z, w] = b.rotation;
        Pose::from_parts(
            Vector::new(
                (b.centre[0] - frame[0]) as f32,
                (b.centre[1] - frame[1]) as f32,
                (b.centre[2] - frame[2]) as f32,
            ),
            Rotation::from_xyzw(x, y, z, w).normalize(),
        )
    }

    /// A frame near `p` (whole texels, so samples stay on integers + 0.5).
    fn frame_near(p: [f64; 3]) -> [f64; 3] {
        [p[0].floor(), p[1].floor(), 0.0]
    }

    fn world(frame: [f64; 3], p: Vector) -> [f64; 3] {
        [
            f64::from(p.x) + frame[0],
            f64::from(p.y) + frame[1],
            f64::from(p.z) + frame[2],
        ]
    }

    /// The deepest contact (or the closest within `margin`) between the box
    /// and the terrain's contact surfaces; `None` when they are farther
    /// apart than `margin`, or the box is not finite.
    ///
    /// ```
    /// use strata_collide::{BoxShape, TerrainCollider};
    /// let level = strata_level::Level::flat(128, 128, 40, 1).unwrap();
    /// let collider = TerrainCollider::new(&level);
    /// // A 4x2x1.5 box sunk 0.25 into the ground at 40.
    /// let b = BoxShape::axis_aligned([60.5, 60.5, 40.5], [2.0, 1.0, 0.75]);
    /// let c = collider.contact_box(&b, 0.0).unwrap();
    /// assert!((c.distance + 0.25).abs() < 1e-3 && c.normal[2] > 0.99);
    /// ```
    pub fn contact_box(&self, b: &BoxShape, margin: f32) -> Option<BoxContact> {
        if !(b.is_valid() && margin.is_finite() && margin >= 0.0) {
            return None;
        }
        let r = b.radius() + f64::from(margin);
        let cuboid = Cuboid::new(Vector::from(b.half_extents));
        let frame = Self::frame_near(b.centre);
        let pose = Self::box_pose(b, frame);
        let mut best: Option<BoxContact> = None;
        let area = [
            b.centre[0] - r,
            b.centre[0] + r,
            b.centre[1] - r,
            b.centre[1] + r,
        ];
        self.for_each_piece(area, frame, |s, hf_pose| {
            for field in s.fields() {
                let Ok(Some(c)) = query::contact(&hf_pose, field, &pose, &cuboid, margin) else {
                    continue;
                };
                if best.is_none_or(|b| c.dist < b.distance) {
                    best = Some(BoxContact {
                        distance: c.dist,
                        point: Self::world(frame, c.point1),
                        normal: c.normal1.to_array(),
                    });
                }
            }
        });
        best
    }

    /// Move the box along `dir` (normalised here) up to `max_distance`:
    /// where it first touches the terrain's contact surfaces.
    ///
    /// ```
    /// use strata_collide::{BoxShape, TerrainCollider};
    /// let level = strata_level::Level::flat(128, 128, 40, 1).unwrap();
    /// let collider = TerrainCollider::new(&level);
    /// let b = BoxShape::axis_aligned([60.5, 60.5, 50.0], [2.0, 1.0, 0.75]);
    /// let hit = collider.cast_box(&b, [0.0, 0.0, -1.0], 100.0).unwrap();
    /// assert!((hit.distance - 9.25).abs() < 1e-3);
    /// ```
    pub fn cast_box(&self, b: &BoxShape, dir: [f64; 3], max_distance: f64) -> Option<BoxCastHit> {
        let len = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        if !(len > 0.0
            && len.is_finite()
            && max_distance.is_finite()
            && max_distance >= 0.0
            && b.is_valid())
        {
            return None;
        }
        let max_distance = max_distance.min(T_LIMIT);
        let d = [dir[0] / len, dir[1] / len, dir[2] / len];
        let end = [
            b.centre[0] + d[0] * max_distance,
            b.centre[1] + d[1] * max_distance,
        ];
        let r = b.radius();
        let cuboid = Cuboid::new(Vector::from(b.half_extents));
        let frame = Self::frame_near(b.centre);
        let pose = Self::box_pose(b, frame);
        let vel = Vector::new(d[0] as f32, d[1] as f32, d[2] as f32);
        let options = ShapeCastOptions::with_max_time_of_impact(max_distance as f32);
        let mut best: Option<BoxCastHit> = None;
        let area = [
            b.centre[0].min(end[0]) - r,
            b.centre[0].max(end[0]) + r,
            b.centre[1].min(end[1]) - r,
            b.centre[1].max(end[1]) + r,
        ];
        self.for_each_piece(area, frame, |s, hf_pose| {
            for field in s.fields() {
                let hit =
                    query::cast_shapes(&hf_pose, Vector::ZERO, field, &pose, vel, &cuboid, options);
                let Ok(Some(h)) = hit else { continue };
                let t = f64::from(h.time_of_impact);
                if best.is_none_or(|b| t < b.distance) {
                    best = Some(BoxCastHit {
                        distance: t,
                        point: Self::world(frame, h.witness1),
                        normal: h.normal1.to_array(),
                    });
                }
            }
        });
        best
    }

    /// The contact surfaces of chunk `index` (its samples `c * 128 ..=
    /// c * 128 + 128` in x and y, the last row and column being the next
    /// chunk's first), centred in the chunk's own cell; `None` for an index
    /// past the last chunk.
    pub fn chunk_surfaces(&self, index: usize) -> Option<crate::surface::Surfaces> {
        self.chunk_surfaces_every(index, 1)
    }

    /// [`TerrainCollider::chunk_surfaces`] through every `step`-th sample
    /// only: 1/step² the triangles (cheaper contacts for a physics world)
    /// for a surface that is exact at those samples only. `step` is rounded
    /// down to a power of two and clamped to 1..=the chunk's side.
    pub fn chunk_surfaces_every(
        &self,
        index: usize,
        step: u32,
    ) -> Option<crate::surface::Surfaces> {
        if index >= self.layout.count() {
            return None;
        }
        let (cx, cy) = self.layout.coords(index);
        let (sx, sy) = (self.layout.size_x, self.layout.size_y);
        let step = if step <= 1 {
            1
        } else {
            (1u32 << step.ilog2()).min(sx).min(sy)
        };
        Some(
            self.columns
                .surfaces(i64::from(cx * sx), i64::from(cy * sy), sx, sy, step),
        )
    }

    /// Where chunk `index`'s surfaces ([`TerrainCollider::chunk_surfaces`])
    /// sit, in the frame whose origin is the world point `origin`.
    pub fn chunk_pose(&self, index: usize, origin: [f64; 3]) -> Pose {
        let (cx, cy) = self.layout.coords(index);
        let (sx, sy) = (f64::from(self.layout.size_x), f64::from(self.layout.size_y));
        crate::surface::Surfaces::pose_of(
            [
                f64::from(cx) * sx + 0.5 + sx * 0.5,
                f64::from(cy) * sy + 0.5 + sy * 0.5,
                0.0,
            ],
            origin,
        )
    }
}
