//! The scene the window and the headless mode (and its test) share: a flat
//! level with a slab bridging the road, a crater dug at start, the camera,
//! and the vehicle's path across them.

use glam::Vec3;
use strata_camera::Camera;
use strata_level::edit::{EditRect, edit_columns};
use strata_level::{Column, EditSite, Level};

/// The road the vehicle follows: along x at this y.
pub const ROAD_Y: f32 = 128.0;
/// Where the road starts and ends (x).
pub const ROAD_X: (f32, f32) = (60.0, 210.0);
/// The slab across the road: x range, y range; ground 40, cave up to its
/// ceiling at 70, its top at 80.
pub const SLAB_X: (i64, i64) = (100, 132);
const SLAB_Y: (i64, i64) = (96, 160);
/// Ground height outside the slab and crater.
pub const GROUND: u8 = 40;
const CEILING: u8 = 70;
const SLAB_TOP: u8 = 80;
/// The crater dug at start: centre x on the road, radius, depth.
pub const CRATER: (i64, u32, f32) = (180, 18, 20.0);
/// Vehicle half extents (x, y, z): a 10 x 6 x 4 box (a Vangers mechos is
/// about that many texels long).
pub const VEHICLE_HALF: Vec3 = Vec3::new(5.0, 3.0, 2.0);

/// Flat ground with a slab (cave 40..70, top 80) across the road.
pub fn level() -> anyhow::Result<Level> {
    let mut level = Level::flat(256, 256, GROUND, 1)?;
    let slab = EditRect {
        x: SLAB_X.0,
        y: SLAB_Y.0,
        width: (SLAB_X.1 - SLAB_X.0) as u32,
        height: (SLAB_Y.1 - SLAB_Y.0) as u32,
    };
    edit_columns(&mut level, slab, |_, _, c| Column {
        mid: CEILING,
        high: SLAB_TOP,
        dual: true,
        upper_type: 5,
        ..c
    });
    Ok(level)
}

/// The crater dug at start, on the road.
pub fn crater_site() -> EditSite {
    let mut site = EditSite::fostral();
    (site.centre_x, site.centre_y, site.radius, site.depth) =
        (CRATER.0, ROAD_Y as i64, CRATER.1, CRATER.2);
    site
}

/// Above and behind the road, looking down along +y at 60°, so the slab top
/// hides the road under it; the same field of view at any size.
pub fn camera(width: u32, height: u32) -> anyhow::Result<Camera> {
    let mut camera = Camera::new(Vec3::new(135.0, 60.0, 130.0), 0.0, -60.0, width, height)?;
    camera.focal_px = 0.7 * width as f32;
    Ok(camera)
}

/// The road position at `t` in 0..1 (x only; height comes from the collider).
pub fn road_x(t: f32) -> f32 {
    ROAD_X.0 + (ROAD_X.1 - ROAD_X.0) * t.clamp(0.0, 1.0)
}

/// The `t` at road position `x`.
pub fn t_at(x: f32) -> f32 {
    (x - ROAD_X.0) / (ROAD_X.1 - ROAD_X.0)
}

/// Height the terrain collider's ray casts start from: below the slab's
/// ceiling, so a cast down finds the floor under the slab, not its top.
pub const CAST_FROM: f64 = 60.0;
