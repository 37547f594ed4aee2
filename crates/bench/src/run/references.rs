//! The CPU references a `strata compare` run measures against: per view the
//! geometric reference and the colour reference (for ꟻLIP), each from the
//! cache when present, saved as the view's pictures.

use super::Plan;
use crate::session::Session;
use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use strata_reference::{ColorImage, Reference, ReferenceCache, Tracer};

impl Plan {
    /// The reference of every view (from the cache when present) and its picture.
    pub(super) fn references(&self, session: &mut Session) -> anyhow::Result<Vec<Reference>> {
        let cache = ReferenceCache::new(&self.opts.cache_dir);
        let bar = ProgressBar::new(self.cameras.len() as u64);
        bar.set_style(
            ProgressStyle::with_template(
                "{bar:30} {pos}/{len} references  {msg}  [{elapsed_precise}]",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        // Hash the level once (64 MiB for a Fostral-sized map) and build the
        // tracer's pyramid only if some view misses the cache.
        let level = &self.world.level;
        let hash = level.content_hash();
        let mut tracer: Option<Tracer> = None;
        let mut out = Vec::new();
        for (v, (view, camera)) in self.opts.views.iter().zip(&self.cameras).enumerate() {
            bar.set_message(view.name.clone());
            let r = match cache.get(&hash, camera) {
                Some(r) => r,
                None => {
                    let tracer = tracer.get_or_insert_with(|| Tracer::new(level));
                    cache
                        .get_or_compute_traced(tracer, &hash, camera)
                        .with_context(|| format!("reference of view `{}`", view.name))?
                        .0
                }
            };
            session.save_reference(v, &view.name, &r, camera.far)?;
            out.push(r);
            bar.inc(1);
        }
        bar.finish_and_clear();
        Ok(out)
    }

    /// The CPU colour reference of every view (cached), saved as the
    /// view's colour picture; `None` per view where ꟻLIP is not measured
    /// (the browser build).
    pub(super) fn color_references(
        &self,
        session: &mut Session,
    ) -> anyhow::Result<Vec<Option<ColorImage>>> {
        #[cfg(not(target_arch = "wasm32"))]
        {
            let cache = ReferenceCache::new(&self.opts.cache_dir);
            let level = &self.world.level;
            let hash = level.content_hash();
            let ramps = strata_reference::TerrainRamps::from_world(&self.world);
            let bar = ProgressBar::new(self.cameras.len() as u64);
            bar.set_style(
                ProgressStyle::with_template(
                    "{bar:30} {pos}/{len} colour references  {msg}  [{elapsed_precise}]",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            let mut tracer: Option<Tracer> = None;
            let mut out = Vec::new();
            for (v, (view, camera)) in self.opts.views.iter().zip(&self.cameras).enumerate() {
                bar.set_message(view.name.clone());
                let c = match cache.get_color(&hash, camera, &ramps, self.opts.shadows) {
                    Some(c) => c,
                    None => {
                        let tracer = tracer.get_or_insert_with(|| Tracer::new(level));
                        cache
                            .get_or_compute_color(tracer, &hash, camera, &ramps, self.opts.shadows)
                            .with_context(|| format!("colour reference of view `{}`", view.name))?
                            .0
                    }
                };
                session.save_picture(
                    crate::session::GridMode::Flip,
                    (v, 0),
                    &format!("{}-color-reference", view.name),
                    crate::flip::reference_picture(&c),
                )?;
                out.push(Some(c));
                bar.inc(1);
            }
            bar.finish_and_clear();
            Ok(out)
        }
        #[cfg(target_arch = "wasm32")]
        {
            let _ = session;
            Ok(vec![None; self.cameras.len()])
        }
    }
}
