//! `phantogram view`: the desktop viewer. A window shows the phantogram as the phone would; the
//! mouse tilts a virtual phone (or a sensor log replays in real time), keys switch the anaglyph
//! method and calibrate.
//!
//! The virtual phone produces accelerometer, gyroscope and magnetometer events from its
//! orientation, so the same session, fusion, containment and renderer run as on a device.
//! The window surface follows the lifecycle of [`phantogram::surface::SurfaceHost`]:
//! `resumed` → resume, `Resized` → resize, `suspended` → suspend.

use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result, anyhow};
use phantogram::anaglyph::Method;
use phantogram::containment::{Aabb, ContainmentSmoother};
use phantogram::glam::{Quat, Vec3};
use phantogram::model::Model;
use phantogram::render::{FrameInput, Gpu, Renderer};
use phantogram::sensors::SensorEvent;
use phantogram::surface::{DrawOutcome, SurfaceHost, SurfaceState};
use phantogram::{Session, SessionConfig};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

pub struct ViewerArgs {
    pub model: Model,
    /// The artifact's bounds (without the floor), for containment.
    pub bounds: Aabb,
    /// Light from this environment instead of the generated studio.
    pub environment: Option<phantogram::ibl::Environment>,
    pub log: Option<Vec<SensorEvent>>,
    pub method: Method,
    /// Exit after presenting this many frames (tests, scripted screenshots).
    pub frames: Option<u64>,
    /// Exercise suspend, resume and resize while running (a self-test of the surface lifecycle).
    pub lifecycle_test: bool,
    /// Open the calibration screens at start.
    pub calibration: bool,
}

/// A phone tilted by the mouse: pitch about the screen's horizontal, roll about its vertical.
struct VirtualPhone {
    pitch_rad: f32,
    roll_rad: f32,
    last: Option<(f64, Quat)>,
}

impl VirtualPhone {
    fn orientation(&self) -> Quat {
        Quat::from_rotation_x(self.pitch_rad) * Quat::from_rotation_y(self.roll_rad)
    }

    /// Sensor events for the current orientation at `t_s`.
    fn events(&mut self, t_s: f64) -> Vec<SensorEvent> {
        let q = self.orientation();
        let t_ns = (t_s * 1e9) as i64;
        let mut out = vec![
            SensorEvent::accelerometer(t_ns, q.inverse() * Vec3::Z * 9.81),
            SensorEvent::magnetometer(t_ns, q.inverse() * phantogram::synthetic::default_field_world_ut()),
        ];
        let rate = match self.last {
            Some((t0, q0)) if t_s > t0 => (q0.inverse() * q).to_scaled_axis() / (t_s - t0) as f32,
            _ => Vec3::ZERO,
        };
        out.push(SensorEvent::gyroscope(t_ns, rate));
        self.last = Some((t_s, q));
        out
    }
}

struct App {
    args: ViewerArgs,
    window: Option<Arc<Window>>,
    renderer: Option<Renderer>,
    host: SurfaceHost,
    session: Session,
    smoother: ContainmentSmoother,
    phone: VirtualPhone,
    log_cursor: usize,
    log_t0: Option<i64>,
    method: Method,
    start: Instant,
    last_frame_s: f64,
    dragging: bool,
    cursor: Option<(f64, f64)>,
    presented: u64,
    error: Option<anyhow::Error>,
    /// The calibration screens, while open (key `c`).
    calibration_ui: Option<phantogram::calibration_ui::CalibrationUi>,
    calibration: phantogram::calibration::Calibration,
    calibration_path: Option<std::path::PathBuf>,
    egui_ctx: egui::Context,
    egui_input: Option<egui_winit::State>,
    overlay: phantogram::calibration_ui::OverlayHost,
}

/// The phone's density scale (pixels per point) the calibration screens are laid out for.
const PHONE_PIXELS_PER_POINT: f32 = 2.75;

impl App {
    fn size(&self) -> (u32, u32) {
        self.window.as_ref().map_or((0, 0), |w| {
            let s = w.inner_size();
            (s.width, s.height)
        })
    }

    fn feed_sensors(&mut self, now_s: f64) {
        match &self.args.log {
            Some(events) => {
                // Real-time replay: every event up to the log time that has elapsed.
                let t0 = *self.log_t0.get_or_insert(events.first().map_or(0, |e| e.t_ns));
                let until = t0 + (now_s * 1e9) as i64;
                while let Some(e) = events.get(self.log_cursor).filter(|e| e.t_ns <= until) {
                    let _ = self.session.push(*e);
                    self.log_cursor += 1;
                }
            }
            None => {
                for e in self.phone.events(now_s) {
                    let _ = self.session.push(e);
                }
            }
        }
    }

    fn frame(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let now_s = self.start.elapsed().as_secs_f64();
        let dt = (now_s - self.last_frame_s).max(1e-3) as f32;
        self.last_frame_s = now_s;
        self.feed_sensors(now_s);
        let view = self.session.frame()?;
        let push = self.smoother.follow(
            &self.args.bounds,
            &view.stereo_eyes_m(),
            &self.session.config().screen,
            dt,
        );
        let input = FrameInput::from_view(&view, Vec3::Z * -push);
        let Some(renderer) = self.renderer.as_mut() else {
            return Ok(());
        };
        let mut actions = Vec::new();
        let painted = match (
            self.calibration_ui.as_mut(),
            self.egui_input.as_mut(),
            self.window.clone(),
        ) {
            (Some(ui_state), Some(egui_input), Some(window)) => {
                let screen = self.session.config().screen;
                // Display pixels of the virtual phone → window pixels; egui's points are laid
                // out as on the phone.
                let k = window.inner_size().width as f32 / screen.width_px() as f32;
                self.egui_ctx
                    .set_zoom_factor(PHONE_PIXELS_PER_POINT * k / window.scale_factor() as f32);
                let raw = egui_input.take_egui_input(&window);
                let mut output = self
                    .egui_ctx
                    .run_ui(raw, |ui| actions = ui_state.show(ui, &screen, PHONE_PIXELS_PER_POINT));
                egui_input.handle_platform_output(&window, std::mem::take(&mut output.platform_output));
                Some(output)
            }
            _ => None,
        };
        let outcome = match painted {
            Some(mut output) => {
                let ctx = self.egui_ctx.clone();
                let overlay = &mut self.overlay;
                overlay.begin(&mut output);
                let outcome = self
                    .host
                    .draw_with(renderer, &input, self.method, |gpu, view, format, size| {
                        overlay.paint(gpu, &ctx, &mut output, view, format, size)
                    })?;
                if self.overlay.end(&mut output) {
                    self.fresh_egui();
                }
                outcome
            }
            None => self.host.draw(renderer, &input, self.method)?,
        };
        if outcome == DrawOutcome::Presented {
            self.presented += 1;
        }
        for action in actions {
            self.apply(action);
        }
        if self.args.lifecycle_test {
            self.lifecycle_step(&input)?;
        }
        if self.args.frames.is_some_and(|n| self.presented >= n) {
            event_loop.exit();
        }
        Ok(())
    }

    /// Suspends after 5 frames (a draw then must be skipped), resumes, and resizes to half and
    /// back after 10 and 12 frames.
    fn lifecycle_step(&mut self, input: &FrameInput) -> Result<()> {
        let (Some(renderer), Some(window)) = (self.renderer.as_mut(), self.window.clone()) else {
            return Ok(());
        };
        let (w, h) = (window.inner_size().width, window.inner_size().height);
        match self.presented {
            5 if self.host.stats().suspended == 0 => {
                self.host.suspend();
                let outcome = self.host.draw(renderer, input, self.method)?;
                if outcome == DrawOutcome::Presented || self.host.state() != SurfaceState::Suspended {
                    return Err(anyhow!("drew while suspended"));
                }
                self.host.resume(renderer.gpu(), window, w, h)?;
            }
            10 => self.host.resize(renderer.gpu(), (w / 2).max(1), (h / 2).max(1)),
            12 => self.host.resize(renderer.gpu(), w, h),
            _ => {}
        }
        Ok(())
    }

    fn apply(&mut self, action: phantogram::calibration_ui::CalibrationAction) {
        use phantogram::calibration_ui::CalibrationAction as A;
        match action {
            A::FlatAngleHere => self.flat_angle_here(),
            A::ResetLight => match self.session.recalibrate_light() {
                Ok(()) => eprintln!("light re-tied to the room at this pose"),
                Err(e) => eprintln!("light: {e}"),
            },
            A::Changed(c) => {
                // The screens do not set the flat angle; the session holds the current one.
                self.calibration = phantogram::calibration::Calibration {
                    flat_up_device: self.calibration.flat_up_device,
                    ..c
                };
                self.apply_calibration();
                self.save_calibration();
            }
            A::Closed => self.calibration_ui = None,
        }
    }

    /// Makes the current pose straight on, and keeps it in the calibration file.
    fn flat_angle_here(&mut self) {
        match self.session.calibrate_flat_angle() {
            Ok(()) => eprintln!("flat angle: this pose is now straight on"),
            Err(e) => return eprintln!("flat angle: {e}"),
        }
        self.calibration.flat_up_device = self.session.flat_up_device();
        self.save_calibration();
    }

    fn save_calibration(&self) {
        if let Some(path) = &self.calibration_path {
            match self.calibration.save(path) {
                Ok(()) => eprintln!("calibration saved to {}", path.display()),
                Err(e) => eprintln!("warning: could not save the calibration to {}: {e}", path.display()),
            }
        }
    }

    /// Puts the calibrated IPD, distance, pixel density and flat angle into the session.
    fn apply_calibration(&mut self) {
        // The virtual phone's panel as a phone would report it; a calibrated density goes over it.
        let panel = phantogram::screen::Screen::default().panel();
        if let Err(refused) = self.session.apply_calibration(&self.calibration, panel) {
            eprintln!("warning: calibration not fully applied: {refused}");
        }
    }

    /// A new egui context (and its input state), which sends every texture again: after the
    /// overlay had to be remade for a new surface format.
    fn fresh_egui(&mut self) {
        self.egui_ctx = egui::Context::default();
        self.egui_input = self.window.as_ref().map(|w| egui_state(&self.egui_ctx, w));
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        self.error.get_or_insert(e);
        event_loop.exit();
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        let result = (|| -> Result<()> {
            if self.window.is_none() {
                let attrs = Window::default_attributes()
                    .with_title("Phantogram")
                    .with_inner_size(winit::dpi::PhysicalSize::new(405, 900));
                self.window = Some(Arc::new(
                    event_loop.create_window(attrs).context("creating the window")?,
                ));
            }
            let window = self.window.clone().expect("created above");
            if self.renderer.is_none() {
                let gpu = Gpu::for_display(Box::new(event_loop.owned_display_handle()), window.clone())?;
                eprintln!("viewing on {}", gpu.describe());
                let renderer = Renderer::with_environment(gpu, &self.args.model, self.args.environment.as_ref())?;
                self.renderer = Some(renderer);
            }
            if self.egui_input.is_none() {
                self.egui_input = Some(egui_state(&self.egui_ctx, &window));
            }
            let (w, h) = self.size();
            let renderer = self.renderer.as_ref().expect("created above");
            self.host.resume(renderer.gpu(), window.clone(), w, h)?;
            window.request_redraw();
            Ok(())
        })();
        if let Err(e) = result {
            self.fail(event_loop, e);
        }
    }

    fn suspended(&mut self, _event_loop: &ActiveEventLoop) {
        self.host.suspend();
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        // While the calibration screens are open, the mouse and keys drive them.
        if self.calibration_ui.is_some()
            && let (Some(state), Some(window)) = (self.egui_input.as_mut(), self.window.as_ref())
        {
            let consumed = state.on_window_event(window, &event).consumed;
            let passes = matches!(
                event,
                WindowEvent::CloseRequested | WindowEvent::Resized(_) | WindowEvent::RedrawRequested
            );
            if consumed || !passes {
                return;
            }
        }
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Some(r) = &self.renderer {
                    self.host.resize(r.gpu(), size.width, size.height);
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                self.dragging = state == ElementState::Pressed;
                self.cursor = None;
            }
            WindowEvent::CursorMoved { position, .. } if self.dragging => {
                if let Some((x, y)) = self.cursor {
                    // Half a degree per pixel, within ±80°.
                    let k = 0.5f32.to_radians();
                    let limit = 80f32.to_radians();
                    self.phone.roll_rad = (self.phone.roll_rad + (position.x - x) as f32 * k).clamp(-limit, limit);
                    self.phone.pitch_rad = (self.phone.pitch_rad + (position.y - y) as f32 * k).clamp(-limit, limit);
                }
                self.cursor = Some((position.x, position.y));
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                match event.logical_key.as_ref() {
                    Key::Named(NamedKey::Escape) => event_loop.exit(),
                    Key::Character(c) => match c {
                        "1" | "2" | "3" | "4" | "5" | "6" | "7" | "8" => {
                            let i: usize = c.parse().unwrap_or(1);
                            self.method = Method::ALL[i - 1];
                            eprintln!("anaglyph: {}", self.method);
                        }
                        "m" => {
                            self.method = if self.method.is_stereo() {
                                Method::Mono
                            } else {
                                Method::DuboisRedCyan
                            };
                            eprintln!("anaglyph: {}", self.method);
                        }
                        "f" => self.flat_angle_here(),
                        "r" => {
                            self.session.reset_flat_angle();
                            self.calibration.flat_up_device = None;
                            self.save_calibration();
                            eprintln!("flat angle reset: lying flat is straight on");
                        }
                        "l" => match self.session.recalibrate_light() {
                            Ok(()) => eprintln!("light re-tied to the room at this pose"),
                            Err(e) => eprintln!("light: {e}"),
                        },
                        "c" => {
                            self.calibration_ui = Some(phantogram::calibration_ui::CalibrationUi::with_calibration(
                                self.calibration,
                            ));
                        }
                        _ => {}
                    },
                    _ => {}
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.frame(event_loop) {
                    self.fail(event_loop, e);
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(w) = &self.window {
            w.request_redraw();
        }
    }
}

/// Runs the viewer until the window closes (or `frames` are presented).
pub fn run(args: ViewerArgs) -> Result<()> {
    let event_loop =
        EventLoop::new().context("no display to open a window on (set DISPLAY, or use `phantogram render`)")?;
    event_loop.set_control_flow(ControlFlow::Poll);
    eprintln!(
        "drag to tilt the phone; keys: 1-8 anaglyph method, m mono/stereo, f flat angle here, r reset it, l re-tie the light, c calibration screens, Esc quit"
    );
    let calibration_path = phantogram::calibration::Calibration::default_path();
    let calibration = match &calibration_path {
        Some(path) => {
            let (c, warning) = phantogram::calibration::Calibration::load(path);
            if let Some(w) = warning {
                eprintln!("warning: {w}");
            }
            c
        }
        None => Default::default(),
    };
    let method = args.method;
    let args_calibration_open = args
        .calibration
        .then(|| phantogram::calibration_ui::CalibrationUi::with_calibration(calibration));
    let mut app = App {
        args,
        window: None,
        renderer: None,
        host: SurfaceHost::new(),
        session: Session::new(SessionConfig::default())?,
        smoother: ContainmentSmoother::default(),
        phone: VirtualPhone {
            pitch_rad: 35f32.to_radians(),
            roll_rad: 0.0,
            last: None,
        },
        log_cursor: 0,
        log_t0: None,
        method,
        start: Instant::now(),
        last_frame_s: 0.0,
        dragging: false,
        cursor: None,
        presented: 0,
        error: None,
        calibration_ui: args_calibration_open,
        calibration,
        calibration_path,
        egui_ctx: egui::Context::default(),
        egui_input: None,
        overlay: phantogram::calibration_ui::OverlayHost::new(),
    };
    app.apply_calibration();
    event_loop.run_app(&mut app).context("the window's event loop failed")?;
    let s = app.host.stats();
    eprintln!(
        "presented {} frames ({} skipped); surface resumed {}, suspended {}, reconfigured {}, recreated {}",
        s.presented, s.skipped, s.resumed, s.suspended, s.reconfigured, s.recreated
    );
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// egui's input state for `window`, feeding `ctx`.
fn egui_state(ctx: &egui::Context, window: &Window) -> egui_winit::State {
    egui_winit::State::new(
        ctx.clone(),
        egui::ViewportId::ROOT,
        window,
        Some(window.scale_factor() as f32),
        None,
        None,
    )
}
