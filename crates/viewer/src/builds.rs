//! Methods built off the render thread. A method's first use (or a changed
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
    fn spawn(name: &str, build: impl FnOnce() -> Built + Send + 'static) -> anyhow::Result<Self> {
        use anyhow::Context;
        std::thread::Builder::new()
            .name(format!("build {name}"))
            .spawn(build)
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

/// A browser page has one thread: the build runs on it, in the second
/// frame after it was asked for (so the frame between shows that it runs),
/// and that frame waits for it.
#[cfg(target_arch = "wasm32")]
struct Job {
    build: Option<Box<dyn FnOnce() -> Built>>,
    result: Option<Built>,
    polls: u32,
}

#[cfg(target_arch = "wasm32")]
impl Job {
    fn spawn(_name: &str, build: impl FnOnce() -> Built + 'static) -> anyhow::Result<Self> {
        Ok(Job {
            build: Some(Box::new(build)),
            result: None,
            polls: 0,
        })
    }

    fn is_finished(&mut self) -> bool {
        self.polls += 1;
        if self.polls >= 2
            && let Some(build) = self.build.take()
        {
            self.result = Some(build());
        }
        self.result.is_some()
    }

    fn join(self) -> Built {
        self.result
            .unwrap_or_else(|| Err(anyhow::anyhow!("the build never ran")))
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
        let shared = renderer.shared_handle();
        let level = Arc::clone(level);
        let (owned_name, owned_settings) = (name.to_string(), settings.clone());
        let thread = Job::spawn(name, move || {
            methods::create(&owned_name, &shared, &level, &owned_settings)
        })?;
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
