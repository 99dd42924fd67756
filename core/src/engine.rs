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
//! [`Engine::calibration_warning`]. A
//! three-finger tap ([`Gesture::Calibrate`]) or [`Engine::open_calibration`] opens the
//! calibration screens ([`crate::calibration_ui`], feature `ui`): drawn over the frame, driven by
//! the same touches, which reach no gesture while they are open. What they change, and a double
//! tap's flat angle, is applied at once and saved to that path.
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
use std::sync::{Arc, Mutex, MutexGuard};

use glam::Vec3;
use thiserror::Error;

use crate::anaglyph::Method;
use crate::calibration::Calibration;
use crate::containment::{Aabb, ContainmentSmoother};
use crate::gesture::{Gesture, Gestures, TouchPhase};
use crate::render::{FrameInput, Gpu, RenderError, Renderer};
use crate::screen::{DisplayRotation, PanelSpec, Screen, ScreenError};
use crate::sensors::{Rejection, SensorEvent, SensorInbox, SensorStats};
use crate::surface::{DrawOutcome, SurfaceHost, SurfaceStats};
use crate::wgpu;
use crate::{Session, SessionConfig, SessionError};

/// Largest offscreen or surface side accepted (wgpu's downlevel limit).
pub const MAX_SIDE_PX: u32 = 8192;

/// The least width and height, in points, the screens are laid out on (see
/// `draw_with_screens`): any real phone window is larger.
#[cfg(feature = "ui")]
const MIN_SCREEN_PT: f32 = 240.0;

/// The impostors planned for `model` and announced to its `detail` (none without levels of
/// detail): within what the artifact's memory budget leaves of it.
fn impostors_for(
    model: &crate::model::Model,
    detail: Option<&mut phantogram_detail::Detail>,
    memory_bytes: u64,
) -> crate::impostors::ImpostorBaker {
    let Some(detail) = detail else {
        return Default::default();
    };
    let left = memory_bytes.saturating_sub(crate::budget::model_bytes(model));
    crate::impostors::ImpostorBaker::plan_for(model, left, detail)
}

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
    /// shell forwards, in colour when it forwards the chroma planes) are blended into a map of the
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

/// The text scales the screens follow ([`Engine::set_text_scale`]): Android's smallest font
/// size to twice the default.
pub const TEXT_SCALE_RANGE: std::ops::RangeInclusive<f32> = 0.85..=2.0;

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
    /// newest had seen ([`EngineConfig::room_light`]).
    pub room_light_updates: u64,
    pub room_light_coverage: f32,
}

/// What a shell embeds; see the module docs.
pub struct Engine {
    session: Session,
    renderer: Renderer,
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
    /// The light when the room's is off: [`EngineConfig::environment_path`]'s, or the studio's.
    static_environment: Option<crate::ibl::Environment>,
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
    /// Show the system's document picker for a `.glb`, `.gltf` or `.zip`.
    OpenFile,
    /// Show the system's camera permission request (the user has read why, on the core's
    /// camera page, and wants it): see [`Engine::camera_permission_needed`].
    CameraPermission,
    /// Share the view through the system's share sheet: take [`Engine::snapshot_png`] of this
    /// kind and hand the PNG over.
    Share(Snapshot),
}

impl ShellRequest {
    /// The request's number across the bridges (C and JNI): 0 is "none", so never used here.
    pub fn code(self) -> i32 {
        match self {
            Self::OpenFile => 1,
            Self::CameraPermission => 2,
            Self::Share(Snapshot::Composed) => 3,
            Self::Share(Snapshot::SideBySide) => 4,
        }
    }
}

/// Paints over a composed frame: the GPU, the frame's view, its format and size.
type OverlayPaint<'a> = dyn FnMut(&Gpu, &wgpu::TextureView, wgpu::TextureFormat, [u32; 2]) + 'a;

/// Which full screen is open over the picture.
#[cfg(feature = "ui")]
enum Page {
    Menu(crate::calibration_ui::menu::MenuUi),
    Calibration(crate::calibration_ui::CalibrationUi),
    /// The card of the annotation with this index in [`ModelInfo::annotations`].
    Annotation(usize),
    /// What the gestures do.
    Help,
    Welcome(crate::calibration_ui::welcome::WelcomeUi),
    Settings(crate::calibration_ui::settings::SettingsUi),
    Material(crate::calibration_ui::material::MaterialUi),
}

/// The screens' state on the render thread: the page open (if any), egui's context, the touches
/// waiting for the next frame, and the overlay painter (made with the first frame drawn).
#[cfg(feature = "ui")]
struct Screens {
    page: Option<Page>,
    /// The gallery's items, read from the library when the menu opens and after a change.
    items: Vec<crate::calibration_ui::menu::MenuItem>,
    ctx: egui::Context,
    events: Vec<egui::Event>,
    overlay: crate::calibration_ui::OverlayHost,
    /// The finger that drives the screens: the first one down; others are ignored.
    pointer: Option<i32>,
    /// The status banner's rectangle in the last frame (points), while one shows: a touch that
    /// starts there is the banner's, any other the gestures'.
    banner_pt: Option<egui::Rect>,
    /// The gallery's pictures as egui textures, by artifact id.
    thumbnail_textures: std::collections::HashMap<String, egui::TextureHandle>,
    /// The banner's button (Cancel or OK) in the last frame, points.
    banner_button_pt: Option<egui::Rect>,
}

impl std::fmt::Debug for Engine {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Engine")
            .field("method", &self.method)
            .field("stats", &self.stats)
            .finish_non_exhaustive()
    }
}

fn load_error(e: crate::artifacts::LoadError) -> EngineError {
    match e {
        crate::artifacts::LoadError::Library(e) => EngineError::Library(e),
        crate::artifacts::LoadError::Render(e) => EngineError::Render(e),
        crate::artifacts::LoadError::Cancelled => EngineError::InvalidArgument("loading was cancelled".into()),
        crate::artifacts::LoadError::Read { name, error } => EngineError::InvalidArgument(format!("{name}: {error}")),
    }
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
    /// Files (model, environment, calibration) are read before the device is opened, so that a
    /// bad one is reported as such even where no GPU can be found.
    pub fn new(config: EngineConfig) -> Result<Self, EngineError> {
        // Opening the device and loading the model overlap the renderer's lighting tables.
        crate::render::prepare_lighting_tables_in_background(config.environment_path.is_none());
        Self::with_gpu_from(Gpu::headless, config)
    }

    /// As [`Self::new`] on a given device.
    pub fn with_gpu(gpu: Gpu, config: EngineConfig) -> Result<Self, EngineError> {
        Self::with_gpu_from(|| Ok(gpu), config)
    }

    fn with_gpu_from(
        gpu: impl FnOnce() -> Result<Gpu, RenderError>,
        config: EngineConfig,
    ) -> Result<Self, EngineError> {
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
        // The GPU first: the model's budget takes the device's texture limit.
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
        let environment = match &config.environment_path {
            Some(path) => Some(crate::ibl::Environment::load(path)?),
            None => None,
        };
        let mut renderer = Renderer::with_environment(gpu, &model, environment.as_ref())?;
        let mut detail = detail;
        let impostors = impostors_for(&model, detail.as_mut(), budget.memory_bytes);
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
        let room_light = match crate::room_light::RoomLightWorker::spawn(
            camera_pose,
            phantogram_roomlight::CaptureParams::default(),
            crate::render::PREFILTERED_BASE_WIDTH,
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
            static_environment: environment,
            lamp: None,
            lamp_finger: None,
            last_device_to_world: None,
        };
        engine.apply_calibration();
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

    /// Puts the calibration into the session ([`Session::apply_calibration`]) over the platform's
    /// panel, and into the gestures (their slop) and the face tracker (its metric scale).
    fn apply_calibration(&mut self) {
        if let Err(refused) = self.session.apply_calibration(&self.calibration, self.platform_panel) {
            self.calibration_warning = Some(format!("calibration not fully applied: {refused}"));
        }
        self.session.set_turn_by_touch(self.calibration.turn_by_touch);
        self.gestures = Gestures::new(self.session.config().screen.panel().xdpi);
        // The camera's metric scale: the viewer's own IPD, once calibrated.
        #[cfg(feature = "face")]
        if let Some(face) = &self.face {
            face.set_ipd_m(self.calibration.ipd_m);
        }
    }

    /// Saves the calibration where [`EngineConfig::calibration_path`] says (if anywhere); a
    /// failure becomes [`Self::calibration_warning`].
    fn save_calibration(&mut self) {
        if let Some(path) = &self.calibration_path
            && let Err(e) = self.calibration.save(path)
        {
            self.calibration_warning = Some(format!("{}: {e}; the calibration was not saved", path.display()));
        }
    }

    /// The calibration in use (from the file, the screens and the gestures).
    pub fn calibration(&self) -> Calibration {
        self.calibration
    }

    /// Why the calibration file could not be read, applied or written, if it could not: for the
    /// shell's log. The engine runs on with the defaults (or what it could apply).
    /// Changes the material of the artifact on screen (the material screen's sliders and
    /// presets; sanitised): shown from the next frame, remembered for this artifact (written to
    /// the library's `appearances.json`). A failure to write is returned; the change still shows.
    pub fn set_appearance(&mut self, appearance: crate::render::Appearance) -> Result<(), EngineError> {
        let appearance = appearance.sanitised();
        self.renderer.appearance = appearance;
        self.appearances
            .set(&appearance_key(&self.model_info), appearance)
            .map_err(|source| EngineError::Io {
                what: "the material change could not be saved",
                source,
            })
    }

    /// Hands a camera frame to the live room light (RGBA, YUV or luma; with its exposure when the
    /// platform reports it); from any thread through [`SharedEngine::camera_frame`] too.
    /// Returns `false` when the room light is off ([`EngineConfig::room_light`]).
    pub fn room_light_frame(&self, frame: crate::camera::OwnedFrame) -> bool {
        match &self.room_light {
            Some(worker) => worker.submit(frame),
            None => false,
        }
    }

    /// As [`Self::room_light_frame`], with the device's orientation (device → world) when the
    /// frame was taken: a desktop replay whose camera follows a log of its own.
    pub fn room_light_frame_oriented(&self, frame: crate::camera::OwnedFrame, world_from_device: glam::Quat) -> bool {
        match &self.room_light {
            Some(worker) => worker.submit_oriented(frame, Some(world_from_device)),
            None => false,
        }
    }

    /// Switches the room's own light on or off (off: the studio's, or the configured
    /// environment's, from the next frame; the map seen so far is kept for when it is on again).
    /// Not saved: the settings screen saves its choice.
    pub fn set_room_light(&mut self, on: bool) {
        let Some(worker) = &self.room_light else { return };
        let was_on = worker.is_on();
        worker.set_on(on);
        if was_on && !on && self.stats.room_light_updates > 0 {
            // A failed upload keeps the room's light; the next switch tries again.
            let _ = self
                .renderer
                .set_environment_or_studio(self.static_environment.as_ref());
        }
    }

    /// Whether the room's own light is on.
    pub fn room_light_on(&self) -> bool {
        self.room_light.as_ref().is_some_and(|w| w.is_on())
    }

    /// The anaglyph glasses the front camera saw on the viewer with the newest face (colour camera
    /// frames and face tracking needed): which filter is over which eye. The first-run glasses
    /// check says it beside its question.
    pub fn glasses_seen(&self) -> Option<phantogram_sensing::glasses::GlassesSeen> {
        self.last_glasses
    }

    /// The live room light's worker (its counts, waiting for it; on or off).
    pub fn room_light(&self) -> Option<&crate::room_light::RoomLightWorker> {
        self.room_light.as_deref()
    }

    /// Tells the room light where the device looks now and lights the scene with its newest
    /// update (an upload only: the worker did the work).
    fn update_room_light(&mut self, device_to_world: Option<glam::Quat>) {
        let Some(worker) = &self.room_light else { return };
        if let Some(q) = device_to_world {
            worker.set_orientation(q);
        }
        if let Some(update) = worker.take_update() {
            // Where the GPU convolves the specular levels, the worker leaves them to it from
            // the next update on (asked here, not at start-up: it makes a compute pipeline).
            worker.set_prefilter_on_gpu(self.renderer.prefilters_on_gpu());
            self.stats.room_light_updates += 1;
            self.stats.room_light_coverage = update.coverage;
            // A failed upload keeps the light there was; the next update tries again.
            let _ = match &update.specular {
                crate::room_light::Specular::Base(base) => self.renderer.set_environment_base(base, &update.sh),
                crate::room_light::Specular::Levels(levels) => {
                    self.renderer.set_prefiltered_environment(levels, &update.sh)
                }
            };
        }
    }

    /// Shows `appearance` on the artifact on screen without remembering it (the command line's
    /// `--material`, a preview); the next artifact comes with its own.
    pub fn show_appearance(&mut self, appearance: crate::render::Appearance) {
        self.renderer.appearance = appearance.sanitised();
    }

    /// The material of the artifact on screen (the default: as its glTF says).
    pub fn appearance(&self) -> crate::render::Appearance {
        self.renderer.appearance
    }

    pub fn calibration_warning(&self) -> Option<&str> {
        self.calibration_warning.as_deref()
    }

    /// Opens the calibration screens (also the three-finger tap). Returns `false` when this build
    /// has none (feature `ui` off).
    pub fn open_calibration(&mut self) -> bool {
        #[cfg(feature = "ui")]
        {
            let calibration = self.calibration;
            let page = Page::Calibration(crate::calibration_ui::CalibrationUi::with_calibration(calibration));
            let screens = self.screens();
            if !matches!(screens.page, Some(Page::Calibration(_))) {
                screens.page = Some(page);
            }
            true
        }
        #[cfg(not(feature = "ui"))]
        false
    }

    /// What a screen reader (TalkBack, VoiceOver) can land on in the last frame drawn, in
    /// reading order: the open screen's text and controls, or the picture itself (activating it
    /// opens the menu, as a tap does). See [`crate::calibration_ui::accessibility`].
    #[cfg(feature = "ui")]
    pub fn accessibility_nodes(&self) -> &[crate::calibration_ui::accessibility::AccessNode] {
        self.access.nodes()
    }

    /// Changes whenever [`Self::accessibility_nodes`] do: the shells re-read them then.
    #[cfg(feature = "ui")]
    pub fn accessibility_generation(&self) -> u64 {
        self.access.generation()
    }

    /// A screen reader's "activate" on node `id`: the control acts in the next frame as if
    /// tapped. `false` for an id not among the current nodes, or one that does nothing.
    #[cfg(feature = "ui")]
    pub fn accessibility_click(&mut self, id: i32) -> bool {
        if self.picture_access_node().is_some_and(|p| p.id == id)
            && self.screens.as_ref().is_none_or(|s| s.page.is_none())
        {
            return self.open_menu();
        }
        match self.access.click_event(id) {
            Some(event) => {
                self.screens().events.push(event);
                true
            }
            None => false,
        }
    }

    /// A screen reader's step up (`steps` > 0) or down on slider `id` (a swipe up or down on
    /// it): the slider moves by its step in the next frame. `false` for an id that is not an
    /// adjustable node now.
    #[cfg(feature = "ui")]
    pub fn accessibility_adjust(&mut self, id: i32, steps: i32) -> bool {
        match self.access.adjust_event(id, steps) {
            Some(event) => {
                self.screens().events.push(event);
                true
            }
            None => false,
        }
    }

    /// The picture as a screen reader finds it: the artifact's title, the whole surface.
    #[cfg(feature = "ui")]
    fn picture_access_node(&mut self) -> Option<crate::calibration_ui::accessibility::AccessNode> {
        use crate::calibration_ui::accessibility::{AccessNode, AccessRole};
        let (w, h) = self.target_size().filter(|&(w, h)| w > 0 && h > 0)?;
        let title = match &self.model_info.artifact {
            Some(a) => a.title.clone(),
            None => self.model_info.name.clone(),
        };
        Some(AccessNode {
            id: self.access.id_for("picture"),
            role: AccessRole::Image,
            label: format!("{title}, in 3-D for red and cyan glasses. Activate for the menu."),
            value: None,
            checked: None,
            disabled: false,
            clickable: true,
            adjustable: false,
            bounds_px: [0.0, 0.0, w as f32, h as f32],
        })
    }

    /// Opens the menu: the artifact gallery, opening a file, the way to the calibration (also a
    /// single tap). Returns `false` when this build has no screens (feature `ui` off).
    pub fn open_menu(&mut self) -> bool {
        #[cfg(feature = "ui")]
        {
            if !self.menu_open() {
                let mut menu = crate::calibration_ui::menu::MenuUi::new();
                menu.lamp_on = self.lamp.is_some();
                self.screens().page = Some(Page::Menu(menu));
                self.refresh_menu_items();
            }
            true
        }
        #[cfg(not(feature = "ui"))]
        false
    }

    /// The full screen open over the picture, if any.
    #[cfg(feature = "ui")]
    fn page(&self) -> Option<&Page> {
        self.screens.as_ref().and_then(|s| s.page.as_ref())
    }

    /// Whether the calibration screens are showing (touches then drive them, not gestures).
    pub fn calibration_open(&self) -> bool {
        #[cfg(feature = "ui")]
        return matches!(self.page(), Some(Page::Calibration(_)));
        #[cfg(not(feature = "ui"))]
        false
    }

    /// Where annotation `index`'s marker was in the last frame drawn, physical pixels of the
    /// target (the cyclopean eye's view: between the two the eyes see); `None` before a frame
    /// or for no such annotation.
    pub fn annotation_px(&self, index: usize) -> Option<[f32; 2]> {
        let a = self.model_info.annotations.get(index)?;
        let mono = self.last_mono?;
        let centre = crate::model::Model::pin_centre(a) - Vec3::Z * self.last_push_m;
        let p = mono.project(centre)?.pixel;
        let k = self.target_scale();
        Some([p.x * k, p.y * k])
    }

    /// Target pixels per screen pixel: 1 on a phone; less in the desktop viewer's window.
    fn target_scale(&self) -> f32 {
        let screen_width_px = self.session.config().screen.width_px() as f32;
        self.target_size()
            .map(|(w, _)| w)
            .filter(|&w| w > 0)
            .map_or(1.0, |w| w as f32 / screen_width_px)
    }

    /// The annotation whose marker is nearest `px` (physical pixels), within 6 mm on the glass
    /// (a fingertip).
    fn annotation_at(&self, px: [f32; 2]) -> Option<usize> {
        let screen = self.session.config().screen;
        let reach_px = 0.006 / 0.0254 * screen.panel().xdpi * self.target_scale();
        (0..self.model_info.annotations.len())
            .filter_map(|i| {
                let [x, y] = self.annotation_px(i)?;
                let d = (x - px[0]).hypot(y - px[1]);
                (d <= reach_px).then_some((i, d))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    }

    /// Shows annotation `index`'s card (as a tap on its marker does). Returns `false` for no
    /// such annotation or without screens (feature `ui` off).
    pub fn open_annotation(&mut self, index: usize) -> bool {
        #[cfg(feature = "ui")]
        if index < self.model_info.annotations.len() {
            self.screens().page = Some(Page::Annotation(index));
            return true;
        }
        let _ = index;
        false
    }

    /// The annotation whose card is showing, if one is.
    pub fn open_annotation_index(&self) -> Option<usize> {
        #[cfg(feature = "ui")]
        if let Some(Page::Annotation(i)) = self.page() {
            return Some(*i);
        }
        None
    }

    /// Whether the menu is showing (touches then drive it, not gestures).
    pub fn menu_open(&self) -> bool {
        #[cfg(feature = "ui")]
        return matches!(self.page(), Some(Page::Menu(_)));
        #[cfg(not(feature = "ui"))]
        false
    }

    /// Each eye's image to the filter that is really in front of it: swapped when the glasses
    /// check found the glasses on the other way round.
    fn oriented<'a>(&self, mut input: FrameInput<'a>) -> FrameInput<'a> {
        if self.calibration.glasses_swapped {
            std::mem::swap(&mut input.left, &mut input.right);
        }
        input
    }

    /// How the eyes are found, in words for the menu: the front camera's state.
    pub fn eyes_status(&self) -> String {
        let stats = self.stats();
        let text = if !self.face_tracking_on() {
            "Front camera off: the view follows the phone's tilt."
        } else if stats.face_tracking_stopped {
            "Face tracking stopped: the view follows the phone's tilt."
        } else if stats.eyes_from_camera {
            "The front camera is following your eyes."
        } else {
            "Front camera on, looking for your eyes (meanwhile the view follows the tilt)."
        };
        text.to_owned()
    }

    fn face_tracking_on(&self) -> bool {
        #[cfg(feature = "face")]
        return self.face.is_some();
        #[cfg(not(feature = "face"))]
        false
    }

    /// Whether the first-run screens are showing.
    pub fn welcome_open(&self) -> bool {
        #[cfg(feature = "ui")]
        return matches!(self.page(), Some(Page::Welcome(_)));
        #[cfg(not(feature = "ui"))]
        false
    }

    /// The shell has no camera permission yet and may ask for it. Instead of the system's
    /// request out of the blue, the core shows its camera page (what the camera is for, that no
    /// picture is kept) as soon as no other screen is open — after the first-run screens, if
    /// they show — and only when the user taps "Use the camera" asks the shell
    /// ([`ShellRequest::CameraPermission`]). "Not now" leaves tilt only, until the next start.
    /// Without the `ui` feature the request is made at once.
    pub fn camera_permission_needed(&mut self) {
        #[cfg(feature = "ui")]
        {
            self.camera_page_pending = true;
            self.open_pending_camera_page();
        }
        #[cfg(not(feature = "ui"))]
        self.requests.push(ShellRequest::CameraPermission);
    }

    /// Opens the camera page if it waits and nothing else is open.
    #[cfg(feature = "ui")]
    fn open_pending_camera_page(&mut self) {
        if self.camera_page_pending && self.page().is_none() {
            self.camera_page_pending = false;
            self.set_page(Some(Page::Welcome(crate::calibration_ui::welcome::WelcomeUi::camera())));
        }
    }

    /// The oldest request of the core's screens not yet taken (see [`ShellRequest`]); call until
    /// `None` after each frame.
    pub fn take_shell_request(&mut self) -> Option<ShellRequest> {
        (!self.requests.is_empty()).then(|| self.requests.remove(0))
    }

    #[cfg(feature = "ui")]
    fn screens(&mut self) -> &mut Screens {
        self.screens.get_or_insert_with(|| {
            Box::new(Screens {
                page: None,
                items: Vec::new(),
                ctx: egui::Context::default(),
                events: Vec::new(),
                overlay: crate::calibration_ui::OverlayHost::new(),
                pointer: None,
                banner_pt: None,
                banner_button_pt: None,
                thumbnail_textures: std::collections::HashMap::new(),
            })
        })
    }

    /// Reads the gallery's items from the library again.
    #[cfg(feature = "ui")]
    fn refresh_menu_items(&mut self) {
        let artifacts = self.artifacts();
        self.thumbnails.request(&artifacts);
        let screens = self.screens();
        let items = artifacts
            .into_iter()
            .map(|a| {
                let id = a.id.to_string();
                crate::calibration_ui::menu::MenuItem {
                    removable: a.id.origin == crate::library::Origin::Imported,
                    thumbnail: screens.thumbnail_textures.get(&id).map(egui::TextureHandle::id),
                    id,
                    title: a.title,
                    credit: a.credit,
                    licence: a.licence,
                }
            })
            .collect();
        screens.items = items;
    }

    /// Waits up to `timeout` until the open menu's pictures are all made (or found impossible),
    /// drawing them meanwhile; for tests and tools (the shells just keep drawing frames).
    /// Returns whether none is left to make.
    #[cfg(feature = "ui")]
    pub fn wait_for_thumbnails(&mut self, timeout: std::time::Duration) -> bool {
        let deadline = std::time::Instant::now() + timeout;
        loop {
            self.take_thumbnails();
            if self.thumbnails.pending() == 0 {
                return true;
            }
            if std::time::Instant::now() >= deadline {
                return false;
            }
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
    }

    /// Takes the gallery's finished pictures (drawing at most one a frame) into egui textures.
    #[cfg(feature = "ui")]
    fn take_thumbnails(&mut self) {
        let renderer = &mut self.renderer;
        let new = self.thumbnails.poll(|posed| crate::thumbnails::render(renderer, posed));
        if new.is_empty() {
            return;
        }
        let size = crate::thumbnails::THUMBNAIL_PX as usize;
        for id in new {
            let Some(image) = self
                .thumbnails
                .get(&id)
                .map(|t| egui::ColorImage::from_rgba_unmultiplied([size, size], &t.rgba))
            else {
                continue;
            };
            let screens = self.screens();
            let texture = screens
                .ctx
                .load_texture(format!("thumbnail {id}"), image, egui::TextureOptions::LINEAR);
            for item in screens.items.iter_mut().filter(|i| i.id == id) {
                item.thumbnail = Some(texture.id());
            }
            screens.thumbnail_textures.insert(id, texture);
        }
    }

    /// The centre of a control of the screen showing, in the last frame drawn, in physical
    /// pixels: for tests and automation. Names are the open page's (`widget_rect` of
    /// [`crate::calibration_ui::CalibrationUi`], [`crate::calibration_ui::menu::MenuUi`],
    /// [`crate::calibration_ui::settings::SettingsUi`],
    /// [`crate::calibration_ui::material::MaterialUi`] or
    /// [`crate::calibration_ui::welcome::WelcomeUi`]); `banner` is the status banner's button
    /// (Cancel or OK) whatever page shows.
    #[cfg(feature = "ui")]
    pub fn control_px(&self, name: &str) -> Option<[f32; 2]> {
        let screens = self.screens.as_ref()?;
        let rect = match (&screens.page, name) {
            (_, "banner") => screens.banner_button_pt?,
            (Some(Page::Calibration(ui)), _) => ui.widget_rect(name)?,
            (Some(Page::Menu(ui)), _) => ui.widget_rect(name)?,
            (Some(Page::Settings(ui)), _) => ui.widget_rect(name)?,
            (Some(Page::Material(ui)), _) => ui.widget_rect(name)?,
            (Some(Page::Welcome(ui)), _) => ui.widget_rect(name)?,
            _ => return None,
        };
        let ppp = self.pixels_per_point();
        Some([rect.center().x * ppp, rect.center().y * ppp])
    }

    /// Physical pixels per egui point on this display: Android's density (dpi / 160), which iOS's
    /// scale (≈ ppi / 163) nearly equals, so controls have the platform's size; times the
    /// target's width over the panel's, so that a smaller target (the desktop viewer's window
    /// standing in for the phone) shows the phone's layout, smaller. On a phone they are equal.
    #[cfg(feature = "ui")]
    fn pixels_per_point(&self) -> f32 {
        let screen = self.session.config().screen;
        let density = (screen.panel().xdpi / 160.0).clamp(1.0, 4.0) * self.text_scale;
        let target_width_px = self.target_size().map(|(w, _)| w);
        match target_width_px.filter(|&w| w > 0) {
            Some(w) => density * (w as f32 / screen.width_px() as f32).clamp(0.1, 10.0),
            None => density,
        }
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

    /// What is on screen ([`EngineConfig::model_path`], or the library's artifact).
    pub fn model_info(&self) -> &ModelInfo {
        &self.model_info
    }

    /// Every artifact the library offers (built in, bundled, imported), for the gallery.
    pub fn artifacts(&self) -> Vec<crate::library::ArtifactEntry> {
        let mut list = self.loader.library().list();
        // The Diorama is a scene, not a file: listed after the built-in artifacts.
        let after_built_ins = list
            .iter()
            .position(|e| e.id.origin != crate::library::Origin::BuiltIn)
            .unwrap_or(list.len());
        list.insert(after_built_ins, diorama_entry());
        list
    }

    /// Starts showing an artifact of the library: loaded in the background (see
    /// [`crate::artifacts`]); the artifact on screen stays until it is ready. Progress and
    /// failure: [`Self::loading_status`].
    pub fn select_artifact(&mut self, id: crate::library::ArtifactId) {
        if id.to_string() == crate::diorama::DIORAMA_ID {
            self.loader.cancel();
            self.show_diorama();
            return;
        }
        let placing = self.placing();
        self.loader.start(crate::artifacts::Request::Select(id), placing);
    }

    /// Shows the Diorama in place of the artifact (made at once: no file to load).
    fn show_diorama(&mut self) {
        let screen = self.session.config().screen;
        let scene = match crate::diorama::DioramaScene::new(&screen) {
            Ok(scene) => scene,
            Err(e) => {
                self.loader.fail("Diorama".into(), e.to_string());
                return;
            }
        };
        if let Err(e) = self.renderer.set_model(scene.model()) {
            self.loader.fail("Diorama".into(), e.to_string());
            return;
        }
        let model = scene.model();
        self.bounds = model.bounds().unwrap_or(self.bounds);
        self.model_info = ModelInfo::of(model, Some(diorama_entry()));
        self.renderer.appearance = self.appearances.get(&appearance_key(&self.model_info));
        self.smoother = ContainmentSmoother::default();
        self.detail = None;
        self.impostors = Default::default();
        self.seen = None;
        self.side_hint = None;
        self.diorama = Some(Box::new(scene));
        self.diorama_grab = None;
    }

    /// The Diorama on screen, if it is.
    pub fn diorama(&self) -> Option<&crate::diorama::DioramaScene> {
        self.diorama.as_deref()
    }

    /// Imports a file the user opened (its display name and bytes: a `.glb`, `.gltf` or `.zip`)
    /// into the library and shows it when loaded, in the background as [`Self::select_artifact`].
    pub fn import_artifact(&mut self, name: &str, bytes: Vec<u8>) {
        self.import_artifact_from(name, crate::artifacts::FileSource::Bytes(bytes));
    }

    /// As [`Self::import_artifact`], the content read on the loader's thread when it is a
    /// reader (see [`crate::artifacts::FileSource`]).
    pub fn import_artifact_from(&mut self, name: &str, source: crate::artifacts::FileSource) {
        let placing = self.placing();
        self.loader.start(
            crate::artifacts::Request::Import {
                name: name.to_owned(),
                source,
            },
            placing,
        );
    }

    /// Removes an imported artifact from the library (if it is on screen, it stays there until
    /// another is chosen).
    pub fn remove_artifact(&mut self, id: &crate::library::ArtifactId) -> Result<(), EngineError> {
        Ok(self.loader.library().remove(id)?)
    }

    /// Gives up the load under way; the artifact on screen stays.
    pub fn cancel_loading(&mut self) {
        self.loader.cancel();
    }

    /// Loading progress, or why the last load failed (until [`Self::dismiss_message`]).
    pub fn loading_status(&self) -> LoadStatus {
        self.loader.status()
    }

    /// The user has read the failure message.
    pub fn dismiss_message(&mut self) {
        self.loader.dismiss();
    }

    /// Waits up to `timeout` for the load under way and shows its artifact (for the desktop
    /// tools and tests; the shells just keep drawing, which takes finished loads in turn).
    /// Returns whether a new artifact is now on screen.
    pub fn wait_for_artifact(&mut self, timeout: std::time::Duration) -> bool {
        match self.loader.wait(timeout) {
            Some(prepared) => self.install(prepared),
            None => false,
        }
    }

    fn placing(&self) -> crate::artifacts::Placing {
        crate::artifacts::Placing {
            screen: self.session.config().screen,
            fit: self.fit,
            floor: self.floor,
            memory_bytes: self.loader.budget().memory_bytes,
        }
    }

    /// Uploads a loaded artifact in place of the one on screen; on failure the old one stays
    /// and the reason goes to [`Self::loading_status`].
    fn install(&mut self, prepared: crate::artifacts::Prepared) -> bool {
        match self.renderer.set_model(&prepared.model) {
            Ok(()) => {
                self.diorama = None;
                self.diorama_grab = None;
                self.detail = prepared.detail.map(|mut d| {
                    d.set_target(self.frame_target_s);
                    d
                });
                self.impostors =
                    impostors_for(&prepared.model, self.detail.as_mut(), self.loader.budget().memory_bytes);
                // The best scan taking over from its preview is the same artifact: what was
                // seen of it stays seen.
                let same_artifact = self.model_info.preview
                    && self.model_info.artifact.as_ref().map(|a| &a.id)
                        == prepared.info.artifact.as_ref().map(|a| &a.id);
                if !(same_artifact && self.seen.is_some()) {
                    self.seen = self.side_hints.then_some(prepared.seen);
                }
                self.side_hint = None;
                self.bounds = prepared.bounds;
                self.model_info = prepared.info;
                self.renderer.appearance = self.appearances.get(&appearance_key(&self.model_info));
                self.smoother = ContainmentSmoother::default();
                true
            }
            Err(e) => {
                let title = prepared.info.artifact.map_or(prepared.info.name, |a| a.title);
                self.loader.fail(title, e.to_string());
                false
            }
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

    /// The system's text size setting (Android's `Configuration.fontScale`, iOS's Dynamic Type
    /// as a ratio to the default size): the core's screens scale their text and controls
    /// together by it, within [`TEXT_SCALE_RANGE`] (beyond it the phone's screen holds too
    /// little; the galleries scroll). A scale that is not a finite positive number is an
    /// [`EngineError::InvalidArgument`].
    pub fn set_text_scale(&mut self, scale: f32) -> Result<(), EngineError> {
        if !(scale.is_finite() && scale > 0.0) {
            return Err(EngineError::InvalidArgument(format!(
                "text scale must be a positive number, got {scale}"
            )));
        }
        self.text_scale = scale.clamp(*TEXT_SCALE_RANGE.start(), *TEXT_SCALE_RANGE.end());
        Ok(())
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

    /// One touch event (physical pixels, nanoseconds on a monotonic clock); acts on the gesture
    /// it completes and returns it.
    pub fn touch(&mut self, phase: TouchPhase, pointer_id: i32, x_px: f32, y_px: f32, t_ns: i64) -> Option<Gesture> {
        #[cfg(feature = "ui")]
        {
            let ppp = self.pixels_per_point();
            let gestures_idle = self.gestures.is_idle();
            if let Some(screens) = self.screens.as_mut() {
                let (x_pt, y_pt) = (x_px / ppp, y_px / ppp);
                // A page takes every touch; the banner only those that start on it while no
                // gesture is under way.
                let on_banner = phase == TouchPhase::Down
                    && gestures_idle
                    && screens.pointer.is_none()
                    && screens.banner_pt.is_some_and(|r| r.contains(egui::pos2(x_pt, y_pt)));
                if screens.page.is_some() || screens.pointer == Some(pointer_id) || on_banner {
                    screens.touch(phase, pointer_id, x_pt, y_pt);
                    return None;
                }
            }
        }
        // With a lamp on, a finger's drag moves the lamp (not the view, not the Diorama's
        // bodies); taps and the other gestures still reach the recogniser (a tap opens the menu).
        if !self.touch_lamp(phase, pointer_id, [x_px, y_px]) {
            self.drag_to_turn(phase, pointer_id, [x_px, y_px]);
            self.touch_diorama(phase, pointer_id, [x_px, y_px]);
        }
        let g = self.gestures.touch(phase, pointer_id, x_px, y_px, t_ns)?;
        self.apply_gesture(g);
        Some(g)
    }

    /// A lamp on screen follows the first finger down as it moves (a tap does not move it: taps
    /// stay the menu's). Returns whether a lamp is on (its drags are then the lamp's).
    fn touch_lamp(&mut self, phase: TouchPhase, pointer_id: i32, px: [f32; 2]) -> bool {
        if self.lamp.is_none() {
            self.lamp_finger = None;
            return false;
        }
        match (phase, self.lamp_finger) {
            (TouchPhase::Down, None) => self.lamp_finger = Some(pointer_id),
            (TouchPhase::Move, Some(id)) if id == pointer_id => {
                let at = self.glass_point_m(px);
                let orientation = self.last_device_to_world;
                if let Some(lamp) = self.lamp.as_mut() {
                    lamp.move_to(at.x, at.y, orientation);
                }
            }
            (TouchPhase::Up | TouchPhase::Cancel, Some(id)) if id == pointer_id => self.lamp_finger = None,
            _ => {}
        }
        true
    }

    /// The point of the glass (device frame, z = 0) under display pixel `px` of the target.
    fn glass_point_m(&self, px: [f32; 2]) -> Vec3 {
        let screen = self.session.config().screen;
        screen.glass_point_of_pixel(glam::Vec2::from(px) / self.target_scale())
    }

    /// Puts a lamp over the diorama in place of the room's light (`None`: back to the room's
    /// light): a raking light ([`crate::lamp::LampSetting::raking`]) starts at the screen's left
    /// edge, a torch above its top edge; a finger then moves it ([`Self::touch`]).
    pub fn set_lamp(&mut self, setting: Option<crate::lamp::LampSetting>) {
        let screen = self.session.config().screen;
        self.lamp_finger = None;
        // The edges as the viewer sees them (the display may be turned).
        let (w, h) = (screen.width_px() as f32, screen.height_px() as f32);
        self.lamp = setting.map(|s| {
            let at = match s.anchor {
                crate::lamp::LampAnchor::Room => screen.glass_point_of_pixel(glam::Vec2::new(0.0, 0.5 * h)),
                crate::lamp::LampAnchor::Torch => screen.glass_point_of_pixel(glam::Vec2::new(0.5 * w, 0.0)),
            };
            crate::lamp::PlacedLamp::new(s, at.x, at.y)
        });
        if self.lamp.is_none() {
            self.renderer.lamp = None;
        }
    }

    /// The lamp placed, if any.
    pub fn lamp(&self) -> Option<&crate::lamp::PlacedLamp> {
        self.lamp.as_ref()
    }

    /// The Diorama's finger: a body under the first finger down (on the line from the eye
    /// through the touched point of the glass) is held and follows the finger at its depth;
    /// lifting the finger lets it go with its speed (a flick).
    fn touch_diorama(&mut self, phase: TouchPhase, pointer_id: i32, px: [f32; 2]) {
        if self.diorama.is_none() {
            return;
        }
        let screen = self.session.config().screen;
        let scale = self.target_scale();
        let (Some(mono), Some(scene)) = (self.last_mono, self.diorama.as_deref_mut()) else {
            return;
        };
        let glass = screen.glass_point_of_pixel(glam::Vec2::new(px[0], px[1]) / scale);
        let eye = mono.eye_m;
        let Some(direction) = (glass - eye).try_normalize() else {
            return;
        };
        match (phase, self.diorama_grab) {
            (TouchPhase::Down, None) => {
                let world = scene.world();
                if let Some(i) = world.pick(eye, direction) {
                    let depth = (world.stepped_poses()[i].translation_m - eye).dot(direction);
                    scene.world_mut().grab(i, eye + direction * depth);
                    self.diorama_grab = Some((pointer_id, depth));
                }
            }
            (TouchPhase::Move, Some((id, depth))) if id == pointer_id => {
                scene.world_mut().drag_to(eye + direction * depth);
            }
            (TouchPhase::Up | TouchPhase::Cancel, Some((id, _))) if id == pointer_id => {
                scene.world_mut().release();
                self.diorama_grab = None;
            }
            _ => {}
        }
    }

    /// "Reduce motion": the first finger down drags the artifact around
    /// ([`crate::turn_by_touch`]); a drag across about a phone's width (60 mm) turns it 90°.
    fn drag_to_turn(&mut self, phase: TouchPhase, pointer_id: i32, px: [f32; 2]) {
        const RAD_PER_MM: f32 = std::f32::consts::FRAC_PI_2 / 60.0;
        if !self.session.turning_by_touch() {
            self.drag_px = None;
            return;
        }
        match (phase, self.drag_px) {
            (TouchPhase::Down, None) => self.drag_px = Some((pointer_id, px)),
            (TouchPhase::Move, Some((id, last))) if id == pointer_id => {
                // Millimetres on the glass: the displayed image's size over the target's pixels
                // (the panel's on a phone; smaller in a desktop window or an offscreen test).
                let screen = self.session.config().screen;
                let (w_px, h_px) = self
                    .target_size()
                    .filter(|&(w, h)| w > 0 && h > 0)
                    .unwrap_or((screen.width_px(), screen.height_px()));
                let right_rad = (px[0] - last[0]) * screen.width_m() * 1e3 / w_px as f32 * RAD_PER_MM;
                let down_rad = (px[1] - last[1]) * screen.height_m() * 1e3 / h_px as f32 * RAD_PER_MM;
                self.session.turn_by_touch(right_rad, down_rad);
                self.drag_px = Some((id, px));
            }
            (TouchPhase::Up | TouchPhase::Cancel, Some((id, _))) if id == pointer_id => self.drag_px = None,
            _ => {}
        }
    }

    fn apply_gesture(&mut self, g: Gesture) {
        self.stats.gestures += 1;
        // Without gravity yet the calibrations cannot be done; the gesture is then a no-op, as a
        // user would expect from tapping a phone that has not measured anything.
        match g {
            // In the Diorama a double tap puts everything back in the tray.
            Gesture::StraightOn => match self.diorama.as_deref_mut() {
                Some(scene) => scene.reset(),
                None => {
                    let _ = self.calibrate_flat_angle();
                }
            },
            Gesture::Calibrate => {
                self.open_calibration();
            }
            Gesture::Menu => {
                // A tap on an annotation's marker reads it; anywhere else opens the menu.
                match self.gestures.last_tap_px().and_then(|px| self.annotation_at(px)) {
                    Some(i) => {
                        self.open_annotation(i);
                    }
                    None => {
                        self.open_menu();
                    }
                }
            }
            Gesture::AnchorLight => {
                let _ = self.session.recalibrate_light();
            }
            Gesture::ToggleStereo => {
                self.method = if self.method == Method::Mono {
                    self.stereo_method
                } else {
                    Method::Mono
                };
            }
        }
    }

    /// Makes the current holding pose count as straight on (and saves it with the calibration).
    pub fn calibrate_flat_angle(&mut self) -> Result<(), EngineError> {
        self.session.calibrate_flat_angle()?;
        self.calibration.flat_up_device = self.session.flat_up_device();
        self.save_calibration();
        Ok(())
    }

    /// Lying flat counts as straight on again (and the calibration file says so).
    pub fn reset_flat_angle(&mut self) {
        self.session.reset_flat_angle();
        self.calibration.flat_up_device = None;
        self.save_calibration();
    }

    /// Ties the light to the room again, at the current pose (as a long press does).
    pub fn anchor_light(&mut self) -> Result<(), EngineError> {
        Ok(self.session.recalibrate_light()?)
    }

    /// Draws one frame that will be on screen at `display_t_ns` (sensor clock; `None`: for the
    /// newest sensor state, no prediction).
    pub fn draw(&mut self, display_t_ns: Option<i64>) -> Result<DrawOutcome, EngineError> {
        if let Some(prepared) = self.loader.poll() {
            self.install(prepared);
        }
        if let Some(g) = display_t_ns.and_then(|t| self.gestures.poll(t)) {
            self.apply_gesture(g);
        }
        if matches!(self.target, Target::Detached) {
            self.stats.frames_skipped += 1;
            return Ok(DrawOutcome::Skipped("suspended"));
        }
        self.take_face_result();
        let view = self.session.frame_at(display_t_ns)?;
        let dt_s = match (self.last_display_t_ns, display_t_ns) {
            (Some(a), Some(b)) if b > a => ((b - a) as f32 * 1e-9).min(0.1),
            _ => 1.0 / 60.0,
        };
        if display_t_ns.is_some() {
            self.last_display_t_ns = display_t_ns;
        }
        let push = match self.diorama.as_deref_mut() {
            // The Diorama keeps its bodies inside the eyes' pyramids itself (its own
            // containment, per body): the scene is not pushed back as a whole.
            Some(scene) => {
                let t_ns = display_t_ns.or(view.sensor_t_ns).unwrap_or(0);
                scene.update(&view, self.session.newest_specific_force(), t_ns);
                self.renderer.update_vertices(scene.model())?;
                0.0
            }
            None => self
                .smoother
                .follow(&self.bounds, &view.stereo_eyes_m(), &self.session.config().screen, dt_s),
        };
        self.last_push_m = push;
        self.last_mono = Some(view.mono);
        self.update_room_light(view.device_to_world);
        self.last_device_to_world = view.device_to_world;
        let centre = (self.bounds.min + self.bounds.max) * 0.5 + Vec3::Z * -push;
        self.renderer.lamp = self.lamp.as_mut().map(|l| l.lamp(view.device_to_world, centre));
        let input = self.oriented(frame_input(&view, Vec3::Z * -push));
        self.follow_seen_sides(&view, centre, display_t_ns);
        let levels = self.choose_levels(&input);
        let fades = match self.detail.as_mut() {
            Some(d) => d.fade(display_t_ns.map(|t| t as f64 * 1e-9)),
            None => Vec::new(),
        };
        let input = FrameInput {
            levels: &levels,
            fades: &fades,
            ..input
        };
        self.stats.eyes_from_camera = matches!(self.session.eye_source(), crate::eyetrack::EyeSource::Camera);
        let started = std::time::Instant::now();
        let outcome = self.draw_input(&input);
        // A frame that baked impostors took longer than the budget's choice made it: it says
        // nothing about the budget.
        let baked = std::mem::take(&mut self.baked_this_frame);
        if let (Some(detail), Ok(DrawOutcome::Presented), false) = (self.detail.as_mut(), &outcome, baked) {
            // GPU time where the device measures it (each reading once, when it arrives); the
            // frame's wall time otherwise.
            if self.renderer.times_gpu() {
                if let Some(gpu_s) = self.renderer.take_gpu_time_s() {
                    detail.frame_took(gpu_s);
                }
            } else {
                detail.frame_took(started.elapsed().as_secs_f64());
            }
        }
        outcome
    }

    /// Marks what this frame's view shows of the artifact (centred at `centre`, device frame)
    /// and takes the hint toward an unseen side. Needs display times: without them (frames
    /// drawn on request) no one can be said to linger.
    fn follow_seen_sides(&mut self, view: &crate::session::FrameView, centre: Vec3, display_t_ns: Option<i64>) {
        self.side_hint = None;
        let (Some(seen), Some(t_ns)) = (self.seen.as_mut(), display_t_ns) else {
            return;
        };
        let [left, right] = view.stereo_eyes_m();
        let t_s = t_ns as f64 * 1e-9;
        seen.look((left + right) * 0.5 - centre, t_s);
        self.side_hint = seen.hint(t_s);
    }

    /// The hint toward an unseen side shown this frame, if any (see [`EngineConfig::side_hints`]).
    pub fn side_hint(&self) -> Option<phantogram_detail::seen::Hint> {
        self.side_hint
    }

    /// Each part's level of detail for the frame `input` shows (empty: all at full detail).
    /// First bakes a few of the impostors the last choice would have drawn.
    fn choose_levels(&mut self, input: &FrameInput) -> Vec<u8> {
        let Some(detail) = self.detail.as_mut() else {
            return Vec::new();
        };
        // A failed bake stops the baking: the parts without impostors keep their polygons, and
        // the picture is the same.
        let baked = self.impostors.step(&mut self.renderer, detail);
        self.baked_this_frame = baked.is_ok_and(|n| n > 0);
        let eyes = input.eyes_drawn(self.method);
        detail.choose(&eyes, input.offset, None).to_vec()
    }

    /// The frame time the budget for big scans aims at, seconds (default
    /// [`DEFAULT_FRAME_TARGET_S`]): their parts' levels of detail follow the measured frame
    /// times towards it. Not a finite positive number: unchanged.
    pub fn set_frame_target_s(&mut self, target_s: f64) {
        if target_s.is_finite() && target_s > 0.0 {
            self.frame_target_s = target_s;
            if let Some(d) = self.detail.as_mut() {
                d.set_target(target_s);
            }
        }
    }

    /// The big scan's impostors: baked, planned and not baked (each is baked once the chooser
    /// would draw it, a few a frame), and the GPU memory of those baked, bytes
    /// ([`crate::impostors`]).
    pub fn impostor_progress(&self) -> (usize, usize, u64) {
        (
            self.impostors.baked(),
            self.impostors.pending(),
            self.impostors.baked_bytes(),
        )
    }

    /// What the big scan's chooser did in the last frame: triangles drawn per eye, the budget,
    /// and switches (`None` for a model drawn whole).
    pub fn detail_stats(&self) -> Option<(phantogram_detail::ChoiceStats, u64)> {
        self.detail.as_ref().map(|d| (d.last_choice(), d.budget_triangles()))
    }

    /// The screens (when a page or the banner is up) and the frame, presented.
    fn draw_input(&mut self, input: &FrameInput) -> Result<DrawOutcome, EngineError> {
        let input = *input;
        #[cfg(feature = "ui")]
        {
            self.open_pending_camera_page();
            if self.menu_open() {
                self.take_thumbnails();
            }
            let page_open = self.screens.as_ref().is_some_and(|s| s.page.is_some());
            let status = self.loader.status();
            if page_open || status != LoadStatus::Idle || self.side_hint.is_some() {
                return self.draw_with_screens(&input, status);
            } else if let Some(screens) = self.screens.as_mut() {
                screens.banner_pt = None;
                screens.banner_button_pt = None;
            }
            // The bare picture: one thing for a screen reader to land on.
            let picture = self.picture_access_node();
            self.access.replace(picture.into_iter().collect());
        }
        self.present(&input, None)
    }

    /// Draws `input` to the target, `overlay` painted over the composed frame before it is
    /// presented or read back, and counts the outcome.
    fn present(
        &mut self,
        input: &FrameInput,
        overlay: Option<&mut OverlayPaint<'_>>,
    ) -> Result<DrawOutcome, EngineError> {
        let outcome = match &mut self.target {
            Target::Detached => DrawOutcome::Skipped("suspended"),
            Target::Window(host) => match overlay {
                Some(paint) => {
                    host.draw_with(&mut self.renderer, input, self.method, |g, v, f, s| paint(g, v, f, s))?
                }
                None => host.draw(&mut self.renderer, input, self.method)?,
            },
            Target::Offscreen { width, height } => {
                let (w, h) = (*width, *height);
                if w == 0 || h == 0 {
                    DrawOutcome::Skipped("zero-sized")
                } else {
                    let pixels = match overlay {
                        Some(paint) => self
                            .renderer
                            .render_with_overlay(input, self.method, w, h, |g, v, f, s| paint(g, v, f, s))?,
                        None => self.renderer.render(input, self.method, w, h)?,
                    };
                    self.last_frame = Some((w, h, pixels));
                    DrawOutcome::Presented
                }
            }
        };
        match outcome {
            DrawOutcome::Presented => self.stats.frames_drawn += 1,
            DrawOutcome::Skipped(_) => self.stats.frames_skipped += 1,
        }
        Ok(outcome)
    }

    /// [`Self::draw`] with the screens over the frame: one egui frame with the touches since the
    /// last (the open page, then the status banner over it), painted over the picture, then what
    /// the viewer chose is applied.
    #[cfg(feature = "ui")]
    fn draw_with_screens(&mut self, input: &FrameInput, status: LoadStatus) -> Result<DrawOutcome, EngineError> {
        use crate::calibration_ui::menu::{Banner, BannerAction, show_banner};
        let size = self.target_size();
        // Nothing to lay the screens out on: the plain draw skips (and counts) the frame.
        let (w, h) = match size {
            Some((w, h)) if w > 0 && h > 0 => (w, h),
            _ => return self.present(input, None),
        };
        let ppp = self.pixels_per_point();
        let screen = self.session.config().screen;
        let current = self.model_info.artifact.as_ref().map(|a| a.id.to_string());
        self.screens();
        // Out of `self` while the frame is drawn, which the painter needs them for.
        let Some(mut screens) = self.screens.take() else {
            return self.present(input, None);
        };
        screens.ctx.set_pixels_per_point(ppp);
        // AccessKit nodes for the screen readers, every frame (a flag; egui re-enables nothing
        // by itself after the context is made anew).
        screens.ctx.enable_accesskit();
        // On a sliver of a surface (split screen, mid-resize) the screens are laid out at a
        // least size and cut off at its edges, rather than squeezed into negative widths
        // (egui asserts on those; found by the random JNI calls on a 1-pixel surface).
        let raw = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(
                egui::Pos2::ZERO,
                egui::vec2((w as f32 / ppp).max(MIN_SCREEN_PT), (h as f32 / ppp).max(MIN_SCREEN_PT)),
            )),
            events: std::mem::take(&mut screens.events),
            ..Default::default()
        };
        let banner = match status {
            LoadStatus::Idle => None,
            LoadStatus::Loading { title, fraction } => Some(Banner::Loading { title, fraction }),
            LoadStatus::Failed { title, message } => Some(Banner::Failed { title, message }),
        };
        let (mut calibration_actions, mut menu_actions) = (Vec::new(), Vec::new());
        let mut welcome_actions = Vec::new();
        let mut settings_actions = Vec::new();
        let mut material_actions = Vec::new();
        let filters = filter_colours(self.method);
        let camera_glasses = self.last_glasses;
        let mut card_closed = false;
        // Only the menu says how the eyes are found.
        let eyes_status = match &screens.page {
            Some(Page::Menu(_)) => self.eyes_status(),
            _ => String::new(),
        };
        let annotations = &self.model_info.annotations;
        // The hint only over the bare picture: in the picture's axes (x right, y down).
        let side_hint = self.side_hint.filter(|_| screens.page.is_none()).map(|h| {
            let toward = glam::Vec3::new(h.toward.x, h.toward.y, 0.0);
            [toward.dot(screen.right_device()), -toward.dot(screen.up_device())]
        });
        let mut banner_action = None;
        let mut banner_pt = None;
        let mut banner_button_pt = None;
        let (page, items) = (&mut screens.page, &screens.items);
        let mut output = screens.ctx.run_ui(raw, |root| {
            match page {
                Some(Page::Calibration(ui)) => calibration_actions = ui.show(root, &screen, ppp),
                Some(Page::Menu(menu)) => menu_actions = menu.show(root, items, current.as_deref(), &eyes_status),
                Some(Page::Help) => {
                    card_closed = crate::calibration_ui::menu::show_annotation(
                        root.ctx(),
                        "How to use it",
                        crate::calibration_ui::menu::GESTURE_HELP,
                    )
                    .0
                }
                Some(Page::Welcome(welcome)) => {
                    welcome.camera_glasses = camera_glasses;
                    welcome_actions = welcome.show(root, filters)
                }
                Some(Page::Settings(settings)) => settings_actions = settings.show(root),
                Some(Page::Material(material)) => material_actions = material.show(root),
                Some(Page::Annotation(i)) => match annotations.get(*i) {
                    Some(a) => {
                        card_closed = crate::calibration_ui::menu::show_annotation(root.ctx(), &a.title, &a.lead).0
                    }
                    None => card_closed = true,
                },
                None => {
                    if let Some(toward) = side_hint {
                        crate::calibration_ui::side_hint::show_side_hint(root.ctx(), toward, 16.0);
                    }
                }
            }
            if let Some(b) = &banner {
                let (action, area, button) = show_banner(root.ctx(), b);
                banner_action = action;
                banner_pt = Some(area);
                banner_button_pt = Some(button);
            }
        });
        screens.banner_pt = banner_pt;
        screens.banner_button_pt = banner_button_pt;
        if let Some(update) = output.platform_output.accesskit_update.take() {
            let mut nodes = self.access.flatten(&update, ppp);
            if screens.page.is_none()
                && let Some(picture) = self.picture_access_node()
            {
                // Under a banner or the hint, the picture is still there to land on (first).
                nodes.insert(0, picture);
            }
            // Once, with the picture in: the generation moves only when the nodes do.
            self.access.replace(nodes);
        }
        screens.overlay.begin(&mut output);
        let drawn = {
            let ctx = screens.ctx.clone();
            let overlay = &mut screens.overlay;
            let mut paint = |gpu: &Gpu, view: &wgpu::TextureView, format: wgpu::TextureFormat, size: [u32; 2]| {
                overlay.paint(gpu, &ctx, &mut output, view, format, size);
            };
            self.present(input, Some(&mut paint))
        };
        // Also after a failed draw: what it did not upload is kept for the next frame.
        if screens.overlay.end(&mut output) {
            screens.ctx = egui::Context::default();
        }
        self.screens = Some(screens);
        let outcome = drawn?;
        for action in calibration_actions {
            self.apply_calibration_action(action);
        }
        for action in menu_actions {
            self.apply_menu_action(action);
        }
        if card_closed {
            self.set_page(None);
        }
        for action in welcome_actions {
            self.apply_welcome_action(action);
        }
        for action in settings_actions {
            self.apply_settings_action(action);
        }
        for action in material_actions {
            match action {
                crate::calibration_ui::material::MaterialAction::Changed(a) => {
                    if let Err(e) = self.set_appearance(a) {
                        // Shown all the same; the banner says it will not be remembered.
                        self.loader.fail(self.model_info.name.clone(), e.to_string());
                    }
                }
                crate::calibration_ui::material::MaterialAction::Close => self.set_page(None),
            }
        }
        match banner_action {
            Some(BannerAction::Cancel) => self.cancel_loading(),
            Some(BannerAction::Dismiss) => self.dismiss_message(),
            None => {}
        }
        Ok(outcome)
    }

    #[cfg(feature = "ui")]
    fn set_page(&mut self, page: Option<Page>) {
        if !matches!(page, Some(Page::Menu(_))) {
            // Pictures not started yet are not needed now; asked for again at the next menu.
            self.thumbnails.cancel_pending();
        }
        self.screens().page = page;
    }

    /// Applies and saves what the settings screen changed; a new floor, protrusion or size shows
    /// the artifact on screen again with it (loaded anew from the library in the background).
    #[cfg(feature = "ui")]
    fn apply_settings_action(&mut self, action: crate::calibration_ui::settings::SettingsAction) {
        use crate::calibration_ui::settings::SettingsAction as A;
        match action {
            A::Changed(s) => {
                self.set_method(s.method);
                let surface_now = self.fit.placement == crate::model::Placement::Surface;
                let placing_changed = s.floor != self.floor
                    || s.protrude_fraction != self.fit.protrude_fraction
                    || s.true_size != self.fit.true_size
                    || s.surface != surface_now;
                self.floor = s.floor;
                self.fit.protrude_fraction = s.protrude_fraction;
                self.fit.true_size = s.true_size;
                if s.surface != surface_now {
                    self.fit.placement = if s.surface {
                        crate::model::Placement::Surface
                    } else {
                        crate::model::Placement::Auto
                    };
                }
                self.calibration.surface = s.surface;
                self.calibration.method = Some(s.method);
                self.calibration.floor = Some(s.floor);
                self.calibration.protrude_fraction = Some(s.protrude_fraction);
                self.calibration.true_size = s.true_size;
                self.calibration.turn_by_touch = s.turn_by_touch;
                self.session.set_turn_by_touch(s.turn_by_touch);
                if s.room_light != self.room_light_on() {
                    self.set_room_light(s.room_light);
                    self.calibration.room_light = Some(s.room_light);
                }
                self.save_calibration();
                if placing_changed && let Some(id) = self.model_info.artifact.as_ref().map(|a| a.id.clone()) {
                    self.select_artifact(id);
                }
            }
            A::Close => self.set_page(None),
        }
    }

    #[cfg(feature = "ui")]
    fn apply_welcome_action(&mut self, action: crate::calibration_ui::welcome::WelcomeAction) {
        use crate::calibration_ui::welcome::WelcomeAction as A;
        match action {
            A::Start => {
                // The pose held now is straight on (without gravity yet, lying flat stays it).
                let _ = self.session.calibrate_flat_angle();
                self.calibration.flat_up_device = self.session.flat_up_device().or(self.calibration.flat_up_device);
                self.calibration.introduced = true;
                self.save_calibration();
                self.set_page(None);
            }
            A::GlassesSwapped(swapped) => {
                self.calibration.glasses_swapped = swapped;
                self.save_calibration();
            }
            A::Calibrate => {
                self.calibration.introduced = true;
                self.save_calibration();
                self.set_page(None);
                self.open_calibration();
            }
            A::AllowCamera => {
                self.requests.push(ShellRequest::CameraPermission);
                self.set_page(None);
            }
            A::CameraNotNow => self.set_page(None),
        }
    }

    #[cfg(feature = "ui")]
    fn apply_menu_action(&mut self, action: crate::calibration_ui::menu::MenuAction) {
        use crate::calibration_ui::menu::MenuAction as A;
        match action {
            A::Select(id) => {
                match id.parse() {
                    Ok(id) => self.select_artifact(id),
                    Err(e) => self.loader.fail(id, format!("{e}")),
                }
                // Back to the picture, where the banner shows the progress.
                self.set_page(None);
            }
            A::Remove(id) => {
                let removed = id
                    .parse()
                    .map_err(EngineError::from)
                    .and_then(|id| self.remove_artifact(&id));
                if let Err(e) = removed {
                    self.loader.fail(id, e.to_string());
                }
                self.refresh_menu_items();
            }
            A::OpenFile => {
                self.requests.push(ShellRequest::OpenFile);
                self.set_page(None);
            }
            A::Share { side_by_side } => {
                let kind = if side_by_side {
                    Snapshot::SideBySide
                } else {
                    Snapshot::Composed
                };
                self.requests.push(ShellRequest::Share(kind));
                self.set_page(None);
            }
            A::Calibrate => {
                self.set_page(None);
                self.open_calibration();
            }
            A::Help => self.set_page(Some(Page::Help)),
            A::Settings => {
                let settings = crate::calibration_ui::settings::Settings {
                    method: self.method,
                    floor: self.floor,
                    protrude_fraction: self.fit.protrude_fraction,
                    true_size: self.fit.true_size,
                    surface: self.fit.placement == crate::model::Placement::Surface,
                    turn_by_touch: self.session.turning_by_touch(),
                    room_light: self.room_light_on(),
                };
                self.set_page(Some(Page::Settings(crate::calibration_ui::settings::SettingsUi::new(
                    settings,
                ))));
            }
            A::Material => {
                let ui = crate::calibration_ui::material::MaterialUi::new(self.appearance());
                self.set_page(Some(Page::Material(ui)));
            }
            A::Lamp => {
                // Closed at once: the next finger on the glass moves the lamp.
                let on = self.lamp.is_some();
                self.set_lamp((!on).then(crate::lamp::LampSetting::raking));
                self.set_page(None);
            }
            A::Close => self.set_page(None),
        }
    }

    #[cfg(feature = "ui")]
    fn apply_calibration_action(&mut self, action: crate::calibration_ui::CalibrationAction) {
        use crate::calibration_ui::CalibrationAction as A;
        match action {
            A::FlatAngleHere => {
                // Without gravity yet there is no pose to take; the screens stay as they are.
                let _ = self.calibrate_flat_angle();
            }
            A::ResetLight => {
                let _ = self.session.recalibrate_light();
            }
            A::Changed(c) => {
                // The screens do not set the flat angle; the session holds the current one.
                self.calibration = Calibration {
                    flat_up_device: self.calibration.flat_up_device,
                    glasses_swapped: self.calibration.glasses_swapped,
                    introduced: self.calibration.introduced,
                    ..c
                };
                self.apply_calibration();
                self.save_calibration();
            }
            A::Closed => self.set_page(None),
        }
    }

    #[cfg(feature = "face")]
    fn take_face_result(&mut self) {
        let newest = self.face.as_ref().and_then(|f| f.newest());
        if let Some(obs) = newest.filter(|o| self.last_face_t_ns != Some(o.capture_t_ns)) {
            self.last_face_t_ns = Some(obs.capture_t_ns);
            if obs.eyes_m.is_some() {
                self.last_glasses = obs.glasses;
            }
            self.session.observe_face(obs);
        }
    }

    #[cfg(not(feature = "face"))]
    fn take_face_result(&mut self) {
        let _ = self.last_face_t_ns;
    }

    /// The current view as a picture to share, at the target's size (the screen's when
    /// detached), without the screens drawn over it: width, height and sRGB RGBA pixels.
    pub fn snapshot(&mut self, kind: Snapshot) -> Result<(u32, u32, Vec<u8>), EngineError> {
        let screen = self.session.config().screen;
        let (w, h) = self
            .target_size()
            .filter(|&(w, h)| w > 0 && h > 0)
            .unwrap_or((screen.width_px(), screen.height_px()));
        let view = self.session.frame_at(self.last_display_t_ns)?;
        let input = self.oriented(frame_input(&view, Vec3::Z * -self.last_push_m));
        Ok(match kind {
            Snapshot::Composed => (w, h, self.renderer.render(&input, self.method, w, h)?),
            Snapshot::SideBySide => (w * 2, h, self.renderer.render_side_by_side(&input, w, h)?),
        })
    }

    /// [`Self::snapshot`] as a PNG file's bytes, for the platform's share sheet.
    pub fn snapshot_png(&mut self, kind: Snapshot) -> Result<Vec<u8>, EngineError> {
        let (w, h, pixels) = self.snapshot(kind)?;
        encode_png(w, h, &pixels).map_err(|e| EngineError::Share(e.to_string()))
    }

    /// The last offscreen frame: width, height and 8-bit sRGB RGBA pixels, rows top to bottom.
    pub fn last_frame(&self) -> Result<(u32, u32, &[u8]), EngineError> {
        self.last_frame
            .as_ref()
            .map(|(w, h, p)| (*w, *h, p.as_slice()))
            .ok_or(EngineError::NoFrame)
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

#[cfg(feature = "ui")]
impl Screens {
    /// One touch, in points, as egui's pointer: the first finger down drives it.
    fn touch(&mut self, phase: TouchPhase, pointer_id: i32, x_pt: f32, y_pt: f32) {
        if !(x_pt.is_finite() && y_pt.is_finite()) {
            return;
        }
        let button = |pos, pressed| egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::default(),
        };
        let pos = egui::pos2(x_pt, y_pt);
        // Every finger as egui's touch too: egui scrolls by dragging only once it has seen a
        // touch screen (`DragScroll::OnTouch`), so without these no panel scrolls under a finger.
        let touch_phase = match phase {
            TouchPhase::Down => egui::TouchPhase::Start,
            TouchPhase::Move => egui::TouchPhase::Move,
            TouchPhase::Up => egui::TouchPhase::End,
            TouchPhase::Cancel => egui::TouchPhase::Cancel,
        };
        self.events.push(egui::Event::Touch {
            device_id: egui::TouchDeviceId(0),
            id: egui::TouchId(u64::from(pointer_id as u32)),
            phase: touch_phase,
            pos,
            force: None,
        });
        match phase {
            TouchPhase::Down if self.pointer.is_none() => {
                self.pointer = Some(pointer_id);
                self.events.extend([egui::Event::PointerMoved(pos), button(pos, true)]);
            }
            TouchPhase::Move if self.pointer == Some(pointer_id) => self.events.push(egui::Event::PointerMoved(pos)),
            TouchPhase::Up if self.pointer == Some(pointer_id) => {
                self.pointer = None;
                self.events.extend([button(pos, false), egui::Event::PointerGone]);
            }
            // Taken by the system: let go far away, which egui takes for a drag, not a click.
            TouchPhase::Cancel if self.pointer == Some(pointer_id) => {
                self.pointer = None;
                let away = egui::pos2(-1.0e4, -1.0e4);
                self.events.extend([
                    egui::Event::PointerMoved(away),
                    button(away, false),
                    egui::Event::PointerGone,
                ]);
            }
            _ => {}
        }
    }
}

fn add_surface_stats(a: SurfaceStats, b: SurfaceStats) -> SurfaceStats {
    SurfaceStats {
        presented: a.presented + b.presented,
        skipped: a.skipped + b.skipped,
        reconfigured: a.reconfigured + b.reconfigured,
        recreated: a.recreated + b.recreated,
        resumed: a.resumed + b.resumed,
        suspended: a.suspended + b.suspended,
    }
}

/// An [`Engine`] shared between the render thread and the platform's producer threads; what the
/// bridges hold behind their handles. See the module docs for the threading contract.
pub struct SharedEngine {
    inbox: Arc<SensorInbox>,
    #[cfg(feature = "face")]
    face: Option<Arc<crate::face::FaceWorker>>,
    room_light: Option<Arc<crate::room_light::RoomLightWorker>>,
    camera_frames: std::sync::atomic::AtomicU64,
    engine: Mutex<Engine>,
}

impl SharedEngine {
    pub fn new(engine: Engine) -> Self {
        Self {
            inbox: engine.inbox(),
            #[cfg(feature = "face")]
            face: engine.face_worker(),
            room_light: engine.room_light.clone(),
            camera_frames: std::sync::atomic::AtomicU64::new(0),
            engine: Mutex::new(engine),
        }
    }

    /// From any thread, without waiting for a frame. Bad samples are rejected and counted.
    pub fn push_sensor(&self, event: SensorEvent) -> Result<(), Rejection> {
        self.inbox.push(event)
    }

    /// From any thread, without waiting for inference: hands the frame to the face tracker
    /// (replacing one not yet started), and to the live room light when it is on. `Ok(false)`
    /// when face tracking is off.
    #[cfg(feature = "face")]
    pub fn camera_frame(&self, frame: crate::face::OwnedFrame) -> Result<bool, EngineError> {
        crate::face::UprightImage::new(frame.as_frame())?;
        if let Some(room) = &self.room_light
            && room.is_on()
        {
            room.submit(frame.clone());
        }
        match &self.face {
            Some(worker) => {
                worker.submit(frame);
                self.camera_frames.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                Ok(true)
            }
            None => Ok(false),
        }
    }

    /// From any thread: the exposure of the camera frame captured at `capture_t_ns`, where the
    /// platform reports it apart from the frame (Camera2's capture results); the room light
    /// matches it to its frame. Ignored when the room light is off.
    pub fn camera_exposure(&self, capture_t_ns: i64, exposure: crate::camera::Exposure) {
        if let Some(room) = &self.room_light {
            room.note_exposure(capture_t_ns, exposure);
        }
    }

    /// The engine, for lifecycle, touch and drawing (waits for a frame in progress).
    pub fn lock(&self) -> MutexGuard<'_, Engine> {
        self.engine.lock().unwrap_or_else(|p| p.into_inner())
    }

    pub fn stats(&self) -> EngineStats {
        let mut s = self.lock().stats();
        s.camera_frames = self.camera_frames.load(std::sync::atomic::Ordering::Relaxed);
        s
    }
}

/// The sRGB colours of a method's two filters, left eye's first, for the glasses check: each
/// passes through its own filter only. `None` for mono (no glasses).
#[cfg(feature = "ui")]
fn filter_colours(method: Method) -> Option<([u8; 3], [u8; 3])> {
    match method {
        Method::Mono => None,
        Method::DuboisGreenMagenta => Some(([0, 255, 0], [255, 0, 255])),
        Method::DuboisAmberBlue => Some(([255, 190, 0], [0, 0, 255])),
        Method::DuboisRedCyan | Method::HalfColor | Method::Optimized | Method::Gray | Method::Color => {
            Some(([255, 0, 0], [0, 255, 255]))
        }
    }
}

/// `width × height` sRGB RGBA pixels (rows top to bottom, as the engine's frames) as a PNG
/// file's bytes: what the share sheet, the gallery's cache and `phantogram render` write.
pub fn encode_png(width: u32, height: u32, rgba: &[u8]) -> Result<Vec<u8>, image::ImageError> {
    let mut png = Vec::new();
    image::write_buffer_with_format(
        &mut std::io::Cursor::new(&mut png),
        rgba,
        width,
        height,
        image::ExtendedColorType::Rgba8,
        image::ImageFormat::Png,
    )?;
    Ok(png)
}

/// The Diorama's entry in the artifact library.
fn diorama_entry() -> crate::library::ArtifactEntry {
    crate::library::ArtifactEntry {
        id: crate::library::ArtifactId::built_in("diorama"),
        title: "Diorama: tilt to roll marbles".into(),
        credit: Some(crate::builtin::CREDIT.into()),
        licence: Some(crate::builtin::LICENCE.into()),
        model_path: None,
    }
}

/// What the renderer draws for a frame the session computed, with the mesh moved by `offset`
/// (containment's push-back). Without any orientation yet, the device is taken as lying flat
/// facing north. (Here, not in the renderer: the renderer knows nothing of the sensors.)
pub fn frame_input(view: &crate::session::FrameView, offset: Vec3) -> FrameInput<'_> {
    FrameInput {
        left: &view.left,
        right: &view.right,
        mono: &view.mono,
        toward_light: view.toward_light_device,
        device_to_world: view.device_to_world.unwrap_or(glam::Quat::IDENTITY),
        offset,
        levels: &[],
        fades: &[],
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
