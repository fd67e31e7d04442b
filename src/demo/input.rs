//! The demo's input: window events, keys and mouse, the actions they map to, and the script
//! commands that drive the same actions in tests and recordings.

use std::path::PathBuf;

use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::ActiveEventLoop;
use winit::keyboard::{KeyCode, PhysicalKey};

use super::controls::{self, Action, KNOBS};
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
                self.input.held.insert(code);
                if event.repeat && !matches!(code, KeyCode::Equal | KeyCode::Minus) {
                    return Ok(());
                }
                if let Some(action) = key_action(code, self.input.shift) {
                    self.act(event_loop, action)?;
                }
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let down = state == ElementState::Pressed;
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
            WindowEvent::MouseWheel { delta, .. } => {
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
                let all = Technique::ALL;
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
                        (knob.set)(&mut self.scene, &mut self.options.base, next);
                        // Values only (lights, material and profile tables): the next frame
                        // writes them into its per-frame slot. A new shape (two materials'
                        // parameters became equal, or apart) needs a new frame.
                        let in_place = match self.renderer.as_mut() {
                            Some(r) => r.retune(&self.options.base) && r.can_update(&self.scene)?,
                            None => false,
                        };
                        if knob.rebuild || !in_place {
                            self.rebuild_pending = true;
                        }
                    }
                    None => self.say(format!("nothing in this scene uses {}", knob.name), false),
                }
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

/// The action of a key press (camera keys are held, not actions).
pub(super) fn key_action(code: KeyCode, shift: bool) -> Option<Action> {
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
    controls::action_named(name)
}
