//! Which chunks a camera wants read next ([`PagedTerrain`]'s side of the
//! streaming): the pages the last frame asked for, then the view's
//! footprint (by distance, or per level of detail), most wanted first.

use super::{PAGE, PagedTerrain};
use strata_camera::Camera;

impl PagedTerrain {
    /// The chunks to read, most wanted first: what the last frame asked for
    /// (nearest the eye first), then the view's footprint, none resident,
    /// none given up, at most what the atlas can take.
    pub(super) fn wanted(&self, camera: &Camera) -> Vec<u32> {
        let eye = camera.position.truncate();
        let dist = |c: u32| self.ids.distance(eye, c);
        let usable = |c: &u32| {
            self.residency.slot_of(*c).is_none()
                && self
                    .failures
                    .get(c)
                    .is_none_or(|&n| n < self.options.read_tries)
        };
        let mut asked: Vec<u32> = self.requested.iter().copied().filter(usable).collect();
        asked.sort_by(|a, b| dist(*a).total_cmp(&dist(*b)));
        // Then what a CPU reader asked for, in its order.
        asked.extend(self.cpu_requests.iter().copied().filter(usable));
        let mut footprint: Vec<u32> = self.footprint(camera).into_iter().filter(usable).collect();
        footprint.sort_by(|a, b| dist(*a).total_cmp(&dist(*b)));
        let cap = (self.plan.slots as usize / 2).max(1);
        let mut seen = std::collections::HashSet::new();
        asked
            .into_iter()
            .chain(footprint)
            .filter(|c| seen.insert(*c))
            .take(cap)
            .collect()
    }

    /// The chunks within the far plane's reach around the eye, in any
    /// direction (a turn of the camera then finds its pages resident), and
    /// under the frustum's far corners, wrapped.
    fn footprint(&self, camera: &Camera) -> Vec<u32> {
        if self.ids.levels() > 0 && self.options.lod_pixels > 0.0 {
            return self.lod_footprint(camera);
        }
        let eye = camera.position;
        let (w, h) = (camera.width as f32, camera.height as f32);
        let scale = camera.far / camera.focal_px;
        // Around the eye, no farther than half the atlas covers as a disc:
        // a far plane of thousands of texels would otherwise keep the whole
        // atlas churning (the frustum's far corners and the frames' own
        // requests still reach past it).
        let disc = PAGE as f32 * (self.plan.slots as f32 / (2.0 * std::f32::consts::PI)).sqrt();
        let reach = glam::Vec2::splat(camera.far.min(disc));
        let mut lo = eye.truncate() - reach;
        let mut hi = eye.truncate() + reach;
        for (px, py) in [(0.0, 0.0), (w, 0.0), (0.0, h), (w, h)] {
            let p = eye + camera.image_direction(px, py) * scale;
            lo = lo.min(p.truncate());
            hi = hi.max(p.truncate());
        }
        let page = PAGE as f32;
        let (x0, x1) = ((lo.x / page).floor() as i64, (hi.x / page).floor() as i64);
        let (y0, y1) = ((lo.y / page).floor() as i64, (hi.y / page).floor() as i64);
        let (gx, gy) = (i64::from(self.grid.0), i64::from(self.grid.1));
        // No more than the grid: a far plane past the world sees it whole.
        let (x1, y1) = (x1.min(x0 + gx - 1), y1.min(y0 + gy - 1));
        let mut out = Vec::new();
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                out.push((cy.rem_euclid(gy) * gx + cx.rem_euclid(gx)) as u32);
            }
        }
        out
    }

    /// With levels of detail: for each level the march reads (multiples of
    /// its level ratio, `step`), that level's pages within the distance
    /// where camera rays still take it (their footprint below the next
    /// level's; the coarsest out to the far plane), in any direction. A
    /// horizon view then prefetches a few rings of pages, not every chunk
    /// out to the far plane.
    fn lod_footprint(&self, camera: &Camera) -> Vec<u32> {
        let eye = camera.position.truncate();
        let levels = self.ids.levels();
        let step = self.step.max(1);
        let mut seen = std::collections::HashSet::new();
        let mut out = Vec::new();
        for k in (0..=levels).step_by(step as usize) {
            let next = k + step;
            let reach = if next > levels {
                camera.far
            } else {
                ((1u64 << next) as f32 * camera.focal_px * self.options.lod_pixels).min(camera.far)
            };
            let side = (PAGE << k) as f32;
            let (gx, gy) = self.ids.grid(k);
            let (gx, gy) = (i64::from(gx), i64::from(gy));
            let r = ((reach / side).ceil() as i64 + 1).min(gx.max(gy));
            let (cx0, cy0) = ((eye.x / side).floor() as i64, (eye.y / side).floor() as i64);
            // A page counts when its centre is within reach plus half its diagonal.
            let limit = (reach + side * std::f32::consts::FRAC_1_SQRT_2).powi(2);
            for dy in -r..=r {
                for dx in -r..=r {
                    let (cx, cy) = ((cx0 + dx).rem_euclid(gx), (cy0 + dy).rem_euclid(gy));
                    let id = self.ids.id(k, cx as u32, cy as u32);
                    if self.ids.distance(eye, id) <= limit && seen.insert(id) {
                        out.push(id);
                    }
                }
            }
        }
        out
    }
}
