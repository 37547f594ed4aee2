//! Which method is drawn: switching (building in the background what is not
//! kept with the current settings), the A/B split, knobs applied in place or
//! by a rebuild, and finished builds collected.

use super::Viewer;
use crate::builds::Finished;
use crate::knobs::{Knob, relevant};
use anyhow::bail;
use strata_render::methods;

impl Viewer {
    /// Draw `name` from now on, building it first (in the background) when
    /// it is not kept with the current settings.
    pub(super) fn request_method(&mut self, name: &str) -> anyhow::Result<()> {
        if !methods::names().contains(&name) {
            bail!(
                "unknown method `{name}`; known: {}",
                methods::names().join(", ")
            );
        }
        if self.paged.is_some() {
            return self.request_paged_method(name);
        }
        let current = self.renderer.method_name();
        if self.make_current(name)? {
            if current != name {
                self.previous_method = current.to_string();
                self.renderer.activate(name)?;
                self.say(format!("drawing {name}"));
            }
            self.waiting_for = None;
        } else {
            self.builds
                .start(&self.renderer, &self.level, name, &self.settings)?;
            self.waiting_for = Some(name.to_string());
        }
        Ok(())
    }

    /// Whether `name` is kept with the current settings, giving them to it
    /// in place where it can take them (otherwise it needs a rebuild).
    pub(super) fn make_current(&mut self, name: &str) -> anyhow::Result<bool> {
        if self.is_current(name) {
            return Ok(true);
        }
        self.renderer.update_settings(name, &self.settings)
    }

    /// Whether `name` is kept, built with the current settings.
    pub(super) fn is_current(&self, name: &str) -> bool {
        self.renderer
            .settings_of(name)
            .is_some_and(|s| relevant(name, s) == relevant(name, &self.settings))
    }

    pub(super) fn set_split(&mut self, split: Option<String>) -> anyhow::Result<()> {
        if split.is_some() && self.paged.is_some() {
            return self.refuse(
                "A/B needs two methods over one world in memory; a paged world draws one at a time"
                    .into(),
            );
        }
        if let Some(name) = &split {
            if !methods::names().contains(&name.as_str()) {
                bail!("unknown method `{name}`");
            }
            if !self.make_current(name)? {
                self.builds
                    .start(&self.renderer, &self.level, name, &self.settings)?;
            }
        }
        self.split = split;
        Ok(())
    }

    pub(super) fn on_knob(&mut self, knob: Knob) -> anyhow::Result<()> {
        if knob == Knob::Shadows {
            self.renderer.set_shadows(self.settings.shadows);
            return Ok(());
        }
        if self.paged.is_some() {
            let name = self.renderer.method_name();
            if knob.read_by(name) && !self.make_current(name)? {
                self.rebuild_paged(name)?;
            }
            return Ok(());
        }
        // What is on screen and reads the knob takes it in place or is
        // rebuilt; other kept methods catch up when next shown.
        let shown: Vec<String> = std::iter::once(self.renderer.method_name().to_string())
            .chain(self.split.clone())
            .collect();
        for name in shown {
            if knob.read_by(&name) && !self.make_current(&name)? {
                self.builds
                    .start(&self.renderer, &self.level, &name, &self.settings)?;
            }
        }
        Ok(())
    }

    pub(super) fn set_knob(&mut self, knob: Knob, value: f32) -> anyhow::Result<()> {
        knob.set(&mut self.settings, value)?;
        self.on_knob(knob)
    }

    /// Keep finished builds; activate the one waited for.
    pub(super) fn collect_builds(&mut self) -> anyhow::Result<()> {
        for finished in self.builds.collect(&mut self.renderer, &self.level) {
            match finished {
                Finished::Kept { name, seconds } => {
                    self.say(format!("built {name} in {seconds:.2} s"));
                    if self.waiting_for.as_deref() == Some(name.as_str()) {
                        self.request_method(&name)?;
                    }
                }
                Finished::Failed { name, error } => {
                    if self.waiting_for.as_deref() == Some(name.as_str()) {
                        self.waiting_for = None;
                    }
                    if self.split.as_deref() == Some(name.as_str()) {
                        self.split = None;
                    }
                    if self.player.is_some() {
                        return Err(error.context(format!("building {name}")));
                    }
                    self.say(format!("building {name} failed: {error:#}"));
                }
            }
        }
        Ok(())
    }
}
