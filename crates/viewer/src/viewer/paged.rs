//! The viewer over paged terrain (issue 33, [`crate::paged`]): one paged
//! method at a time (switching rebuilds the renderer over the same pages;
//! the others are refused with the reason), digging through the edit layer,
//! saving a store in place, and the paging numbers for the overlay, the
//! page state and the `memory` line.

use super::Viewer;
use crate::paged::{EditedPages, Planes, refusal};
use std::sync::Arc;
use strata_camera::Camera;
use strata_level::{Column, EditSite, ViewSpec};
use strata_render::paged::{PAGED_METHODS, PagingStats};
use strata_render::{Renderer, methods};
use web_time::Instant;

/// Most digs kept for undo over a paged world (each holds the planes of
/// the chunks it touched, 128 KiB apiece).
const UNDO_DEPTH: usize = 32;

pub(super) struct PagedState {
    pub world: crate::paged::PagedWorld,
    /// Per dig, the chunks it touched as they were before.
    undo: Vec<Vec<(u32, Arc<Planes>)>>,
    /// The paging after the last frame.
    stats: Option<PagingStats>,
    /// Frames drawn and bytes uploaded over the session.
    frames: u64,
    uploaded_total: u64,
    /// Over the session: frames with pending pixels, the sum and largest of
    /// their percent of the frame, the most bytes resident.
    pending_frames: u64,
    pending_pct_sum: f64,
    pending_pct_max: f64,
    resident_max: u64,
}

impl PagedState {
    pub fn new(world: crate::paged::PagedWorld) -> Self {
        PagedState {
            world,
            undo: Vec::new(),
            stats: None,
            frames: 0,
            uploaded_total: 0,
            pending_frames: 0,
            pending_pct_sum: 0.0,
            pending_pct_max: 0.0,
            resident_max: 0,
        }
    }

    /// One line over the session: pending pixels, uploads, residency.
    pub fn summary(&self) -> String {
        let s = self.stats.clone().unwrap_or_default();
        format!(
            "paged: {} frames, {} with pending pixels (mean {:.3} %, max {:.2} % of the frame); {:.1} MiB uploaded; resident at most {:.1} MiB, {:.1} of {:.1} MiB budget on the GPU; {} read error(s)",
            self.frames,
            self.pending_frames,
            self.pending_pct_sum / (self.frames.max(1) as f64),
            self.pending_pct_max,
            self.uploaded_total as f64 / 1048576.0,
            self.resident_max as f64 / 1048576.0,
            s.gpu_bytes as f64 / 1048576.0,
            s.gpu_budget as f64 / 1048576.0,
            s.read_errors
        )
    }

    fn pending_pct(&self, render_size: (u32, u32)) -> f64 {
        let pixels = f64::from(render_size.0) * f64::from(render_size.1);
        self.stats.as_ref().map_or(0.0, |s| {
            100.0 * f64::from(s.pending_pixels) / pixels.max(1.0)
        })
    }

    /// The overlay's lines: resident bytes of the budget, this frame's
    /// uploads, pending pixels, read errors.
    pub fn overlay_lines(&self, render_size: (u32, u32)) -> Vec<String> {
        let Some(s) = &self.stats else {
            return vec!["paged: no frame yet".into()];
        };
        let mib = |b: u64| b as f64 / 1048576.0;
        let (w, h) = self.world.pages.size();
        let mut lines = vec![
            format!(
                "paged {w}x{h}: {:.1} of {:.1} MiB on the GPU",
                mib(s.gpu_bytes),
                mib(s.gpu_budget)
            ),
            format!(
                "resident {} of {} pages ({:.1} MiB)",
                s.resident_pages,
                s.slots,
                mib(s.resident_bytes)
            ),
            format!(
                "uploaded {} pages ({:.2} MiB) this frame; {:.1} MiB in all",
                s.uploaded_pages,
                mib(s.uploaded_bytes),
                mib(self.uploaded_total)
            ),
            format!(
                "pending {} px ({:.2} % of the frame), {} in flight",
                s.pending_pixels,
                self.pending_pct(render_size),
                s.in_flight
            ),
        ];
        if let Some(remote) = self.world.pages.remote() {
            let r = remote.stats();
            lines.push(format!(
                "streamed: {} pages fetched ({:.2} MiB), {} in flight, {} failed, {} cancelled",
                r.done,
                mib(r.bytes),
                r.in_flight,
                r.failed,
                r.cancelled
            ));
        }
        if s.read_errors > 0 {
            lines.push(format!(
                "read errors: {} ({})",
                s.read_errors,
                s.first_error.as_deref().unwrap_or("")
            ));
        }
        if self.world.pages.edited_chunks() > 0 {
            lines.push(format!(
                "{} edited chunk(s) not yet saved",
                self.world.pages.edited_chunks()
            ));
        }
        lines
    }

    /// ` paged_...=` fields for the `memory` line.
    pub fn memory_fields(&self, render_size: (u32, u32)) -> String {
        let s = self.stats.clone().unwrap_or_default();
        format!(
            " paged_gpu_bytes={} paged_budget={} resident_pages={} resident_bytes={} \
             uploaded_bytes={} uploaded_total={} pending_pixels={} pending_pct={:.3} \
             pending_frames={} pending_pct_max={:.3} read_errors={} edited_chunks={}",
            s.gpu_bytes,
            s.gpu_budget,
            s.resident_pages,
            s.resident_bytes,
            s.uploaded_bytes,
            self.uploaded_total,
            s.pending_pixels,
            self.pending_pct(render_size),
            self.pending_frames,
            self.pending_pct_max,
            s.read_errors,
            self.world.pages.edited_chunks()
        )
    }
}

/// The camera of `view` over paged `pages` (reads the chunk under it).
pub(super) fn camera_over(
    pages: &EditedPages,
    view: &ViewSpec,
    width: u32,
    height: u32,
) -> anyhow::Result<Camera> {
    crate::paged::camera_over(pages.size(), |x, y| pages.column(x, y), view, width, height)
}

/// The paged method to open with: `method` when it draws paged terrain,
/// else the first that does.
pub(super) fn first_method(method: &str) -> &str {
    if refusal(method).is_none() {
        method
    } else {
        PAGED_METHODS[0]
    }
}

impl Viewer {
    /// The map's width and height, texels.
    pub(super) fn world_size(&self) -> (u32, u32) {
        match &self.paged {
            Some(p) => p.world.pages.size(),
            None => (self.level.width(), self.level.height()),
        }
    }

    /// The column under map point (`x`, `y`).
    pub(super) fn column_at(&self, x: f32, y: f32) -> anyhow::Result<Column> {
        match &self.paged {
            Some(p) => p
                .world
                .pages
                .column(x.floor() as i64, y.floor() as i64)
                .map_err(anyhow::Error::msg),
            None => Ok(self.level.column_at(x, y)),
        }
    }

    pub(super) fn undo_depth(&self) -> usize {
        match &self.paged {
            Some(p) => p.undo.len(),
            None => self.digger.can_undo(),
        }
    }

    /// Say `why`, or, under a script, stop it with `why` (a script that
    /// asked for the refused thing would otherwise wait for it forever).
    pub(super) fn refuse(&mut self, why: String) -> anyhow::Result<()> {
        if self.player.is_some() {
            anyhow::bail!("{why}");
        }
        self.say(why);
        Ok(())
    }

    pub(super) fn say_paged_start(&mut self, asked: &str) {
        let drawn = self.renderer.method_name();
        if let Some(why) = refusal(asked) {
            self.say(format!("{why}: drawing {drawn}"));
        }
        if let Some(p) = &self.paged {
            let o = &p.world.options;
            let line = format!(
                "paged terrain: budget {:.1} MiB, at most {} page(s) uploaded per frame",
                o.gpu_budget as f64 / 1048576.0,
                o.upload_pages
            );
            self.say(line);
        }
    }

    /// After the frame: keep its paging numbers.
    pub(super) fn after_paged_frame(&mut self) {
        if self.paged.is_none() {
            return;
        }
        let stats = self.renderer.paged_terrain().map(|t| t.stats());
        let render_size = self.render_size();
        let mut report = None;
        if let Some(p) = &mut self.paged {
            if let Some(s) = &stats {
                p.uploaded_total += s.uploaded_bytes;
                if s.read_errors > 0 && p.stats.as_ref().is_none_or(|o| o.read_errors == 0) {
                    report = Some(format!(
                        "paged read error (after {} tries; resident pages keep drawing): {}",
                        p.world.options.read_tries,
                        s.first_error.as_deref().unwrap_or("")
                    ));
                }
            }
            p.frames += 1;
            p.stats = stats;
            let pending = p.pending_pct(render_size);
            if pending > 0.0 {
                p.pending_frames += 1;
                p.pending_pct_sum += pending;
                p.pending_pct_max = p.pending_pct_max.max(pending);
            }
            p.resident_max = p
                .resident_max
                .max(p.stats.as_ref().map_or(0, |s| s.resident_bytes));
        }
        if let Some(line) = report {
            // In a page also above the canvas (the overlay may be off).
            #[cfg(target_arch = "wasm32")]
            crate::page::show_notice(&line);
            self.say(line);
        }
    }

    /// Switch to `name` over the same pages, or refuse it with the reason.
    pub(super) fn request_paged_method(&mut self, name: &str) -> anyhow::Result<()> {
        if let Some(why) = refusal(name) {
            return self.refuse(why);
        }
        if let Err(e) = methods::check_support(name, &self.gpu.caps) {
            return self.refuse(format!("{e:#}"));
        }
        self.waiting_for = None;
        if self.renderer.method_name() == name && self.is_current(name) {
            return Ok(());
        }
        self.previous_method = self.renderer.method_name().to_string();
        self.rebuild_paged(name)?;
        self.say(format!("drawing {name} (paged)"));
        Ok(())
    }

    /// A new paged renderer for `name` with the current settings, over the
    /// same pages (the old one is kept until the new one is made, so a
    /// refusal leaves the view as it was; the two atlases coexist a moment).
    pub(super) fn rebuild_paged(&mut self, name: &str) -> anyhow::Result<()> {
        let Some(p) = &self.paged else {
            anyhow::bail!("not a paged world");
        };
        let (w, h) = self.render_size();
        let (pages, options) = (p.world.pages.clone(), p.world.options.clone());
        let start = Instant::now();
        let renderer = Renderer::new_paged(
            &self.gpu,
            pages,
            &self.colors,
            name,
            &self.settings,
            w,
            h,
            options,
        )?;
        self.renderer = renderer;
        self.renderer.set_shadow_reuse(true);
        self.renderer.set_depth_attachment(true);
        self.compositor.rebind_picture(self.renderer.shared());
        self.say(format!(
            "paged {name} set up in {:.2} s",
            start.elapsed().as_secs_f64()
        ));
        Ok(())
    }

    /// Dig where picture point `at` shows terrain: the point from the
    /// frame's depth (what is on screen), the crater cut into the edit layer,
    /// the touched pages refreshed.
    pub(super) fn dig_paged(&mut self, at: (f32, f32)) -> anyhow::Result<()> {
        if cfg!(target_arch = "wasm32") {
            return self.refuse(
                "digging paged terrain picks the point from the frame's depth read back at once, which a page cannot wait for; not in the browser yet".into(),
            );
        }
        let camera = self.camera()?;
        let start = Instant::now();
        let depth = self.renderer.read_depth()?;
        let (w, h) = self.render_size();
        let (i, j) = (
            (at.0.max(0.0) as u32).min(w - 1),
            (at.1.max(0.0) as u32).min(h - 1),
        );
        let d = depth[(j * w + i) as usize];
        if d >= 1.0 {
            self.say("nothing to dig there: sky".into());
            return Ok(());
        }
        let point = camera.position + camera.pixel_ray(i, j) * camera.depth_to_distance(i, j, d);
        let pick_ms = start.elapsed().as_secs_f64() * 1e3;
        let start = Instant::now();
        let site = EditSite {
            centre_x: point.x.floor() as i64,
            centre_y: point.y.floor() as i64,
            radius: self.digger.radius,
            depth: self.digger.depth,
            ..EditSite::fostral()
        };
        let Some(p) = &mut self.paged else {
            anyhow::bail!("not a paged world");
        };
        let dug = match p.world.pages.dig(&site) {
            Ok(dug) => dug,
            Err(e) => return self.refuse(format!("cannot dig there: {e:#}")),
        };
        if dug.chunks.is_empty() {
            self.say("the crater changed nothing".into());
            return Ok(());
        }
        if p.undo.len() == UNDO_DEPTH {
            p.undo.remove(0);
        }
        p.undo.push(dug.before);
        self.renderer.refresh_pages(&dug.chunks)?;
        self.unsaved = true;
        self.say(format!(
            "dug r={} at {:.0}, {:.0}, {:.0}: {} chunk(s); pick {pick_ms:.2} ms, edit + refresh {:.2} ms",
            site.radius,
            point.x,
            point.y,
            point.z,
            dug.chunks.len(),
            start.elapsed().as_secs_f64() * 1e3
        ));
        Ok(())
    }

    pub(super) fn undo_paged(&mut self) -> anyhow::Result<()> {
        let Some(p) = &mut self.paged else {
            anyhow::bail!("not a paged world");
        };
        let Some(before) = p.undo.pop() else {
            self.say("nothing to undo".into());
            return Ok(());
        };
        let chunks = p.world.pages.restore(before);
        let left = p.undo.len();
        self.renderer.refresh_pages(&chunks)?;
        self.say(format!("undone ({left} left)"));
        Ok(())
    }

    /// Save a paged world: a store in place (its edited chunks, all or
    /// nothing), a world in memory through the usual save.
    pub(super) fn save_paged(&mut self, dir: &std::path::Path) -> anyhow::Result<String> {
        let Some(p) = &self.paged else {
            anyhow::bail!("not a paged world");
        };
        let pages = p.world.pages.clone();
        if pages.is_store() {
            #[cfg(not(target_arch = "wasm32"))]
            return pages.save_store(dir, self.saver.overwrite());
            #[cfg(target_arch = "wasm32")]
            anyhow::bail!("no file system to save to in a browser");
        }
        let level = pages.edited_level()?;
        self.saver.save(dir, &level)
    }

    /// The paging numbers for the page state.
    pub(super) fn paging_json(&self) -> serde_json::Value {
        match &self.paged {
            Some(p) => serde_json::json!({
                "stats": p.stats,
                "pending_pct": p.pending_pct(self.render_size()),
                "uploaded_total": p.uploaded_total,
                "edited_chunks": p.world.pages.edited_chunks(),
            }),
            None => serde_json::Value::Null,
        }
    }
}
