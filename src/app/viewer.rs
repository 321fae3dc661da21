//! The window: winit's event loop, the wgpu surface, egui drawn over the 3D view, file
//! dialogs on their own thread and PNG screenshots read back from the GPU.
//!
//! Each frame takes the worker's newest snapshot (never waiting on physics), lays out the
//! UI over it, draws the cloth into the view rectangle and egui on top. The worker wakes
//! the event loop when it publishes, so a paused scene costs no frames.

use super::colour::{self, ColourMap};
use super::files;
use crate::render::{self, Frame, PropMesh, RenderOptions};
use super::script::Script;
use super::session::{Control, FrameInput, Session};
use super::ui::{Action, FileDialog, ViewerUi};
use super::worker::{Command, Snapshot, Worker};
use crate::scene::{CheckedScene, load_scene};
use crate::settings::SCENES;
use anyhow::{Context, anyhow};
use egui_wgpu::wgpu;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender, channel};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop, EventLoopProxy};
use winit::window::{Window, WindowId};

/// How the viewer starts.
#[derive(Debug, Clone, Default)]
pub struct ViewerOptions {
    /// Bundled scene name or scene file; the default scene when `None`.
    pub preset: Option<String>,
    /// Exit (status 0) after drawing this many frames: for smoke tests and scripted runs.
    pub quit_after_frames: Option<u64>,
    /// `KEY=VALUE` overrides of the first scene, as `rosette run --set` takes them.
    pub overrides: Vec<String>,
    /// The first scene, already loaded and checked (else `preset` and `overrides` are).
    pub config: Option<CheckedScene>,
    /// A scripted session, read and checked, played from the first frame.
    pub script: Option<Script>,
    /// Where the session's report is written (JSON), once it ends.
    pub report: Option<PathBuf>,
}

/// Loads the scene the viewer opens on, on the path it opens on (`plan::opening_path`).
pub fn load_first_scene(spec: &str, overrides: &[String]) -> Result<CheckedScene, String> {
    let (checked, _) = load_scene(spec, overrides).map_err(|e| e.to_string())?;
    let path = crate::scene::plan::opening_path(&checked);
    checked.with_path(path).map_err(|e| e.message)
}

/// The scene the viewer opens on: the Cusick drape where it exists, else Euler buckling.
pub fn default_scene() -> &'static str {
    if SCENES.iter().any(|s| s.name == "cusick-drape") { "cusick-drape" } else { "euler-buckling" }
}

/// Whether a window can be opened at all (X11 or Wayland).
pub fn display_available() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY"].iter().any(|k| std::env::var_os(k).is_some_and(|v| !v.is_empty()))
}

/// The message for a machine with no display.
pub const NO_DISPLAY: &str = "no display: neither DISPLAY nor WAYLAND_DISPLAY is set, so the viewer cannot open a window. \
     Render a scene headless instead, e.g. `rosette run cantilever --screenshot cantilever.png`, \
     or start the viewer under a virtual display: `xvfb-run -a rosette view`";

/// Wakes the event loop: a new snapshot or a dialog's answer.
#[derive(Debug, Clone, Copy)]
struct Wake;

/// Opens the viewer and runs until its window closes or its session ends. Returns the
/// session's exit code (0 without a session, or when it ran to its end).
pub fn run(mut options: ViewerOptions) -> anyhow::Result<u8> {
    if !display_available() {
        return Err(anyhow!(NO_DISPLAY));
    }
    let spec = options.preset.clone().unwrap_or_else(|| default_scene().to_string());
    let config = match options.config.take() {
        Some(config) => config,
        None => load_first_scene(&spec, &options.overrides).map_err(|e| anyhow!("{e}"))?,
    };
    let event_loop = EventLoop::<Wake>::with_user_event()
        .build()
        .map_err(|e| anyhow!("cannot connect to the display ({e}). {NO_DISPLAY}"))?;
    let proxy = event_loop.create_proxy();
    let wake = proxy.clone();
    let worker = Worker::spawn(&scene_label(&spec), config, Some(Box::new(move || {
        let _ = wake.send_event(Wake);
    })))
        .map_err(|e| anyhow!("{spec}: {e}"))?;
    // A script starts the scene itself: its first step that needs it running plays it, so a
    // wait for simulated time counts from t = 0 (`Session`).
    if options.script.is_none() {
        worker.send(Command::Play);
    }
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(
        event_loop.owned_display_handle(),
    )));
    let (dialog_tx, dialog_rx) = channel();
    let session = options.script.take().map(Session::new);
    let mut app = App {
        session,
        outcome: Control::Continue,
        options,
        worker,
        ui: ViewerUi::default(),
        egui: egui::Context::default(),
        instance,
        gpu: None,
        frames: 0,
        fatal: None,
        proxy,
        dialog_tx,
        dialog_rx,
        dialog_open: false,
        screenshot: None,
        next_repaint: None,
        last_frame: None,
        want_frame: None,
    };
    event_loop.run_app(&mut app).context("the window's event loop failed")?;
    if let Some(e) = app.fatal {
        return Err(e);
    }
    app.finish_session()
}

/// A preset name as typed, or a file's stem.
fn scene_label(spec: &str) -> String {
    Path::new(spec).file_stem().map_or_else(|| spec.to_string(), |s| s.to_string_lossy().into_owned())
}

/// GPU state that exists while the window does.
struct Gpu {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: wgpu::SurfaceConfiguration,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    /// The cloth renderer shared with headless screenshots.
    scene_renderer: render::Renderer,
    /// Depth buffer of the window's size, for the cloth pass.
    depth: Option<(wgpu::TextureView, [u32; 2])>,
}

struct App {
    options: ViewerOptions,
    /// The scripted session being played, if any, and how it ended.
    session: Option<Session>,
    outcome: Control,
    worker: Worker,
    ui: ViewerUi,
    egui: egui::Context,
    instance: wgpu::Instance,
    gpu: Option<Gpu>,
    frames: u64,
    /// An error that ended the viewer (no usable GPU, no window).
    fatal: Option<anyhow::Error>,
    proxy: EventLoopProxy<Wake>,
    dialog_tx: Sender<(FileDialog, Option<PathBuf>)>,
    dialog_rx: Receiver<(FileDialog, Option<PathBuf>)>,
    dialog_open: bool,
    /// Where the next frame is to be saved as PNG.
    screenshot: Option<PathBuf>,
    /// When egui asked for its next frame (an animation, the chart's progress bar), if it
    /// asked for one later rather than at once.
    next_repaint: Option<std::time::Instant>,
    /// When the last frame was done, and how long it took to draw.
    last_frame: Option<(std::time::Instant, std::time::Duration)>,
    /// The next frame the one being drawn asks for (scheduled once it is done).
    want_frame: Option<std::time::Instant>,
}

impl ApplicationHandler<Wake> for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gpu.is_some() {
            return;
        }
        match self.create_gpu(event_loop) {
            Ok(gpu) => {
                gpu.window.request_redraw();
                self.gpu = Some(gpu);
            }
            Err(e) => {
                self.fatal = Some(e);
                event_loop.exit();
            }
        }
    }

    /// Sleeps until the frame egui asked for later (`request_repaint_after`), or until the
    /// next event when it asked for none.
    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        match self.next_repaint {
            Some(due) if due <= std::time::Instant::now() => {
                self.next_repaint = None;
                if let Some(gpu) = &self.gpu {
                    gpu.window.request_redraw();
                }
                event_loop.set_control_flow(ControlFlow::Wait);
            }
            Some(due) => event_loop.set_control_flow(ControlFlow::WaitUntil(due)),
            None => event_loop.set_control_flow(ControlFlow::Wait),
        }
    }

    /// A new snapshot (or a dialog's answer): drawn as soon as drawing may take its share of
    /// the time again ([`App::schedule`]), whatever is newest then.
    fn user_event(&mut self, _event_loop: &ActiveEventLoop, _event: Wake) {
        self.schedule(std::time::Instant::now());
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(gpu) = &mut self.gpu else { return };
        let response = gpu.egui_state.on_window_event(&gpu.window, &event);
        // egui asks for a repaint after every event, the redraw itself included: drawn at
        // once for the user's input, while a redraw's own request would draw frames back to
        // back (what egui wants after a frame it says with its repaint delay, scheduled).
        if response.repaint && !matches!(event, WindowEvent::RedrawRequested) {
            gpu.window.request_redraw();
        }
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                gpu.config.width = size.width.max(1);
                gpu.config.height = size.height.max(1);
                gpu.surface.configure(&gpu.device, &gpu.config);
                gpu.window.request_redraw();
            }
            WindowEvent::RedrawRequested => self.redraw(event_loop),
            _ => {}
        }
    }
}

/// The share of the time the window spends drawing frames for new snapshots at most. With
/// a GPU a frame costs a millisecond or two and every snapshot is drawn; drawn in software
/// (Mesa's llvmpipe, as under Xvfb) a frame of a 3 000-triangle garment cost about as much
/// CPU as the physics of its step, and drawing every one doubled the time a garment took to
/// settle on a two-core machine (docs/performance-log.md, "2026-12-07").
const DRAW_SHARE: f64 = 0.25;

/// How often a session looks at the scene when nothing else asks for a frame.
const SESSION_FRAME: std::time::Duration = std::time::Duration::from_millis(50);

impl App {
    /// Asks for a frame at `due`, or later where drawing would take more than its share of
    /// the time ([`DRAW_SHARE`]): the frame then waits until the last one's cost is repaid.
    /// The user's own input (the mouse, keys, a resize) is drawn at once instead.
    fn schedule(&mut self, due: std::time::Instant) {
        let earliest = self.last_frame.map(|(end, cost)| end + cost.mul_f64((1.0 - DRAW_SHARE) / DRAW_SHARE));
        let due = earliest.map_or(due, |e| e.max(due));
        self.next_repaint = Some(self.next_repaint.map_or(due, |d| d.min(due)));
        if due <= std::time::Instant::now()
            && let Some(gpu) = &self.gpu
        {
            self.next_repaint = None;
            gpu.window.request_redraw();
        }
    }

    /// Ends the session: its report written where asked, its outcome said on the terminal,
    /// and its exit code (0 without a session).
    fn finish_session(&mut self) -> anyhow::Result<u8> {
        let Some(session) = &self.session else { return Ok(0) };
        let outcome = match &self.outcome {
            // The window was closed before the script ended.
            Control::Continue => Control::Quit,
            other => other.clone(),
        };
        let mut code = match &outcome {
            Control::Fail(failure) => {
                crate::errln!("error: {}, line {}: {}", session.script_name(), failure.line, failure.message);
                failure.code
            }
            _ => 0,
        };
        if let Some(path) = &self.options.report {
            let text = session.report(&self.ui, &outcome).to_json();
            if let Err(e) = crate::io::write::whole(path, text.as_bytes()) {
                crate::errln!("error: --report {}: cannot write the session's report: {e}", path.display());
                if code == 0 {
                    code = super::session::EXIT_NO_OUTPUT;
                }
            }
        }
        Ok(code)
    }

    fn create_gpu(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<Gpu> {
        let attributes = Window::default_attributes()
            .with_title("Rosette: woven-fabric simulator")
            .with_inner_size(winit::dpi::LogicalSize::new(1400.0, 860.0));
        let window = Arc::new(event_loop.create_window(attributes).context("cannot create the window")?);
        let surface = self.instance.create_surface(Arc::clone(&window)).context("cannot create a drawing surface for the window")?;
        let adapter = pollster::block_on(self.instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            compatible_surface: Some(&surface),
            ..Default::default()
        }))
        .context("no graphics adapter can draw to this window (on a machine without a GPU install Mesa: mesa-vulkan-drivers)")?;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("rosette viewer"),
            required_limits: wgpu::Limits::downlevel_webgl2_defaults().using_resolution(adapter.limits()),
            ..Default::default()
        }))
        .context("cannot open the graphics device")?;
        let size = window.inner_size();
        let mut config = surface
            .get_default_config(&adapter, size.width.max(1), size.height.max(1))
            .ok_or_else(|| anyhow!("the graphics adapter cannot present to this window"))?;
        // egui blends in gamma space: prefer a non-sRGB surface format.
        let capabilities = surface.get_capabilities(&adapter);
        if let Some(format) = capabilities.formats.iter().find(|f| !f.is_srgb()) {
            config.format = *format;
        }
        config.present_mode = wgpu::PresentMode::AutoVsync;
        surface.configure(&device, &config);
        let egui_state = egui_winit::State::new(
            self.egui.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(device.limits().max_texture_dimension_2d as usize),
        );
        let egui_renderer = egui_wgpu::Renderer::new(&device, config.format, egui_wgpu::RendererOptions::default());
        let scene_renderer = render::Renderer::new(&device, &queue, config.format, 1);
        Ok(Gpu { window, surface, device, queue, config, egui_state, egui_renderer, scene_renderer, depth: None })
    }

    fn redraw(&mut self, event_loop: &ActiveEventLoop) {
        let started = std::time::Instant::now();
        self.draw(event_loop);
        self.last_frame = Some((std::time::Instant::now(), started.elapsed()));
        if let Some(due) = self.want_frame.take() {
            self.schedule(due);
        }
    }

    fn draw(&mut self, event_loop: &ActiveEventLoop) {
        self.poll_dialogs();
        let snapshot = self.worker.latest();
        let Some(gpu) = &mut self.gpu else { return };
        let mut input = gpu.egui_state.take_egui_input(&gpu.window);
        let ui = &mut self.ui;
        let mut actions = Vec::new();
        if let (Some(session), Control::Continue) = (&mut self.session, &self.outcome) {
            let frame = FrameInput { snapshot: &snapshot, ui, events: &mut input.events, actions: &mut actions, commands_sent: self.worker.sent() };
            self.outcome = session.frame(frame);
        }
        let output = self.egui.run_ui(input, |root| actions.extend(ui.show(root, &snapshot)));
        gpu.egui_state.handle_platform_output(&gpu.window, output.platform_output);
        let pixels_per_point = output.pixels_per_point;
        let jobs = self.egui.tessellate(output.shapes, pixels_per_point);
        let mut textures = output.textures_delta;
        for (id, deltas) in &textures.set {
            for delta in deltas {
                gpu.egui_renderer.update_texture(&gpu.device, &gpu.queue, *id, delta);
            }
        }
        let frame = match gpu.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(frame) | wgpu::CurrentSurfaceTexture::Suboptimal(frame) => Some(frame),
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                gpu.surface.configure(&gpu.device, &gpu.config);
                None
            }
            _ => None,
        };
        let size = [gpu.config.width, gpu.config.height];
        let screen = egui_wgpu::ScreenDescriptor { size_in_pixels: size, pixels_per_point };
        if let Some(frame) = frame {
            let view = frame.texture.create_view(&wgpu::TextureViewDescriptor::default());
            encode_frame(gpu, &view, &jobs, &screen, &snapshot, ui);
            gpu.queue.present(frame);
            // The frame's cost includes the drawing itself, which a software renderer does
            // on threads of its own after the submit: the next frame's schedule weighs it.
            let _ = gpu.device.poll(wgpu::PollType::wait_indefinitely());
        }
        if let Some(path) = self.screenshot.take() {
            let saved = save_screenshot(gpu, &jobs, &screen, &snapshot, ui, &path).map_err(|e| format!("{e:#}"));
            match &saved {
                Ok(()) => ui.notice = Some(format!("saved {}", path.display())),
                Err(e) => ui.messages.push(format!("screenshot not saved: {e}")),
            }
            if let (Some(session), Control::Continue) = (&mut self.session, &self.outcome) {
                self.outcome = session.saved(&path, saved, snapshot.time);
            }
        }
        for id in &textures.free {
            gpu.egui_renderer.free_texture(id);
        }
        textures.clear();
        let repaint_delay = output.viewport_output.get(&egui::ViewportId::ROOT).map(|v| v.repaint_delay);
        // A later repaint (egui says Duration::MAX for none) is scheduled once the frame is
        // done, as every frame not asked for by the user's input is.
        self.next_repaint = None;
        let later = |d: std::time::Duration| (d < std::time::Duration::from_secs(3600)).then(|| std::time::Instant::now() + d);
        self.want_frame = repaint_delay.and_then(later);
        self.frames += 1;
        if self.session.is_some() && self.outcome != Control::Continue {
            event_loop.exit();
            return;
        }
        if self.options.quit_after_frames.is_some_and(|n| self.frames >= n) {
            // What a scripted run of the viewer measured: the simulation's pace under the
            // window's own rendering (the toolbar's figures, once, for logs and CI).
            let s = &snapshot.stats;
            crate::outln!(
                "viewer: {} frames; {} simulated {:.3} s in {} steps on {} triangles; last second: {:.2}x real time, {:.1} steps/s",
                self.frames, snapshot.scene_name, snapshot.time, snapshot.steps, s.triangles, s.real_time_factor, s.steps_per_second
            );
            event_loop.exit();
            return;
        }
        if self.options.quit_after_frames.is_some() || self.session.as_ref().is_some_and(Session::feeding_input) {
            gpu.window.request_redraw();
        } else if self.session.is_some() {
            // A session's waits look at the clock even while the scene is paused.
            let due = std::time::Instant::now() + SESSION_FRAME;
            self.want_frame = Some(self.want_frame.map_or(due, |d| d.min(due)));
        }
        for action in actions {
            self.act(action, &snapshot);
        }
    }

    fn act(&mut self, action: Action, snapshot: &Snapshot) {
        let dialog = match action {
            Action::Send(command) => {
                self.worker.send(command);
                return;
            }
            Action::SaveScreenshot(path) => {
                self.screenshot = Some(path);
                self.schedule(std::time::Instant::now());
                return;
            }
            Action::Screenshot => {
                let stamp = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
                self.screenshot = Some(PathBuf::from(format!("rosette-{}-{stamp}.png", snapshot.scene_name)));
                if let Some(gpu) = &self.gpu {
                    gpu.window.request_redraw();
                }
                return;
            }
            Action::Pin => {
                self.pin(snapshot);
                return;
            }
            Action::File(dialog) => dialog,
        };
        self.open_dialog(dialog, &snapshot.scene_name);
    }

    /// Pins the current fabric: the view as drawn now (at most 480 pixels wide) and the
    /// measures, shown beside the live view from the next frame.
    fn pin(&mut self, snapshot: &Snapshot) {
        let Some(gpu) = &mut self.gpu else { return };
        let rect = self.ui.view_rect;
        let scale = (480.0 / rect.width().max(1.0)).min(1.0);
        let size = [((rect.width() * scale) as u32).max(16), ((rect.height() * scale) as u32).max(16)];
        match render_view(gpu, snapshot, &self.ui, size) {
            Ok(picture) => {
                self.ui.pinned = Some(super::pin::Pinned::new(snapshot, picture));
                gpu.window.request_redraw();
            }
            Err(e) => self.ui.messages.push(format!("cannot pin: {e:#}")),
        }
    }

    /// Opens a file dialog on its own thread, so the window keeps drawing while it is open.
    fn open_dialog(&mut self, kind: FileDialog, scene: &str) {
        if self.dialog_open {
            return;
        }
        self.dialog_open = true;
        let (tx, proxy) = (self.dialog_tx.clone(), self.proxy.clone());
        let scene = scene.to_string();
        let spawned = std::thread::Builder::new().name("rosette-dialog".into()).spawn(move || {
            let (filter, extension): (&str, &str) = match kind {
                FileDialog::OpenScene | FileDialog::SaveScene => ("scene", "toml"),
                FileDialog::OpenFabric | FileDialog::SaveFabric => ("fabric", "toml"),
                FileDialog::ExportObj => ("Wavefront OBJ", "obj"),
                FileDialog::ExportCsv => ("CSV", "csv"),
                FileDialog::ExportGltf => ("glTF binary", "glb"),
            };
            let mut dialog = rfd::FileDialog::new().add_filter(filter, &[extension]);
            if let FileDialog::OpenScene = kind {
                // A GarmentCode pattern opens as the garment scene `rosette pattern import`
                // would write for it.
                dialog = dialog.add_filter("GarmentCode pattern", &["json"]);
            }
            let path = match kind {
                FileDialog::OpenScene | FileDialog::OpenFabric => dialog.pick_file(),
                _ => dialog.set_file_name(format!("{scene}.{extension}")).save_file(),
            };
            let _ = tx.send((kind, path));
            let _ = proxy.send_event(Wake);
        });
        if spawned.is_err() {
            self.dialog_open = false;
        }
    }

    /// Carries out the answers of closed file dialogs.
    fn poll_dialogs(&mut self) {
        while let Ok((kind, path)) = self.dialog_rx.try_recv() {
            self.dialog_open = false;
            let Some(path) = path else { continue };
            if let Err(e) = self.file_action(kind, &path) {
                self.ui.messages.push(e);
            }
        }
    }

    fn file_action(&mut self, kind: FileDialog, path: &Path) -> Result<(), String> {
        let snapshot = self.worker.latest();
        let write = |text: String| crate::io::write::whole(path, text.as_bytes()).map_err(|e| format!("cannot write {}: {e}", path.display()));
        // Saving a scene or fabric over the file it came from is what Save is for.
        let save = |text: String| crate::io::write::whole_chosen(path, text.as_bytes()).map_err(|e| format!("cannot write {}: {e}", path.display()));
        match kind {
            FileDialog::OpenScene => {
                let spec = path.to_string_lossy().into_owned();
                let (config, _) = load_scene(&spec, &[]).map_err(|e| e.to_string())?;
                self.worker.send(Command::LoadScene { name: scene_label(&spec), config: Box::new(config) });
                return Ok(());
            }
            FileDialog::SaveScene => save(files::scene_toml(&snapshot.config)?)?,
            FileDialog::OpenFabric => {
                self.ui.set_fabric(files::read_fabric(path)?);
                return Ok(());
            }
            FileDialog::SaveFabric => save(files::fabric_toml(&snapshot.config.fabric)?)?,
            FileDialog::ExportObj => write(files::mesh_obj(&snapshot.positions, &snapshot.topology.texture, &snapshot.topology.triangles))?,
            FileDialog::ExportCsv => write(files::measures_csv(&snapshot.measures, &self.ui.history.names, &self.ui.history.rows))?,
            FileDialog::ExportGltf => {
                let frames = [crate::export::ClothFrame { time: snapshot.time, topology: Arc::clone(&snapshot.topology), positions: snapshot.positions.clone() }];
                crate::export::write_glb(path, &snapshot.scene_name, &frames, &snapshot_look(&snapshot)).map_err(|e| e.to_string())?;
            }
        }
        self.ui.notice = Some(format!("saved {}", path.display()));
        Ok(())
    }
}

/// Draws one frame (3D view, then egui over it) into `target`.
fn encode_frame(
    gpu: &mut Gpu,
    target: &wgpu::TextureView,
    jobs: &[egui::ClippedPrimitive],
    screen: &egui_wgpu::ScreenDescriptor,
    snapshot: &Snapshot,
    ui: &ViewerUi,
) {
    let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("viewer frame") });
    draw_scene(gpu, &mut encoder, target, screen, snapshot, ui);
    let user_buffers = gpu.egui_renderer.update_buffers(&gpu.device, &gpu.queue, &mut encoder, jobs, screen);
    {
        let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("egui"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                resolve_target: None,
                depth_slice: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })],
            ..Default::default()
        });
        gpu.egui_renderer.render(&mut pass.forget_lifetime(), jobs, screen);
    }
    gpu.queue.submit(user_buffers.into_iter().chain(std::iter::once(encoder.finish())));
}

/// Clears `target` to the background and draws the cloth and props into the view
/// rectangle left between the panels.
fn draw_scene(
    gpu: &mut Gpu,
    encoder: &mut wgpu::CommandEncoder,
    target: &wgpu::TextureView,
    screen: &egui_wgpu::ScreenDescriptor,
    snapshot: &Snapshot,
    ui: &ViewerUi,
) {
    let [width, height] = screen.size_in_pixels;
    if gpu.depth.as_ref().is_none_or(|(_, size)| *size != [width, height]) {
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("viewer depth"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: render::DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        gpu.depth = Some((texture.create_view(&wgpu::TextureViewDescriptor::default()), [width, height]));
    }
    // The view rectangle in pixels, inside the target.
    let ppp = screen.pixels_per_point;
    let rect = ui.view_rect;
    let x0 = (rect.min.x * ppp).round().clamp(0.0, width as f32);
    let y0 = (rect.min.y * ppp).round().clamp(0.0, height as f32);
    let x1 = (rect.max.x * ppp).round().clamp(x0, width as f32);
    let y1 = (rect.max.y * ppp).round().clamp(y0, height as f32);
    let (view_w, view_h) = ((x1 - x0) as u32, (y1 - y0) as u32);
    let options = RenderOptions { wireframe: ui.wireframe, ..RenderOptions::default() };
    let draw = view_w > 0 && view_h > 0 && !snapshot.positions.is_empty();
    if draw {
        let frame = snapshot_frame(snapshot, ui);
        gpu.scene_renderer.prepare(&gpu.device, &gpu.queue, &frame, &ui.camera.view(), &options, [view_w, view_h]);
    }
    let [r, g, b] = options.background.map(f64::from);
    let depth = &gpu.depth.as_ref().expect("made above").0;
    let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("cloth"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target,
            resolve_target: None,
            depth_slice: None,
            // Non-sRGB target: the background's sRGB values are stored as they are.
            ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 }), store: wgpu::StoreOp::Store },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Discard }),
            stencil_ops: None,
        }),
        ..Default::default()
    });
    if draw {
        pass.set_viewport(x0, y0, view_w as f32, view_h as f32, 0.0, 1.0);
        gpu.scene_renderer.paint(&mut pass);
    }
}

/// What the view draws of `snapshot`: the cloth in the chosen colour map, the props and the
/// floor.
fn snapshot_frame(snapshot: &Snapshot, ui: &ViewerUi) -> Frame {
    let topology = &snapshot.topology;
    let mut frame = Frame::from_cloth(&snapshot.positions, &topology.triangles, &topology.texture, topology.warp_angle);
    if let ColourMap::Field(map) = ui.colour_map {
        frame.cloth_scalar = colour::field(snapshot, map);
    }
    frame.props = snapshot
        .props
        .iter()
        .map(|(p, t)| PropMesh { positions: p.iter().map(|v| v.as_vec3().to_array()).collect(), triangles: t.clone() })
        .collect();
    frame.floor_z = snapshot.ground_z.map(|z| z as f32).or_else(|| frame.floor_below());
    frame.look = snapshot_look(snapshot);
    frame
}

/// The look of the fabric the snapshot's scene runs (the default where it no longer checks).
fn snapshot_look(snapshot: &Snapshot) -> crate::appearance::Look {
    crate::appearance::Look::or_default(&snapshot.config.fabric.appearance, snapshot.config.base_dir.as_deref())
}

/// The 3D view alone (no panels), as the window's camera sees it, rendered offscreen at
/// `size` pixels and read back.
fn render_view(gpu: &mut Gpu, snapshot: &Snapshot, ui: &ViewerUi, size: [u32; 2]) -> anyhow::Result<image::RgbaImage> {
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("pinned view"),
        size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: gpu.config.format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
    let options = RenderOptions { wireframe: ui.wireframe, ..RenderOptions::default() };
    gpu.scene_renderer.prepare(&gpu.device, &gpu.queue, &snapshot_frame(snapshot, ui), &ui.camera.view(), &options, size);
    let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("pinned view") });
    gpu.scene_renderer.render(&mut encoder, &view);
    gpu.queue.submit([encoder.finish()]);
    Ok(render::read_back(&gpu.device, &gpu.queue, &texture)?)
}

/// Renders the frame again into an offscreen texture, reads it back and writes a PNG.
fn save_screenshot(
    gpu: &mut Gpu,
    jobs: &[egui::ClippedPrimitive],
    screen: &egui_wgpu::ScreenDescriptor,
    snapshot: &Snapshot,
    ui: &ViewerUi,
    path: &Path,
) -> anyhow::Result<()> {
    let [width, height] = screen.size_in_pixels;
    let format = gpu.config.format;
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("screenshot"),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
    encode_frame(gpu, &view, jobs, screen, snapshot, ui);
    let image = render::read_back(&gpu.device, &gpu.queue, &texture)?;
    crate::io::write::png_file(path, image.as_raw(), image.dimensions(), 4, crate::io::write::Effort::Balanced).map_err(anyhow::Error::msg)
}
