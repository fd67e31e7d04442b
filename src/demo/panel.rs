//! The demo's panel, drawn with egui: scene and technique pickers, the comparison views, the
//! lights, the knobs, the per-pass GPU timing table, messages and the key list; and, over the
//! frame, the labels that say which side of a comparison is which.
//!
//! egui gets its input from the window's events through egui-winit ([`Gui::on_event`]); the
//! panel is built once per frame ([`super::Demo::run_ui`]) from the demo's state, and what the
//! user changes comes back as [`PanelAction`]s, applied by the same code the keys and scripts go
//! through, before the frame is rendered. The presenter draws the triangles egui makes into the
//! swapchain image after the frame, so screenshots never show the panel.

use egui::{Align2, Color32, FontId, Id, LayerId, Order, RichText, Stroke};
use glam::Vec3;
use winit::event::WindowEvent;
use winit::window::Window;

use super::controls::{self, Action, Comparison, INTENSITY_RANGE, KNOBS};
use super::Demo;
use crate::features::debug_view::DebugView;
use crate::frame::Technique;
use crate::scene::BUILTIN_SCENES;

/// Colour of error messages.
const ERROR: Color32 = Color32::from_rgb(255, 110, 100);
/// Colour of the comparison labels' text.
const LABEL: Color32 = Color32::from_rgb(255, 215, 100);

/// egui's context and its window-event translator.
pub(super) struct Gui {
    pub(super) ctx: egui::Context,
    pub(super) state: egui_winit::State,
}

impl Gui {
    pub(super) fn new(window: &Window) -> Self {
        let ctx = egui::Context::default();
        let state = egui_winit::State::new(
            ctx.clone(),
            egui::ViewportId::ROOT,
            window,
            Some(window.scale_factor() as f32),
            None,
            None,
        );
        Self { ctx, state }
    }

    /// Hands a window event to egui.
    pub(super) fn on_event(&mut self, window: &Window, event: &WindowEvent) {
        // Whether egui "consumed" it is decided per kind of input by the caller
        // (`wants_pointer`, `wants_keys`): a focused slider must not swallow the demo's keys.
        let _ = self.state.on_window_event(window, event);
    }

    /// Whether the pointer is over the panel or dragging one of its widgets: the camera
    /// leaves the mouse alone then.
    pub(super) fn wants_pointer(&self) -> bool {
        self.ctx.is_pointer_over_egui() || self.ctx.egui_is_using_pointer()
    }

    /// Whether a text field has the keyboard: the demo's keys do nothing then.
    pub(super) fn wants_keys(&self) -> bool {
        self.ctx.text_edit_focused()
    }
}

/// A change asked for in the panel.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum PanelAction {
    /// What a key does.
    Act(Action),
    /// Switch to this technique.
    Technique(Technique),
    /// Load this built-in scene.
    Scene(String),
    /// Select this light.
    SelectLight(usize),
    /// The selected light's position (direction for a directional light).
    LightVector(Vec3),
    /// The selected light's intensity.
    LightIntensity(f32),
    /// Set knob N to this value.
    Knob(usize, f32),
}

impl Demo<'_> {
    /// Builds the frame's UI into `ui` (covering the window); pushes what the user changed.
    pub(super) fn panel_ui(&self, ui: &mut egui::Ui, actions: &mut Vec<PanelAction>) {
        self.comparison_labels(ui);
        let ctx = ui.ctx().clone();
        if self.view.help {
            egui::Window::new("keys")
                .anchor(Align2::RIGHT_TOP, [-8.0, 8.0])
                .vscroll(true)
                .show(&ctx, key_list);
        }
        if self.view.hidden {
            return;
        }
        let max_height = (ui.max_rect().height() - 24.0).max(80.0);
        egui::Window::new("lucent")
            .default_pos([8.0, 8.0])
            .min_width(330.0)
            .default_height(max_height)
            .max_height(max_height)
            .vscroll(true)
            .show(&ctx, |ui| {
                self.header_ui(ui, actions);
                ui.separator();
                self.view_ui(ui, actions);
                egui::CollapsingHeader::new("lights")
                    .default_open(true)
                    .show(ui, |ui| self.lights_ui(ui, actions));
                egui::CollapsingHeader::new("knobs")
                    .default_open(true)
                    .show(ui, |ui| self.knobs_ui(ui, actions));
                egui::CollapsingHeader::new("GPU time per pass")
                    .default_open(true)
                    .show(ui, |ui| self.timing_ui(ui, actions));
                if let Some((message, error)) = &self.view.message {
                    ui.separator();
                    let text = RichText::new(message);
                    ui.label(if *error { text.color(ERROR) } else { text });
                }
                let mut help = self.view.help;
                if ui.checkbox(&mut help, "key list (F1)").changed() {
                    actions.push(PanelAction::Act(Action::ToggleHelp));
                }
            });
    }

    /// Which side of a comparison is which, at the bottom of each side, and the divider.
    fn comparison_labels(&self, ui: &egui::Ui) {
        if !self.comparison.active() {
            return;
        }
        let painter = ui.ctx().layer_painter(LayerId::new(
            Order::Background,
            Id::new("comparison labels"),
        ));
        let rect = ui.max_rect();
        let (left, right) = self.comparison.labels(self.technique_name());
        let font = FontId::proportional(14.0);
        let label = |text: &str, x: f32| {
            let galley = painter.layout_no_wrap(text.to_string(), font.clone(), LABEL);
            let size = galley.size();
            let at = Align2::CENTER_BOTTOM
                .anchor_size(egui::pos2(x, rect.bottom() - 6.0), size)
                .min;
            painter.rect_filled(
                egui::Rect::from_min_size(at, size).expand(4.0),
                3.0,
                Color32::from_black_alpha(190),
            );
            painter.galley(at, galley, LABEL);
        };
        match right {
            Some(right) => {
                let mid = rect.center().x;
                painter.vline(mid, rect.y_range(), Stroke::new(2.0, Color32::WHITE));
                label(&left, (rect.left() + mid) / 2.0);
                label(&right, (mid + rect.right()) / 2.0);
            }
            None => label(&left, rect.center().x),
        }
    }

    /// The technique the frame shows, by name (the renderer's when there is one: `auto`
    /// resolves to what the scene asks for).
    pub(super) fn technique_name(&self) -> &'static str {
        self.renderer
            .as_ref()
            .map_or(self.technique.name(), |r| r.settings.technique.name())
    }

    fn header_ui(&self, ui: &mut egui::Ui, actions: &mut Vec<PanelAction>) {
        let (w, h) = self
            .presenter
            .as_ref()
            .map_or((0, 0), |p| (p.extent.width, p.extent.height));
        let mode = self
            .presenter
            .as_ref()
            .map_or("?".to_string(), |p| format!("{:?}", p.present_mode));
        ui.label(format!("{w}x{h}, {mode}"));
        egui::ComboBox::from_label("scene")
            .selected_text(self.scene.name.as_str())
            .show_ui(ui, |ui| {
                for (name, about) in BUILTIN_SCENES {
                    let chosen = ui
                        .selectable_label(self.scene.name == *name, *name)
                        .on_hover_text(*about);
                    if chosen.clicked() && self.scene.name != *name {
                        actions.push(PanelAction::Scene((*name).to_string()));
                    }
                }
            });
        // The assets' licences (CC BY) ask for credit wherever they are shown.
        for credit in &self.scene.credits {
            ui.label(egui::RichText::new(credit).small());
        }
        egui::ComboBox::from_label("technique (T)")
            .selected_text(self.technique.name())
            .show_ui(ui, |ui| {
                for (name, technique) in Technique::all() {
                    if ui
                        .selectable_label(self.technique == technique, name)
                        .on_hover_text(technique.summary())
                        .clicked()
                        && self.technique != technique
                    {
                        actions.push(PanelAction::Technique(technique));
                    }
                }
            });
        if self.technique == Technique::Auto {
            ui.label(format!("auto: {}", self.technique_name()));
        }
    }

    fn view_ui(&self, ui: &mut egui::Ui, actions: &mut Vec<PanelAction>) {
        let Comparison {
            mut split,
            mut difference,
        } = self.comparison;
        if ui
            .checkbox(
                &mut split,
                "split view (C): left plain lighting, right technique",
            )
            .changed()
        {
            actions.push(PanelAction::Act(Action::ToggleSplit));
        }
        if ui
            .checkbox(&mut difference, "difference x4 (X): |technique - plain|")
            .changed()
        {
            actions.push(PanelAction::Act(Action::ToggleDifference));
        }
        ui.horizontal(|ui| {
            let shown = self.renderer.as_ref().and_then(|r| r.settings.debug_view);
            if ui
                .button(format!(
                    "view: {} (V)",
                    shown.map_or("frame", DebugView::name)
                ))
                .clicked()
            {
                actions.push(PanelAction::Act(Action::CycleDebugView));
            }
            if let Some(mode) = controls::pow_mode(&self.scene) {
                let name = controls::POW_MODES
                    .iter()
                    .find(|(m, _)| *m == mode)
                    .map_or("?", |(_, n)| n);
                if ui.button(format!("pow: {name} (P)")).clicked() {
                    actions.push(PanelAction::Act(Action::CyclePow));
                }
            }
        });
        ui.horizontal(|ui| {
            if ui.button("reset camera (R)").clicked() {
                actions.push(PanelAction::Act(Action::ResetCamera));
            }
            if ui.button("screenshot (F12)").clicked() {
                actions.push(PanelAction::Act(Action::Screenshot));
            }
            if ui.button("reload shaders (F5)").clicked() {
                actions.push(PanelAction::Act(Action::ReloadShaders));
            }
        });
    }

    fn lights_ui(&self, ui: &mut egui::Ui, actions: &mut Vec<PanelAction>) {
        let lights = &self.scene.lights;
        let Some(light) = lights.get(self.light) else {
            ui.label("this scene has no light");
            return;
        };
        let describe = |i: usize| format!("{}: {}", i + 1, controls::light_kind_name(&lights[i]));
        egui::ComboBox::from_label("light (L)")
            .selected_text(describe(self.light))
            .show_ui(ui, |ui| {
                for i in 0..lights.len() {
                    if ui.selectable_label(i == self.light, describe(i)).clicked() {
                        actions.push(PanelAction::SelectLight(i));
                    }
                }
            });
        let v = controls::light_vector(light);
        let directional = matches!(light.kind, crate::scene::LightKind::Directional { .. });
        let mut edited = v;
        ui.horizontal(|ui| {
            ui.label(if directional { "direction" } else { "position" });
            let speed = if directional {
                0.01
            } else {
                0.01 * f64::from(self.orbit.distance)
            };
            for (value, axis) in [
                (&mut edited.x, "x "),
                (&mut edited.y, "y "),
                (&mut edited.z, "z "),
            ] {
                ui.add(egui::DragValue::new(value).speed(speed).prefix(axis));
            }
        });
        if edited != v {
            actions.push(PanelAction::LightVector(edited));
        }
        let mut intensity = light.intensity;
        if ui
            .add(
                egui::Slider::new(&mut intensity, INTENSITY_RANGE.0..=INTENSITY_RANGE.1)
                    .logarithmic(true)
                    .text("intensity ([ ])"),
            )
            .changed()
        {
            actions.push(PanelAction::LightIntensity(intensity));
        }
        ui.label("move: arrows (screen), Shift+Up/Down (depth)");
    }

    fn knobs_ui(&self, ui: &mut egui::Ui, actions: &mut Vec<PanelAction>) {
        for (i, knob) in KNOBS.iter().enumerate() {
            let Some(mut value) = (knob.get)(&self.scene, &self.options.base) else {
                continue;
            };
            let selected = if i == self.view.knob { " (+/-)" } else { "" };
            let slider = egui::Slider::new(&mut value, knob.range.0..=knob.range.1)
                .logarithmic(!knob.additive)
                .text(format!("{} {}{selected}", i + 1, knob.name));
            if ui.add(slider).changed() {
                actions.push(PanelAction::Knob(i, value));
            }
        }
    }

    fn timing_ui(&self, ui: &mut egui::Ui, actions: &mut Vec<PanelAction>) {
        let mut isolated = self.isolated;
        if ui
            .checkbox(&mut isolated, "each pass isolated, as bench --isolate (I)")
            .changed()
        {
            actions.push(PanelAction::Act(Action::ToggleTiming));
        }
        ui.label(format!(
            "mean of {} frames{}",
            self.stats.shown_frames,
            if self.comparison.active() {
                "; the plain frame of the comparison is not timed"
            } else {
                ""
            }
        ));
        egui::Grid::new("timings")
            .num_columns(2)
            .striped(true)
            .show(ui, |ui| {
                let mut total = 0.0;
                for (name, ms) in &self.stats.shown {
                    total += ms;
                    ui.label(name);
                    ui.monospace(format!("{ms:8.3} ms"));
                    ui.end_row();
                }
                ui.strong("sum of passes");
                ui.monospace(format!("{total:8.3} ms"));
                ui.end_row();
                let wall = self.stats.shown_wall;
                ui.label("frame (CPU wall)");
                ui.monospace(format!(
                    "{wall:8.3} ms ({:.1} fps)",
                    if wall > 0.0 { 1e3 / wall } else { 0.0 }
                ));
                ui.end_row();
            });
    }
}

/// The key list, as its own window (F1).
fn key_list(ui: &mut egui::Ui) {
    egui::Grid::new("keys").num_columns(2).show(ui, |ui| {
        for k in controls::KEYS {
            ui.monospace(k.name);
            ui.label(k.help);
            ui.end_row();
        }
        for (k, h) in controls::CAMERA_HELP {
            ui.monospace(*k);
            ui.label(*h);
            ui.end_row();
        }
    });
}
