//! The interactive demo (`lucent demo`): a window to fly around a scene in, switch techniques,
//! turn the knobs and watch the per-pass GPU times move. Built with the `window` feature.
//!
//! - [`present`]: surface, swapchain, per-frame submit and present (resize, minimize,
//!   `OUT_OF_DATE`/`SUBOPTIMAL`, bounded waits).
//! - [`controls`]: the orbit/fly camera, the knobs, the key list (no window needed).
//! - `input`: window events, keys and the mouse, and script commands, turned into actions.
//! - [`overlay`]: on-screen text rasterized on the CPU.
//! - [`script`]: `--script FILE`, scripted input for tests.
//! - [`watch`]: shader hot reload's file polling.
//!
//! The frame itself is the ordinary [`Renderer`]: it is rebuilt on resize, on a technique
//! change, on a knob change that changes the frame's shape (a pow form) and when a file under
//! the GLSL root changes; knobs that change only values (lights, translucency parameters, SSS
//! width and sensitivity) are written into the next frame's per-frame parameters without
//! re-uploading the scene. A rebuild that fails (a shader typo) keeps the previous renderer
//! running and shows the error. Layering: the binary calls
//! this module, which uses the renderer and passes; nothing below knows about windows.

pub mod controls;
mod input;
pub mod overlay;
pub mod present;
pub mod script;
pub mod watch;

use std::collections::{BTreeMap, HashSet};
use std::ffi::{CStr, CString};
use std::path::PathBuf;
use std::time::{Duration, Instant};

use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::KeyCode;
use winit::window::{Window, WindowId};

use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::{ContextDesc, GpuContext};
use crate::features::debug_view::DebugView;
use crate::frame::{FrameDesc, FrameRunner, FrameSettings, Renderer, Technique};
use crate::images::output;
use crate::scene::Scene;
use crate::{LucentError, Result};

use controls::{OrbitCamera, KNOBS};
use overlay::{Panel, TextRenderer, Tone};
use present::{Drawn, Presenter};
use script::Script;
use watch::ShaderWatcher;

/// How often the on-screen timings are refreshed.
const TIMING_REFRESH: Duration = Duration::from_millis(250);
/// One script tick while nothing can be presented (minimized).
const IDLE_TICK: Duration = Duration::from_millis(16);
/// With `--frames`, how long the window may stay minimized with nothing left to restore it
/// before the demo gives up (so a script can never hang).
const MINIMIZED_LIMIT: Duration = Duration::from_secs(10);
/// Fly speed, scene units per second per unit of camera distance.
const FLY_SPEED: f32 = 0.5;
/// Degrees of orbit per pixel dragged.
const ORBIT_PER_PIXEL: f32 = 0.3;

/// What `lucent demo` was asked for.
#[derive(Clone, Debug)]
pub struct DemoOptions {
    /// Built-in scene name or `.toml` file.
    pub scene: String,
    /// Technique at start; `None`: the one the scene is made for (or `none`).
    pub technique: Option<Technique>,
    /// Window size at start.
    pub size: (u32, u32),
    /// FIFO (true) or a tearing present mode when available.
    pub vsync: bool,
    /// Exit after this many presented frames.
    pub frames: Option<u64>,
    /// Scripted input.
    pub script: Option<PathBuf>,
    /// Write the last frame (without the overlay) here on exit.
    pub screenshot: Option<PathBuf>,
    /// Validation layer (also `LUCENT_VALIDATION=1`).
    pub validation: bool,
    /// Device name filter.
    pub device: Option<String>,
    /// Frame settings besides size and technique (G-buffer precision, merging, ...).
    pub base: FrameSettings,
}

/// Opens the window and runs the demo until it is closed, `Esc`, `--frames` or the script's
/// `quit`. Errors: no display, no device that can present, a bad script, a device or surface
/// lost, validation errors (when validation is on).
pub fn run(options: DemoOptions) -> Result<()> {
    if options.frames == Some(0) {
        return Err(LucentError::InvalidInput(
            "--frames must be at least 1".into(),
        ));
    }
    let script = options.script.as_deref().map(Script::load).transpose()?;
    let mut scene = crate::bake::scene::load_scene_baked(&options.scene)?;
    let event_loop = EventLoop::new().map_err(|e| {
        LucentError::InvalidInput(format!(
            "cannot open a window ({e}); is a display available (DISPLAY or WAYLAND_DISPLAY)? \
             `lucent bench` and `lucent render` run headless"
        ))
    })?;
    let display = event_loop
        .display_handle()
        .map_err(|e| LucentError::InvalidInput(format!("no display handle: {e}")))?
        .as_raw();
    let extensions = ash_window::enumerate_required_extensions(display)
        .map_err(|e| LucentError::vulkan("enumerate_required_extensions", e))?
        .iter()
        // SAFETY: ash-window returns pointers to static NUL-terminated extension names.
        .map(|&p| unsafe { CStr::from_ptr(p) }.to_owned())
        .collect::<Vec<CString>>();
    let gpu = GpuContext::new(&ContextDesc {
        instance_extensions: extensions,
        swapchain: true,
        ..ContextDesc::from_env(options.validation, options.device.clone())
    })?;
    let shaders = ShaderCompiler::new(
        ShaderCompiler::default_glsl_root(),
        Some(ShaderCompiler::default_cache_dir()),
    )?;
    // Run-time compilation (not the shipped SPIR-V): edited shaders reload while the demo runs.
    let glsl_root = shaders.glsl_root().ok_or_else(|| {
        crate::LucentError::InvalidInput("hot reload needs a run-time shader compiler".into())
    })?;
    let pipeline_cache = PipelineCache::load_default(&gpu)?;
    // The monospaced sibling of the plot font when there is one (fonts-dejavu-core has both):
    // the timing columns line up.
    let font = crate::font::font_file().map(|p| {
        let mono = p.with_file_name("DejaVuSansMono.ttf");
        if mono.is_file() {
            mono
        } else {
            p
        }
    });
    let text = match font.and_then(|p| TextRenderer::load(&p)) {
        Ok(t) => Some(t),
        Err(e) => {
            log::warn!("no on-screen text: {e}");
            None
        }
    };
    // Default: what the scene's materials ask for.
    let technique = options.technique.unwrap_or(Technique::Auto);
    let orbit = OrbitCamera::from_camera(&scene.camera);
    orbit.apply(&mut scene.camera);
    let mut app = Demo {
        gpu: &gpu,
        shaders: &shaders,
        pipeline_cache: &pipeline_cache,
        watcher: ShaderWatcher::new(glsl_root),
        text,
        technique,
        debug_view: None,
        isolated: false,
        runner: None,
        scene,
        orbit,
        script,
        options,
        window: None,
        presenter: None,
        renderer: None,
        error: None,
        input: Input::default(),
        view: View::default(),
        stats: Stats::new(),
        tick: 0,
        presented: 0,
        minimized_ticks: 0,
        recreations: 0,
        minimized_by_script: false,
        window_zero: false,
        resize_pending: false,
        swapchain_stale: false,
        rebuild_pending: false,
        screenshot_pending: Vec::new(),
        screenshots_taken: 0,
        last_idle_tick: Instant::now(),
        minimized_since: None,
        last_frame: Instant::now(),
        done: false,
    };
    let ran = event_loop
        .run_app(&mut app)
        .map_err(|e| LucentError::InvalidInput(format!("window event loop failed: {e}")));
    let finished = app.finish();
    let error = app.error.take();
    drop(app);
    if let Err(e) = pipeline_cache.save(&gpu.device) {
        log::warn!("pipeline cache not saved: {e}");
    }
    pipeline_cache.destroy(&gpu.device);
    let errors = gpu.validation_error_count();
    if let Some(e) = error {
        return Err(e);
    }
    ran?;
    finished?;
    if errors > 0 {
        return Err(LucentError::InvalidInput(format!(
            "the validation layer reported {errors} error(s)"
        )));
    }
    Ok(())
}

/// Held keys and the mouse.
#[derive(Default)]
struct Input {
    held: HashSet<KeyCode>,
    shift: bool,
    orbiting: bool,
    panning: bool,
    cursor: Option<(f64, f64)>,
}

/// What the overlay shows besides the timings.
#[derive(Default)]
struct View {
    help: bool,
    hidden: bool,
    knob: usize,
    /// The latest message and whether it is an error (shader compile errors stay until a
    /// rebuild succeeds).
    message: Option<(String, bool)>,
    panel: Option<Panel>,
    panel_text: Vec<(String, Tone)>,
}

/// Pass times averaged over the frames since the last refresh.
struct Stats {
    sums: BTreeMap<usize, (String, f64)>,
    wall: f64,
    frames: u32,
    since: Instant,
    shown: Vec<(String, f64)>,
    shown_wall: f64,
    shown_frames: u32,
}

impl Stats {
    fn new() -> Self {
        Self {
            sums: BTreeMap::new(),
            wall: 0.0,
            frames: 0,
            since: Instant::now(),
            shown: Vec::new(),
            shown_wall: 0.0,
            shown_frames: 0,
        }
    }

    fn add(&mut self, passes: &[crate::backend::timer::ScopeTime], wall_ms: f64) {
        for (i, p) in passes.iter().enumerate() {
            let entry = self.sums.entry(i).or_insert_with(|| (p.name.clone(), 0.0));
            if entry.0 != p.name {
                *entry = (p.name.clone(), 0.0);
            }
            entry.1 += p.ms;
        }
        self.wall += wall_ms;
        self.frames += 1;
    }

    /// Publishes the means when the refresh interval passed; true when it did.
    fn refresh(&mut self) -> bool {
        if self.since.elapsed() < TIMING_REFRESH || self.frames == 0 {
            return false;
        }
        let n = f64::from(self.frames);
        self.shown = self
            .sums
            .values()
            .map(|(name, s)| (name.clone(), s / n))
            .collect();
        self.shown_wall = self.wall / n;
        self.shown_frames = self.frames;
        self.sums.clear();
        self.wall = 0.0;
        self.frames = 0;
        self.since = Instant::now();
        true
    }

    /// Drops the numbers (after a rebuild: the passes changed).
    fn clear(&mut self) {
        self.sums.clear();
        self.wall = 0.0;
        self.frames = 0;
    }
}

struct Demo<'a> {
    gpu: &'a GpuContext,
    shaders: &'a ShaderCompiler,
    pipeline_cache: &'a PipelineCache,
    watcher: ShaderWatcher,
    text: Option<TextRenderer>,
    technique: Technique,
    debug_view: Option<DebugView>,
    /// Isolated timing (each physical pass its own submission) instead of in-frame.
    isolated: bool,
    /// Runs the isolated frames (sized for the current renderer's passes).
    runner: Option<FrameRunner>,
    scene: Scene,
    orbit: OrbitCamera,
    script: Option<Script>,
    options: DemoOptions,
    window: Option<Window>,
    presenter: Option<Presenter>,
    renderer: Option<Renderer>,
    error: Option<LucentError>,
    input: Input,
    view: View,
    stats: Stats,
    /// Script clock: presented frames plus idle ticks while minimized.
    tick: u64,
    presented: u64,
    /// Script ticks spent minimized (nothing presented).
    minimized_ticks: u64,
    /// Swapchain recreations after the first.
    recreations: u64,
    minimized_by_script: bool,
    window_zero: bool,
    resize_pending: bool,
    /// The swapchain reported OUT_OF_DATE or SUBOPTIMAL: recreate before the next frame.
    swapchain_stale: bool,
    rebuild_pending: bool,
    screenshot_pending: Vec<PathBuf>,
    screenshots_taken: u32,
    last_idle_tick: Instant,
    minimized_since: Option<Instant>,
    last_frame: Instant,
    done: bool,
}

impl ApplicationHandler for Demo<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() || self.done {
            return;
        }
        if let Err(e) = self.open(event_loop) {
            self.fail(event_loop, e);
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        if let Err(e) = self.on_event(event_loop, event) {
            self.fail(event_loop, e);
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if self.done || self.window.is_none() {
            return;
        }
        match self.frame(event_loop) {
            Ok(()) => {}
            Err(e) => self.fail(event_loop, e),
        }
    }
}

impl Demo<'_> {
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: LucentError) {
        if self.error.is_none() {
            self.error = Some(e);
        }
        self.done = true;
        event_loop.exit();
    }

    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let (w, h) = self.options.size;
        let attributes = Window::default_attributes()
            .with_title(format!("lucent demo — {}", self.scene.name))
            .with_inner_size(PhysicalSize::new(w, h));
        let window = event_loop
            .create_window(attributes)
            .map_err(|e| LucentError::InvalidInput(format!("cannot create a window: {e}")))?;
        let display = window
            .display_handle()
            .map_err(|e| LucentError::InvalidInput(format!("no display handle: {e}")))?
            .as_raw();
        let handle = window
            .window_handle()
            .map_err(|e| LucentError::InvalidInput(format!("no window handle: {e}")))?
            .as_raw();
        // SAFETY: the handles are the live window's; the surface is destroyed (by the
        // presenter) before the window is dropped (see `finish`).
        let surface = unsafe {
            ash_window::create_surface(&self.gpu.entry, &self.gpu.instance, display, handle, None)
        }
        .map_err(|e| LucentError::vulkan("vkCreate*SurfaceKHR", e))?;
        let size = window.inner_size();
        self.window_zero = size.width == 0 || size.height == 0;
        self.window = Some(window);
        let presenter = Presenter::new(
            self.gpu,
            surface,
            (size.width, size.height),
            self.options.vsync,
        )?;
        self.presenter = Some(presenter);
        self.rebuild_pending = true;
        event_loop.set_control_flow(ControlFlow::Poll);
        Ok(())
    }

    fn minimized(&self) -> bool {
        self.minimized_by_script
            || self.window_zero
            || self
                .presenter
                .as_ref()
                .is_some_and(Presenter::is_zero_sized)
    }

    /// One turn of the loop: input, script, reloads, resize, then a frame unless minimized.
    fn frame(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let dt = self.last_frame.elapsed().as_secs_f32().min(0.25);
        self.last_frame = Instant::now();
        // A deforming scene animates in real time (each frame's update deforms it at its time;
        // a long stall advances it at most a quarter of a second).
        if self.scene.deformation.is_some() {
            self.scene.time += dt;
        }
        self.run_script(event_loop)?;
        if self.done {
            return Ok(());
        }
        let changed = self.watcher.poll();
        if let Some(first) = changed.first() {
            self.say(format!("shader change: {}", first.display()), false);
            self.rebuild_pending = true;
        }
        self.fly(dt);

        if self.resize_pending || self.swapchain_stale {
            let size = self.window_size();
            let same = self
                .presenter
                .as_ref()
                .is_some_and(|p| (p.extent.width, p.extent.height) == size);
            // A Resized event to the size the swapchain already has needs nothing; a stale
            // swapchain (OUT_OF_DATE, SUBOPTIMAL) is recreated whatever the size.
            let needed = self.swapchain_stale || !same;
            self.resize_pending = false;
            self.swapchain_stale = false;
            if let Some(p) = self.presenter.as_mut().filter(|_| needed) {
                let old = p.extent;
                p.recreate(self.gpu, size)?;
                self.recreations += 1;
                log::info!(
                    "swapchain recreated: {}x{} -> {}x{}",
                    old.width,
                    old.height,
                    p.extent.width,
                    p.extent.height
                );
                if p.extent != old && !p.is_zero_sized() {
                    self.rebuild_pending = true;
                }
            }
        }
        if self.minimized() {
            return self.idle(event_loop);
        }
        self.minimized_since = None;
        event_loop.set_control_flow(ControlFlow::Poll);
        if self.rebuild_pending || self.renderer.is_none() {
            self.rebuild_pending = false;
            self.rebuild()?;
        }
        self.orbit.apply(&mut self.scene.camera);
        let Some(renderer) = self.renderer.as_mut() else {
            return Ok(());
        };
        renderer.update(&self.scene)?;
        let panel = self.overlay_panel();
        let (Some(presenter), Some(renderer)) = (self.presenter.as_mut(), self.renderer.as_ref())
        else {
            return Ok(());
        };
        let started = Instant::now();
        let isolated = match (self.isolated, self.runner.as_mut()) {
            (true, Some(runner)) => Some(runner.run_isolated(self.gpu, &renderer.executable)?),
            _ => None,
        };
        match presenter.draw(self.gpu, renderer, panel.as_ref(), isolated.is_none())? {
            Drawn::OutOfDate => self.swapchain_stale = true,
            Drawn::Presented { passes, stale } => {
                let passes = isolated.map_or(passes, |t| t.passes);
                self.stats
                    .add(&passes, started.elapsed().as_secs_f64() * 1e3);
                self.presented += 1;
                self.tick += 1;
                if stale {
                    self.swapchain_stale = true;
                }
                for path in std::mem::take(&mut self.screenshot_pending) {
                    self.write_screenshot(&path)?;
                }
                if self.options.frames.is_some_and(|n| self.presented >= n) {
                    self.done = true;
                    event_loop.exit();
                }
            }
        }
        Ok(())
    }

    /// Minimized: nothing is rendered; the loop sleeps (timer ticks only when a script or
    /// `--frames` needs the clock to run).
    fn idle(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let since = *self.minimized_since.get_or_insert_with(Instant::now);
        let scripted = self.script.is_some() || self.options.frames.is_some();
        if !scripted {
            event_loop.set_control_flow(ControlFlow::Wait);
            return Ok(());
        }
        if self.last_idle_tick.elapsed() >= IDLE_TICK {
            self.last_idle_tick = Instant::now();
            self.tick += 1;
            self.minimized_ticks += 1;
        }
        let script_done = self.script.as_ref().is_none_or(Script::finished);
        if script_done && since.elapsed() > MINIMIZED_LIMIT {
            return Err(LucentError::InvalidInput(format!(
                "the window stayed minimized for {} s with {} of {} frames presented and no \
                 script command left to restore it",
                MINIMIZED_LIMIT.as_secs(),
                self.presented,
                self.options.frames.unwrap_or(0)
            )));
        }
        event_loop.set_control_flow(ControlFlow::WaitUntil(Instant::now() + IDLE_TICK));
        Ok(())
    }

    fn window_size(&self) -> (u32, u32) {
        if self.minimized_by_script || self.window_zero {
            return (0, 0);
        }
        self.window
            .as_ref()
            .map_or((0, 0), |w| (w.inner_size().width, w.inner_size().height))
    }

    /// Builds the renderer for the current size, technique and scene. A failure keeps the
    /// previous renderer (if any) and shows the error; without a previous one it is fatal.
    fn rebuild(&mut self) -> Result<()> {
        let Some(presenter) = self.presenter.as_ref() else {
            return Ok(());
        };
        let settings = FrameSettings {
            width: presenter.extent.width,
            height: presenter.extent.height,
            technique: self.technique,
            debug_view: self.debug_view.filter(|v| self.view_available(*v)),
            ..self.options.base
        };
        self.orbit.apply(&mut self.scene.camera);
        let started = Instant::now();
        match Renderer::new(
            self.gpu,
            self.shaders,
            self.pipeline_cache,
            &self.scene,
            settings,
        ) {
            Ok(new) => {
                self.gpu.wait_idle()?;
                let runner = FrameRunner::new(self.gpu, new.executable.plan.physical.len());
                if let Some(old) = self.runner.take() {
                    old.destroy(self.gpu);
                }
                if let Some(old) = self.renderer.replace(new) {
                    old.destroy(self.gpu);
                }
                self.runner = Some(runner?);
                self.stats.clear();
                if self.view.message.as_ref().is_some_and(|(_, error)| *error) {
                    self.view.message = None;
                }
                log::info!(
                    "renderer {}x{} {} built in {:.0} ms",
                    settings.width,
                    settings.height,
                    settings.technique.name(),
                    started.elapsed().as_secs_f64() * 1e3
                );
                Ok(())
            }
            Err(e @ (LucentError::DeviceLost { .. } | LucentError::SurfaceLost { .. })) => Err(e),
            Err(e) if self.renderer.is_some() => {
                self.say(
                    format!("rebuild failed, the previous frame keeps running:\n{e}"),
                    true,
                );
                Ok(())
            }
            Err(e) => Err(e),
        }
    }

    /// Whether the current frame has what `view` shows (GB2 for thickness and material ID,
    /// the split lighting for the pre-blur view).
    fn view_available(&self, view: DebugView) -> bool {
        let settings = FrameSettings {
            technique: self.technique,
            ..self.options.base
        };
        let Ok(features) = FrameDesc::new(&self.scene, &settings) else {
            return false;
        };
        match view {
            DebugView::Thickness | DebugView::MaterialId | DebugView::TranslucencyTerm => {
                features.translucency.is_some()
            }
            DebugView::LitBeforeSss => features.sss.is_some(),
            DebugView::Albedo | DebugView::Normal | DebugView::Depth => true,
        }
    }

    /// The debug view after the current one among those the frame has (`None`: the frame).
    fn next_debug_view(&self) -> Option<DebugView> {
        let all = DebugView::ALL;
        let start = match self.debug_view {
            None => 0,
            Some(v) => all.iter().position(|(_, a)| *a == v).map_or(0, |i| i + 1),
        };
        all[start.min(all.len())..]
            .iter()
            .map(|(_, v)| *v)
            .find(|v| self.view_available(*v))
    }

    fn write_screenshot(&mut self, path: &std::path::Path) -> Result<()> {
        let Some(renderer) = self.renderer.as_ref() else {
            return Ok(());
        };
        let (w, h) = (renderer.settings.width, renderer.settings.height);
        output::write_png_rgba8(path, w, h, &renderer.read_display(self.gpu)?)?;
        self.say(format!("wrote {} ({w}x{h})", path.display()), false);
        println!("wrote {} ({w}x{h})", path.display());
        Ok(())
    }

    /// The overlay's lines, re-rasterized only when they changed.
    fn overlay_panel(&mut self) -> Option<Panel> {
        if self.view.hidden {
            return None;
        }
        let text = self.text.as_ref()?;
        let presenter = self.presenter.as_ref()?;
        let refreshed = self.stats.refresh();
        if !refreshed && self.view.panel.is_some() && !self.view.panel_text.is_empty() {
            let lines = self.overlay_lines();
            if lines == self.view.panel_text {
                return self.view.panel.clone();
            }
        }
        let lines = self.overlay_lines();
        let extent = presenter.extent;
        self.view.panel = text.render(
            &lines,
            extent.width,
            extent.height,
            present::is_bgra(presenter.format()),
        );
        self.view.panel_text = lines;
        self.view.panel.clone()
    }

    fn overlay_lines(&self) -> Vec<(String, Tone)> {
        let mut lines = Vec::new();
        let (w, h) = self
            .presenter
            .as_ref()
            .map_or((0, 0), |p| (p.extent.width, p.extent.height));
        let mode = self
            .presenter
            .as_ref()
            .map_or("?".to_string(), |p| format!("{:?}", p.present_mode));
        lines.push((
            format!(
                "{} — technique {} (T) — {w}x{h} — {mode} — F1 keys",
                self.scene.name,
                self.technique.name()
            ),
            Tone::Accent,
        ));
        lines.push((
            format!(
                "GPU ms per pass, {} (I), mean of {} frames:",
                if self.isolated {
                    "isolated: each pass its own submission"
                } else {
                    "in-frame timestamps"
                },
                self.stats.shown_frames
            ),
            Tone::Normal,
        ));
        let mut total = 0.0;
        for (name, ms) in &self.stats.shown {
            total += ms;
            lines.push((format!("  {name:<22} {ms:8.3}"), Tone::Normal));
        }
        lines.push((
            format!("  {:<22} {total:8.3}", "sum of passes"),
            Tone::Normal,
        ));
        lines.push((
            format!(
                "  {:<22} {:8.3}   ({:.1} fps)",
                "frame (CPU wall)",
                self.stats.shown_wall,
                if self.stats.shown_wall > 0.0 {
                    1e3 / self.stats.shown_wall
                } else {
                    0.0
                }
            ),
            Tone::Normal,
        ));
        let knob = &KNOBS[self.view.knob];
        let value = (knob.get)(&self.scene, &self.options.base)
            .map_or("not used by this scene".to_string(), |v| format!("{v:.4}"));
        lines.push((
            format!(
                "knob {} ({}): {value}   (+/-)",
                self.view.knob + 1,
                knob.name
            ),
            Tone::Normal,
        ));
        let shown = self.renderer.as_ref().and_then(|r| r.settings.debug_view);
        lines.push((
            format!("view (V): {}", shown.map_or("frame", DebugView::name)),
            Tone::Normal,
        ));
        if let Some(mode) = controls::pow_mode(&self.scene) {
            let name = controls::POW_MODES
                .iter()
                .find(|(m, _)| *m == mode)
                .map_or("?", |(_, n)| n);
            lines.push((format!("pow form (P): {name}"), Tone::Normal));
        }
        if let Some((message, error)) = &self.view.message {
            let tone = if *error { Tone::Error } else { Tone::Normal };
            for line in message.lines().take(12) {
                lines.push((line.to_string(), tone));
            }
        }
        if self.view.help {
            lines.extend(
                controls::help_lines()
                    .into_iter()
                    .map(|l| (l, Tone::Accent)),
            );
        }
        lines
    }

    /// Writes `--screenshot`, prints the final state, and tears down the GPU objects in order.
    fn finish(&mut self) -> Result<()> {
        let mut result = Ok(());
        if self.error.is_none() {
            if let Some(path) = self.options.screenshot.clone() {
                if self.renderer.is_some() && self.presented > 0 {
                    result = self.write_screenshot(&path);
                } else {
                    result = Err(LucentError::InvalidInput(
                        "no frame was presented: no screenshot to write".into(),
                    ));
                }
            }
            if let Some(r) = &self.renderer {
                let c = &self.scene.camera;
                println!(
                    "demo: {} frames presented, {} ticks minimized, {} swapchain recreations; \
                     last frame {}x{} technique {} camera eye {:.4} {:.4} {:.4} target {:.4} {:.4} {:.4}",
                    self.presented,
                    self.minimized_ticks,
                    self.recreations,
                    r.settings.width,
                    r.settings.height,
                    r.settings.technique.name(),
                    c.eye.x,
                    c.eye.y,
                    c.eye.z,
                    c.target.x,
                    c.target.y,
                    c.target.z
                );
            }
            if let Some(script) = &self.script {
                if !script.finished() {
                    log::warn!("the demo ended before the script's last commands");
                }
            }
        }
        let idle = self.gpu.wait_idle();
        if let Some(r) = self.runner.take() {
            r.destroy(self.gpu);
        }
        if let Some(r) = self.renderer.take() {
            r.destroy(self.gpu);
        }
        if let Some(p) = self.presenter.take() {
            p.destroy(self.gpu);
        }
        self.window = None;
        result.and(idle)
    }
}
