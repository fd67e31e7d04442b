//! The demo's input: window events, keys and mouse, the actions they map to, and the script
//! commands that drive the same actions in tests and recordings.

use std::path::PathBuf;

use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::ActiveEventLoop;
use winit::keyboard::{KeyCode, PhysicalKey};

use super::controls::{self, Action, LightMove, KNOBS};
use super::script::Command;
use super::{Demo, FLY_SPEED, ORBIT_PER_PIXEL};
use crate::frame::Technique;
use crate::{LucentError, Result};

impl Demo<'_> {
    pub(super) fn on_event(
        &mut self,
        event_loop: &ActiveEventLoop,
        event: WindowEvent,
    ) -> Result<()> {
        if let (Some(window), Some(gui)) = (self.window.as_ref(), self.gui.as_mut()) {
            gui.on_event(window, &event);
        }
        let panel_pointer = self.gui.as_ref().is_some_and(|g| g.wants_pointer());
        let panel_keys = self.gui.as_ref().is_some_and(|g| g.wants_keys());
        match event {
            WindowEvent::CloseRequested => {
                self.done = true;
                event_loop.exit();
            }
            WindowEvent::Resized(size) => {
                self.window_zero = size.width == 0 || size.height == 0;
                self.resize_pending = true;
            }
            WindowEvent::ScaleFactorChanged { .. } => {
                // The new physical size follows as a Resized event; the swapchain follows it.
                self.resize_pending = true;
            }
            WindowEvent::ModifiersChanged(m) => self.input.shift = m.state().shift_key(),
            WindowEvent::KeyboardInput { event, .. } => {
                let PhysicalKey::Code(code) = event.physical_key else {
                    return Ok(());
                };
                if event.state == ElementState::Released {
                    self.input.held.remove(&code);
                    return Ok(());
                }
                // Typing into one of the panel's fields: the keys are the field's.
                if panel_keys {
                    return Ok(());
                }
                self.input.held.insert(code);
                if event.repeat && !repeats(code) {
                    return Ok(());
                }
                if let Some(action) = key_action(code, self.input.shift) {
                    self.act(event_loop, action)?;
                }
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let down = state == ElementState::Pressed;
                // A press on the panel is the panel's; a release always ends a drag.
                if down && panel_pointer {
                    return Ok(());
                }
                match button {
                    MouseButton::Left => self.input.orbiting = down,
                    MouseButton::Right | MouseButton::Middle => self.input.panning = down,
                    _ => {}
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                let (x, y) = (position.x, position.y);
                if let Some((px, py)) = self.input.cursor {
                    let (dx, dy) = ((x - px) as f32, (y - py) as f32);
                    if self.input.orbiting {
                        self.orbit
                            .orbit(-dx * ORBIT_PER_PIXEL, dy * ORBIT_PER_PIXEL);
                    } else if self.input.panning {
                        let height = self.window.as_ref().map_or(1, |w| w.inner_size().height);
                        // Guarded: a zero-height window reports motion too.
                        let h = height.max(1) as f32;
                        self.orbit.pan(-dx / h, dy / h);
                    }
                }
                self.input.cursor = Some((x, y));
            }
            WindowEvent::MouseWheel { delta, .. } if !panel_pointer => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 50.0,
                };
                self.orbit.zoom(0.9f32.powf(lines));
            }
            _ => {}
        }
        Ok(())
    }

    /// Carries out one action (a key, or a script's `key`).
    pub(super) fn act(&mut self, event_loop: &ActiveEventLoop, action: Action) -> Result<()> {
        match action {
            Action::NextTechnique | Action::PreviousTechnique => {
                let all = Technique::all();
                let i = all
                    .iter()
                    .position(|(_, t)| *t == self.technique)
                    .unwrap_or(0);
                let next = if action == Action::NextTechnique {
                    (i + 1) % all.len()
                } else {
                    (i + all.len() - 1) % all.len()
                };
                self.technique = all[next].1;
                self.rebuild_pending = true;
            }
            Action::CyclePow => match controls::cycle_pow_mode(&mut self.scene) {
                Some(name) => {
                    self.say(format!("pow form: {name}"), false);
                    self.rebuild_pending = true;
                }
                None => self.say("no translucent material in this scene".into(), false),
            },
            Action::CycleDebugView => {
                self.debug_view = self.next_debug_view();
                self.rebuild_pending = true;
            }
            Action::SelectKnob(i) => self.view.knob = i.min(KNOBS.len() - 1),
            Action::KnobUp | Action::KnobDown => {
                let knob = &KNOBS[self.view.knob];
                match (knob.get)(&self.scene, &self.options.base) {
                    Some(value) => {
                        let next = knob.stepped(value, action == Action::KnobUp);
                        self.set_knob(self.view.knob, next)?;
                    }
                    None => self.say(format!("nothing in this scene uses {}", knob.name), false),
                }
            }
            Action::NextLight | Action::PreviousLight => {
                let next = controls::cycle_light(
                    self.light,
                    self.scene.lights.len(),
                    action == Action::NextLight,
                );
                self.select_light(next);
            }
            Action::MoveLight(dir) => self.move_light(dir)?,
            Action::LightBrighter | Action::LightDimmer => {
                let Some(light) = self.scene.lights.get_mut(self.light) else {
                    self.say("this scene has no light".into(), false);
                    return Ok(());
                };
                light.intensity =
                    controls::stepped_intensity(light.intensity, action == Action::LightBrighter);
                let message = format!("light {} intensity {:.4}", self.light + 1, light.intensity);
                self.values_changed()?;
                self.say(message, false);
            }
            Action::ToggleSplit | Action::ToggleDifference => {
                let was = self.comparison;
                if action == Action::ToggleSplit {
                    self.comparison.split = !self.comparison.split;
                } else {
                    self.comparison.difference = !self.comparison.difference;
                }
                if !self.comparison.active() && was.active() {
                    // Nothing compares any more: the second renderer goes (the GPU is idle
                    // between frames).
                    self.gpu.wait_idle()?;
                    self.drop_comparison();
                }
                let (left, right) = self.comparison.labels(self.technique_name());
                let text = match right {
                    Some(right) => format!("{left} | {right}"),
                    None => left,
                };
                self.say(text, false);
            }
            Action::ResetCamera => self.orbit.reset(),
            Action::ToggleHelp => self.view.help = !self.view.help,
            Action::ToggleOverlay => self.view.hidden = !self.view.hidden,
            Action::Screenshot => {
                self.screenshots_taken += 1;
                self.screenshot_pending.push(PathBuf::from(format!(
                    "lucent-screenshot-{}.png",
                    self.screenshots_taken
                )));
            }
            Action::ReloadShaders => self.rebuild_pending = true,
            Action::ToggleTiming => {
                self.isolated = !self.isolated;
                self.stats.clear();
            }
            Action::Quit => {
                self.done = true;
                event_loop.exit();
            }
        }
        Ok(())
    }

    /// Sets knob `index` to `value` (clamped to its range) everywhere it applies.
    pub(super) fn set_knob(&mut self, index: usize, value: f32) -> Result<()> {
        let Some(knob) = KNOBS.get(index) else {
            return Ok(());
        };
        let value = value.clamp(knob.range.0, knob.range.1);
        (knob.set)(&mut self.scene, &mut self.options.base, value);
        // Values only (lights, material and profile tables): the next frame writes them into
        // its per-frame slot. A new shape (two materials' parameters became equal, or apart)
        // needs a new frame.
        if knob.rebuild {
            self.rebuild_pending = true;
        }
        self.values_changed()
    }

    /// Selects light `index` (when the scene has it).
    pub(super) fn select_light(&mut self, index: usize) {
        let Some(light) = self.scene.lights.get(index) else {
            self.say("this scene has no such light".into(), false);
            return;
        };
        let kind = controls::light_kind_name(light);
        self.light = index;
        self.say(format!("light {} ({kind}) selected", index + 1), false);
    }

    /// Moves the selected light one step in the camera's frame.
    fn move_light(&mut self, dir: LightMove) -> Result<()> {
        let (basis, distance) = (self.orbit.basis(), self.orbit.distance);
        let Some(light) = self.scene.lights.get_mut(self.light) else {
            self.say("this scene has no light".into(), false);
            return Ok(());
        };
        if !controls::move_light(light, dir, basis, distance) {
            self.say(
                "a directional light has no position: it tilts left, right, up and down".into(),
                false,
            );
            return Ok(());
        }
        let v = controls::light_vector(light);
        let message = format!(
            "light {} {} {:.3} {:.3} {:.3}",
            self.light + 1,
            if matches!(light.kind, crate::scene::LightKind::Directional { .. }) {
                "direction"
            } else {
                "at"
            },
            v.x,
            v.y,
            v.z
        );
        self.values_changed()?;
        self.say(message, false);
        Ok(())
    }

    pub(super) fn say(&mut self, message: String, error: bool) {
        if error {
            log::error!("{message}");
        } else {
            log::info!("{message}");
        }
        self.view.message = Some((message, error));
    }

    pub(super) fn run_script(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let Some(script) = self.script.as_mut() else {
            return Ok(());
        };
        for command in script.due(self.tick) {
            log::info!("script tick {}: {command:?}", self.tick);
            match command {
                Command::Resize(w, h) => {
                    let window = self.window.as_ref();
                    if w == 0 || h == 0 {
                        // A window system may refuse a zero size (X11 does): the demo enters
                        // the zero-size state itself and asks the window system to minimize.
                        self.minimized_by_script = true;
                        if let Some(window) = window {
                            window.set_minimized(true);
                        }
                    } else {
                        self.minimized_by_script = false;
                        if let Some(window) = window {
                            window.set_minimized(false);
                            // Applied now (Some) or later through a Resized event (None).
                            let _ = window.request_inner_size(PhysicalSize::new(w, h));
                        }
                    }
                    self.resize_pending = true;
                }
                Command::Technique(name) => {
                    self.technique = Technique::parse(&name)
                        .map_err(|e| LucentError::InvalidInput(format!("script: {e}")))?;
                    self.rebuild_pending = true;
                }
                Command::Orbit(dx, dy) => self.orbit.orbit(dx, dy),
                Command::Zoom(f) => self.orbit.zoom(f),
                Command::Pan(dx, dy) => self.orbit.pan(dx, dy),
                Command::Fly(f, r, u) => self.orbit.fly(f, r, u),
                Command::Reset => self.orbit.reset(),
                Command::Key(name) => {
                    let action = controls::action_named(&name).ok_or_else(|| {
                        LucentError::InvalidInput(format!(
                            "script: unknown key '{name}'; known: {}",
                            controls::KEYS
                                .iter()
                                .map(|k| k.name)
                                .collect::<Vec<_>>()
                                .join(", ")
                        ))
                    })?;
                    self.act(event_loop, action)?;
                }
                Command::Screenshot(path) => self.screenshot_pending.push(path),
                Command::Quit => {
                    self.done = true;
                    event_loop.exit();
                }
            }
        }
        Ok(())
    }

    pub(super) fn fly(&mut self, dt: f32) {
        let held = |k| self.input.held.contains(&k);
        let axis = |plus, minus| f32::from(u8::from(held(plus))) - f32::from(u8::from(held(minus)));
        let forward = axis(KeyCode::KeyW, KeyCode::KeyS);
        let right = axis(KeyCode::KeyD, KeyCode::KeyA);
        let up = axis(KeyCode::KeyE, KeyCode::KeyQ);
        if forward != 0.0 || right != 0.0 || up != 0.0 {
            let step = FLY_SPEED * self.orbit.distance * dt;
            self.orbit.fly(forward * step, right * step, up * step);
        }
    }
}

/// Whether holding `code` repeats its action (steps of a value; toggles do not repeat).
fn repeats(code: KeyCode) -> bool {
    matches!(
        code,
        KeyCode::Equal
            | KeyCode::Minus
            | KeyCode::ArrowLeft
            | KeyCode::ArrowRight
            | KeyCode::ArrowUp
            | KeyCode::ArrowDown
            | KeyCode::BracketLeft
            | KeyCode::BracketRight
    )
}

/// The action of a key press (camera keys are held, not actions).
pub(super) fn key_action(code: KeyCode, shift: bool) -> Option<Action> {
    controls::action_named(key_name(code, shift)?)
}

/// The name (as the key list and scripts write it) of a key press, if it has an action.
fn key_name(code: KeyCode, shift: bool) -> Option<&'static str> {
    let name = match code {
        KeyCode::F1 => "F1",
        KeyCode::KeyT if shift => "Shift+T",
        KeyCode::KeyT => "T",
        KeyCode::KeyP => "P",
        KeyCode::KeyV => "V",
        KeyCode::Digit1 | KeyCode::Numpad1 => "1",
        KeyCode::Digit2 | KeyCode::Numpad2 => "2",
        KeyCode::Digit3 | KeyCode::Numpad3 => "3",
        KeyCode::Digit4 | KeyCode::Numpad4 => "4",
        KeyCode::Digit5 | KeyCode::Numpad5 => "5",
        KeyCode::Digit6 | KeyCode::Numpad6 => "6",
        KeyCode::Digit7 | KeyCode::Numpad7 => "7",
        KeyCode::Digit8 | KeyCode::Numpad8 => "8",
        KeyCode::KeyL if shift => "Shift+L",
        KeyCode::KeyL => "L",
        KeyCode::ArrowLeft => "Left",
        KeyCode::ArrowRight => "Right",
        KeyCode::ArrowUp if shift => "Shift+Up",
        KeyCode::ArrowUp => "Up",
        KeyCode::ArrowDown if shift => "Shift+Down",
        KeyCode::ArrowDown => "Down",
        KeyCode::BracketRight => "]",
        KeyCode::BracketLeft => "[",
        KeyCode::KeyC => "C",
        KeyCode::KeyX => "X",
        KeyCode::Equal | KeyCode::NumpadAdd | KeyCode::PageUp => "+",
        KeyCode::Minus | KeyCode::NumpadSubtract | KeyCode::PageDown => "-",
        KeyCode::KeyR => "R",
        KeyCode::KeyH => "H",
        KeyCode::KeyI => "I",
        KeyCode::F5 => "F5",
        KeyCode::F12 => "F12",
        KeyCode::Escape => "Esc",
        _ => return None,
    };
    Some(name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::demo::controls::Comparison;

    #[test]
    fn every_key_of_the_list_has_a_keyboard_key_and_back() {
        let codes = [
            KeyCode::F1,
            KeyCode::KeyT,
            KeyCode::KeyP,
            KeyCode::KeyV,
            KeyCode::Digit1,
            KeyCode::Digit2,
            KeyCode::Digit3,
            KeyCode::Digit4,
            KeyCode::Digit5,
            KeyCode::Digit6,
            KeyCode::Digit7,
            KeyCode::Digit8,
            KeyCode::Equal,
            KeyCode::Minus,
            KeyCode::KeyL,
            KeyCode::ArrowLeft,
            KeyCode::ArrowRight,
            KeyCode::ArrowUp,
            KeyCode::ArrowDown,
            KeyCode::BracketLeft,
            KeyCode::BracketRight,
            KeyCode::KeyC,
            KeyCode::KeyX,
            KeyCode::KeyR,
            KeyCode::KeyH,
            KeyCode::KeyI,
            KeyCode::F5,
            KeyCode::F12,
            KeyCode::Escape,
        ];
        let mut named: Vec<&str> = Vec::new();
        for code in codes {
            for shift in [false, true] {
                let name = key_name(code, shift).unwrap_or_else(|| panic!("{code:?}"));
                assert_eq!(
                    key_action(code, shift),
                    controls::action_named(name),
                    "{name}"
                );
                named.push(name);
            }
        }
        // Every key of the list is reachable from the keyboard.
        for k in controls::KEYS {
            assert!(named.contains(&k.name), "no keyboard key for {}", k.name);
        }
        assert_eq!(
            key_action(KeyCode::ArrowUp, true),
            Some(Action::MoveLight(LightMove::Forward))
        );
        assert_eq!(
            key_action(KeyCode::ArrowUp, false),
            Some(Action::MoveLight(LightMove::Up))
        );
        assert_eq!(key_action(KeyCode::KeyL, true), Some(Action::PreviousLight));
        assert_eq!(key_action(KeyCode::KeyC, false), Some(Action::ToggleSplit));
        assert_eq!(
            key_action(KeyCode::KeyX, false),
            Some(Action::ToggleDifference)
        );
        assert_eq!(key_action(KeyCode::KeyW, false), None);
        // Steps repeat while held; toggles do not.
        assert!(repeats(KeyCode::ArrowLeft) && repeats(KeyCode::BracketRight));
        assert!(!repeats(KeyCode::KeyC) && !repeats(KeyCode::KeyT));
    }

    #[test]
    fn comparison_labels_say_which_side_is_which() {
        let split = Comparison {
            split: true,
            difference: false,
        };
        let (left, right) = split.labels("translucency");
        assert_eq!(left, "left: plain lighting (none)");
        assert_eq!(right.as_deref(), Some("right: translucency"));
        let both = Comparison {
            split: true,
            difference: true,
        };
        assert!(both
            .labels("lbb")
            .1
            .unwrap()
            .contains("difference |lbb - plain| x4"));
        assert!(!Comparison::default().active());
    }
}
