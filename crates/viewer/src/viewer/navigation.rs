//! Where the camera is: the level's views, a copied view line, flying to a
//! point of the map, the camera of the picture.

use super::{Viewer, paged};
use crate::fly::FlyCamera;
use strata_camera::Camera;

impl Viewer {
    pub(super) fn go_to_view(&mut self, index: usize) {
        let Some(view) = self.views.get(index).cloned() else {
            self.say(format!("the level has no view {}", index + 1));
            return;
        };
        let (w, h) = self.render_size();
        let camera = match &self.paged {
            Some(p) => paged::camera_over(&p.world.pages, &view, w, h),
            None => Camera::from_view(&self.level, &view, w, h).map_err(anyhow::Error::from),
        };
        match camera {
            Ok(camera) => {
                let speed = self.fly.speed;
                self.fly = FlyCamera::from_camera(&camera);
                self.fly.speed = speed;
                self.say(format!("view {}", view.name));
            }
            Err(e) => self.say(format!("view {}: {e}", view.name)),
        }
    }

    pub(super) fn copy_view(&mut self, name: &str) {
        let column = match self.column_at(self.fly.position.x, self.fly.position.y) {
            Ok(c) => c,
            Err(e) => return self.say(format!("copy view: {e:#}")),
        };
        let line = self.fly.view_spec(column, name).to_string();
        println!("{line}");
        self.overlay.copy_text(line.clone());
        self.say(format!("copied: {line}"));
    }

    /// Fly to `to` (x, y), keeping the eye's height above the ground.
    pub(super) fn teleport(&mut self, to: glam::Vec2) {
        let columns = self
            .column_at(self.fly.position.x, self.fly.position.y)
            .and_then(|here| {
                let (w, h) = self.world_size();
                let (x, y) = (to.x.rem_euclid(w as f32), to.y.rem_euclid(h as f32));
                Ok((here, x, y, self.column_at(x, y)?))
            });
        let (here, x, y, there) = match columns {
            Ok(c) => c,
            Err(e) => return self.say(format!("cannot fly there: {e:#}")),
        };
        let clearance = (self.fly.position.z - f32::from(here.top())).max(20.0);
        let z = (f32::from(there.top()) + clearance).min(400.0);
        self.fly.position = glam::Vec3::new(x, y, z);
        self.say(format!("flew to {x:.0}, {y:.0}"));
    }

    pub(super) fn camera(&self) -> anyhow::Result<Camera> {
        let (w, h) = self.render_size();
        self.fly.camera(w, h)
    }
}
