//! Read-backs that finish a frame or more after they start (a browser cannot
//! wait for the GPU): the score of the drawn method(s) against the CPU
//! reference, and the window's screenshot.

use super::Viewer;
use anyhow::Context;
use strata_camera::Camera;
use strata_render::gpu::TextureReadback;
use web_time::Instant;

/// A score on its way: the reference, and each drawn method's depth.
pub(super) struct Scoring {
    camera: Camera,
    reference: strata_reference::Reference,
    reference_ms: f64,
    reads: Vec<(String, TextureReadback)>,
    done: Vec<(String, Vec<u8>)>,
}

impl Viewer {
    /// Score what the drawn method(s) show from here against the CPU
    /// reference for the same camera (DESIGN §3 metrics): draw each and start
    /// its depth read-back; [`Viewer::poll_score`] finishes it.
    pub(super) fn score(&mut self) -> anyhow::Result<()> {
        if self.paged.is_some() {
            return self.refuse(
                "scoring traces the CPU reference over the whole world in memory; a paged world is not (`strata reference --level STORE` reads it in bounded memory)".into(),
            );
        }
        let camera = self.camera()?;
        let start = Instant::now();
        let reference = strata_reference::render_reference(&self.level, &camera);
        let reference_ms = start.elapsed().as_secs_f64() * 1e3;
        let active = self.renderer.method_name();
        let shown: Vec<&'static str> = std::iter::once(active)
            .chain(
                self.split
                    .as_deref()
                    .and_then(|b| self.renderer.method_names().into_iter().find(|m| *m == b)),
            )
            .collect();
        let mut reads = Vec::new();
        for method in shown {
            // Draw it again: in A/B mode the depth target holds the other side.
            self.renderer.activate(method)?;
            self.renderer.render_frame(&camera)?;
            reads.push((method.to_string(), self.renderer.start_read_depth()));
        }
        self.renderer.activate(active)?;
        self.scoring = Some(Scoring {
            camera,
            reference,
            reference_ms,
            reads,
            done: Vec::new(),
        });
        self.poll_score()
    }

    /// Finish a score whose read-backs have all arrived.
    pub(super) fn poll_score(&mut self) -> anyhow::Result<()> {
        let Some(scoring) = &mut self.scoring else {
            return Ok(());
        };
        let mut i = 0;
        while i < scoring.reads.len() {
            match scoring.reads[i].1.try_take(&self.gpu.device) {
                Some(bytes) => {
                    let (method, _) = scoring.reads.remove(i);
                    scoring.done.push((method, bytes?));
                }
                None => i += 1,
            }
        }
        if !scoring.reads.is_empty() {
            return Ok(());
        }
        let Some(scoring) = self.scoring.take() else {
            return Ok(());
        };
        let mut scores = Vec::new();
        for (method, bytes) in scoring.done {
            let depth: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes);
            let distance = strata_reference::distance_from_depth(&scoring.camera, &depth);
            let metrics = strata_reference::metrics::try_compare(&scoring.reference, &distance)?;
            scores.push((method, metrics));
        }
        for (method, m) in &scores {
            let line = format!(
                "score {method}: see-through {:.3} %, covers-sky {:.3} %, depth p50 {:.3} p95 {:.3}, \
                 coherence {:.3} %",
                m.see_through, m.covers_sky, m.depth_p50, m.depth_p95, m.coherence
            );
            println!("{line}");
            self.say(line);
        }
        self.say(format!("reference {:.0} ms", scoring.reference_ms));
        self.scores = scores;
        self.scored += 1;
        Ok(())
    }

    /// Save a screenshot whose read-back has arrived.
    pub(super) fn poll_screenshot(&mut self) -> anyhow::Result<()> {
        let Some((path, read)) = &self.screenshot_reading else {
            return Ok(());
        };
        let Some(pixels) = read.try_take(&self.gpu.device) else {
            return Ok(());
        };
        let path = path.clone();
        self.screenshot_reading = None;
        let (w, h) = self.compositor.window_size();
        let image = image::RgbaImage::from_raw(w, h, pixels?)
            .ok_or_else(|| anyhow::anyhow!("screenshot buffer has the wrong size"))?;
        let mut png = Vec::new();
        image
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .context("encoding the screenshot")?;
        self.platform
            .save_file(&path, &png)
            .with_context(|| format!("writing the screenshot {}", path.display()))?;
        self.say(format!("screenshot {}", path.display()));
        Ok(())
    }
}
