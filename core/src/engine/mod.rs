//! The embedding API: everything a platform shell drives, in one object. The Android JNI bridge,
//! the iOS C ABI and the desktop tests that stand in for both wrap an [`Engine`] (through
//! [`SharedEngine`]) and only translate platform events into its calls.
//!
//! An engine owns the sensor [`Session`], the [`Renderer`] with its GPU device, the loaded model,
//! the containment smoother, the optional face tracker and the touch [`Gestures`]. Its drawing
//! target follows the surface lifecycle of [`crate::surface`]:
//!
//! * [`Engine::resume_window`] — a drawable exists (Android `surfaceCreated`, iOS view in a
//!   window); [`Engine::resume_offscreen`] — an offscreen target instead (desktop tests, the C
//!   and JVM bridge tests);
//! * [`Engine::resize`] — physical pixels changed (rotation, split screen);
//! * [`Engine::suspend`] — the drawable is going away. **Important:** only the target goes; the
//!   device, the model and the sensor state stay, so resuming is cheap and nothing is reloaded.
//!
//! [`Engine::draw`] makes one frame for the time it will be on screen: drains the sensors, takes
//! the newest face-tracking result, predicts the orientation, keeps the artifact in the front
//! frustum, renders both eyes and composes them with the anaglyph method (or mono), and presents
//! (or keeps the pixels, offscreen). Drawing while suspended is a skipped frame, not an error.
//!
//! ## Calibration
//! The viewer's calibration (eye distance, viewing distance, pixel density, flat angle; see
//! [`crate::calibration`]) is read from [`EngineConfig::calibration_path`] at start and applied;
//! a missing file (not calibrated yet) gives the defaults, a damaged one the defaults and
//! [`Engine::calibration_warning`]. A three-finger tap
//! ([`Gesture::Calibrate`](crate::gesture::Gesture::Calibrate)) or [`Engine::open_calibration`]
//! opens the calibration screens ([`crate::calibration_ui`], feature `ui`): drawn over the frame, driven by
//! the same touches, which reach no gesture while they are open. What they change, and a double
//! tap's flat angle, is applied at once and saved to that path.
//!
//! ## Where each part lives
//! One type, [`Engine`], its methods in a file per concern: here its making, lifecycle and
//! accessors; `drawing` (a frame, from sensors to presenting); `touch` (gestures, the lamp, the
//! Diorama's pieces); `screens` (what is drawn over the frame, and what it asks of the shell);
//! `loading` (the artifact library and loading); `lighting` (appearance and the room light);
//! `calibration_flow` (the viewer's calibration); `shared` ([`SharedEngine`]).
//!
//! ## Threading
//! **Important:** sensor events and camera frames arrive on platform threads (Android's sensor
//! looper and CameraX executor, Core Motion's and AVFoundation's queues) while the render thread
//! draws. [`SharedEngine`] makes that safe without making producers wait for a frame: sensor
//! events go straight into the session's lock-protected inbox and camera frames into the face
//! worker's one-slot mailbox; everything else (lifecycle, touch, drawing) takes the engine's
//! mutex, so a `surfaceDestroyed` on the UI thread waits for a frame in progress and returns
//! only when the surface is gone, as Android requires. The face tracker runs on its own thread.
//!
//! ## Panics and errors
//! Bad input (sizes, unknown methods, files) yields [`EngineError`]; nothing here panics on data
//! from outside. The bridges still catch panics at every entry point; a poisoned mutex (a panic
//! while drawing) is recovered, since the engine's state stays consistent between calls.

use std::path::PathBuf;
use std::sync::Arc;

use glam::Vec3;
use thiserror::Error;

use crate::anaglyph::Method;
use crate::calibration::Calibration;
use crate::containment::{Aabb, ContainmentSmoother};
use crate::gesture::Gestures;
use crate::render::{Gpu, RenderError, Renderer};
use crate::screen::{DisplayRotation, PanelSpec, Screen, ScreenError};
use crate::sensors::{SensorInbox, SensorStats};
use crate::surface::{SurfaceHost, SurfaceStats};
use crate::wgpu;
use crate::{Session, SessionConfig, SessionError};

mod calibration_flow;
mod device_loss;
mod drawing;
mod lighting;
mod loading;
mod screens;
mod shared;
mod touch;

pub use drawing::{encode_png, frame_input};
pub use screens::TEXT_SCALE_RANGE;
pub use shared::SharedEngine;

use drawing::add_surface_stats;
use loading::{impostors_for, load_error};
#[cfg(feature = "ui")]
use screens::{Page, Screens};

/// Largest offscreen or surface side accepted (wgpu's downlevel limit).
pub const MAX_SIDE_PX: u32 = 8192;

/// The frame time a big scan's level-of-detail budget aims at by default, seconds: a frame of
/// 30 a second, both eyes (the relief-texture paper holds at least 10; a phantogram that lags
/// the hand by more than a frame at 30 Hz no longer looks fixed in the room), less the budget
/// controller's dead band (4 %, `phantogram_detail::BudgetController`): the controller settles
/// on its target, and a target at the frame's period itself would miss it every other frame.
pub const DEFAULT_FRAME_TARGET_S: f64 = 1.0 / 30.0 / 1.04;

/// How a shell starts an engine.
#[derive(Clone, Debug)]
pub struct EngineConfig {
    /// The display panel in its natural orientation (Android `DisplayMetrics`, iOS `UIScreen`).
    pub panel: PanelSpec,
    pub rotation: DisplayRotation,
    pub method: Method,
    /// A glTF 2.0 file to show (the desktop's command line); `None`: [`Self::artifact`].
    pub model_path: Option<PathBuf>,
    /// The library's artifact to show first (what the shell saved last time); `None`: the
    /// default artifact. An id no longer in the library falls back to the default with
    /// [`Engine::loading_status`] saying so.
    pub artifact: Option<crate::library::ArtifactId>,
    /// Where imported artifacts are kept (a folder in the app's private storage); `None`:
    /// nothing can be imported.
    pub library_dir: Option<PathBuf>,
    /// Artifacts shipped with the app (glTF/GLB files or Voyager folders), read-only.
    pub bundled_dir: Option<PathBuf>,
    /// An equirectangular HDR/EXR environment; `None`: the generated studio.
    pub environment_path: Option<PathBuf>,
    /// Where [`Self::environment_path`]'s room has a sun (a small source with a good share of
    /// its light, [`crate::ibl::sun`]), light with it: the directional light comes from the sun,
    /// with its colour and strength, and casts its shadow, as soft as the sun's width makes it,
    /// and the image light is the room without it (a long press, or "Light: fix to the room
    /// again", then leaves the sun where the room has it: re-anchoring moves only the key
    /// light). While the room's own live light is
    /// shown ([`Self::room_light`]) the key light is back. On by default; off: the room's light as
    /// it is, and the default key light over the viewer's shoulder besides (the light a room
    /// without a sun always gets).
    pub sun_from_environment: bool,
    /// The folder with the face-tracking models; `None`: tilt only (no camera, or permission
    /// refused).
    pub face_models_dir: Option<PathBuf>,
    /// The front camera's position in the device frame, metres; `None`: centred 4 mm above the
    /// panel's top edge (typical of phones).
    pub camera_position_m: Option<Vec3>,
    /// How a loaded model is placed in the diorama (standing or facing, how much stands in front
    /// of the glass); the default artifact is made to fit.
    pub fit: crate::model::DioramaFit,
    /// Draw the diorama's floor under the artifact.
    pub floor: bool,
    /// Let the straight-on pose follow slowly the pose the viewer settles into (after one was
    /// taken, while no face is tracked; `phantogram_sensing::straight_on`). On by default, as
    /// on the phones.
    pub adapt_straight_on: bool,
    /// Where the viewer's calibration is kept (a file in the app's private storage); `None`: the
    /// defaults, and nothing saved. **Important:** with a path whose calibration does not say
    /// the first run is done, the engine opens on the first-run screens (how to hold the phone,
    /// the glasses check, "Start"); the desktop's `render` passes none.
    pub calibration_path: Option<PathBuf>,
    /// Light the artifact with the room itself, as the camera sees it
    /// ([`crate::room_light`]): camera frames ([`Engine::room_light_frame`], or every frame the
    /// shell forwards, in colour when it forwards the chroma planes, from the rear camera too where
    /// the platform runs both cameras at once) are blended into a map of the
    /// room whose light replaces the studio's (or [`Self::environment_path`]'s) once the first
    /// update is made. This is the start-up default; the calibration file's choice (the settings
    /// screen's "Light" switch, [`Engine::set_room_light`]) overrides it. Off by default: on a
    /// phone the map's reduction costs CPU time (see `benchmarks/ibl.md`), so the visitor opts in.
    pub room_light: bool,
    /// When the viewer lingers on one view of an artifact, point at a side not seen yet
    /// ([`phantogram_detail::seen`]): an arrow at the picture's edge, drawn at the glass. On by
    /// default, as on the phones; a recording (`phantogram render`) turns it off.
    pub side_hints: bool,
}

impl Default for EngineConfig {
    fn default() -> Self {
        Self {
            panel: PanelSpec::TYPICAL_PHONE,
            rotation: DisplayRotation::Deg0,
            method: Method::default(),
            model_path: None,
            artifact: None,
            library_dir: None,
            bundled_dir: None,
            environment_path: None,
            sun_from_environment: true,
            face_models_dir: None,
            camera_position_m: None,
            fit: crate::model::DioramaFit::default(),
            floor: true,
            adapt_straight_on: true,
            calibration_path: None,
            room_light: false,
            side_hints: true,
        }
    }
}

#[derive(Debug, Error)]
pub enum EngineError {
    #[error(transparent)]
    Render(#[from] RenderError),
    #[error(transparent)]
    Model(#[from] crate::model::ModelError),
    #[error(transparent)]
    Library(#[from] crate::library::LibraryError),
    #[error(transparent)]
    Environment(#[from] crate::ibl::EnvironmentError),
    #[error(transparent)]
    Session(#[from] SessionError),
    #[error(transparent)]
    Screen(#[from] ScreenError),
    #[cfg(feature = "face")]
    #[error(transparent)]
    Face(#[from] crate::face::FaceError),
    #[error("face tracking needs the `face` feature, which this build does not have")]
    NoFaceSupport,
    #[error("{0}")]
    InvalidArgument(String),
    #[error("no offscreen frame to read: resume an offscreen target and draw first")]
    NoFrame,
    #[error("the picture could not be encoded: {0}")]
    Share(String),
    /// A file the engine keeps could not be written, or a thread of its own not started.
    #[error("{what}: {source}")]
    Io {
        what: &'static str,
        #[source]
        source: std::io::Error,
    },
}

/// The key an artifact's material changes are kept under: its library id, or `file:NAME` for a
/// model opened from the command line.
fn appearance_key(info: &ModelInfo) -> String {
    info.artifact
        .as_ref()
        .map_or_else(|| format!("file:{}", info.name), |a| a.id.to_string())
}

/// What [`Engine::snapshot`] makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Snapshot {
    /// The frame as on screen: the anaglyph (or mono) composition.
    Composed,
    /// The stereo pair side by side for parallel viewing: left eye's image on the left.
    SideBySide,
}

/// The one classification of [`EngineError`]s that both bridges map onto their platform's errors
/// (JNI: the exception class thrown; C ABI: the `PgStatus`), so that the same failure means the
/// same thing to the Kotlin and the Swift shell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// The caller passed something unusable (a size, a method name, a malformed camera frame).
    InvalidArgument,
    /// The call came in the wrong state (reading a frame before one was drawn offscreen).
    InvalidState,
    /// This build or engine cannot do it (face tracking without the `face` feature).
    Unsupported,
    /// A file or the face networks could not be loaded or run, a file the engine keeps not
    /// written, a thread of its own not started.
    Load,
    /// The GPU failed (device, surface, read-back).
    Render,
}

impl EngineError {
    pub fn kind(&self) -> ErrorKind {
        match self {
            Self::InvalidArgument(_) | Self::Screen(_) | Self::Session(_) => ErrorKind::InvalidArgument,
            #[cfg(feature = "face")]
            Self::Face(crate::face::FaceError::BadFrame(_)) => ErrorKind::InvalidArgument,
            #[cfg(feature = "face")]
            Self::Face(_) => ErrorKind::Load,
            Self::Library(crate::library::LibraryError::BadId { .. }) => ErrorKind::InvalidArgument,
            Self::Model(_) | Self::Environment(_) | Self::Library(_) | Self::Io { .. } => ErrorKind::Load,
            Self::Render(_) | Self::Share(_) => ErrorKind::Render,
            Self::NoFrame => ErrorKind::InvalidState,
            Self::NoFaceSupport => ErrorKind::Unsupported,
        }
    }
}

/// Where frames go.
enum Target {
    Detached,
    Window(Box<SurfaceHost>),
    Offscreen { width: u32, height: u32 },
}

pub use crate::artifacts::{LoadStatus, ModelInfo};

/// Counters, for logs, the shells' debug overlays and tests.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EngineStats {
    pub frames_drawn: u64,
    pub frames_skipped: u64,
    pub resumed: u64,
    pub suspended: u64,
    pub resized: u64,
    pub sensors: SensorStats,
    pub surface: SurfaceStats,
    /// Camera frames handed to the face tracker, and those it had to drop (busy).
    pub camera_frames: u64,
    pub camera_frames_dropped: u64,
    /// Camera frames the face tracker failed on ([`Engine::face_tracking_error`] says why the
    /// last one did), and whether tracking has stopped altogether (no thread, or an internal
    /// error): the eyes then come from gravity alone.
    pub camera_frames_failed: u64,
    pub face_tracking_stopped: bool,
    pub gestures: u64,
    /// Whether the last frame's eyes came from the camera.
    pub eyes_from_camera: bool,
    /// Image-based lights made from the room so far, and the share of the sphere (0 to 1) the
    /// newest had seen ([`EngineConfig::room_light`]), and what its map was scaled by to the
    /// level of the light it replaced (`room_light`'s **Level**; `None` before the first).
    pub room_light_updates: u64,
    pub room_light_coverage: f32,
    pub room_light_gain: Option<f32>,
    /// GPU devices lost and replaced ([`Engine::draw`]).
    pub devices_recovered: u64,
}

/// What a shell embeds; see the module docs.
pub struct Engine {
    session: Session,
    renderer: Renderer,
    /// The CPU's copy of the artifact on screen (the Diorama keeps its own): what a new device
    /// is given when one is lost ([`device_loss`]). The budget counts the artifact twice for it.
    model: crate::model::Model,
    /// Opens a new device when the one drawing was lost: as the first was opened
    /// ([`Engine::set_device_reopener`]).
    reopen_gpu: Box<dyn Fn() -> Result<Gpu, RenderError> + Send + Sync>,
    model_info: ModelInfo,
    bounds: Aabb,
    /// A big scan's levels of detail and their per-frame choice ([`phantogram_detail`]); `None`
    /// for a model drawn whole (and for the Diorama).
    detail: Option<phantogram_detail::Detail>,
    /// The big scan's parts' impostors: planned, and baked a few a frame once the chooser would
    /// draw them ([`crate::impostors`]).
    impostors: crate::impostors::ImpostorBaker,
    /// This frame baked some (its time is not fed to the budget).
    baked_this_frame: bool,
    /// The frame time the detail's budget aims at, seconds ([`Engine::set_frame_target_s`]).
    frame_target_s: f64,
    /// Which sides of the artifact the viewer has seen (`None`: hints off, or the Diorama), and
    /// the hint toward an unseen one this frame.
    seen: Option<phantogram_detail::seen::SeenSides>,
    side_hints: bool,
    side_hint: Option<phantogram_detail::seen::Hint>,
    loader: crate::artifacts::Loader,
    /// How loaded files are fitted and floored (the configuration's).
    fit: crate::model::DioramaFit,
    floor: bool,
    smoother: ContainmentSmoother,
    method: Method,
    /// The method to return to when stereo is toggled back on.
    stereo_method: Method,
    target: Target,
    last_display_t_ns: Option<i64>,
    /// Containment's push-back in the last frame, metres (snapshots show that frame's view).
    last_push_m: f32,
    /// The cyclopean eye's projection in the last frame: what a tap on the picture points at.
    last_mono: Option<crate::projection::OffAxisProjection>,
    #[cfg(feature = "face")]
    face: Option<Arc<crate::face::FaceWorker>>,
    last_face_t_ns: Option<i64>,
    /// The glasses the face tracker saw last (with the newest face), for the glasses check.
    last_glasses: Option<phantogram_sensing::glasses::GlassesSeen>,
    gestures: Gestures,
    last_frame: Option<(u32, u32, Vec<u8>)>,
    stats: EngineStats,
    calibration: Calibration,
    calibration_path: Option<PathBuf>,
    calibration_warning: Option<String>,
    /// The panel as the platform reports it; a calibrated density goes over it.
    platform_panel: PanelSpec,
    /// The system's text size setting, applied to the screens ([`Engine::set_text_scale`]).
    text_scale: f32,
    /// The finger turning the artifact and where it was ("reduce motion"), physical pixels.
    drag_px: Option<(i32, [f32; 2])>,
    /// The Diorama, while it is the artifact on screen ([`crate::diorama`]).
    diorama: Option<Box<crate::diorama::DioramaScene>>,
    /// The finger holding a Diorama body: its pointer and the body's depth along the sight line.
    diorama_grab: Option<(i32, f32)>,
    /// The screens drawn over the picture (menu, calibration, status banner); made when first
    /// needed and kept, so egui's fonts are uploaded once.
    #[cfg(feature = "ui")]
    screens: Option<Box<Screens>>,
    /// What a screen reader can land on in the last frame ([`Engine::accessibility_nodes`]).
    #[cfg(feature = "ui")]
    access: crate::calibration_ui::accessibility::AccessTree,
    /// What the core asks of the shell (a file picker), until taken.
    requests: Vec<ShellRequest>,
    /// The camera page waits for the screens in front of it to close.
    #[cfg(feature = "ui")]
    camera_page_pending: bool,
    /// The gallery's pictures, made while the menu is open.
    #[cfg(feature = "ui")]
    thumbnails: crate::thumbnails::Thumbnails,
    /// The material screen's changes per artifact (`<library>/appearances.json`).
    appearances: crate::appearances::AppearanceStore,
    /// The live room light's worker, when [`EngineConfig::room_light`] is on.
    room_light: Option<Arc<crate::room_light::RoomLightWorker>>,
    /// The room light's update the scene was last lit by, kept to light a new device with
    /// ([`device_loss`]).
    room_light_shown: Option<crate::room_light::RoomLightUpdate>,
    /// The light when the room's is off: [`EngineConfig::environment_path`]'s, or the studio's.
    static_environment: Option<crate::ibl::Environment>,
    /// That environment's sun, taken out of it ([`EngineConfig::sun_from_environment`]): the
    /// directional light while the room's own light is not shown.
    static_sun: Option<crate::ibl::sun::Sun>,
    /// A lamp the visitor placed (in place of the room's light), and the finger moving it.
    lamp: Option<crate::lamp::PlacedLamp>,
    lamp_finger: Option<i32>,
    /// The device → world orientation of the last frame drawn (for a touch between frames).
    last_device_to_world: Option<glam::Quat>,
}

/// Something only the platform can do, asked for by the core's screens: the shell takes these
/// with [`Engine::take_shell_request`] after each frame and answers through the engine's
/// calls (for a file: [`Engine::import_artifact`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShellRequest {
    /// Show the system's document picker for a `.glb`, `.gltf`, `.stl`, `.ply`, `.obj`, `.xyz`, `.pts`,
    /// `.las`, `.laz`, `.e57`, `.usdz` or `.zip`.
    OpenFile,
    /// Show the system's camera permission request (the user has read why, on the core's
    /// camera page, and wants it): see [`Engine::camera_permission_needed`].
    CameraPermission,
    /// Share the view through the system's share sheet: take [`Engine::snapshot_png`] of this
    /// kind and hand the PNG over.
    Share(Snapshot),
    /// Run the rear camera beside the front one where the platform can (`true`: the room light
    /// was switched on, or is on at start) or stop it (`false`: switched off), so that a second
    /// camera costs power only while its frames are used. The shell starts with the front
    /// camera alone.
    RearCamera(bool),
}

impl ShellRequest {
    /// The request's number across the bridges (C and JNI): 0 is "none", so never used here.
    pub fn code(self) -> i32 {
        match self {
            Self::OpenFile => 1,
            Self::CameraPermission => 2,
            Self::Share(Snapshot::Composed) => 3,
            Self::Share(Snapshot::SideBySide) => 4,
            Self::RearCamera(true) => 5,
            Self::RearCamera(false) => 6,
        }
    }
}

impl std::fmt::Debug for Engine {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Engine")
            .field("method", &self.method)
            .field("stats", &self.stats)
            .finish_non_exhaustive()
    }
}

/// The camera of a bridge's code (0 front, 1 rear: [`crate::camera::CameraFacing::from_code`]),
/// or the one error both bridges report for any other.
pub fn camera_facing(code: i64) -> Result<crate::camera::CameraFacing, EngineError> {
    u32::try_from(code)
        .ok()
        .and_then(crate::camera::CameraFacing::from_code)
        .ok_or_else(|| EngineError::InvalidArgument(format!("camera must be 0 (front) or 1 (rear), got {code}")))
}

fn check_size(width: u32, height: u32) -> Result<(), EngineError> {
    if width > MAX_SIDE_PX || height > MAX_SIDE_PX {
        return Err(EngineError::InvalidArgument(format!(
            "size {width}×{height} is too large (at most {MAX_SIDE_PX} pixels per side)"
        )));
    }
    Ok(())
}

impl Engine {
    /// Opens the GPU device (hardware first, software fallback), loads and fits the model, the
    /// environment and (if asked) the face models. Takes from tens of milliseconds (default
    /// artifact) to about a second (a large scan): call it off the UI thread. It also starts a
    /// short-lived thread that computes the renderer's lighting tables meanwhile (once per
    /// process, [`crate::render::prepare_lighting_tables`]).
    ///
    /// The calibration and environment files are read before the device is opened, so that a
    /// bad one is reported as such even where no GPU can be found; the model after it (its
    /// budget takes the device's largest texture).
    pub fn new(config: EngineConfig) -> Result<Self, EngineError> {
        Self::with_gpu_from(Gpu::headless, config)
    }

    /// As [`Self::new`] on a given device.
    pub fn with_gpu(gpu: Gpu, config: EngineConfig) -> Result<Self, EngineError> {
        Self::with_gpu_from(|| Ok(gpu), config)
    }

    /// As [`Self::new`] on the device `gpu` opens once the files are read (a window's display:
    /// [`Gpu::for_display`]).
    pub fn with_gpu_from(
        gpu: impl FnOnce() -> Result<Gpu, RenderError>,
        config: EngineConfig,
    ) -> Result<Self, EngineError> {
        // Opening the device and loading the model overlap the renderer's lighting tables.
        crate::render::prepare_lighting_tables_in_background(config.environment_path.is_none());
        let screen = Screen::new(config.panel, config.rotation)?;
        let protrude = config.fit.protrude_fraction;
        if !(0.0..=1.0).contains(&protrude) {
            return Err(EngineError::InvalidArgument(format!(
                "the fraction of the model in front of the glass must be between 0 and 1, got {protrude}"
            )));
        }
        let session_config = SessionConfig {
            screen,
            straight_on: config
                .adapt_straight_on
                .then(crate::straight_on::StraightOnParams::default),
            ..SessionConfig::default()
        };
        let session = Session::new(session_config)?;
        let (calibration, calibration_warning) = match &config.calibration_path {
            Some(path) => Calibration::load(path),
            None => (Calibration::default(), None),
        };
        // What the viewer chose in the settings screen wins over the shell's defaults.
        let method = calibration.method.unwrap_or(config.method);
        let floor = calibration.floor.unwrap_or(config.floor);
        let fit = crate::model::DioramaFit {
            protrude_fraction: calibration.protrude_fraction.unwrap_or(config.fit.protrude_fraction),
            true_size: config.fit.true_size || calibration.true_size,
            placement: if calibration.surface {
                crate::model::Placement::Surface
            } else {
                config.fit.placement
            },
            ..config.fit
        };
        // The environment before the device, so that a bad file is named as such whether or not
        // a device opens; the model after it: its budget takes the device's texture limit.
        let environment = match &config.environment_path {
            Some(path) => Some(crate::ibl::Environment::load(path)?),
            None => None,
        };
        // The room's light level with its sun (what a live room light replaces), then the sun
        // taken out of it where it has one.
        let environment_level = environment.as_ref().map(|e| e.mean_luminance());
        let (environment, sun) = match environment {
            Some(env) if config.sun_from_environment => {
                let (sun, rest) = crate::ibl::sun::Sun::take_out(env);
                (Some(rest), sun)
            }
            other => (other, None),
        };
        let gpu = gpu()?;
        let budget = crate::budget::ResourceBudget {
            max_image_side_px: crate::budget::ResourceBudget::PHONE
                .max_image_side_px
                .min(gpu.device.limits().max_texture_dimension_2d),
            ..crate::budget::ResourceBudget::PHONE
        };
        let library = crate::library::Library::new(config.library_dir.clone(), config.bundled_dir.clone());
        #[cfg(feature = "ui")]
        let thumbnails = crate::thumbnails::Thumbnails::new(
            library.clone(),
            budget,
            config.library_dir.as_ref().map(|d| d.join("thumbnails")),
        );
        let mut loader = crate::artifacts::Loader::new(library, budget);
        let placing = crate::artifacts::Placing {
            screen,
            fit,
            floor,
            memory_bytes: budget.memory_bytes,
        };
        let prepared = match (&config.model_path, &config.artifact) {
            (Some(path), _) => {
                let model = crate::model::load_model_within(path, budget)?;
                crate::artifacts::prepare(model, None, false, &placing, &crate::progress::Progress::new(), None)?
            }
            // The Diorama is made once the engine exists (below); the default artifact first.
            (None, Some(id)) if id.to_string() == crate::diorama::DIORAMA_ID => loader
                .load_now(&crate::library::ArtifactId::default_artifact(), &placing)
                .map_err(load_error)?,
            (None, Some(id)) => match loader.load_now(id, &placing) {
                Ok(p) => p,
                // What the shell saved may have been removed or damaged since: the default
                // artifact, and the reason on screen.
                Err(e) => {
                    loader.fail(id.to_string(), e.to_string());
                    loader
                        .load_now(&crate::library::ArtifactId::default_artifact(), &placing)
                        .map_err(load_error)?
                }
            },
            (None, None) => loader
                .load_now(&crate::library::ArtifactId::default_artifact(), &placing)
                .map_err(load_error)?,
        };
        let crate::artifacts::Prepared {
            model,
            bounds,
            info: model_info,
            detail,
            seen,
        } = prepared;
        let seen = config.side_hints.then_some(seen);
        let mut renderer = Renderer::with_environment(gpu, &model, environment.as_ref())?;
        let mut detail = detail;
        let impostors = impostors_for(&model, detail.as_mut(), budget.memory_bytes, &renderer);
        let (appearances, appearance_warning) =
            crate::appearances::AppearanceStore::open(config.library_dir.as_ref().map(|d| d.join("appearances.json")));
        renderer.appearance = appearances.get(&appearance_key(&model_info));
        let calibration_warning = calibration_warning.or(appearance_warning);
        // The front camera, for the face tracker and the room light alike.
        let camera_pose = crate::camera::CameraPose::front(config.camera_position_m.unwrap_or(Vec3::new(
            0.0,
            screen.panel_height_m() * 0.5 + 0.004,
            0.0,
        )));
        #[cfg(feature = "face")]
        let face = match &config.face_models_dir {
            Some(dir) => {
                let models = Arc::new(crate::face::FaceModels::load(dir)?);
                let tracker = crate::face::FaceTracker::new(models, camera_pose);
                Some(Arc::new(crate::face::FaceWorker::spawn(tracker)))
            }
            None => None,
        };
        #[cfg(not(feature = "face"))]
        if config.face_models_dir.is_some() {
            return Err(EngineError::NoFaceSupport);
        }
        // The worker waits, idle, while the room light is off, so the setting can switch it on.
        // The room's light keeps the level of the light it replaces (`room_light`'s **Level**).
        let level = environment_level.unwrap_or_else(|| crate::ibl::Environment::studio().mean_luminance());
        // Where on the back the rear camera sits does not matter to a map of the room's light at
        // infinity; only which way it looks.
        let cameras = crate::camera::DeviceCameras {
            front: camera_pose,
            rear: crate::camera::CameraPose::rear(camera_pose.position_m),
        };
        let room_light = match crate::room_light::RoomLightWorker::spawn(
            cameras,
            phantogram_roomlight::CaptureParams::default(),
            crate::render::PREFILTERED_BASE_WIDTH,
            Some(level),
        ) {
            Ok(worker) => {
                worker.set_on(calibration.room_light.unwrap_or(config.room_light));
                Some(Arc::new(worker))
            }
            Err(source) if config.room_light => {
                return Err(EngineError::Io {
                    what: "the room light's thread could not start",
                    source,
                });
            }
            // Asked for later only: the switch then keeps the studio's light.
            Err(_) => None,
        };
        let mut engine = Self {
            session,
            renderer,
            model,
            reopen_gpu: Box::new(Gpu::headless),
            model_info,
            bounds,
            detail,
            impostors,
            baked_this_frame: false,
            frame_target_s: DEFAULT_FRAME_TARGET_S,
            seen,
            side_hints: config.side_hints,
            side_hint: None,
            loader,
            fit,
            floor,
            smoother: ContainmentSmoother::default(),
            method,
            stereo_method: if method == Method::Mono {
                Method::default()
            } else {
                method
            },
            target: Target::Detached,
            last_display_t_ns: None,
            last_push_m: 0.0,
            last_mono: None,
            #[cfg(feature = "face")]
            face,
            last_face_t_ns: None,
            last_glasses: None,
            gestures: Gestures::new(config.panel.xdpi),
            last_frame: None,
            stats: EngineStats::default(),
            calibration,
            calibration_path: config.calibration_path,
            calibration_warning,
            platform_panel: config.panel,
            text_scale: 1.0,
            drag_px: None,
            diorama: None,
            diorama_grab: None,
            #[cfg(feature = "ui")]
            screens: None,
            #[cfg(feature = "ui")]
            access: Default::default(),
            requests: Vec::new(),
            #[cfg(feature = "ui")]
            camera_page_pending: false,
            #[cfg(feature = "ui")]
            thumbnails,
            appearances,
            room_light,
            room_light_shown: None,
            static_environment: environment,
            static_sun: sun,
            lamp: None,
            lamp_finger: None,
            last_device_to_world: None,
        };
        engine.apply_calibration();
        if engine.room_light_on() {
            engine.requests.push(ShellRequest::RearCamera(true));
        }
        if config.model_path.is_none()
            && config
                .artifact
                .as_ref()
                .is_some_and(|id| id.to_string() == crate::diorama::DIORAMA_ID)
        {
            engine.show_diorama();
        }
        #[cfg(feature = "ui")]
        if engine.calibration_path.is_some() && !engine.calibration.introduced {
            engine.screens().page = Some(Page::Welcome(crate::calibration_ui::welcome::WelcomeUi::new()));
        }
        Ok(engine)
    }

    /// Target pixels per screen pixel: 1 on a phone; less in the desktop viewer's window.
    fn target_scale(&self) -> f32 {
        let screen_width_px = self.session.config().screen.width_px() as f32;
        self.target_size()
            .map(|(w, _)| w)
            .filter(|&w| w > 0)
            .map_or(1.0, |w| w as f32 / screen_width_px)
    }

    /// The drawing target's size in physical pixels; `None` while detached or while the window's
    /// surface is not active.
    fn target_size(&self) -> Option<(u32, u32)> {
        match &self.target {
            Target::Detached => None,
            Target::Window(host) => match host.state() {
                crate::surface::SurfaceState::Active { width, height } => Some((width, height)),
                _ => None,
            },
            Target::Offscreen { width, height } => Some((*width, *height)),
        }
    }

    /// The session's sensor inbox: push events from any thread.
    pub fn inbox(&self) -> Arc<SensorInbox> {
        self.session.inbox()
    }

    pub fn session(&self) -> &Session {
        &self.session
    }

    pub fn renderer(&self) -> &Renderer {
        &self.renderer
    }

    /// The face worker, if face tracking is on: submit camera frames from any thread.
    #[cfg(feature = "face")]
    pub fn face_worker(&self) -> Option<Arc<crate::face::FaceWorker>> {
        self.face.clone()
    }

    pub fn method(&self) -> Method {
        self.method
    }

    pub fn set_method(&mut self, method: Method) {
        self.method = method;
        if method != Method::Mono {
            self.stereo_method = method;
        }
    }

    /// The motion sensors' ranges as the platform declares them (Android's
    /// `Sensor.getMaximumRange()`), so that clipped readings are known from the first one.
    pub fn set_sensor_ranges(&mut self, ranges: crate::sensors::SensorRanges) {
        self.session.set_sensor_ranges(ranges);
    }

    /// A drawable appeared: draw into `window` at `width × height` physical pixels.
    pub fn resume_window(
        &mut self,
        window: Arc<dyn wgpu::DisplayAndWindowHandle>,
        width: u32,
        height: u32,
    ) -> Result<(), EngineError> {
        check_size(width, height)?;
        let mut host = SurfaceHost::new();
        host.resume(self.renderer.gpu(), window, width, height)?;
        self.target = Target::Window(Box::new(host));
        self.last_frame = None;
        self.stats.resumed += 1;
        Ok(())
    }

    /// Draw into an offscreen image of `width × height` pixels (read with [`Self::last_frame`]).
    pub fn resume_offscreen(&mut self, width: u32, height: u32) -> Result<(), EngineError> {
        check_size(width, height)?;
        self.target = Target::Offscreen { width, height };
        // A frame of the previous target must not be read as this one's.
        self.last_frame = None;
        self.stats.resumed += 1;
        Ok(())
    }

    /// The target's size changed, in physical pixels (zero: minimised; frames are skipped).
    pub fn resize(&mut self, width: u32, height: u32) -> Result<(), EngineError> {
        check_size(width, height)?;
        match &mut self.target {
            Target::Detached => {}
            Target::Window(host) => host.resize(self.renderer.gpu(), width, height),
            Target::Offscreen { width: w, height: h } => {
                (*w, *h) = (width, height);
            }
        }
        self.stats.resized += 1;
        Ok(())
    }

    /// The drawable is going away: drop the target (and with it the surface and the window it
    /// borrows) before returning. Keeps the device, the model and the sensor state.
    pub fn suspend(&mut self) {
        if let Target::Window(host) = &mut self.target {
            host.suspend();
            self.stats.surface = add_surface_stats(self.stats.surface, host.stats());
        }
        if !matches!(self.target, Target::Detached) {
            self.stats.suspended += 1;
        }
        self.target = Target::Detached;
        self.last_frame = None;
    }

    /// The display's panel or rotation changed (Android configuration change, iOS trait change).
    pub fn set_display(&mut self, panel: PanelSpec, rotation: DisplayRotation) -> Result<(), EngineError> {
        self.session.set_screen(Screen::new(panel, rotation)?);
        // The platform's panel again: the calibrated density must go back over it.
        self.platform_panel = panel;
        self.apply_calibration();
        Ok(())
    }

    pub fn stats(&self) -> EngineStats {
        let mut s = self.stats;
        s.sensors = self.session.stats();
        if let Target::Window(host) = &self.target {
            s.surface = add_surface_stats(s.surface, host.stats());
        }
        #[cfg(feature = "face")]
        if let Some(f) = &self.face {
            s.camera_frames_dropped = f.dropped_frames();
            s.camera_frames_failed = f.failed_frames();
            s.face_tracking_stopped = !f.is_running();
        }
        s
    }

    /// Why face tracking last failed on a camera frame (a malformed frame, an inference error),
    /// if it has; counted in [`EngineStats::camera_frames_failed`].
    pub fn face_tracking_error(&self) -> Option<String> {
        #[cfg(feature = "face")]
        if let Some(f) = &self.face {
            return f.last_error();
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_send_sync<T: Send + Sync>() {}

    /// The bridges map these kinds, not the variants: what each variant means to a shell is
    /// decided here once.
    #[test]
    fn errors_are_classified_once() {
        assert_eq!(
            EngineError::InvalidArgument("x".into()).kind(),
            ErrorKind::InvalidArgument
        );
        assert_eq!(
            EngineError::Screen(ScreenError::EmptyPanel {
                width_px: 0,
                height_px: 1
            })
            .kind(),
            ErrorKind::InvalidArgument
        );
        assert_eq!(EngineError::NoFrame.kind(), ErrorKind::InvalidState);
        assert_eq!(EngineError::NoFaceSupport.kind(), ErrorKind::Unsupported);
        #[cfg(feature = "face")]
        {
            use crate::face::FaceError;
            assert_eq!(
                EngineError::Face(FaceError::BadFrame("x".into())).kind(),
                ErrorKind::InvalidArgument
            );
            assert_eq!(
                EngineError::Face(FaceError::Inference("x".into())).kind(),
                ErrorKind::Load
            );
        }
    }

    #[test]
    fn the_shared_engine_may_cross_threads() {
        assert_send_sync::<SharedEngine>();
    }

    #[test]
    fn sizes_beyond_the_device_limit_are_refused_with_the_limit() {
        let e = check_size(9000, 10).unwrap_err().to_string();
        assert!(e.contains("8192"), "{e}");
        assert!(check_size(0, 0).is_ok(), "zero is a minimised window, not an error");
    }
}
