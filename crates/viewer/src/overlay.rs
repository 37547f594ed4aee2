//! The overlay (egui): frame rate, GPU time per pass, the methods and their
//! knobs, A/B split, views, digging, memory, the adapter. It draws from a
//! read-only [`Status`] and edits only the desired settings and crater size;
//! everything else it asks for comes back as [`Action`]s, applied by the
//! viewer after the frame.

use crate::fly::FlyCamera;
use crate::knobs::Knob;
use egui_wgpu::ScreenDescriptor;
use strata_level::ViewSpec;
use strata_render::methods::{Slider, SliderKind};
use strata_render::{AdapterReport, FrameTimings, MethodSettings, RetainedBytes, methods};
use winit::window::Window;

/// What the user asked for this frame.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    Method(String),
    Split(Option<String>),
    View(usize),
    /// A knob's new value is in the desired settings: apply it to what uses
    /// it (in place, or by a background rebuild).
    Knob(Knob),
    Undo,
    CopyView,
    Screenshot,
    /// Score the drawn method(s) against the CPU reference.
    Score,
    /// Fly to this world position (x, y), from a click on the map.
    Teleport(glam::Vec2),
}

/// One drawn method's last frame.
pub struct Drawn<'a> {
    pub method: &'a str,
    pub timings: &'a FrameTimings,
}

/// A method build in flight.
pub struct Building<'a> {
    pub method: &'a str,
    pub seconds: f64,
    /// Fraction done, for builds that report it (the mesh fit).
    pub done: Option<f32>,
}

impl Building<'_> {
    /// A spinner and the time so far, with a bar where the fraction is known.
    fn show(&self, ui: &mut egui::Ui, heading: bool) {
        ui.horizontal(|ui| {
            ui.spinner();
            let text = format!("building {}: {:.1} s", self.method, self.seconds);
            if heading {
                ui.heading(text);
            } else {
                ui.label(text);
            }
        });
        if let Some(done) = self.done {
            ui.add(egui::ProgressBar::new(done).show_percentage());
        }
    }
}

/// What the overlay shows.
pub struct Status<'a> {
    pub adapter: &'a AdapterReport,
    /// What the adapter can do: methods it cannot run are listed as unavailable.
    pub caps: &'a strata_render::caps::Capabilities,
    pub frame_ms: f64,
    pub drawn: Vec<Drawn<'a>>,
    pub active: &'a str,
    pub split: Option<&'a str>,
    /// Kept methods and their memory beyond the shared frame.
    pub kept: Vec<(&'a str, RetainedBytes)>,
    pub shared_gpu_bytes: u64,
    /// Builds running: method, seconds so far.
    pub building: Vec<Building<'a>>,
    /// The method the viewer waits for, when it is still being built.
    pub waiting_for: Option<&'a str>,
    pub views: &'a [ViewSpec],
    pub camera: &'a FlyCamera,
    pub render_size: (u32, u32),
    pub window_size: (u32, u32),
    pub undo_depth: usize,
    /// The last scores against the reference.
    pub scores: &'a [(String, strata_reference::Metrics)],
    pub log: &'a [String],
    /// Paged terrain's numbers (resident bytes of the budget, uploads this
    /// frame, pending pixels, read errors); `None` for a world in memory.
    pub paging: Option<Vec<String>>,
}

/// What the overlay may change directly.
pub struct Editable<'a> {
    pub settings: &'a mut MethodSettings,
    pub crater_radius: &'a mut u32,
    pub crater_depth: &'a mut f32,
    /// The A/B divider, as a fraction of the picture's width.
    pub split_at: &'a mut f32,
}

pub struct Overlay {
    context: egui::Context,
    input: egui_winit::State,
    painter: egui_wgpu::Renderer,
    pub visible: bool,
    map: Option<Map>,
}

/// The map's texture and how its pixels relate to the level.
struct Map {
    texture: egui::TextureHandle,
    /// Texels per map pixel.
    scale: f32,
    size: egui::Vec2,
}

const MIB: f64 = 1024.0 * 1024.0;

/// Keys and mouse, as the help section and the README list them.
pub const CONTROLS: &[(&str, &str)] = &[
    ("W A S D", "fly forward / left / back / right"),
    ("Space, E / C, Q", "up / down"),
    ("Shift", "4x speed; mouse wheel: base speed"),
    ("right mouse drag", "look around"),
    (
        "left click",
        "dig a crater at the cursor (physics on: drop a ball)",
    ),
    #[cfg(not(target_arch = "wasm32"))]
    (
        "O",
        "physics toy on / off (rapier bodies on the terrain collider)",
    ),
    #[cfg(not(target_arch = "wasm32"))]
    ("Shift+click, middle click", "physics on: drop a box; dig"),
    #[cfg(not(target_arch = "wasm32"))]
    ("X", "clear the physics bodies"),
    #[cfg(target_arch = "wasm32")]
    ("O", "physics toy: native only"),
    ("Ctrl+Z or U", "undo the last dig"),
    #[cfg(not(target_arch = "wasm32"))]
    ("Ctrl+S", "save the edited world (--save-to)"),
    #[cfg(target_arch = "wasm32")]
    ("Ctrl+S", "saving: not available in the browser"),
    ("1 .. 9, 0", "switch method (built on first use)"),
    ("B", "A/B split: this method left, the previous one right"),
    ("F1 .. F12", "jump to the level's views"),
    (
        "V",
        "copy the view (views.txt line, printed and to the clipboard)",
    ),
    ("P", "screenshot to PNG"),
    ("Tab", "hide / show this overlay"),
    ("Esc", "quit"),
];

impl Overlay {
    pub fn new(window: &Window, device: &wgpu::Device, target_format: wgpu::TextureFormat) -> Self {
        let context = egui::Context::default();
        let input = egui_winit::State::new(
            context.clone(),
            egui::ViewportId::ROOT,
            window,
            Some(window.scale_factor() as f32),
            None,
            Some(device.limits().max_texture_dimension_2d as usize),
        );
        let painter = egui_wgpu::Renderer::new(device, target_format, Default::default());
        Overlay {
            context,
            input,
            painter,
            visible: true,
            map: None,
        }
    }

    /// Upload the `regions` of `map` that an edit repainted.
    pub fn update_map(&mut self, map: &crate::minimap::Minimap, regions: &[[u32; 4]]) {
        let Some(m) = &mut self.map else {
            return self.set_map(map);
        };
        for &region in regions {
            let [x, y, w, h] = region;
            let size = [w as usize, h as usize];
            let image = egui::ColorImage::from_rgba_unmultiplied(size, &map.region(region));
            let at = [x as usize, y as usize];
            m.texture
                .set_partial(at, image, egui::TextureOptions::NEAREST);
        }
    }

    /// Show `map`.
    pub fn set_map(&mut self, map: &crate::minimap::Minimap) {
        let size = [map.width as usize, map.height as usize];
        let image = egui::ColorImage::from_rgba_unmultiplied(size, &map.rgba);
        let options = egui::TextureOptions::NEAREST;
        match &mut self.map {
            Some(m) => m.texture.set(image, options),
            None => {
                self.map = Some(Map {
                    texture: self.context.load_texture("map", image, options),
                    scale: map.scale as f32,
                    size: egui::vec2(map.width as f32, map.height as f32),
                })
            }
        }
    }

    /// Feed a window event; true when egui used it (the viewer then ignores it).
    pub fn on_window_event(&mut self, window: &Window, event: &winit::event::WindowEvent) -> bool {
        // A hidden overlay takes nothing (egui still tracks the input, and
        // its last drawn panels would otherwise swallow clicks).
        self.input.on_window_event(window, event).consumed && self.visible
    }

    /// Whether the pointer is over (or dragging) the overlay.
    pub fn wants_pointer(&self) -> bool {
        self.visible && self.context.egui_wants_pointer_input()
    }

    pub fn wants_keyboard(&self) -> bool {
        self.visible && self.context.egui_wants_keyboard_input()
    }

    pub fn copy_text(&self, text: String) {
        self.context.copy_text(text);
    }

    /// Lay out and paint the overlay onto `target` (loaded, not cleared).
    #[allow(clippy::too_many_arguments)]
    pub fn paint(
        &mut self,
        window: &Window,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        status: &Status<'_>,
        editable: &mut Editable<'_>,
        timestamps: Option<wgpu::RenderPassTimestampWrites<'_>>,
    ) -> Vec<Action> {
        let mut actions = Vec::new();
        let raw = self.input.take_egui_input(window);
        let visible = self.visible;
        let map = self.map.as_ref();
        let mut output = self.context.run_pass(raw, |ctx| {
            if let Some(method) = status.waiting_for {
                progress(ctx, method, status);
            }
            if visible {
                panel(ctx, status, map, editable, &mut actions);
            }
        });
        self.input
            .handle_platform_output(window, output.platform_output);
        let primitives = self
            .context
            .tessellate(output.shapes, output.pixels_per_point);
        let screen = ScreenDescriptor {
            size_in_pixels: [status.window_size.0, status.window_size.1],
            pixels_per_point: output.pixels_per_point,
        };
        let mut textures = std::mem::take(&mut output.textures_delta);
        for (id, deltas) in textures.set.drain() {
            for delta in deltas {
                self.painter.update_texture(device, queue, id, &delta);
            }
        }
        let extra = self
            .painter
            .update_buffers(device, queue, encoder, &primitives, &screen);
        if !extra.is_empty() {
            queue.submit(extra);
        }
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("overlay"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: timestamps,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            self.painter
                .render(&mut pass.forget_lifetime(), &primitives, &screen);
        }
        for id in textures.free.drain() {
            self.painter.free_texture(&id);
        }
        actions
    }
}

/// The centred note while a wanted method is still being built.
fn progress(ctx: &egui::Context, method: &str, status: &Status<'_>) {
    egui::Area::new(egui::Id::unique("building"))
        .anchor(egui::Align2::CENTER_CENTER, egui::vec2(0.0, 0.0))
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                match status.building.iter().find(|b| b.method == method) {
                    Some(build) => build.show(ui, true),
                    None => {
                        ui.heading(format!("waiting for {method}"));
                    }
                }
                ui.label(format!(
                    "still drawing {} meanwhile; it is kept once built",
                    status.active
                ));
            });
        });
}

fn panel(
    ctx: &egui::Context,
    status: &Status<'_>,
    map: Option<&Map>,
    editable: &mut Editable<'_>,
    actions: &mut Vec<Action>,
) {
    egui::Window::new("Strata")
        .default_pos(egui::pos2(8.0, 8.0))
        .default_width(300.0)
        .resizable(false)
        // As tall as the window allows; it scrolls beyond that.
        .default_height(ctx.content_rect().height() - 60.0)
        .vscroll(true)
        .show(ctx, |ui| panel_contents(ui, status, map, editable, actions));
}

fn panel_contents(
    ui: &mut egui::Ui,
    status: &Status<'_>,
    map: Option<&Map>,
    editable: &mut Editable<'_>,
    actions: &mut Vec<Action>,
) {
    ui.label(format!(
        "{} ({}, {})",
        status.adapter.name, status.adapter.backend, status.adapter.device_type
    ));
    ui.label(format!(
        "render {}x{}, window {}x{}",
        status.render_size.0, status.render_size.1, status.window_size.0, status.window_size.1
    ));
    ui.strong(format!(
        "{:.1} fps ({:.1} ms per frame)",
        1000.0 / status.frame_ms.max(1e-3),
        status.frame_ms
    ));
    section(ui, "GPU time per pass", true, |ui| timings(ui, status));
    if let Some(lines) = &status.paging {
        section(ui, "paged terrain", true, |ui| {
            for line in lines {
                ui.label(line);
            }
        });
    }
    methods_section(ui, status, editable, actions);
    section(ui, "settings", true, |ui| {
        knobs(ui, status, editable, actions)
    });
    section(ui, "camera and views", true, |ui| {
        views(ui, status, actions)
    });
    if let Some(map) = map {
        section(ui, "map (click to fly there)", true, |ui| {
            map_view(ui, map, status.camera, actions)
        });
    }
    section(ui, "dig (left click)", true, |ui| {
        ui.add(egui::Slider::new(editable.crater_radius, 2..=128).text("radius"));
        ui.horizontal(|ui| {
            ui.add(egui::Slider::new(editable.crater_depth, 5.0..=200.0).text("depth"));
            let undo = ui.add_enabled(
                status.undo_depth > 0,
                egui::Button::new(format!("undo ({})", status.undo_depth)),
            );
            if undo.clicked() {
                actions.push(Action::Undo);
            }
        });
    });
    section(ui, "accuracy (M)", false, |ui| {
        accuracy(ui, status, actions)
    });
    section(ui, "memory", false, |ui| memory(ui, status));
    ui.horizontal(|ui| {
        if ui.button("copy view").clicked() {
            actions.push(Action::CopyView);
        }
        if ui.button("screenshot").clicked() {
            actions.push(Action::Screenshot);
        }
    });
    for line in status.log.iter().rev().take(4).rev() {
        ui.small(line);
    }
    ui.collapsing("controls", |ui| {
        egui::Grid::new("controls").show(ui, |ui| {
            for (keys, what) in CONTROLS {
                ui.monospace(*keys);
                ui.label(*what);
                ui.end_row();
            }
        });
    });
}

/// A collapsible part of the panel.
fn section(ui: &mut egui::Ui, title: &str, open: bool, body: impl FnOnce(&mut egui::Ui)) {
    egui::CollapsingHeader::new(title)
        .default_open(open)
        .show(ui, body);
}

fn timings(ui: &mut egui::Ui, status: &Status<'_>) {
    egui::Grid::new("timings").striped(true).show(ui, |ui| {
        for drawn in &status.drawn {
            let t = drawn.timings;
            ui.strong(drawn.method);
            ui.label(match t.gpu_ms {
                Some(ms) => format!("GPU {ms:.2} ms"),
                None => "GPU: no timestamps".into(),
            });
            ui.label(format!("wait {:.1} ms", t.cpu_ms));
            ui.end_row();
            for (pass, ms) in &t.passes {
                ui.label(format!("  {pass}"));
                ui.label(format!("{ms:.3} ms"));
                ui.end_row();
            }
        }
    });
}

/// Why `name` cannot be drawn here: the adapter lacks what it needs, or
/// the world is paged and it draws whole worlds only.
fn refusal(status: &Status<'_>, name: &str) -> Option<String> {
    methods::check_support(name, status.caps)
        .err()
        .map(|e| format!("{e:#}"))
        .or_else(|| {
            status
                .paging
                .as_ref()
                .and_then(|_| crate::paged::refusal(name))
        })
}

fn methods_section(
    ui: &mut egui::Ui,
    status: &Status<'_>,
    editable: &mut Editable<'_>,
    actions: &mut Vec<Action>,
) {
    ui.label("method (keys 1 .. 9, 0)");
    ui.horizontal_wrapped(|ui| {
        for (i, name) in methods::names().into_iter().enumerate() {
            let refused = refusal(status, name);
            if let Some(why) = refused {
                ui.add_enabled(
                    false,
                    egui::Button::selectable(false, format!("{} {name} (unavailable)", i + 1)),
                )
                .on_disabled_hover_text(why);
                continue;
            }
            let building = status.building.iter().any(|b| b.method == name);
            let kept = status.kept.iter().any(|(m, _)| *m == name);
            let label = format!(
                "{} {name}{}",
                i + 1,
                if building {
                    " (building)"
                } else if kept {
                    ""
                } else {
                    " *"
                }
            );
            if ui
                .selectable_label(status.active == name, label)
                .on_hover_text(if kept {
                    "built and kept"
                } else if building {
                    "being built"
                } else {
                    "* built on first use"
                })
                .clicked()
            {
                actions.push(Action::Method(name.to_string()));
            }
        }
    });
    let unavailable: Vec<String> = methods::names()
        .into_iter()
        .filter_map(|name| refusal(status, name))
        .collect();
    if !unavailable.is_empty() {
        ui.collapsing(
            format!("{} unavailable on this adapter", unavailable.len()),
            |ui| {
                for line in unavailable {
                    ui.label(line);
                }
            },
        );
    }
    ui.horizontal(|ui| {
        let mut split = status.split.is_some();
        if ui.checkbox(&mut split, "A/B split").changed() {
            actions.push(Action::Split(
                split.then(|| other_method(status.active).to_string()),
            ));
        }
        if let Some(b) = status.split {
            egui::ComboBox::from_id_salt("split method")
                .selected_text(format!("right: {b}"))
                .show_ui(ui, |ui| {
                    for name in methods::names() {
                        if name != status.active && ui.selectable_label(b == name, name).clicked() {
                            actions.push(Action::Split(Some(name.to_string())));
                        }
                    }
                });
        }
    });
    if status.split.is_some() {
        ui.add(egui::Slider::new(editable.split_at, 0.05..=0.95).text("divider"));
    }
    for build in &status.building {
        build.show(ui, false);
    }
}

/// A method to compare with when none was chosen.
pub fn other_method(active: &str) -> &'static str {
    if active == "ray" { "mesh" } else { "ray" }
}

fn knobs(
    ui: &mut egui::Ui,
    status: &Status<'_>,
    editable: &mut Editable<'_>,
    actions: &mut Vec<Action>,
) {
    let shown: Vec<&str> = std::iter::once(status.active).chain(status.split).collect();
    let s = &mut *editable.settings;
    for k in Knob::all() {
        let response = match k {
            Knob::Method(slider) if shown.iter().any(|m| k.read_by(m)) => slider_ui(ui, slider, s),
            Knob::Method(_) => continue,
            Knob::Shadows => ui.checkbox(&mut s.shadows, "shadows"),
        };
        // Knobs methods take in place apply while dragging; the others (a
        // new mesh fit, in the background) when the drag ends or a click
        // changes them.
        let live = matches!(k, Knob::Method(slider) if slider.live) || k == Knob::Shadows;
        let live = live && response.changed();
        if live || response.drag_stopped() || (response.changed() && !response.dragged()) {
            actions.push(Action::Knob(k));
        }
    }
}

/// One method slider as its kind draws it.
fn slider_ui(
    ui: &mut egui::Ui,
    slider: &Slider,
    s: &mut strata_render::MethodSettings,
) -> egui::Response {
    let value = (slider.get)(s);
    match slider.kind {
        SliderKind::Count { min, max } => {
            let mut v = value as u32;
            let r = ui.add(egui::Slider::new(&mut v, min..=max).text(slider.label));
            (slider.put)(s, v as f32);
            r
        }
        SliderKind::Number { min, max } => {
            let mut v = value;
            let r = ui.add(egui::Slider::new(&mut v, min..=max).text(slider.label));
            (slider.put)(s, v);
            r
        }
        SliderKind::Toggle => {
            let mut on = value != 0.0;
            let r = ui.checkbox(&mut on, slider.label);
            (slider.put)(s, f32::from(u8::from(on)));
            r
        }
    }
}

fn views(ui: &mut egui::Ui, status: &Status<'_>, actions: &mut Vec<Action>) {
    let c = status.camera;
    ui.label(format!(
        "eye {:.0}, {:.0}, {:.0}  yaw {:.0}°  pitch {:.0}°  speed {:.0}",
        c.position.x, c.position.y, c.position.z, c.yaw_deg, c.pitch_deg, c.speed
    ));
    egui::ComboBox::from_id_salt("views")
        .selected_text("jump to view (F1-F12)")
        .show_ui(ui, |ui| {
            for (i, view) in status.views.iter().enumerate() {
                if ui
                    .selectable_label(false, format!("F{} {}", i + 1, view.name))
                    .clicked()
                {
                    actions.push(Action::View(i));
                }
            }
        });
}

fn accuracy(ui: &mut egui::Ui, status: &Status<'_>, actions: &mut Vec<Action>) {
    if ui
        .button("score this view against the CPU reference")
        .clicked()
    {
        actions.push(Action::Score);
    }
    egui::Grid::new("scores").striped(true).show(ui, |ui| {
        if !status.scores.is_empty() {
            for head in [
                "",
                "see-through",
                "covers sky",
                "depth p50/p95",
                "coherence",
            ] {
                ui.strong(head);
            }
            ui.end_row();
        }
        for (method, m) in status.scores {
            ui.label(method);
            ui.label(format!("{:.2} %", m.see_through));
            ui.label(format!("{:.2} %", m.covers_sky));
            ui.label(format!("{:.2} / {:.2}", m.depth_p50, m.depth_p95));
            ui.label(format!("{:.2} %", m.coherence));
            ui.end_row();
        }
    });
}

/// A square of the map around the eye (the map's full width), the eye and
/// its heading on it; a click flies there.
fn map_view(ui: &mut egui::Ui, map: &Map, camera: &FlyCamera, actions: &mut Vec<Action>) {
    let side = ui.available_width().min(220.0);
    let zoom = side / map.size.x;
    // Rows shown: as many map pixels as fit, centred on the eye, kept inside.
    let rows = (side / zoom).min(map.size.y);
    let eye = egui::vec2(camera.position.x, camera.position.y) / map.scale;
    let top = (eye.y - rows * 0.5).clamp(0.0, map.size.y - rows);
    let uv = egui::Rect::from_min_max(
        egui::pos2(0.0, top / map.size.y),
        egui::pos2(1.0, (top + rows) / map.size.y),
    );
    let response = ui.add(
        egui::Image::new((map.texture.id(), egui::vec2(side, rows * zoom)))
            .uv(uv)
            .sense(egui::Sense::click()),
    );
    let origin = response.rect.min;
    let at = origin + egui::vec2(eye.x, eye.y - top) * zoom;
    let (sin, cos) = camera.yaw_deg.to_radians().sin_cos();
    let painter = ui.painter_at(response.rect);
    let marker = egui::Color32::from_rgb(255, 220, 60);
    painter.line_segment(
        [at, at + egui::vec2(sin, cos) * 14.0],
        egui::Stroke::new(2.0, marker),
    );
    painter.circle_filled(at, 3.5, marker);
    if let Some(click) = response
        .interact_pointer_pos()
        .filter(|_| response.clicked())
    {
        let p = (click - origin) / zoom + egui::vec2(0.0, top);
        actions.push(Action::Teleport(glam::Vec2::new(p.x, p.y) * map.scale));
    }
}

fn memory(ui: &mut egui::Ui, status: &Status<'_>) {
    ui.label(format!(
        "shared frame (terrain, targets, shadow) {:.1} MiB GPU",
        status.shared_gpu_bytes as f64 / MIB
    ));
    egui::Grid::new("memory").show(ui, |ui| {
        for (method, bytes) in &status.kept {
            ui.label(*method);
            ui.label(format!("{:.1} MiB GPU", bytes.gpu as f64 / MIB));
            ui.label(format!("{:.2} MiB CPU", bytes.cpu as f64 / MIB));
            ui.end_row();
        }
    });
}
