//! What the demo's input does: the orbit/fly camera, the tunable knobs, and the key list.
//!
//! Nothing here knows about windows: keys are named by [`Action`]s (the window module maps
//! keyboard keys to them, and scripts name them by [`KeyBinding::name`]), so the camera and
//! the knobs are tested without a display.

use glam::Vec3;

use crate::frame::FrameSettings;
use crate::scene::material::PowMode;
use crate::scene::{Camera, Light, LightKind, Scene};

/// Smallest camera distance to its target: zooming further in would make the view matrix
/// degenerate (eye == target).
const MIN_DISTANCE: f32 = 1e-3;
/// Largest camera distance to its target.
const MAX_DISTANCE: f32 = 1e5;
/// Pitch stays this far from straight up or down, where `look_at` with +Y up degenerates.
const MAX_PITCH_DEGREES: f32 = 89.0;

/// An orbit camera around a target, with panning and flying, seeded from a scene's camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    /// Point looked at.
    pub target: Vec3,
    /// Turn around +Y, degrees.
    pub yaw: f32,
    /// Elevation, degrees (positive: looking down from above).
    pub pitch: f32,
    /// Distance from eye to target.
    pub distance: f32,
    initial: (Vec3, f32, f32, f32),
}

impl OrbitCamera {
    /// The orbit that reproduces `camera` exactly (eye and target).
    pub fn from_camera(camera: &Camera) -> Self {
        let offset = camera.eye - camera.target;
        // Guarded: a scene camera with eye == target has no direction; look along -Z then.
        let distance = offset.length().clamp(MIN_DISTANCE, MAX_DISTANCE);
        let dir = if offset.length() > 0.0 {
            offset / offset.length()
        } else {
            Vec3::Z
        };
        let pitch = dir.y.clamp(-1.0, 1.0).asin().to_degrees();
        let yaw = dir.x.atan2(dir.z).to_degrees();
        Self {
            target: camera.target,
            yaw,
            pitch,
            distance,
            initial: (camera.target, yaw, pitch, distance),
        }
    }

    /// Eye position.
    pub fn eye(&self) -> Vec3 {
        let (yaw, pitch) = (self.yaw.to_radians(), self.pitch.to_radians());
        self.target
            + self.distance
                * Vec3::new(
                    pitch.cos() * yaw.sin(),
                    pitch.sin(),
                    pitch.cos() * yaw.cos(),
                )
    }

    /// Writes eye and target into `camera` (field of view and planes stay).
    pub fn apply(&self, camera: &mut Camera) {
        camera.eye = self.eye();
        camera.target = self.target;
    }

    /// Turns around the target.
    pub fn orbit(&mut self, yaw_degrees: f32, pitch_degrees: f32) {
        self.yaw = (self.yaw + yaw_degrees) % 360.0;
        self.pitch = (self.pitch + pitch_degrees).clamp(-MAX_PITCH_DEGREES, MAX_PITCH_DEGREES);
    }

    /// Multiplies the distance to the target by `factor`.
    pub fn zoom(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.distance = (self.distance * factor).clamp(MIN_DISTANCE, MAX_DISTANCE);
        }
    }

    /// Moves eye and target in the view plane by `dx`, `dy` times the distance.
    pub fn pan(&mut self, dx: f32, dy: f32) {
        let (_, right, up) = self.basis();
        self.target += (right * dx + up * dy) * self.distance;
    }

    /// Moves eye and target forward, right and up (world units).
    pub fn fly(&mut self, forward: f32, right: f32, up: f32) {
        let (f, r, u) = self.basis();
        self.target += f * forward + r * right + u * up;
    }

    /// Back to the camera it was created from.
    pub fn reset(&mut self) {
        (self.target, self.yaw, self.pitch, self.distance) = self.initial;
    }

    /// Forward, right and up of the view (unit vectors; right is horizontal).
    pub fn basis(&self) -> (Vec3, Vec3, Vec3) {
        let forward = (self.target - self.eye()).normalize_or(Vec3::NEG_Z);
        let right = forward.cross(Vec3::Y).normalize_or(Vec3::X);
        let up = right.cross(forward);
        (forward, right, up)
    }
}

/// A scene parameter the demo's keys adjust.
pub struct Knob {
    /// Name shown on screen.
    pub name: &'static str,
    /// Added per key press (additive knobs) or multiplied (the others).
    pub step: f32,
    /// Whether `step` is added (true) or multiplied.
    pub additive: bool,
    /// Range the value is clamped to (the scene validation's range).
    pub range: (f32, f32),
    /// The value in this scene and frame settings; `None` when nothing in the scene uses it.
    pub get: fn(&Scene, &FrameSettings) -> Option<f32>,
    /// Writes the value everywhere it applies.
    pub set: fn(&mut Scene, &mut FrameSettings, f32),
    /// Whether a change needs the renderer rebuilt (it changes passes or shader
    /// permutations); the others only change values of the per-frame parameters (uniforms,
    /// the material and profile tables), which the next frame writes without re-uploading
    /// the scene.
    pub rebuild: bool,
}

impl Knob {
    /// The value one press up (`up`) or down from `value`, clamped to the range.
    pub fn stepped(&self, value: f32, up: bool) -> f32 {
        let next = match (self.additive, up) {
            (true, true) => value + self.step,
            (true, false) => value - self.step,
            (false, true) => value * self.step,
            (false, false) => value / self.step,
        };
        next.clamp(self.range.0, self.range.1)
    }
}

fn translucency_param(
    scene: &Scene,
    f: fn(&crate::scene::material::Translucency) -> f32,
) -> Option<f32> {
    scene
        .objects
        .iter()
        .find_map(|o| o.material.translucency.as_ref().map(f))
}

fn set_translucency_param(
    scene: &mut Scene,
    value: f32,
    f: fn(&mut crate::scene::material::Translucency, f32),
) {
    for object in &mut scene.objects {
        if let Some(t) = object.material.translucency.as_mut() {
            f(t, value);
        }
    }
}

/// The knobs, selected with keys 1..; a new knob is one entry here.
pub const KNOBS: &[Knob] = &[
    Knob {
        name: "light translucency scale",
        step: 1.25,
        additive: false,
        range: (1e-3, 100.0),
        get: |s, _| s.lights.first().map(|l| l.translucency_scale),
        set: |s, _, v| s.lights.iter_mut().for_each(|l| l.translucency_scale = v),
        rebuild: false,
    },
    Knob {
        name: "translucency power",
        step: 1.25,
        additive: false,
        range: (0.1, 1e4),
        get: |s, _| translucency_param(s, |t| t.power),
        set: |s, _, v| set_translucency_param(s, v, |t, v| t.power = v),
        rebuild: false,
    },
    Knob {
        name: "translucency distortion",
        step: 0.05,
        additive: true,
        range: (0.0, 10.0),
        get: |s, _| translucency_param(s, |t| t.distortion),
        set: |s, _, v| set_translucency_param(s, v, |t, v| t.distortion = v),
        rebuild: false,
    },
    Knob {
        name: "translucency ambient",
        step: 0.05,
        additive: true,
        range: (0.0, 1.0),
        get: |s, _| translucency_param(s, |t| t.ambient),
        set: |s, _, v| set_translucency_param(s, v, |t, v| t.ambient = v),
        rebuild: false,
    },
    Knob {
        name: "SSS width (world units per mm)",
        step: 1.25,
        additive: false,
        range: (1e-5, 10.0),
        get: |s, _| {
            s.objects
                .iter()
                .find_map(|o| o.material.sss.as_ref().map(|p| p.units_per_mm))
        },
        set: |s, _, v| {
            for o in &mut s.objects {
                if let Some(p) = o.material.sss.as_mut() {
                    p.units_per_mm = v;
                }
            }
        },
        rebuild: false,
    },
    Knob {
        name: "bilateral sensitivity (LBB)",
        step: 1.25,
        additive: false,
        range: (0.0, 1e3),
        get: |s, f| {
            s.objects
                .iter()
                .any(|o| o.material.sss.is_some())
                .then_some(f.sss.sensitivity)
        },
        set: |_, f, v| f.sss.sensitivity = v,
        rebuild: false,
    },
    Knob {
        name: "environment intensity",
        step: 1.25,
        additive: false,
        range: (1e-3, 100.0),
        get: |s, _| Some(s.environment.intensity()),
        // The nine coefficients are per-frame uniforms: a value change.
        set: |s, _, v| s.environment.set_intensity(v),
        rebuild: false,
    },
    Knob {
        name: "anti-aliasing (0 off, 1 FXAA)",
        step: 1.0,
        additive: true,
        range: (0.0, 1.0),
        get: |_, f| {
            Some(match f.antialias {
                crate::features::antialias::Antialias::Off => 0.0,
                crate::features::antialias::Antialias::Fxaa => 1.0,
            })
        },
        set: |_, f, v| {
            f.antialias = if v >= 0.5 {
                crate::features::antialias::Antialias::Fxaa
            } else {
                crate::features::antialias::Antialias::Off
            }
        },
        // A pass and an image more or less.
        rebuild: true,
    },
];

/// One press of a light key moves a positioned light by this fraction of the camera's distance
/// to its target (so a step looks the same whatever the scene's scale).
pub const LIGHT_STEP: f32 = 0.05;
/// One press of a light key tilts a directional light by this much (radians, about 5.7°).
pub const LIGHT_TILT: f32 = 0.1;
/// One intensity key press multiplies or divides the light's intensity by this.
pub const INTENSITY_STEP: f32 = 1.25;
/// Range of the intensity the keys and the slider set.
pub const INTENSITY_RANGE: (f32, f32) = (1e-3, 1e5);

/// A direction a light key moves the selected light, in the camera's frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightMove {
    /// Along the view's right vector (horizontal).
    Right,
    /// Against it.
    Left,
    /// Along the view's up vector.
    Up,
    /// Against it.
    Down,
    /// Away from the camera (the view direction).
    Forward,
    /// Towards the camera.
    Back,
}

impl LightMove {
    /// The world-space unit vector of this move for a camera with `basis` (forward, right, up,
    /// as [`OrbitCamera::basis`] gives them).
    pub fn vector(self, (forward, right, up): (Vec3, Vec3, Vec3)) -> Vec3 {
        match self {
            LightMove::Right => right,
            LightMove::Left => -right,
            LightMove::Up => up,
            LightMove::Down => -up,
            LightMove::Forward => forward,
            LightMove::Back => -forward,
        }
    }
}

/// Moves `light` one key step in direction `dir` of a camera with `basis` at `distance` from
/// its target: a point or spot light moves by [`LIGHT_STEP`] x `distance`; a directional light
/// (which has no position) tilts its direction by [`LIGHT_TILT`] towards `dir` (a forward or
/// back move, along the view, leaves it as it is: returns false then).
pub fn move_light(
    light: &mut Light,
    dir: LightMove,
    basis: (Vec3, Vec3, Vec3),
    distance: f32,
) -> bool {
    let v = dir.vector(basis);
    match &mut light.kind {
        LightKind::Point { position, .. } | LightKind::Spot { position, .. } => {
            *position += v * LIGHT_STEP * distance;
            true
        }
        LightKind::Directional { direction } => {
            if matches!(dir, LightMove::Forward | LightMove::Back) {
                return false;
            }
            let d = direction.normalize_or(Vec3::NEG_Y);
            *direction = (d + v * LIGHT_TILT).normalize_or(d);
            true
        }
    }
}

/// The light's position (point and spot lights) or direction (directional), as shown and
/// edited in the panel.
pub fn light_vector(light: &Light) -> Vec3 {
    match light.kind {
        LightKind::Point { position, .. } | LightKind::Spot { position, .. } => position,
        LightKind::Directional { direction } => direction,
    }
}

/// Sets what [`light_vector`] returns. A zero or non-finite direction is ignored.
pub fn set_light_vector(light: &mut Light, v: Vec3) {
    if !v.is_finite() {
        return;
    }
    match &mut light.kind {
        LightKind::Point { position, .. } | LightKind::Spot { position, .. } => *position = v,
        LightKind::Directional { direction } => {
            if v.length_squared() > 1e-12 {
                *direction = v;
            }
        }
    }
}

/// The light's kind in words.
pub fn light_kind_name(light: &Light) -> &'static str {
    match light.kind {
        LightKind::Point { .. } => "point",
        LightKind::Spot { .. } => "spot",
        LightKind::Directional { .. } => "directional",
    }
}

/// The intensity one key press up (`up`) or down from `intensity`, within
/// [`INTENSITY_RANGE`].
pub fn stepped_intensity(intensity: f32, up: bool) -> f32 {
    let next = if up {
        intensity * INTENSITY_STEP
    } else {
        intensity / INTENSITY_STEP
    };
    next.clamp(INTENSITY_RANGE.0, INTENSITY_RANGE.1)
}

/// The light index after `current` (`forward`) or before it among `count` lights, wrapping;
/// 0 when there are none.
pub fn cycle_light(current: usize, count: usize, forward: bool) -> usize {
    if count == 0 {
        return 0;
    }
    let current = current.min(count - 1);
    if forward {
        (current + 1) % count
    } else {
        (current + count - 1) % count
    }
}

/// How the window shows the frame: the technique alone, or compared with plain lighting
/// (technique `none`) rendered from the same view.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Comparison {
    /// Left half plain lighting, right half the technique (or the difference, with
    /// `difference`).
    pub split: bool,
    /// |technique - plain| x [`DIFFERENCE_GAIN`], over the whole window (or its right half with
    /// `split`).
    pub difference: bool,
}

/// How much the difference view amplifies |technique - plain| (display-encoded values).
pub const DIFFERENCE_GAIN: f32 = 4.0;

impl Comparison {
    /// Whether the plain-lighting frame is needed at all.
    pub fn active(self) -> bool {
        self.split || self.difference
    }

    /// The words the window shows over each half: `(left, right)`; `right` is `None` when the
    /// whole window shows one thing (then `left` names it).
    pub fn labels(self, technique: &str) -> (String, Option<String>) {
        let diff = format!("|{technique} - plain| x{DIFFERENCE_GAIN}");
        match (self.split, self.difference) {
            (false, false) => (format!("technique: {technique}"), None),
            (false, true) => (format!("difference: {diff}"), None),
            (true, false) => (
                "left: plain lighting (none)".into(),
                Some(format!("right: {technique}")),
            ),
            (true, true) => (
                "left: plain lighting (none)".into(),
                Some(format!("right: difference {diff}")),
            ),
        }
    }
}

/// The pow forms the pow key cycles through, in order.
pub const POW_MODES: &[(PowMode, &str)] = &[
    (PowMode::Exact, "exact pow"),
    (PowMode::SphericalGaussian, "exp2 (seed's form)"),
    (
        PowMode::SphericalGaussianScaled,
        "exp2 (scaled, matches pow)",
    ),
];

/// The pow form of the scene's first translucent material.
pub fn pow_mode(scene: &Scene) -> Option<PowMode> {
    scene
        .objects
        .iter()
        .find_map(|o| o.material.translucency.as_ref().map(|t| t.pow_mode))
}

/// Switches every translucent material to the next pow form; returns its name (`None`: the
/// scene has no translucent material).
pub fn cycle_pow_mode(scene: &mut Scene) -> Option<&'static str> {
    let current = pow_mode(scene)?;
    let index = POW_MODES
        .iter()
        .position(|(m, _)| *m == current)
        .unwrap_or(0);
    let (next, name) = POW_MODES[(index + 1) % POW_MODES.len()];
    for object in &mut scene.objects {
        if let Some(t) = object.material.translucency.as_mut() {
            t.pow_mode = next;
        }
    }
    Some(name)
}

/// Something a key press does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// Next technique of `Technique::all`.
    NextTechnique,
    /// Previous technique.
    PreviousTechnique,
    /// Next pow form (exact, exp2, scaled exp2) of the translucent materials.
    CyclePow,
    /// Next debug view (off, then the views the frame has).
    CycleDebugView,
    /// Selects knob N (index into [`KNOBS`]).
    SelectKnob(usize),
    /// Raises the selected knob one step.
    KnobUp,
    /// Lowers the selected knob one step.
    KnobDown,
    /// Back to the scene's camera.
    ResetCamera,
    /// Shows or hides the key list.
    ToggleHelp,
    /// Shows or hides the panel (knobs, timings, messages).
    ToggleOverlay,
    /// Writes the frame (or the comparison the window shows, without the panel) as a PNG.
    Screenshot,
    /// Rebuilds every pipeline from the shaders on disk now.
    ReloadShaders,
    /// Switches the timing mode: in-frame timestamps or isolated passes (as `bench --isolate`).
    ToggleTiming,
    /// Selects the next light.
    NextLight,
    /// Selects the previous light.
    PreviousLight,
    /// Moves the selected light one step (camera-relative).
    MoveLight(LightMove),
    /// Raises the selected light's intensity one step.
    LightBrighter,
    /// Lowers the selected light's intensity one step.
    LightDimmer,
    /// Split view on or off: left plain lighting, right the technique.
    ToggleSplit,
    /// Difference view on or off: |technique - plain| amplified.
    ToggleDifference,
    /// Ends the demo.
    Quit,
}

/// A key, its name (as scripts and the key list write it) and what it does.
pub struct KeyBinding {
    /// Name, e.g. `F1`, `T`, `Shift+T`, `1`.
    pub name: &'static str,
    /// The action.
    pub action: Action,
    /// One line of help.
    pub help: &'static str,
}

/// Every key with an action (camera keys and the mouse are listed in [`CAMERA_HELP`]).
pub const KEYS: &[KeyBinding] = &[
    KeyBinding {
        name: "F1",
        action: Action::ToggleHelp,
        help: "show / hide this key list",
    },
    KeyBinding {
        name: "T",
        action: Action::NextTechnique,
        help: "next technique",
    },
    KeyBinding {
        name: "Shift+T",
        action: Action::PreviousTechnique,
        help: "previous technique",
    },
    KeyBinding {
        name: "P",
        action: Action::CyclePow,
        help: "translucency pow form: exact / exp2 / scaled exp2",
    },
    KeyBinding {
        name: "V",
        action: Action::CycleDebugView,
        help:
            "debug view: off / albedo / normal / depth / thickness / material ID / translucency term / SSS before blur",
    },
    KeyBinding {
        name: "1",
        action: Action::SelectKnob(0),
        help: "select knob: light translucency scale",
    },
    KeyBinding {
        name: "2",
        action: Action::SelectKnob(1),
        help: "select knob: translucency power",
    },
    KeyBinding {
        name: "3",
        action: Action::SelectKnob(2),
        help: "select knob: translucency distortion",
    },
    KeyBinding {
        name: "4",
        action: Action::SelectKnob(3),
        help: "select knob: translucency ambient",
    },
    KeyBinding {
        name: "5",
        action: Action::SelectKnob(4),
        help: "select knob: SSS width",
    },
    KeyBinding {
        name: "6",
        action: Action::SelectKnob(5),
        help: "select knob: bilateral sensitivity (LBB)",
    },
    KeyBinding {
        name: "7",
        action: Action::SelectKnob(6),
        help: "select knob: environment intensity",
    },
    KeyBinding {
        name: "8",
        action: Action::SelectKnob(7),
        help: "select knob: anti-aliasing (FXAA on/off)",
    },
    KeyBinding {
        name: "+",
        action: Action::KnobUp,
        help: "raise the selected knob (also PageUp)",
    },
    KeyBinding {
        name: "-",
        action: Action::KnobDown,
        help: "lower the selected knob (also PageDown)",
    },
    KeyBinding {
        name: "L",
        action: Action::NextLight,
        help: "select the next light",
    },
    KeyBinding {
        name: "Shift+L",
        action: Action::PreviousLight,
        help: "select the previous light",
    },
    KeyBinding {
        name: "Left",
        action: Action::MoveLight(LightMove::Left),
        help: "move the selected light left (a directional one tilts)",
    },
    KeyBinding {
        name: "Right",
        action: Action::MoveLight(LightMove::Right),
        help: "move the selected light right",
    },
    KeyBinding {
        name: "Up",
        action: Action::MoveLight(LightMove::Up),
        help: "move the selected light up (on screen)",
    },
    KeyBinding {
        name: "Down",
        action: Action::MoveLight(LightMove::Down),
        help: "move the selected light down",
    },
    KeyBinding {
        name: "Shift+Up",
        action: Action::MoveLight(LightMove::Forward),
        help: "move the selected light away from the camera",
    },
    KeyBinding {
        name: "Shift+Down",
        action: Action::MoveLight(LightMove::Back),
        help: "move the selected light towards the camera",
    },
    KeyBinding {
        name: "]",
        action: Action::LightBrighter,
        help: "selected light brighter (x1.25)",
    },
    KeyBinding {
        name: "[",
        action: Action::LightDimmer,
        help: "selected light dimmer (/1.25)",
    },
    KeyBinding {
        name: "C",
        action: Action::ToggleSplit,
        help: "split view: left plain lighting (none), right the technique",
    },
    KeyBinding {
        name: "X",
        action: Action::ToggleDifference,
        help: "difference view: |technique - plain| x4 (the right half with C)",
    },
    KeyBinding {
        name: "R",
        action: Action::ResetCamera,
        help: "reset the camera to the scene's",
    },
    KeyBinding {
        name: "H",
        action: Action::ToggleOverlay,
        help: "hide / show the panel",
    },
    KeyBinding {
        name: "I",
        action: Action::ToggleTiming,
        help: "timing mode: in-frame timestamps / each pass isolated (as bench)",
    },
    KeyBinding {
        name: "F5",
        action: Action::ReloadShaders,
        help: "rebuild the pipelines now (saving under glsl/ does it too)",
    },
    KeyBinding {
        name: "F12",
        action: Action::Screenshot,
        help: "screenshot (PNG: the frame or the comparison, without the panel)",
    },
    KeyBinding {
        name: "Esc",
        action: Action::Quit,
        help: "quit",
    },
];

/// Help lines for the camera (mouse and held keys).
pub const CAMERA_HELP: &[(&str, &str)] = &[
    ("left drag", "orbit around the target"),
    ("right / middle drag", "pan"),
    ("wheel", "zoom"),
    ("W A S D", "fly forward / left / back / right"),
    ("Q E", "fly down / up"),
];

/// The action a key name stands for (script `key NAME`); `+`/`-` also accept `PageUp`,
/// `PageDown`, `Plus`, `Minus`.
pub fn action_named(name: &str) -> Option<Action> {
    let alias = match name {
        "PageUp" | "Plus" | "=" => "+",
        "PageDown" | "Minus" => "-",
        "Escape" => "Esc",
        other => other,
    };
    KEYS.iter()
        .find(|k| k.name.eq_ignore_ascii_case(alias))
        .map(|k| k.action)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cubes() -> Scene {
        crate::bake::scene::load_scene_baked("cubes").unwrap()
    }

    #[test]
    fn orbit_camera_reproduces_the_scene_camera_and_resets() {
        let scene = cubes();
        let mut orbit = OrbitCamera::from_camera(&scene.camera);
        assert!((orbit.eye() - scene.camera.eye).length() < 1e-4);
        orbit.orbit(40.0, 500.0);
        assert!(orbit.pitch <= MAX_PITCH_DEGREES);
        orbit.zoom(0.0); // ignored
        orbit.zoom(1e-30); // clamped
        assert!(orbit.distance >= MIN_DISTANCE);
        orbit.pan(0.5, 0.5);
        orbit.fly(1.0, 2.0, 3.0);
        assert!(orbit.eye().is_finite());
        orbit.reset();
        let mut camera = scene.camera;
        camera.eye = Vec3::ZERO;
        orbit.apply(&mut camera);
        assert!((camera.eye - scene.camera.eye).length() < 1e-4);
        assert_eq!(camera.target, scene.camera.target);
    }

    #[test]
    fn knobs_change_the_scene_and_stay_in_range() {
        let mut scene = cubes();
        let mut settings = FrameSettings::new(64, 48);
        let power = &KNOBS[1];
        let before = (power.get)(&scene, &settings).expect("cubes has translucent materials");
        let mut v = before;
        for _ in 0..200 {
            v = power.stepped(v, true);
        }
        assert_eq!(v, power.range.1);
        (power.set)(&mut scene, &mut settings, v);
        assert_eq!((power.get)(&scene, &settings), Some(v));
        let ambient = &KNOBS[3];
        assert_eq!(ambient.stepped(0.0, false), 0.0);
        for o in &scene.objects {
            o.material.validate().unwrap();
        }
        // The bilateral sensitivity lives in the frame settings, for scenes with SSS only.
        let sensitivity = &KNOBS[5];
        assert_eq!((sensitivity.get)(&scene, &settings), None);
        let skin = crate::scene::builtin("skin").unwrap();
        let start = (sensitivity.get)(&skin, &settings).unwrap();
        let mut skin = skin;
        (sensitivity.set)(&mut skin, &mut settings, start * 2.0);
        assert_eq!(settings.sss.sensitivity, start * 2.0);
        // Every knob key selects an existing knob.
        for k in KEYS {
            if let Action::SelectKnob(i) = k.action {
                assert!(i < KNOBS.len(), "{}", k.name);
            }
        }
    }

    #[test]
    fn light_moves_follow_the_camera_and_directional_lights_tilt() {
        let scene = cubes();
        let mut orbit = OrbitCamera::from_camera(&scene.camera);
        orbit.orbit(37.0, 12.0);
        let basis = orbit.basis();
        let (forward, right, up) = basis;
        assert!((forward.dot(right)).abs() < 1e-5 && (right.dot(up)).abs() < 1e-5);
        assert!(right.y.abs() < 1e-6, "right is horizontal");
        let start = Vec3::new(1.0, 2.0, 3.0);
        let mut light = Light::point(start, Vec3::ONE, 5.0, 10.0);
        let step = LIGHT_STEP * orbit.distance;
        for (dir, expected) in [
            (LightMove::Right, right),
            (LightMove::Left, -right),
            (LightMove::Up, up),
            (LightMove::Down, -up),
            (LightMove::Forward, forward),
            (LightMove::Back, -forward),
        ] {
            set_light_vector(&mut light, start);
            assert!(move_light(&mut light, dir, basis, orbit.distance));
            let moved = light_vector(&light) - start;
            assert!(
                (moved - expected * step).length() < 1e-5,
                "{dir:?}: {moved}"
            );
        }
        // Right then left is back where it started.
        set_light_vector(&mut light, start);
        move_light(&mut light, LightMove::Right, basis, orbit.distance);
        move_light(&mut light, LightMove::Left, basis, orbit.distance);
        assert!((light_vector(&light) - start).length() < 1e-5);

        let down = Vec3::new(0.0, -1.0, 0.0);
        let mut sun = Light::directional(down, Vec3::ONE, 1.0);
        assert!(!move_light(&mut sun, LightMove::Forward, basis, 1.0));
        assert_eq!(light_vector(&sun), down);
        assert!(move_light(&mut sun, LightMove::Right, basis, 1.0));
        let tilted = light_vector(&sun);
        assert!((tilted.length() - 1.0).abs() < 1e-5);
        assert!((tilted.angle_between(down) - LIGHT_TILT.atan()).abs() < 1e-4);
        assert!(tilted.dot(right) > 0.0);
        // A zero or NaN direction is refused; the light stays valid.
        set_light_vector(&mut sun, Vec3::ZERO);
        set_light_vector(&mut sun, Vec3::NAN);
        assert_eq!(light_vector(&sun), tilted);
        sun.validate("sun").unwrap();
        assert_eq!(light_kind_name(&sun), "directional");
    }

    #[test]
    fn intensity_steps_and_light_selection_wrap() {
        assert_eq!(stepped_intensity(4.0, true), 5.0);
        assert_eq!(stepped_intensity(5.0, false), 4.0);
        assert_eq!(
            stepped_intensity(INTENSITY_RANGE.1, true),
            INTENSITY_RANGE.1
        );
        assert_eq!(stepped_intensity(0.0, false), INTENSITY_RANGE.0);
        assert_eq!(cycle_light(0, 3, true), 1);
        assert_eq!(cycle_light(2, 3, true), 0);
        assert_eq!(cycle_light(0, 3, false), 2);
        assert_eq!(cycle_light(7, 3, false), 1);
        assert_eq!(cycle_light(0, 0, true), 0);
    }

    #[test]
    fn pow_cycles_through_every_form_and_back() {
        let mut scene = cubes();
        let first = pow_mode(&scene).unwrap();
        for _ in 0..POW_MODES.len() {
            assert!(cycle_pow_mode(&mut scene).is_some());
        }
        assert_eq!(pow_mode(&scene), Some(first));
        let mut smoke = crate::bake::scene::load_scene_baked("smoke").unwrap();
        if pow_mode(&smoke).is_none() {
            assert_eq!(cycle_pow_mode(&mut smoke), None);
        }
    }

    #[test]
    fn key_names_resolve() {
        assert_eq!(action_named("f1"), Some(Action::ToggleHelp));
        assert_eq!(action_named("PageUp"), Some(Action::KnobUp));
        assert_eq!(action_named("Shift+T"), Some(Action::PreviousTechnique));
        assert_eq!(action_named("nope"), None);
        assert_eq!(action_named("shift+l"), Some(Action::PreviousLight));
        assert_eq!(action_named("]"), Some(Action::LightBrighter));
        // Names are unique (a script's key names one action).
        for (i, k) in KEYS.iter().enumerate() {
            assert!(
                KEYS[i + 1..]
                    .iter()
                    .all(|o| !o.name.eq_ignore_ascii_case(k.name)),
                "{}",
                k.name
            );
        }
    }
}
