//! Methods built off the render thread (natively a thread per build; in a
//! browser page a slice per frame). A method's first use (or a changed
//! setting) can take seconds (the mesh fit, the voxel pyramid on a CPU
//! adapter); the window keeps drawing the current method meanwhile and shows
//! the build's progress. Edits made while a build runs are replayed on the
//! new method before it is kept, so it never shows stale terrain.

use std::sync::Arc;
use strata_level::{DirtyRect, Level};
use strata_render::{Method, MethodSettings, Renderer, methods};
use web_time::Instant;

type Built = anyhow::Result<Box<dyn Method>>;

/// A build on a thread of its own.
#[cfg(not(target_arch = "wasm32"))]
struct Job(std::thread::JoinHandle<Built>);

#[cfg(not(target_arch = "wasm32"))]
impl Job {
    fn start(
        renderer: &Renderer,
        level: &Arc<Level>,
        name: &str,
        settings: &MethodSettings,
    ) -> anyhow::Result<Self> {
        use anyhow::Context;
        let shared = renderer.shared_handle();
        let level = Arc::clone(level);
        let (owned_name, owned_settings) = (name.to_string(), settings.clone());
        std::thread::Builder::new()
            .name(format!("build {name}"))
            .spawn(move || methods::create(&owned_name, &shared, &level, &owned_settings))
            .map(Job)
            .with_context(|| format!("starting a thread to build {name}"))
    }

    fn is_finished(&mut self) -> bool {
        self.0.is_finished()
    }

    fn join(self) -> Built {
        self.0
            .join()
            .unwrap_or_else(|_| Err(anyhow::anyhow!("the build thread panicked")))
    }
}

/// A browser page has one thread: the build runs on it a slice per frame
/// ([`BuildSteps`]: the mesh fits a few chunks, other methods build whole),
/// from the second frame after it was asked for (so the frame between shows
/// that it runs); the current method keeps drawing meanwhile.
#[cfg(target_arch = "wasm32")]
struct Job {
    steps: Box<dyn strata_render::methods::BuildSteps>,
    shared: Arc<strata_render::Shared>,
    level: Arc<Level>,
    result: Option<Built>,
    polls: u32,
}

/// Milliseconds of building per frame in a page: the page keeps drawing at
/// a few frames a second while the mesh fits.
#[cfg(target_arch = "wasm32")]
const STEP_BUDGET_MS: f64 = 80.0;

#[cfg(target_arch = "wasm32")]
impl Job {
    fn start(
        renderer: &Renderer,
        level: &Arc<Level>,
        name: &str,
        settings: &MethodSettings,
    ) -> anyhow::Result<Self> {
        let shared = renderer.shared_handle();
        Ok(Job {
            steps: methods::create_in_steps(name, &shared.caps, settings)?,
            shared,
            level: Arc::clone(level),
            result: None,
            polls: 0,
        })
    }

    fn is_finished(&mut self) -> bool {
        self.polls += 1;
        if self.polls >= 2 && self.result.is_none() {
            match self.steps.step(&self.shared, &self.level, STEP_BUDGET_MS) {
                Ok(None) => {}
                Ok(Some(method)) => self.result = Some(Ok(method)),
                Err(error) => self.result = Some(Err(error)),
            }
        }
        self.result.is_some()
    }

    fn join(self) -> Built {
        self.result
            .unwrap_or_else(|| Err(anyhow::anyhow!("the build never finished")))
    }
}

struct Pending {
    name: String,
    settings: MethodSettings,
    started: Instant,
    thread: Job,
    /// Edits made since the build took its copy of the level.
    edits: Vec<DirtyRect>,
}

/// What a finished build did.
pub enum Finished {
    Kept { name: String, seconds: f64 },
    Failed { name: String, error: anyhow::Error },
}

#[derive(Default)]
pub struct Builds {
    pending: Vec<Pending>,
}

impl Builds {
    /// Build `name` with `settings` on a background thread from `level` (an
    /// `Arc` clone: digging while it runs copies the level on write). A build
    /// of the same method already running is left to finish and replaced.
    pub fn start(
        &mut self,
        renderer: &Renderer,
        level: &Arc<Level>,
        name: &str,
        settings: &MethodSettings,
    ) -> anyhow::Result<()> {
        if self.is_building(name, settings) {
            return Ok(());
        }
        let thread = Job::start(renderer, level, name, settings)?;
        self.pending.push(Pending {
            name: name.to_string(),
            settings: settings.clone(),
            started: Instant::now(),
            thread,
            edits: Vec::new(),
        });
        Ok(())
    }

    pub fn is_building(&self, name: &str, settings: &MethodSettings) -> bool {
        self.pending
            .iter()
            .any(|p| p.name == name && &p.settings == settings)
    }

    /// Builds running: (method, seconds so far).
    pub fn running(&self) -> Vec<(&str, f64)> {
        self.pending
            .iter()
            .map(|p| (p.name.as_str(), p.started.elapsed().as_secs_f64()))
            .collect()
    }

    /// Remember an edit for every running build.
    pub fn record_edit(&mut self, rects: &[DirtyRect]) {
        for p in &mut self.pending {
            p.edits.extend_from_slice(rects);
        }
    }

    /// Keep every finished build in `renderer` (after replaying the edits it
    /// missed on `level`, the current level); report what happened.
    pub fn collect(&mut self, renderer: &mut Renderer, level: &Level) -> Vec<Finished> {
        let mut done = Vec::new();
        let mut i = 0;
        while i < self.pending.len() {
            if !self.pending[i].thread.is_finished() {
                i += 1;
                continue;
            }
            let p = self.pending.remove(i);
            let seconds = p.started.elapsed().as_secs_f64();
            if self.pending.iter().any(|q| q.name == p.name) {
                // A newer build of this method (other settings) supersedes it.
                continue;
            }
            let result = p.thread.join();
            let result = result.and_then(|mut method| {
                if !p.edits.is_empty() {
                    method.apply_edit(renderer.shared(), level, &p.edits)?;
                }
                Ok(method)
            });
            done.push(match result {
                Ok(method) => {
                    renderer.insert_method(method, p.settings);
                    Finished::Kept {
                        name: p.name,
                        seconds,
                    }
                }
                Err(error) => Finished::Failed {
                    name: p.name,
                    error,
                },
            });
        }
        done
    }
}
