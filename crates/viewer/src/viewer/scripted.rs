//! Running a `--script` through the live viewer: one command per frame, or
//! several frames for the commands that move, wait or count.

use super::{Viewer, scaled};
use crate::script::Command;
use anyhow::{Context, bail};
use glam::Vec3;
use std::collections::VecDeque;

/// A script command that spans frames.
enum Running {
    Fly {
        per_frame: Vec3,
        left: u32,
    },
    Turn {
        per_frame: [f32; 2],
        left: u32,
    },
    Frames(u32),
    /// Until this method is drawn (built and active, or the split's right side).
    WaitMethod(String),
    /// Until no build runs (a changed knob's rebuild).
    WaitBuilds,
    /// Until the physics toy's collider is built.
    WaitPhysics,
    /// Until this many scores have finished (their read-backs arrive later).
    WaitScore(u32),
    /// Until the picture has this size; an error after `left` frames.
    WaitSize {
        size: (u32, u32),
        left: u32,
    },
}

pub(super) struct Player {
    commands: VecDeque<(usize, Command)>,
    running: Option<(usize, Running)>,
    /// Quit when the commands run out (a `--script`); a page's player
    /// instead waits for more ([`Player::push`]).
    quit_at_end: bool,
}

impl Player {
    pub(super) fn new(script: crate::Script) -> Self {
        Player {
            commands: script.commands.into(),
            running: None,
            quit_at_end: true,
        }
    }

    /// A player that waits for commands (the page's `strataRun`).
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    pub(super) fn waiting() -> Self {
        Player {
            quit_at_end: false,
            ..Player::new(crate::Script::default())
        }
    }

    /// Queue more commands.
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    pub(super) fn push(&mut self, script: crate::Script) {
        self.commands.extend(script.commands);
    }

    /// Nothing queued or running.
    #[cfg_attr(not(target_arch = "wasm32"), allow(dead_code))]
    pub(super) fn is_idle(&self) -> bool {
        self.running.is_none() && self.commands.is_empty()
    }

    /// Waiting for a build: frames until then only poll.
    pub(super) fn is_waiting(&self) -> bool {
        matches!(
            self.running,
            Some((
                _,
                Running::WaitMethod(_)
                    | Running::WaitBuilds
                    | Running::WaitScore(_)
                    | Running::WaitPhysics
            ))
        )
    }
}

impl Viewer {
    /// Advance the script by one frame.
    pub(super) fn script_step(&mut self) -> anyhow::Result<()> {
        let Some(player) = &mut self.player else {
            return Ok(());
        };
        if let Some((line, running)) = player.running.take() {
            let next = match running {
                Running::Fly { per_frame, left } => {
                    self.fly.translate(per_frame, self.world_size());
                    (left > 1).then_some(Running::Fly {
                        per_frame,
                        left: left - 1,
                    })
                }
                Running::Turn { per_frame, left } => {
                    self.fly.turn(per_frame[0], per_frame[1]);
                    (left > 1).then_some(Running::Turn {
                        per_frame,
                        left: left - 1,
                    })
                }
                Running::Frames(left) => (left > 1).then_some(Running::Frames(left - 1)),
                Running::WaitSize { size, left } => {
                    if self.render_size() == size {
                        None
                    } else if left == 0 {
                        bail!(
                            "the window system left the picture at {}x{}, not {}x{}",
                            self.render_size().0,
                            self.render_size().1,
                            size.0,
                            size.1
                        );
                    } else {
                        Some(Running::WaitSize {
                            size,
                            left: left - 1,
                        })
                    }
                }
                Running::WaitScore(n) => (self.scored < n).then_some(Running::WaitScore(n)),
                Running::WaitBuilds => {
                    (!self.builds.running().is_empty()).then_some(Running::WaitBuilds)
                }
                Running::WaitPhysics => (!self.physics.is_ready()).then_some(Running::WaitPhysics),
                Running::WaitMethod(name) => {
                    let drawn = self.renderer.method_name() == name
                        || (self.split.as_deref() == Some(name.as_str()) && self.is_current(&name));
                    (!drawn).then_some(Running::WaitMethod(name))
                }
            };
            if let Some(player) = &mut self.player {
                player.running = next.map(|n| (line, n));
            }
            return Ok(());
        }
        let Some((line, command)) = player.commands.pop_front() else {
            self.quit |= player.quit_at_end;
            return Ok(());
        };
        self.run_command(line, command)
            .with_context(|| format!("script line {line}"))
    }

    /// The centre of the render pixel that fractions (`fx`, `fy`) of the
    /// picture fall in.
    fn picture_point(&self, fx: f32, fy: f32) -> (f32, f32) {
        let (w, h) = self.render_size();
        let px = (fx * w as f32).floor().min(w as f32 - 1.0) + 0.5;
        let py = (fy * h as f32).floor().min(h as f32 - 1.0) + 0.5;
        (px, py)
    }

    fn run_command(&mut self, line: usize, command: Command) -> anyhow::Result<()> {
        let mut running = None;
        match command {
            Command::View(name) => {
                let i = self
                    .views
                    .iter()
                    .position(|v| v.name == name)
                    .with_context(|| format!("the level has no view `{name}`"))?;
                self.go_to_view(i);
            }
            Command::Method(name) => {
                self.request_method(&name)?;
                running = Some(Running::WaitMethod(name));
            }
            Command::Split(name) => {
                self.set_split(name.clone())?;
                running = name.map(Running::WaitMethod);
            }
            Command::Fly { offset, frames } => {
                running = Some(Running::Fly {
                    per_frame: Vec3::from(offset) / frames as f32,
                    left: frames,
                });
            }
            Command::Turn { degrees, frames } => {
                running = Some(Running::Turn {
                    per_frame: degrees.map(|d| d / frames as f32),
                    left: frames,
                });
            }
            Command::Frames(n) => running = Some(Running::Frames(n)),
            Command::Goto(x, y) => self.teleport(glam::Vec2::new(x, y)),
            Command::Dig(fx, fy) => self.dig_at(self.picture_point(fx, fy))?,
            Command::Physics(on) => {
                if on != self.physics.on {
                    self.toggle_physics();
                }
                if on {
                    if cfg!(target_arch = "wasm32") {
                        bail!("physics is native-only");
                    }
                    running = Some(Running::WaitPhysics);
                }
            }
            Command::Drop(what, fx, fy) => {
                if !self.physics.on {
                    bail!("drop: the physics toy is off (`physics on` first)");
                }
                self.drop_at(self.picture_point(fx, fy), what)?;
            }
            Command::ClearBodies => {
                let line = self.physics.clear();
                self.say(line);
            }
            Command::Undo => self.undo()?,
            Command::Save(dir) => self.save(Some(dir))?,
            Command::Set(knob, value) => {
                self.set_knob(knob, value)?;
                running = Some(Running::WaitBuilds);
            }
            Command::Overlay(on) => self.overlay.visible = on,
            Command::Window(w, h) => {
                // The reply comes as a Resized event; the size may differ
                // from the request only where a window manager refuses it.
                let _ = self
                    .window
                    .request_inner_size(winit::dpi::PhysicalSize::new(w, h));
                running = Some(Running::WaitSize {
                    size: scaled((w, h), self.render_scale),
                    left: 200,
                });
            }
            Command::Screenshot(path) => self.screenshot_after_frame = Some(path),
            Command::CopyView(name) => self.copy_view(&name),
            Command::Score => {
                // Counted before: natively the read-back may finish inside
                // `score` itself, and waiting for one more would never end.
                let scored = self.scored + 1;
                self.score()?;
                running = Some(Running::WaitScore(scored));
            }
            Command::Memory => println!("{}", self.memory_line()),
            Command::LoseDevice => {
                self.say("destroying the GPU device (script)".into());
                self.gpu.device.destroy();
            }
            Command::Quit => self.quit = true,
        }
        // Run the first frame of a multi-frame command now.
        if let (Some(running), Some(player)) = (running, &mut self.player) {
            player.running = Some((line, running));
            return self.script_step();
        }
        Ok(())
    }
}
