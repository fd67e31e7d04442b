//! The interactive demo (`lucent demo`): a window to fly around a scene in, switch techniques
//! and scenes, move the lights, turn the knobs, compare the technique with plain lighting and
//! watch the per-pass GPU times move. Built with the `window` feature.
//!
//! - [`present`]: surface, swapchain, per-frame submit and present (resize, minimize,
//!   `OUT_OF_DATE`/`SUBOPTIMAL`, bounded waits), the panel drawn over the frame.
//! - [`controls`]: the orbit/fly camera, light moves, the knobs, the comparison views, the key
//!   list (no window needed).
//! - `input`: window events, keys and the mouse, and script commands, turned into actions.
//! - `panel`: the egui panel (pickers, sliders, the timing table) and the comparison labels.
//! - [`compare`]: the split and difference views' pass (plain lighting against the technique).
//! - [`script`]: `--script FILE`, scripted input for tests.
//! - [`watch`]: shader hot reload's file polling.
//!
//! The frame itself is the ordinary [`Renderer`]: it is rebuilt on resize, on a technique or
//! scene change, on a knob change that changes the frame's shape (a pow form) and when a file
//! under the GLSL root changes; changes of values only (light positions and intensities,
//! translucency parameters, SSS width and sensitivity) are written into the next frame's
//! per-frame parameters without re-uploading the scene (the light-space shadow maps are drawn
//! every frame from those parameters, so a moved light's shadow follows it). While a
//! comparison view is on, a second renderer with technique `none` renders the same view and is
//! rebuilt with the first. A rebuild that fails (a shader typo, a scene that cannot be built)
//! keeps the previous renderer (and scene) running and shows the error. Layering: the binary
//! calls this module, which uses the renderer and passes; nothing below knows about windows.

pub mod compare;
pub mod controls;
mod input;
mod panel;
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

use compare::Comparer;
use controls::{Comparison, OrbitCamera};
use panel::{Gui, PanelAction};
use present::{Drawn, FrameInput, Presenter, UiFrame};
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
    /// Write the last frame (what the window shows, without the panel) here on exit.
    pub screenshot: Option<PathBuf>,
    /// Validation layer (also `LUCENT_VALIDATION=1`).
    pub validation: bool,
    /// Device name filter.
    pub device: Option<String>,
    /// The GLSL tree to compile and watch (`--shaders`); `None`:
    /// [`ShaderCompiler::default_glsl_root`].
    pub glsl_root: Option<PathBuf>,
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
        options
            .glsl_root
            .clone()
            .unwrap_or_else(ShaderCompiler::default_glsl_root),
        Some(crate::files::default_cache_dir()),
    )?;
    // Run-time compilation (not the shipped SPIR-V): edited shaders reload while the demo runs.
    let glsl_root = shaders.glsl_root().ok_or_else(|| {
        crate::LucentError::InvalidInput("hot reload needs a run-time shader compiler".into())
    })?;
    let pipeline_cache = PipelineCache::load_default(&gpu)?;
    // Default: what the scene's materials ask for.
    let technique = options.technique.unwrap_or(Technique::Auto);
    let orbit = OrbitCamera::from_camera(&scene.camera);
    orbit.apply(&mut scene.camera);
    let mut app = Demo {
        gpu: &gpu,
        shaders: &shaders,
        pipeline_cache: &pipeline_cache,
        watcher: ShaderWatcher::new(glsl_root),
        gui: None,
        technique,
        debug_view: None,
        isolated: false,
        runner: None,
        scene,
        previous_scene: None,
        light: 0,
        comparison: Comparison::default(),
        plain: None,
        comparer: None,
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

/// What the panel shows besides the timings.
#[derive(Default)]
struct View {
    help: bool,
    hidden: bool,
    knob: usize,
    /// The latest message and whether it is an error (shader compile errors stay until a
    /// rebuild succeeds).
    message: Option<(String, bool)>,
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
    /// The panel's egui state (created with the window).
    gui: Option<Gui>,
    technique: Technique,
    debug_view: Option<DebugView>,
    /// Isolated timing (each physical pass its own submission) instead of in-frame.
    isolated: bool,
    /// Runs the isolated frames (sized for the current renderer's passes).
    runner: Option<FrameRunner>,
    scene: Scene,
    /// The scene and camera before a scene switch, until the new scene's renderer is built (a
    /// failed build goes back to them).
    previous_scene: Option<(Scene, OrbitCamera)>,
    /// The selected light (index into `scene.lights`).
    light: usize,
    /// The comparison view shown.
    comparison: Comparison,
    /// Plain lighting (technique `none`) of the same view, while a comparison is shown.
    plain: Option<Renderer>,
    /// The comparison pass, while a comparison is shown.
    comparer: Option<Comparer>,
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
        self.gui = Some(Gui::new(&window));
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
        self.stats.refresh();
        let ui = self.run_ui(event_loop)?;
        if self.done {
            return Ok(());
        }
        let plain_missing = self.comparison.active() && self.plain.is_none();
        if self.rebuild_pending || self.renderer.is_none() || plain_missing {
            self.rebuild_pending = false;
            self.rebuild()?;
        }
        self.orbit.apply(&mut self.scene.camera);
        let Some(renderer) = self.renderer.as_mut() else {
            return Ok(());
        };
        renderer.update(&self.scene)?;
        if let Some(plain) = self.plain.as_mut() {
            plain.update(&self.scene)?;
        }
        let (Some(presenter), Some(renderer)) = (self.presenter.as_mut(), self.renderer.as_ref())
        else {
            return Ok(());
        };
        let started = Instant::now();
        let isolated = match (self.isolated, self.runner.as_mut()) {
            (true, Some(runner)) => Some(runner.run_isolated(self.gpu, &renderer.executable)?),
            _ => None,
        };
        let compare = match (self.plain.as_ref(), self.comparer.as_mut()) {
            (Some(plain), Some(comparer)) if self.comparison.active() => {
                Some((plain, comparer, self.comparison))
            }
            _ => None,
        };
        let input = FrameInput {
            renderer,
            render: isolated.is_none(),
            compare,
            ui,
        };
        match presenter.draw(self.gpu, input)? {
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

    /// Builds the renderer for the current size, technique and scene, and, while a comparison
    /// is shown, the plain-lighting renderer and the comparison pass. A failure keeps the
    /// previous renderers (if any) and the previous scene (after a scene switch) and shows the
    /// error; without a previous renderer it is fatal.
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
        match self.build(settings) {
            Ok((new, compared)) => {
                self.gpu.wait_idle()?;
                let runner = FrameRunner::new(self.gpu, new.executable.plan.physical.len());
                if let Some(old) = self.runner.take() {
                    old.destroy(self.gpu);
                }
                if let Some(old) = self.renderer.replace(new) {
                    old.destroy(self.gpu);
                }
                self.drop_comparison();
                if let Some((plain, comparer)) = compared {
                    self.plain = Some(plain);
                    self.comparer = Some(comparer);
                }
                self.previous_scene = None;
                self.runner = Some(runner?);
                self.stats.clear();
                if self.view.message.as_ref().is_some_and(|(_, error)| *error) {
                    self.view.message = None;
                }
                log::info!(
                    "renderer {}x{} {} built in {:.0} ms{}",
                    settings.width,
                    settings.height,
                    settings.technique.name(),
                    started.elapsed().as_secs_f64() * 1e3,
                    if self.plain.is_some() {
                        " (with plain lighting for the comparison)"
                    } else {
                        ""
                    }
                );
                Ok(())
            }
            Err(e @ (LucentError::DeviceLost { .. } | LucentError::SurfaceLost { .. })) => Err(e),
            Err(e) if self.renderer.is_some() => {
                let scene = match self.previous_scene.take() {
                    Some((scene, orbit)) => {
                        let failed = std::mem::replace(&mut self.scene, scene);
                        self.orbit = orbit;
                        self.light = self.light.min(self.scene.lights.len().saturating_sub(1));
                        self.set_title();
                        format!(
                            " (back to scene {}, {} failed)",
                            self.scene.name, failed.name
                        )
                    }
                    None => String::new(),
                };
                if self.comparison.active() && self.plain.is_none() {
                    // The comparison cannot be shown without its renderer.
                    self.comparison = Comparison::default();
                }
                self.say(
                    format!("rebuild failed, the previous frame keeps running{scene}:\n{e}"),
                    true,
                );
                Ok(())
            }
            Err(e) => Err(e),
        }
    }

    /// The renderer for `settings` and, while a comparison is shown, the plain-lighting
    /// renderer of the same view and the comparison pass.
    fn build(&self, settings: FrameSettings) -> Result<(Renderer, Option<(Renderer, Comparer)>)> {
        let new = |settings| {
            Renderer::new(
                self.gpu,
                self.shaders,
                self.pipeline_cache,
                &self.scene,
                settings,
            )
        };
        let renderer = new(settings)?;
        if !self.comparison.active() {
            return Ok((renderer, None));
        }
        let plain_settings = FrameSettings {
            technique: Technique::None,
            debug_view: None,
            ..settings
        };
        let compared = new(plain_settings).and_then(|plain| {
            match Comparer::new(self.gpu, self.shaders, self.pipeline_cache) {
                Ok(comparer) => Ok((plain, comparer)),
                Err(e) => {
                    plain.destroy(self.gpu);
                    Err(e)
                }
            }
        });
        match compared {
            Ok(c) => Ok((renderer, Some(c))),
            Err(e) => {
                renderer.destroy(self.gpu);
                Err(e)
            }
        }
    }

    /// Destroys the comparison's renderer and pass (the GPU is idle).
    fn drop_comparison(&mut self) {
        if let Some(old) = self.plain.take() {
            old.destroy(self.gpu);
        }
        if let Some(old) = self.comparer.take() {
            old.destroy(self.gpu);
        }
    }

    fn set_title(&self) {
        if let Some(window) = &self.window {
            window.set_title(&format!("lucent demo — {}", self.scene.name));
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
                features.translucency().is_some()
            }
            DebugView::LitBeforeSss => features.sss().is_some(),
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

    /// Writes what the window shows without the panel: the frame, or the comparison.
    fn write_screenshot(&mut self, path: &std::path::Path) -> Result<()> {
        let compared = match (self.comparison.active(), self.comparer.as_ref()) {
            (true, Some(comparer)) => comparer.read(self.gpu)?,
            _ => None,
        };
        let (w, h, pixels) = match compared {
            Some(c) => c,
            None => {
                let Some(renderer) = self.renderer.as_ref() else {
                    return Ok(());
                };
                (
                    renderer.settings.width,
                    renderer.settings.height,
                    renderer.read_display(self.gpu)?,
                )
            }
        };
        output::write_png_rgba8(path, w, h, &pixels)?;
        self.say(format!("wrote {} ({w}x{h})", path.display()), false);
        println!("wrote {} ({w}x{h})", path.display());
        Ok(())
    }

    /// Builds this frame's panel from the window's input and applies what the user changed in
    /// it. `None` without a window.
    fn run_ui(&mut self, event_loop: &ActiveEventLoop) -> Result<Option<UiFrame>> {
        let (Some(window), Some(gui)) = (self.window.as_ref(), self.gui.as_mut()) else {
            return Ok(None);
        };
        let raw = gui.state.take_egui_input(window);
        let ctx = gui.ctx.clone();
        let mut actions = Vec::new();
        let output = ctx.run_ui(raw, |ui| self.panel_ui(ui, &mut actions));
        if let (Some(window), Some(gui)) = (self.window.as_ref(), self.gui.as_mut()) {
            gui.state
                .handle_platform_output(window, output.platform_output);
        }
        let primitives = ctx.tessellate(output.shapes, output.pixels_per_point);
        match self.presenter.as_mut() {
            Some(presenter) => presenter.queue_textures(output.textures_delta),
            None => {
                let mut unused = output.textures_delta;
                unused.clear();
            }
        }
        for action in actions {
            self.apply_panel(event_loop, action)?;
        }
        Ok(Some(UiFrame {
            primitives,
            pixels_per_point: output.pixels_per_point,
        }))
    }

    /// Carries out a change made in the panel.
    fn apply_panel(&mut self, event_loop: &ActiveEventLoop, action: PanelAction) -> Result<()> {
        match action {
            PanelAction::Act(action) => self.act(event_loop, action)?,
            PanelAction::Technique(technique) => {
                self.technique = technique;
                self.rebuild_pending = true;
            }
            PanelAction::Scene(name) => self.switch_scene(&name),
            PanelAction::SelectLight(i) => self.select_light(i),
            PanelAction::LightVector(v) => {
                if let Some(light) = self.scene.lights.get_mut(self.light) {
                    controls::set_light_vector(light, v);
                    self.values_changed()?;
                }
            }
            PanelAction::LightIntensity(intensity) => {
                if let Some(light) = self.scene.lights.get_mut(self.light) {
                    light.intensity =
                        intensity.clamp(controls::INTENSITY_RANGE.0, controls::INTENSITY_RANGE.1);
                    self.values_changed()?;
                }
            }
            PanelAction::Knob(i, value) => self.set_knob(i, value)?,
        }
        Ok(())
    }

    /// Loads built-in scene `name` and rebuilds; an error is shown, and the current scene
    /// stays.
    fn switch_scene(&mut self, name: &str) {
        match crate::bake::scene::load_scene_baked(name) {
            Ok(mut scene) => {
                let orbit = OrbitCamera::from_camera(&scene.camera);
                orbit.apply(&mut scene.camera);
                let old_scene = std::mem::replace(&mut self.scene, scene);
                let old_orbit = std::mem::replace(&mut self.orbit, orbit);
                // Kept until the new scene's renderer is built (see `rebuild`).
                if self.previous_scene.is_none() {
                    self.previous_scene = Some((old_scene, old_orbit));
                }
                self.light = 0;
                self.rebuild_pending = true;
                self.set_title();
                self.say(format!("scene {name}"), false);
            }
            Err(e) => self.say(format!("scene {name} not loaded: {e}"), true),
        }
    }

    /// After a change of values only (a light, a knob): the next frame writes them into its
    /// per-frame parameters, unless the frame's shape changed with them (then it is rebuilt).
    fn values_changed(&mut self) -> Result<()> {
        let mut in_place = true;
        for r in [self.renderer.as_mut(), self.plain.as_mut()]
            .into_iter()
            .flatten()
        {
            in_place &= r.retune(&self.options.base) && r.can_update(&self.scene)?;
        }
        if !in_place {
            self.rebuild_pending = true;
        }
        Ok(())
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
            for (i, light) in self.scene.lights.iter().enumerate() {
                let v = controls::light_vector(light);
                println!(
                    "demo light {}: {} {} {:.5} {:.5} {:.5} intensity {:.5}",
                    i + 1,
                    controls::light_kind_name(light),
                    match light.kind {
                        crate::scene::LightKind::Directional { .. } => "direction",
                        _ => "position",
                    },
                    v.x,
                    v.y,
                    v.z,
                    light.intensity
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
        self.drop_comparison();
        if let Some(p) = self.presenter.take() {
            p.destroy(self.gpu);
        }
        self.window = None;
        result.and(idle)
    }
}
