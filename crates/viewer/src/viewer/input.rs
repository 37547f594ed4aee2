//! Keys and mouse: the fly camera's motion, looking around, digging, and
//! the command keys (methods, views, split, undo, save, copy view, screenshot).

use super::{Viewer, scaled};
use crate::fly::Motion;
use crate::physics::Drop;
use strata_render::methods;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::keyboard::{KeyCode, PhysicalKey};

impl Viewer {
    /// A window event; `Err` ends the viewer with that error.
    pub fn on_window_event(&mut self, event: &WindowEvent) -> anyhow::Result<()> {
        let used = self.overlay.on_window_event(&self.window, event);
        match event {
            WindowEvent::CloseRequested => self.quit = true,
            // A minimised window reports 0x0: keep the old swapchain.
            WindowEvent::Resized(size) if size.width > 0 && size.height > 0 => {
                self.config.width = size.width;
                self.config.height = size.height;
                self.surface.configure(&self.gpu.device, &self.config);
                self.compositor.resize((size.width, size.height));
                self.resize_to = Some(scaled((size.width, size.height), self.render_scale));
            }
            WindowEvent::Focused(false) => {
                self.keys.clear();
                self.looking = false;
                self.grab_cursor(false);
            }
            WindowEvent::ModifiersChanged(m) => {
                self.ctrl = m.state().control_key();
                self.shift = m.state().shift_key();
            }
            WindowEvent::KeyboardInput { event, .. } => {
                let PhysicalKey::Code(code) = event.physical_key else {
                    return Ok(());
                };
                if event.state == ElementState::Released {
                    self.keys.remove(&code);
                } else if !self.overlay.wants_keyboard() || !used {
                    let first = self.keys.insert(code);
                    if first && !event.repeat {
                        self.on_key(code)?;
                    }
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                let now = (position.x as f32, position.y as f32);
                // Cursor deltas stop at the window's edge: only a fallback
                // where the platform sends no raw motion.
                if let (true, false, Some(before)) = (self.looking, self.raw_motion, self.cursor) {
                    self.fly.look(now.0 - before.0, now.1 - before.1);
                }
                self.cursor = Some(now);
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let pressed = *state == ElementState::Pressed;
                match button {
                    MouseButton::Right => {
                        self.looking = pressed && !self.overlay.wants_pointer();
                        self.grab_cursor(self.looking);
                    }
                    MouseButton::Left | MouseButton::Middle
                        if pressed && !used && !self.overlay.wants_pointer() =>
                    {
                        if let Some(at) = self
                            .cursor
                            .and_then(|(x, y)| self.compositor.window_to_picture(x, y))
                        {
                            // Physics on: left click drops (Shift: a box),
                            // middle click digs; off: both dig.
                            match (*button, self.physics.on) {
                                (MouseButton::Left, true) if self.shift => {
                                    self.drop_at(at, Drop::Box)?
                                }
                                (MouseButton::Left, true) => self.drop_at(at, Drop::Sphere)?,
                                _ => self.dig_at(at)?,
                            }
                        }
                    }
                    _ => {}
                }
            }
            WindowEvent::MouseWheel { delta, .. } if !used => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => *y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.fly.speed = (self.fly.speed * 1.25f32.powf(lines)).clamp(2.0, 2000.0);
            }
            WindowEvent::RedrawRequested => self.frame()?,
            _ => {}
        }
        Ok(())
    }

    /// Hide and hold the cursor while looking around, where the platform
    /// allows (X11 confines, Wayland locks); otherwise it just stays visible.
    fn grab_cursor(&self, grab: bool) {
        use winit::window::CursorGrabMode;
        if grab {
            let _ = self
                .window
                .set_cursor_grab(CursorGrabMode::Locked)
                .or_else(|_| self.window.set_cursor_grab(CursorGrabMode::Confined));
        } else {
            let _ = self.window.set_cursor_grab(CursorGrabMode::None);
        }
        self.window.set_cursor_visible(!grab);
    }

    /// Raw mouse motion (unbounded by the window), while looking around.
    pub fn on_mouse_motion(&mut self, dx: f64, dy: f64) {
        if self.looking {
            self.raw_motion = true;
            self.fly.look(dx as f32, dy as f32);
        }
    }

    fn on_key(&mut self, code: KeyCode) -> anyhow::Result<()> {
        // 1 .. 9 then 0: the ten methods in registry order.
        const DIGITS: [KeyCode; 10] = [
            KeyCode::Digit1,
            KeyCode::Digit2,
            KeyCode::Digit3,
            KeyCode::Digit4,
            KeyCode::Digit5,
            KeyCode::Digit6,
            KeyCode::Digit7,
            KeyCode::Digit8,
            KeyCode::Digit9,
            KeyCode::Digit0,
        ];
        const F_KEYS: [KeyCode; 12] = [
            KeyCode::F1,
            KeyCode::F2,
            KeyCode::F3,
            KeyCode::F4,
            KeyCode::F5,
            KeyCode::F6,
            KeyCode::F7,
            KeyCode::F8,
            KeyCode::F9,
            KeyCode::F10,
            KeyCode::F11,
            KeyCode::F12,
        ];
        if let Some(i) = DIGITS.iter().position(|&k| k == code) {
            if let Some(name) = methods::names().get(i) {
                self.request_method(name)?;
            }
        } else if let Some(i) = F_KEYS.iter().position(|&k| k == code) {
            self.go_to_view(i);
        } else {
            match code {
                KeyCode::Escape => self.quit = true,
                KeyCode::Tab => self.overlay.visible = !self.overlay.visible,
                KeyCode::KeyB => {
                    let split = match self.split {
                        Some(_) => None,
                        None => Some(self.previous_method.clone()),
                    };
                    self.set_split(split)?;
                }
                KeyCode::KeyV => self.copy_view("viewer"),
                KeyCode::KeyM => self.score()?,
                KeyCode::KeyP => self.screenshot_after_frame = Some(self.next_screenshot_path()),
                KeyCode::KeyU => self.undo()?,
                KeyCode::KeyO => self.toggle_physics(),
                KeyCode::KeyX => {
                    let line = self.physics.clear();
                    self.say(line);
                }
                KeyCode::KeyZ if self.ctrl => self.undo()?,
                // A failed save is in the log; the session and its edits go on.
                KeyCode::KeyS if self.ctrl => {
                    let _ = self.save(None);
                }
                _ => {}
            }
        }
        Ok(())
    }

    pub(super) fn motion(&self) -> Motion {
        let axis = |plus: &[KeyCode], minus: &[KeyCode]| {
            let held = |keys: &[KeyCode]| keys.iter().any(|k| self.keys.contains(k));
            f32::from(u8::from(held(plus))) - f32::from(u8::from(held(minus)))
        };
        if self.ctrl {
            // Ctrl+Z and friends are commands, not movement.
            return Motion::default();
        }
        Motion {
            forward: axis(
                &[KeyCode::KeyW, KeyCode::ArrowUp],
                &[KeyCode::KeyS, KeyCode::ArrowDown],
            ),
            right: axis(
                &[KeyCode::KeyD, KeyCode::ArrowRight],
                &[KeyCode::KeyA, KeyCode::ArrowLeft],
            ),
            up: axis(
                &[KeyCode::Space, KeyCode::KeyE],
                &[KeyCode::KeyC, KeyCode::KeyQ],
            ),
            fast: self.shift,
        }
    }
}
