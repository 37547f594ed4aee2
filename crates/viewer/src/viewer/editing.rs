//! The world's edits from the viewer's side: digging at a picture point,
//! undo, telling every method and the map of an edit, saving the edited world
//! (and rescuing unsaved edits when the viewer stops on an error), and the
//! `memory` line the soak reads.

use super::Viewer;
use crate::dig::pick;
use crate::physics::Drop;
use std::path::PathBuf;
use std::sync::Arc;
use strata_level::DirtyRect;
use web_time::Instant;

impl Viewer {
    /// Dig where picture point `at` (render pixels) shows terrain.
    pub(super) fn dig_at(&mut self, at: (f32, f32)) -> anyhow::Result<()> {
        if self.paged.is_some() {
            return self.dig_paged(at);
        }
        let camera = self.camera()?;
        let start = Instant::now();
        let Some(hit) = pick(&self.level, &camera, at.0, at.1) else {
            self.say("nothing to dig there: sky".into());
            return Ok(());
        };
        let pick_ms = start.elapsed().as_secs_f64() * 1e3;
        let start = Instant::now();
        let dirty = self.digger.dig(Arc::make_mut(&mut self.level), hit.point);
        self.edited(&dirty)?;
        let p = hit.point;
        self.say(format!(
            "dug r={} at {:.0}, {:.0}, {:.0}: {} rect(s); pick {pick_ms:.2} ms, edit + upload {:.2} ms",
            self.digger.radius,
            p.x,
            p.y,
            p.z,
            dirty.len(),
            start.elapsed().as_secs_f64() * 1e3
        ));
        Ok(())
    }

    /// Drop a body where picture point `at` (render pixels) shows terrain.
    pub(super) fn drop_at(&mut self, at: (f32, f32), what: Drop) -> anyhow::Result<()> {
        let camera = self.camera()?;
        let line = self.physics.drop_at(&camera, at, what);
        self.say(line);
        Ok(())
    }

    /// The physics toy on or off.
    pub(super) fn toggle_physics(&mut self) {
        if self.paged.is_some() && !self.physics.on {
            self.say("the physics toy fits a collider to the whole world in memory; a paged world is not".into());
            return;
        }
        let line = self
            .physics
            .toggle(&self.level, f64::from(self.settings.mesh_quality));
        self.say(line);
    }

    /// Save the edited world to `dir` (Ctrl+S: the default directory).
    /// A refused or failed save is said and the session goes on.
    pub(super) fn save(&mut self, dir: Option<PathBuf>) -> anyhow::Result<()> {
        let dir = dir.unwrap_or_else(|| self.saver.default_dir.clone());
        let said = match &self.paged {
            Some(_) => self.save_paged(&dir),
            None => self.saver.save(&dir, &self.level),
        };
        match said {
            Ok(line) => {
                self.say(line);
                self.unsaved = false;
                Ok(())
            }
            Err(e) => {
                self.say(format!("not saved: {e:#}"));
                Err(e)
            }
        }
    }

    /// The viewer is stopping on an error (a lost device, say): save the
    /// edits, if any, to `<out>/<world>-recovered` so none are lost, and
    /// say where.
    pub fn rescue(&mut self) {
        if let Some(why) = self.gpu.errors.lost() {
            self.say(format!(
                "the GPU device was lost ({why}); what failed after it is a consequence"
            ));
        }
        if !self.unsaved {
            self.say("stopping on an error; no unsaved edits".into());
            return;
        }
        if let Some(p) = &self.paged {
            let line = format!(
                "stopping on an error; {} edited chunk(s) of the paged world are not saved (Ctrl+S saves them in place)",
                p.world.pages.edited_chunks()
            );
            self.say(line);
            return;
        }
        let dir = self
            .out
            .join(format!("{}-recovered", self.saver.world().name));
        match self.saver.save(&dir, &self.level) {
            Ok(line) => self.say(format!("stopping on an error; your edits are kept: {line}")),
            Err(e) => self.say(format!(
                "stopping on an error; the edits could not be saved: {e:#}"
            )),
        }
    }

    /// One `memory` line (script `memory`; `strata soak` reads them):
    /// frames, process RSS, the renderer's GPU bytes (shared + every kept
    /// method) and kept methods' CPU bytes, the undo snapshots' bytes.
    pub(super) fn memory_line(&self) -> String {
        let r = &self.renderer;
        let kept = r.method_names();
        let retained: Vec<_> = kept.iter().filter_map(|m| r.retained_bytes_of(m)).collect();
        let gpu = r.shared_gpu_bytes() + retained.iter().map(|b| b.gpu).sum::<u64>();
        let cpu: u64 = retained.iter().map(|b| b.cpu).sum();
        let rss = self
            .platform
            .rss_bytes()
            .map_or("-".into(), |b| b.to_string());
        let paging = self
            .paged
            .as_ref()
            .map(|p| p.memory_fields(self.render_size()))
            .unwrap_or_default();
        format!(
            "memory frames={} rss_bytes={rss} gpu_bytes={gpu} method_cpu_bytes={cpu} \
             undo_bytes={} undo_depth={} kept={}{paging}",
            self.frames,
            self.digger.undo_bytes(),
            self.digger.can_undo(),
            kept.len()
        )
    }

    pub(super) fn undo(&mut self) -> anyhow::Result<()> {
        if self.paged.is_some() {
            return self.undo_paged();
        }
        match self.digger.undo(Arc::make_mut(&mut self.level)) {
            Some(dirty) => {
                self.edited(&dirty)?;
                self.say(format!("undone ({} left)", self.digger.can_undo()));
            }
            None => self.say("nothing to undo".into()),
        }
        Ok(())
    }

    /// Every kept method and running build learns of an edit.
    pub(super) fn edited(&mut self, dirty: &[DirtyRect]) -> anyhow::Result<()> {
        if dirty.is_empty() {
            return Ok(());
        }
        self.unsaved = true;
        self.saver.record_edit(dirty);
        self.builds.record_edit(dirty);
        self.renderer.apply_edit(&self.level, dirty)?;
        // The physics world's ground changes in the same call: exactly the
        // dirty chunks' colliders are replaced.
        if let Some(line) = self.physics.edited(&self.level, dirty) {
            self.say(line);
        }
        let repainted = self.map.update(&self.level, &self.colors, dirty);
        self.overlay.update_map(&self.map, &repainted);
        Ok(())
    }
}
