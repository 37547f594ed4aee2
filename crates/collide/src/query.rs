//! Queries against the terrain colliders: ray cast, box contact, box cast.
//!
//! Coordinates are unwrapped world units (texels in x and y, altitude in z).
//! The map is a torus, so a query sees the chunk copies around it: cell
//! `(gx, gy)` of the unwrapped chunk grid is chunk `(gx mod nx, gy mod ny)`
//! translated by `(gx * 128, gy * 128)`. Each query runs in the visited
//! cell's local frame, so f32 stays exact however far the map extends.

use crate::terrain::TerrainCollider;
use parry3d::math::{Pose, Rotation, Vector};
use parry3d::query::{self, Ray, RayCast, ShapeCastOptions};
use parry3d::shape::Cuboid;

/// Where a ray first meets the terrain collider.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayHit {
    /// Distance along the unit ray from its origin.
    pub distance: f64,
    /// The hit point (unwrapped world coordinates).
    pub point: [f64; 3],
    /// The hit triangle's unit normal, on the side the ray came from.
    pub normal: [f32; 3],
    /// The chunk (row-major index) whose triangle was hit.
    pub chunk: usize,
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

    fn radius(&self) -> f64 {
        let [a, b, c] = self.half_extents;
        f64::from((a * a + b * b + c * c).sqrt())
    }
}

impl TerrainCollider {
    fn cell_chunk(&self, gx: i64, gy: i64) -> usize {
        let (nx, ny) = (
            i64::from(self.layout.chunks_x),
            i64::from(self.layout.chunks_y),
        );
        self.layout
            .index(gx.rem_euclid(nx) as u32, gy.rem_euclid(ny) as u32)
    }

    fn cell_origin(&self, gx: i64, gy: i64) -> [f64; 2] {
        [
            (gx * i64::from(self.layout.size_x)) as f64,
            (gy * i64::from(self.layout.size_y)) as f64,
        ]
    }

    /// A point of cell `(gx, gy)`'s chunk mesh (chunk-local x, y) in world
    /// coordinates.
    fn world_point(&self, p: Vector, gx: i64, gy: i64) -> [f64; 3] {
        let cell = self.cell_origin(gx, gy);
        [
            f64::from(p.x) + cell[0],
            f64::from(p.y) + cell[1],
            f64::from(p.z),
        ]
    }

    /// Cells whose chunk square `[g·size + 0.5, (g+1)·size + 0.5]` meets
    /// `[lo, hi]` along one axis.
    fn cells(lo: f64, hi: f64, size: u32) -> std::ops::RangeInclusive<i64> {
        let s = f64::from(size);
        ((lo - 0.5) / s).floor() as i64..=((hi - 0.5) / s).floor() as i64
    }

    /// The first point of the terrain along `origin + t dir`, `t` in
    /// `[0, t_max]`. `dir` need not be normalised (it is); a zero or
    /// non-finite ray hits nothing.
    pub fn cast_ray(&self, origin: [f64; 3], dir: [f64; 3], t_max: f64) -> Option<RayHit> {
        let len = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        if !(len > 0.0 && len.is_finite() && t_max.is_finite())
            || origin.iter().any(|v| !v.is_finite())
        {
            return None;
        }
        let d = [dir[0] / len, dir[1] / len, dir[2] / len];
        let (sx, sy) = (f64::from(self.layout.size_x), f64::from(self.layout.size_y));
        // Walk the chunk cells the ray crosses in order (a 2D DDA in the
        // frame where chunk squares start at 0.5). Every triangle of a chunk
        // lies inside its square, so the first cell with a hit holds the
        // nearest hit.
        let (ox, oy) = (origin[0] - 0.5, origin[1] - 0.5);
        let (mut gx, mut gy) = ((ox / sx).floor() as i64, (oy / sy).floor() as i64);
        let axis = |o: f64, d: f64, g: i64, s: f64| -> (i64, f64, f64) {
            if d > 0.0 {
                (1, ((g + 1) as f64 * s - o) / d, s / d)
            } else if d < 0.0 {
                (-1, (g as f64 * s - o) / d, -s / d)
            } else {
                (0, f64::INFINITY, f64::INFINITY)
            }
        };
        let (step_x, mut next_x, delta_x) = axis(ox, d[0], gx, sx);
        let (step_y, mut next_y, delta_y) = axis(oy, d[1], gy, sy);
        let top = f64::from(self.top);
        let mut t_enter = 0.0f64;
        while t_enter <= t_max {
            let t_exit = next_x.min(next_y).min(t_max);
            let chunk = self.cell_chunk(gx, gy);
            let c = &self.chunks[chunk];
            let (z0, z1) = (origin[2] + d[2] * t_enter, origin[2] + d[2] * t_exit);
            let below = z0.min(z1) <= f64::from(c.z_range.1);
            let above = z0.max(z1) >= f64::from(c.z_range.0);
            if let (Some(mesh), true, true) = (&c.mesh, below, above) {
                // Start a little before the cell entry (triangles on the
                // square's edge), in the cell's frame.
                let t0 = (t_enter - 1.0).max(0.0);
                let cell = self.cell_origin(gx, gy);
                let local = Vector::new(
                    (origin[0] + d[0] * t0 - cell[0]) as f32,
                    (origin[1] + d[1] * t0 - cell[1]) as f32,
                    (origin[2] + d[2] * t0) as f32,
                );
                let ray = Ray::new(local, Vector::new(d[0] as f32, d[1] as f32, d[2] as f32));
                if let Some(hit) =
                    mesh.cast_local_ray_and_get_normal(&ray, (t_max - t0) as f32, false)
                {
                    let t = t0 + f64::from(hit.time_of_impact);
                    let mut n = hit.normal;
                    if n.dot(ray.dir) > 0.0 {
                        n = -n;
                    }
                    return Some(RayHit {
                        distance: t,
                        point: [
                            origin[0] + d[0] * t,
                            origin[1] + d[1] * t,
                            origin[2] + d[2] * t,
                        ],
                        normal: [n.x, n.y, n.z],
                        chunk,
                    });
                }
            }
            // Rising above every chunk: nothing more to hit.
            if d[2] >= 0.0 && z1 > top {
                return None;
            }
            if next_x < next_y {
                t_enter = next_x;
                next_x += delta_x;
                gx += step_x;
            } else {
                t_enter = next_y;
                next_y += delta_y;
                gy += step_y;
            }
            if !t_enter.is_finite() {
                return None;
            }
        }
        None
    }

    /// The box's pose in cell `(gx, gy)`'s frame.
    fn local_pose(&self, b: &BoxShape, gx: i64, gy: i64) -> Pose {
        let cell = self.cell_origin(gx, gy);
        let [x, y, z, w] = b.rotation;
        Pose::from_parts(
            Vector::new(
                (b.centre[0] - cell[0]) as f32,
                (b.centre[1] - cell[1]) as f32,
                b.centre[2] as f32,
            ),
            Rotation::from_xyzw(x, y, z, w).normalize(),
        )
    }

    /// The deepest contact (or the closest within `margin`) between the box
    /// and the terrain; `None` when they are farther apart than `margin`.
    ///
    /// ```
    /// use strata_collide::{BoxShape, TerrainCollider};
    /// let level = strata_level::Level::flat(128, 128, 40, 1).unwrap();
    /// let collider = TerrainCollider::fit(&level, 1.0);
    /// // A 4x2x1.5 box sunk 0.25 into the ground at 40.
    /// let b = BoxShape::axis_aligned([60.5, 60.5, 40.5], [2.0, 1.0, 0.75]);
    /// let c = collider.contact_box(&b, 0.0).unwrap();
    /// assert!((c.distance + 0.25).abs() < 1e-3 && c.normal[2] > 0.99);
    /// ```
    pub fn contact_box(&self, b: &BoxShape, margin: f32) -> Option<BoxContact> {
        let r = b.radius() + f64::from(margin);
        let cuboid = Cuboid::new(Vector::from(b.half_extents));
        let mut best: Option<BoxContact> = None;
        for gy in Self::cells(b.centre[1] - r, b.centre[1] + r, self.layout.size_y) {
            for gx in Self::cells(b.centre[0] - r, b.centre[0] + r, self.layout.size_x) {
                let Some(mesh) = &self.chunks[self.cell_chunk(gx, gy)].mesh else {
                    continue;
                };
                let pose = self.local_pose(b, gx, gy);
                let Ok(Some(c)) = query::contact(&Pose::IDENTITY, &**mesh, &pose, &cuboid, margin)
                else {
                    continue;
                };
                if best.is_none_or(|b| c.dist < b.distance) {
                    best = Some(BoxContact {
                        distance: c.dist,
                        point: self.world_point(c.point1, gx, gy),
                        normal: c.normal1.to_array(),
                    });
                }
            }
        }
        best
    }

    /// Move the box along `dir` (normalised here) up to `max_distance`:
    /// where it first touches the terrain.
    ///
    /// ```
    /// use strata_collide::{BoxShape, TerrainCollider};
    /// let level = strata_level::Level::flat(128, 128, 40, 1).unwrap();
    /// let collider = TerrainCollider::fit(&level, 1.0);
    /// let b = BoxShape::axis_aligned([60.5, 60.5, 50.0], [2.0, 1.0, 0.75]);
    /// let hit = collider.cast_box(&b, [0.0, 0.0, -1.0], 100.0).unwrap();
    /// assert!((hit.distance - 9.25).abs() < 1e-3);
    /// ```
    pub fn cast_box(&self, b: &BoxShape, dir: [f64; 3], max_distance: f64) -> Option<BoxCastHit> {
        let len = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        if !(len > 0.0 && len.is_finite() && max_distance.is_finite()) {
            return None;
        }
        let d = [dir[0] / len, dir[1] / len, dir[2] / len];
        let end = [
            b.centre[0] + d[0] * max_distance,
            b.centre[1] + d[1] * max_distance,
        ];
        let r = b.radius();
        let cuboid = Cuboid::new(Vector::from(b.half_extents));
        let vel = Vector::new(d[0] as f32, d[1] as f32, d[2] as f32);
        let options = ShapeCastOptions::with_max_time_of_impact(max_distance as f32);
        let mut best: Option<BoxCastHit> = None;
        let xs = Self::cells(
            b.centre[0].min(end[0]) - r,
            b.centre[0].max(end[0]) + r,
            self.layout.size_x,
        );
        let ys = Self::cells(
            b.centre[1].min(end[1]) - r,
            b.centre[1].max(end[1]) + r,
            self.layout.size_y,
        );
        for gy in ys {
            for gx in xs.clone() {
                let Some(mesh) = &self.chunks[self.cell_chunk(gx, gy)].mesh else {
                    continue;
                };
                let pose = self.local_pose(b, gx, gy);
                let hit = query::cast_shapes(
                    &Pose::IDENTITY,
                    Vector::ZERO,
                    &**mesh,
                    &pose,
                    vel,
                    &cuboid,
                    options,
                );
                let Ok(Some(h)) = hit else { continue };
                let t = f64::from(h.time_of_impact);
                if best.is_none_or(|b| t < b.distance) {
                    best = Some(BoxCastHit {
                        distance: t,
                        point: self.world_point(h.witness1, gx, gy),
                        normal: h.normal1.to_array(),
                    });
                }
            }
        }
        best
    }
}
