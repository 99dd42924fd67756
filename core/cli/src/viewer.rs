//! `phantogram view`: the desktop viewer. A window shows the phantogram as the phone would; the
//! mouse tilts a virtual phone (or a sensor log replays in real time), keys switch the anaglyph
//! method and calibrate.
//!
//! It drives the same [`Engine`] as the phone shells, the way they do: the engine (its GPU
//! opened without a window, as on the phones) is made before the window exists; the window is
//! handed to it on `resumed` ([`Engine::resume_window`]), resized on `Resized`, and taken away on
//! `suspended` ([`Engine::suspend`]); sensor events go into its inbox and every redraw is one
//! [`Engine::draw`]. The virtual phone produces accelerometer, gyroscope and magnetometer events
//! from its orientation. While the calibration screens are open the mouse is a finger
//! ([`Engine::touch`]), as on the phone.

use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result, anyhow};
use phantogram::anaglyph::Method;
use phantogram::engine::Engine;
use phantogram::gesture::TouchPhase;
use phantogram::glam::{Quat, Vec3};
use phantogram::sensors::{SensorEvent, SensorInbox};
use phantogram::surface::DrawOutcome;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

pub struct ViewerArgs {
    pub engine: Engine,
    pub log: Option<Vec<SensorEvent>>,
    /// Exit after presenting this many frames (tests, scripted screenshots).
    pub frames: Option<u64>,
    /// Exercise suspend, resume and resize while running (a self-test of the surface lifecycle).
    pub lifecycle_test: bool,
    /// Open the calibration screens at start.
    pub calibration: bool,
    /// Open the artifacts menu at start.
    pub menu: bool,
    /// After `frames`: print "ready", keep the last frame on screen this long, then close.
    pub linger_s: Option<f32>,
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
    engine: Engine,
    inbox: Arc<SensorInbox>,
    log: Option<Vec<SensorEvent>>,
    frames: Option<u64>,
    linger_s: Option<f32>,
    /// When the lingering after the last frame ends.
    linger_until: Option<Instant>,
    lifecycle_test: bool,
    /// How many of [`App::lifecycle_step`]'s steps were taken.
    lifecycle_steps_done: u8,
    window: Option<Arc<Window>>,
    phone: VirtualPhone,
    log_cursor: usize,
    log_t0: Option<i64>,
    start: Instant,
    dragging: bool,
    /// A finger on the calibration screens (the left button, while they are open).
    touching: bool,
    cursor: Option<(f64, f64)>,
    /// The calibration warning last printed.
    last_warning: Option<String>,
    error: Option<anyhow::Error>,
}

impl App {
    fn size(&self) -> (u32, u32) {
        self.window.as_ref().map_or((0, 0), |w| {
            let s = w.inner_size();
            (s.width, s.height)
        })
    }

    /// The sensor clock now, ns: the virtual phone's (time since start), or the log's.
    fn now_ns(&self) -> i64 {
        let elapsed_ns = self.start.elapsed().as_nanos() as i64;
        match (&self.log, self.log_t0) {
            (Some(_), Some(t0)) => t0 + elapsed_ns,
            _ => elapsed_ns,
        }
    }

    /// Pushes what the sensors said up to now; returns the sensor time of now.
    fn feed_sensors(&mut self) -> i64 {
        if let Some(events) = &self.log {
            self.log_t0.get_or_insert(events.first().map_or(0, |e| e.t_ns));
        }
        let now_ns = self.now_ns();
        match &self.log {
            // Real-time replay: every event up to the log time that has elapsed.
            Some(events) => {
                while let Some(e) = events.get(self.log_cursor).filter(|e| e.t_ns <= now_ns) {
                    let _ = self.inbox.push(*e);
                    self.log_cursor += 1;
                }
            }
            None => {
                for e in self.phone.events(now_ns as f64 * 1e-9) {
                    let _ = self.inbox.push(e);
                }
            }
        }
        now_ns
    }

    fn frame(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        if let Some(until) = self.linger_until {
            // The last frame stays on screen, untouched, for a screenshot.
            if Instant::now() >= until {
                event_loop.exit();
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
            return Ok(());
        }
        let t_ns = self.feed_sensors();
        self.engine.draw(Some(t_ns))?;
        if self.lifecycle_test {
            self.lifecycle_step(t_ns)?;
        }
        if self.frames.is_some_and(|n| self.engine.stats().frames_drawn >= n) {
            match self.linger_s {
                Some(s) => {
                    eprintln!("ready: {} frames presented", self.engine.stats().frames_drawn);
                    self.linger_until = Some(Instant::now() + std::time::Duration::from_secs_f32(s.clamp(0.0, 3600.0)));
                }
                None => event_loop.exit(),
            }
        }
        Ok(())
    }

    /// Suspends after 5 frames (a draw then must be skipped), resumes, and resizes to half and
    /// back after 10 and 12 frames: what a phone does on leaving and returning to the app and on
    /// rotation, through the engine's calls.
    fn lifecycle_step(&mut self, t_ns: i64) -> Result<()> {
        let Some(window) = self.window.clone() else {
            return Ok(());
        };
        let (w, h) = self.size();
        // Each step once, in order, whatever the window system does meanwhile.
        match (self.engine.stats().frames_drawn, self.lifecycle_steps_done) {
            (5.., 0) => {
                self.engine.suspend();
                if self.engine.draw(Some(t_ns))? == DrawOutcome::Presented {
                    return Err(anyhow!("drew while suspended"));
                }
                self.engine.resume_window(window, w, h)?;
            }
            (10.., 1) => self.engine.resize((w / 2).max(1), (h / 2).max(1))?,
            (12.., 2) => self.engine.resize(w, h)?,
            _ => return Ok(()),
        }
        self.lifecycle_steps_done += 1;
        Ok(())
    }

    fn key(&mut self, event_loop: &ActiveEventLoop, key: Key<&str>) {
        match key {
            Key::Named(NamedKey::Escape) => event_loop.exit(),
            Key::Character(c) => match c {
                "1" | "2" | "3" | "4" | "5" | "6" | "7" | "8" => {
                    let i: usize = c.parse().unwrap_or(1);
                    self.engine.set_method(Method::ALL[i - 1]);
                    eprintln!("anaglyph: {}", self.engine.method());
                }
                "m" => {
                    let method = if self.engine.method().is_stereo() {
                        Method::Mono
                    } else {
                        Method::DuboisRedCyan
                    };
                    self.engine.set_method(method);
                    eprintln!("anaglyph: {method}");
                }
                "f" => match self.engine.calibrate_flat_angle() {
                    Ok(()) => eprintln!("flat angle: this pose is now straight on"),
                    Err(e) => eprintln!("flat angle: {e}"),
                },
                "r" => {
                    self.engine.reset_flat_angle();
                    eprintln!("flat angle reset: lying flat is straight on");
                }
                "l" => match self.engine.anchor_light() {
                    Ok(()) => eprintln!("light re-tied to the room at this pose"),
                    Err(e) => eprintln!("light: {e}"),
                },
                "c" => {
                    self.engine.open_calibration();
                }
                "a" => {
                    self.engine.open_menu();
                }
                // Share, as the phones' share sheet: the view as an anaglyph and as a stereo pair.
                "s" => self.save_snapshots(),
                _ => {}
            },
            _ => {}
        }
        self.report_calibration_warning();
    }

    /// Writes the current view as `phantogram-anaglyph-N.png` and `phantogram-pair-N.png` (left
    /// eye on the left) in the working folder, never over an existing file.
    fn save_snapshots(&mut self) {
        let n = (1..10_000)
            .find(|n| {
                !std::path::Path::new(&format!("phantogram-anaglyph-{n}.png")).exists()
                    && !std::path::Path::new(&format!("phantogram-pair-{n}.png")).exists()
            })
            .unwrap_or(0);
        for (kind, name) in [
            (
                phantogram::engine::Snapshot::Composed,
                format!("phantogram-anaglyph-{n}.png"),
            ),
            (
                phantogram::engine::Snapshot::SideBySide,
                format!("phantogram-pair-{n}.png"),
            ),
        ] {
            let written = self
                .engine
                .snapshot_png(kind)
                .map_err(|e| e.to_string())
                .and_then(|png| {
                    let mut file = phantogram::files::AtomicFile::create(std::path::Path::new(&name))
                        .map_err(|e| e.to_string())?;
                    std::io::Write::write_all(file.file(), &png).map_err(|e| e.to_string())?;
                    file.commit().map_err(|e| e.to_string())
                });
            match written {
                Ok(()) => eprintln!("saved {name}"),
                Err(e) => eprintln!("{name}: {e}"),
            }
        }
    }

    /// Says once why the calibration could not be saved or applied, when that changes.
    fn report_calibration_warning(&mut self) {
        let now = self.engine.calibration_warning().map(str::to_owned);
        if now.is_some() && now != self.last_warning {
            eprintln!("warning: {}", now.as_deref().unwrap_or_default());
        }
        self.last_warning = now;
    }

    /// The left button as a finger on the calibration screens.
    fn touch(&mut self, phase: TouchPhase) {
        if let Some((x, y)) = self.cursor {
            let t_ns = self.now_ns();
            self.engine.touch(phase, 0, x as f32, y as f32, t_ns);
        }
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
            let window = self.window.clone().context("no window")?;
            let (w, h) = self.size();
            self.engine.resume_window(window.clone(), w, h)?;
            window.request_redraw();
            Ok(())
        })();
        if let Err(e) = result {
            self.fail(event_loop, e);
        }
    }

    fn suspended(&mut self, _event_loop: &ActiveEventLoop) {
        self.engine.suspend();
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Err(e) = self.engine.resize(size.width, size.height) {
                    self.fail(event_loop, e.into());
                }
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                let pressed = state == ElementState::Pressed;
                if self.engine.calibration_open() || self.touching {
                    self.touching = pressed;
                    self.touch(if pressed { TouchPhase::Down } else { TouchPhase::Up });
                } else {
                    self.dragging = pressed;
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                if self.touching {
                    self.cursor = Some((position.x, position.y));
                    self.touch(TouchPhase::Move);
                    return;
                }
                if self.dragging
                    && let Some((x, y)) = self.cursor
                {
                    // Half a degree per pixel, within ±80°.
                    let k = 0.5f32.to_radians();
                    let limit = 80f32.to_radians();
                    self.phone.roll_rad = (self.phone.roll_rad + (position.x - x) as f32 * k).clamp(-limit, limit);
                    self.phone.pitch_rad = (self.phone.pitch_rad + (position.y - y) as f32 * k).clamp(-limit, limit);
                }
                self.cursor = Some((position.x, position.y));
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                self.key(event_loop, event.logical_key.as_ref());
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.frame(event_loop) {
                    self.fail(event_loop, e);
                }
                // The desktop's answer to the menu's "Open a file": a file dropped on the window.
                while let Some(request) = self.engine.take_shell_request() {
                    match request {
                        phantogram::engine::ShellRequest::OpenFile => {
                            eprintln!(
                                "drop a {} file, or a .zip holding one, on the window to open it",
                                phantogram::library::MODEL_FILE_TYPES
                            )
                        }
                        // The desktop asks no permission (the viewer never reports one missing).
                        phantogram::engine::ShellRequest::CameraPermission => {}
                        // No cameras on the desktop.
                        phantogram::engine::ShellRequest::RearCamera(_) => {}
                        // The desktop's share sheet is the working folder: both pictures, as `s`.
                        phantogram::engine::ShellRequest::Share(_) => self.save_snapshots(),
                    }
                }
            }
            WindowEvent::DroppedFile(path) => {
                let name = path
                    .file_name()
                    .map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned());
                let max = phantogram::budget::ResourceBudget::PHONE.memory_bytes;
                match phantogram::files::read_regular_file(&path, max) {
                    // Loaded and shown in the background, with the banner saying how far.
                    Ok(bytes) => self.engine.import_artifact(&name, bytes),
                    Err(e) => eprintln!("{}: {e}", path.display()),
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

/// The viewer's event loop: the display its windows open on.
pub fn event_loop() -> Result<EventLoop<()>> {
    EventLoop::new().context("no display to open a window on (set DISPLAY, or use `phantogram render`)")
}

/// Runs the viewer on `event_loop` until the window closes (or `frames` are presented).
pub fn run(event_loop: EventLoop<()>, args: ViewerArgs) -> Result<()> {
    event_loop.set_control_flow(ControlFlow::Poll);
    eprintln!(
        "drag to tilt the phone; keys: 1-8 anaglyph method, m mono/stereo, f flat angle here, r reset it, l re-tie the light, c calibration screens, a artifacts menu (or click once), s save the view (anaglyph and stereo pair), Esc quit"
    );
    let mut engine = args.engine;
    if args.calibration {
        engine.open_calibration();
    }
    if args.menu {
        engine.open_menu();
        // Its pictures before the first frame, so the first one shows the menu complete.
        engine.wait_for_thumbnails(std::time::Duration::from_secs(30));
    }
    // Printed when the engine was made.
    let engine_warning = engine.calibration_warning().map(str::to_owned);
    let mut app = App {
        inbox: engine.inbox(),
        engine,
        log: args.log,
        frames: args.frames,
        linger_s: args.linger_s,
        linger_until: None,
        lifecycle_test: args.lifecycle_test,
        lifecycle_steps_done: 0,
        window: None,
        phone: VirtualPhone {
            pitch_rad: 35f32.to_radians(),
            roll_rad: 0.0,
            last: None,
        },
        log_cursor: 0,
        log_t0: None,
        start: Instant::now(),
        dragging: false,
        touching: false,
        cursor: None,
        last_warning: engine_warning,
        error: None,
    };
    event_loop.run_app(&mut app).context("the window's event loop failed")?;
    let s = app.engine.stats();
    eprintln!(
        "presented {} frames ({} skipped); surface resumed {}, suspended {}, reconfigured {}, recreated {}",
        s.frames_drawn,
        s.frames_skipped,
        s.surface.resumed,
        s.surface.suspended,
        s.surface.reconfigured,
        s.surface.recreated
    );
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}
