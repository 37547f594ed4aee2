//! Digging with the mouse: pick the terrain point under the cursor with the
//! CPU reference's exact ray cast (so what is picked does not depend on the
//! method on screen, nor on its holes), cut the paper's crater there, and
//! keep exact snapshots for undo.

use glam::{DVec3, Vec3};
use strata_camera::Camera;
use strata_level::edit::{Snapshot, crater_rect, try_crater};
use strata_level::{DirtyRect, EditSite, Level};
use strata_reference::{ReferenceSettings, Tracer};

/// Undo depth; each entry holds only the crater's own texels.
pub const UNDO_DEPTH: usize = 64;

/// The terrain point a pixel shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pick {
    pub point: Vec3,
    pub distance: f32,
}

/// The world point seen through image point (`px`, `py`) (pixels from the
/// top-left of `camera`'s image), or `None` for sky.
pub fn pick(level: &Level, camera: &Camera, px: f32, py: f32) -> Option<Pick> {
    let dir = camera.image_direction(px, py).as_dvec3();
    // The far plane is along the view axis, as in the reference images.
    let t_max = f64::from(camera.far) * dir.length() / f64::from(camera.focal_px);
    let dir = dir.normalize();
    let origin: DVec3 = camera.position.as_dvec3();
    // A few hundred texel columns at most: cheaper than building the pyramid.
    let hit =
        Tracer::unaccelerated(level).trace(origin, dir, t_max, &ReferenceSettings::default())?;
    Some(Pick {
        point: (origin + dir * hit.distance).as_vec3(),
        distance: hit.distance as f32,
    })
}

/// Craters of one size, with undo.
pub struct Digger {
    pub radius: u32,
    pub depth: f32,
    undo: Vec<Snapshot>,
}

impl Digger {
    /// Craters the size of the level's own edit fixture.
    pub fn new(site: &EditSite) -> Self {
        Digger {
            radius: site.radius.max(1),
            depth: site.depth,
            undo: Vec::new(),
        }
    }

    /// Cut a crater centred under `point`; returns the dirty rectangles
    /// (empty when nothing changed, and then there is nothing to undo). A
    /// point anywhere wraps onto the map; a point that is not finite (NaN,
    /// infinite), a radius of 0 or a depth that is not finite dig nothing.
    pub fn dig(&mut self, level: &mut Level, point: Vec3) -> Vec<DirtyRect> {
        if !point.is_finite() {
            return Vec::new();
        }
        let site = EditSite {
            centre_x: point.x.floor() as i64,
            centre_y: point.y.floor() as i64,
            radius: self.radius,
            depth: self.depth,
            ..EditSite::fostral()
        };
        let snapshot = Snapshot::take(level, crater_rect(&site));
        let dirty = try_crater(level, &site).unwrap_or_default();
        if !dirty.is_empty() {
            if self.undo.len() == UNDO_DEPTH {
                self.undo.remove(0);
            }
            self.undo.push(snapshot);
        }
        dirty
    }

    /// Undo the last dig; `None` when there is none.
    pub fn undo(&mut self, level: &mut Level) -> Option<Vec<DirtyRect>> {
        self.undo.pop().map(|s| s.restore(level))
    }

    pub fn can_undo(&self) -> usize {
        self.undo.len()
    }

    /// Bytes the undo snapshots hold.
    pub fn undo_bytes(&self) -> usize {
        self.undo.iter().map(Snapshot::bytes).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn picks_the_ground_under_the_image_centre_and_sky_above_the_horizon() {
        let level = Level::flat(256, 256, 100, 2).unwrap();
        let camera = Camera::new(Vec3::new(50.0, 60.0, 150.0), 0.0, -45.0, 320, 200).unwrap();
        let hit = pick(&level, &camera, 160.0, 100.0).unwrap();
        // 50 units above the ground looking 45° down: 50 ahead along +y.
        assert!((hit.point - Vec3::new(50.0, 110.0, 100.0)).length() < 0.01);
        assert!((hit.distance - 50.0 * 2f32.sqrt()).abs() < 0.01);
        let level_view = Camera::new(Vec3::new(50.0, 60.0, 150.0), 0.0, 0.0, 320, 200).unwrap();
        assert_eq!(pick(&level, &level_view, 160.0, 10.0), None);
    }

    #[test]
    fn a_dig_lowers_the_picked_ground_and_undo_restores_every_byte() {
        let original = Level::flat(256, 256, 100, 2).unwrap();
        let mut level = original.clone();
        let mut digger = Digger::new(&EditSite::fostral());
        // Across the map's corner: the crater wraps.
        let dirty = digger.dig(&mut level, Vec3::new(255.5, 0.5, 100.0));
        assert!(
            dirty.len() >= 4,
            "a corner crater spans four rects: {dirty:?}"
        );
        assert!(level.column(255, 0).low < 100 && level.column(0, 255).low < 100);
        assert_eq!(digger.can_undo(), 1);
        digger.undo(&mut level).unwrap();
        assert!(level == original);
        assert_eq!(digger.undo(&mut level), None);
    }

    #[test]
    fn a_dig_at_no_point_or_of_no_size_digs_nothing() {
        let original = Level::flat(256, 256, 100, 2).unwrap();
        let mut level = original.clone();
        let mut digger = Digger::new(&EditSite::fostral());
        for bad in [
            Vec3::new(f32::NAN, 10.0, 100.0),
            Vec3::new(10.0, f32::INFINITY, 100.0),
            Vec3::new(10.0, 10.0, f32::NAN),
        ] {
            assert!(digger.dig(&mut level, bad).is_empty(), "{bad}");
        }
        digger.depth = f32::NAN;
        assert!(
            digger
                .dig(&mut level, Vec3::new(10.0, 10.0, 100.0))
                .is_empty()
        );
        (digger.depth, digger.radius) = (20.0, 0);
        assert!(
            digger
                .dig(&mut level, Vec3::new(10.0, 10.0, 100.0))
                .is_empty()
        );
        assert!(level == original && digger.can_undo() == 0);
        // Far outside the map (a pick past the seam): wraps onto it.
        digger.radius = 8;
        let far = digger.dig(&mut level, Vec3::new(10.5 + 256.0 * 40.0, -245.5, 100.0));
        assert!(!far.is_empty() && level.column(10, 10).low < 100);
        assert_eq!(digger.can_undo(), 1);
    }
}
