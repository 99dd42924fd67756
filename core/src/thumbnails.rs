//! Gallery thumbnails: each artifact drawn small by our own renderer, from one three-quarter
//! view, and kept on disk.
//!
//! * Made on demand, for the artifacts the open menu lists: a worker thread
//!   (`artifact-thumbnails`, started with the first request) reads a cached PNG, or loads the
//!   artifact — a Voyager folder's lightest scan when it has one ([`Library::load_preview`]) —
//!   and poses it ([`pose`]); the render thread then draws it
//!   ([`crate::render::Renderer::render_other_model`]) and the PNG goes to the cache.
//! * The pose: the artifact as a visitor first sees it, from 40° above the glass on the side of
//!   the screen's lower edge, turned so that this view is straight on, centred and scaled to fill
//!   [`THUMBNAIL_PX`] square with a small margin.
//! * The cache: `<library>/thumbnails/<hash>.png`, the hash of the artifact's id and its
//!   content's revision (the model file's size and modification time; the program's version for
//!   the built-in ones), so a replaced file gets a new thumbnail. Without a library folder they
//!   are kept in memory only.
//! * A load that fails, or a thumbnail that cannot be drawn, is not asked for again until the
//!   engine restarts: the gallery shows the artifact's title without a picture.
//!
//! **Threading**: [`Thumbnails`] lives on the render thread; the worker shares only channels and
//! an atomic generation (a cancel drops the requests not yet started). **Panics**: a panic in a
//! load (a bug) is caught on the worker and counts as a failed thumbnail.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};

use glam::{Mat4, Quat, Vec3};

use crate::budget::ResourceBudget;
use crate::library::{ArtifactEntry, Library};
use crate::model::Model;
use crate::progress::Progress;
use crate::projection::{DepthRange, OffAxisProjection};
use crate::screen::{DisplayRotation, PanelSpec, Screen};

/// A thumbnail's side, pixels: the gallery's 64-point square at a phone's 3× density.
pub const THUMBNAIL_PX: u32 = 192;

/// How far above the glass the thumbnail's view looks down at the artifact.
pub const VIEW_ELEVATION_RAD: f32 = 40.0 * std::f32::consts::PI / 180.0;
/// The posed artifact's larger half-extent across the view, metres, and the eye's distance.
pub const HALF_EXTENT_M: f32 = 0.045;
pub const EYE_DISTANCE_M: f32 = 0.4;
/// Room around the artifact's silhouette.
const MARGIN: f32 = 1.06;

/// A thumbnail: `THUMBNAIL_PX` square, sRGB RGBA.
#[derive(Clone, Debug, PartialEq)]
pub struct Thumbnail {
    /// The library id, as text.
    pub id: String,
    pub rgba: Vec<u8>,
}

/// A model posed for its thumbnail, and the half-size of the square window it is seen through
/// (metres, in the glass plane `z = 0`, the eye on the `+z` axis).
#[derive(Debug)]
pub struct Posed {
    pub model: Model,
    pub window_half_m: f32,
}

/// Turns `model` (in the device frame, as fitted for the phone) so that the view from
/// [`VIEW_ELEVATION_RAD`] above the glass, from the screen's lower edge, looks along `−z`;
/// centres it and scales it to [`HALF_EXTENT_M`]. `None` for a model without geometry.
pub fn pose(mut model: Model) -> Option<Posed> {
    // The view's direction (0, cos α, −sin α) turned onto −z: a turn about x by −(90° − α).
    let turn = Quat::from_rotation_x(-(std::f32::consts::FRAC_PI_2 - VIEW_ELEVATION_RAD));
    model.transform(Mat4::from_quat(turn));
    let b = model.bounds()?;
    let half = (b.max - b.min) * 0.5;
    let across = half.x.max(half.y);
    if !(across.is_finite() && across > 0.0) {
        return None;
    }
    let scale = HALF_EXTENT_M / across;
    let centre = (b.min + b.max) * 0.5;
    model.transform(Mat4::from_scale(Vec3::splat(scale)) * Mat4::from_translation(-centre));
    // The nearest part is magnified most: the window takes it in at the eye's distance.
    let near_m = (half.z * scale).min(EYE_DISTANCE_M * 0.5);
    let window_half_m = HALF_EXTENT_M * EYE_DISTANCE_M / (EYE_DISTANCE_M - near_m) * MARGIN;
    Some(Posed { model, window_half_m })
}

/// The mono eye through the posed model's window, and the light: what
/// [`crate::render::Renderer::render_other_model`] takes.
pub fn view(window_half_m: f32) -> Option<OffAxisProjection> {
    let dpi = THUMBNAIL_PX as f32 / (2.0 * window_half_m / 0.0254);
    let panel = PanelSpec {
        width_px: THUMBNAIL_PX,
        height_px: THUMBNAIL_PX,
        xdpi: dpi,
        ydpi: dpi,
    };
    let screen = Screen::new(panel, DisplayRotation::Deg0).ok()?;
    let depth = DepthRange {
        near_m: 0.05,
        far_m: 2.0,
    };
    OffAxisProjection::new(&screen, Vec3::Z * EYE_DISTANCE_M, depth).ok()
}

/// The light of every thumbnail: from the upper left, towards the viewer, in the posed frame.
pub fn toward_light() -> Vec3 {
    Vec3::new(-0.4, 0.6, 0.7).normalize()
}

/// Draws a posed model's thumbnail with `renderer` (beside the model it shows).
pub fn render(renderer: &mut crate::render::Renderer, posed: &Posed) -> Option<Vec<u8>> {
    let eye = view(posed.window_half_m)?;
    let input = crate::render::FrameInput {
        left: &eye,
        right: &eye,
        mono: &eye,
        toward_light: toward_light(),
        device_to_world: Quat::IDENTITY,
        offset: Vec3::ZERO,
        levels: &[],
        fades: &[],
    };
    renderer
        .render_other_model(&posed.model, &input, THUMBNAIL_PX, THUMBNAIL_PX)
        .ok()
}

/// What the worker finished.
enum Made {
    Cached(Thumbnail),
    /// A posed model to draw, and where its PNG goes.
    Posed {
        id: String,
        cache: Option<PathBuf>,
        posed: Posed,
    },
    /// Not loadable or not drawable: the gallery shows the title alone.
    Failed(String),
}

struct Job {
    generation: u64,
    entry: ArtifactEntry,
}

/// The gallery's thumbnails (see the module docs).
pub struct Thumbnails {
    library: Library,
    budget: ResourceBudget,
    cache_dir: Option<PathBuf>,
    ready: HashMap<String, Thumbnail>,
    /// Asked for (finished or not): not asked for again while the menu stays open.
    asked: HashSet<String>,
    /// Could not be made: not asked for again.
    failed: HashSet<String>,
    generation: Arc<AtomicU64>,
    tx: Sender<Made>,
    rx: Receiver<Made>,
    worker: Option<Sender<Job>>,
}

impl std::fmt::Debug for Thumbnails {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Thumbnails")
            .field("ready", &self.ready.len())
            .field("asked", &self.asked.len())
            .finish_non_exhaustive()
    }
}

impl Thumbnails {
    /// Thumbnails of `library`'s artifacts, loaded within `budget`, cached in `cache_dir` (none:
    /// in memory only).
    pub fn new(library: Library, budget: ResourceBudget, cache_dir: Option<PathBuf>) -> Self {
        let (tx, rx) = channel();
        Self {
            library,
            budget,
            cache_dir,
            ready: HashMap::new(),
            asked: HashSet::new(),
            failed: HashSet::new(),
            generation: Arc::new(AtomicU64::new(0)),
            tx,
            rx,
            worker: None,
        }
    }

    /// The thumbnail of `id`, once made.
    pub fn get(&self, id: &str) -> Option<&Thumbnail> {
        self.ready.get(id)
    }

    /// Asks for the thumbnails of `entries` not made or asked for yet, in their order.
    pub fn request(&mut self, entries: &[ArtifactEntry]) {
        let generation = self.generation.load(Ordering::Relaxed);
        for entry in entries {
            let id = entry.id.to_string();
            if self.ready.contains_key(&id) || !self.asked.insert(id) {
                continue;
            }
            let job = Job {
                generation,
                entry: entry.clone(),
            };
            if self.queue(job).is_err() {
                return; // no thread: the gallery goes without pictures
            }
        }
    }

    fn queue(&mut self, job: Job) -> Result<(), ()> {
        if self.worker.is_none() {
            let (jobs, inbox) = channel::<Job>();
            let (library, budget, cache_dir) = (self.library.clone(), self.budget, self.cache_dir.clone());
            let (generation, results) = (Arc::clone(&self.generation), self.tx.clone());
            std::thread::Builder::new()
                .name("artifact-thumbnails".into())
                .spawn(move || {
                    crate::background::lower_current_thread_priority();
                    while let Ok(job) = inbox.recv() {
                        if job.generation != generation.load(Ordering::Relaxed) {
                            continue;
                        }
                        let made = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                            crate::background::in_background_pool(|| {
                                make(&library, budget, cache_dir.as_deref(), &job.entry)
                            })
                        }))
                        .unwrap_or_else(|_| Made::Failed(job.entry.id.to_string()));
                        if results.send(made).is_err() {
                            return;
                        }
                    }
                })
                .map_err(drop)?;
            self.worker = Some(jobs);
        }
        self.worker.as_ref().ok_or(())?.send(job).map_err(drop)
    }

    /// Drops the requests not started yet (the menu closed); they are asked for again next time.
    pub fn cancel_pending(&mut self) {
        self.generation.fetch_add(1, Ordering::Relaxed);
        let (ready, failed) = (&self.ready, &self.failed);
        // Failed ones stay asked (not retried); pending ones are forgotten.
        self.asked.retain(|id| ready.contains_key(id) || failed.contains(id));
    }

    /// How many asked for are neither made nor failed yet.
    pub fn pending(&self) -> usize {
        self.asked
            .iter()
            .filter(|id| !self.ready.contains_key(*id) && !self.failed.contains(*id))
            .count()
    }

    /// Takes what the worker finished: cached thumbnails as they are, and at most one posed
    /// model, drawn by `draw` (e.g. [`render`]) and written to the cache — one a frame keeps the
    /// menu responsive. Returns the ids of the thumbnails new since the last call.
    pub fn poll(&mut self, mut draw: impl FnMut(&Posed) -> Option<Vec<u8>>) -> Vec<String> {
        let mut new = Vec::new();
        let mut drawn = false;
        while !drawn && let Ok(made) = self.rx.try_recv() {
            let thumbnail = match made {
                Made::Cached(t) => t,
                Made::Posed { id, cache, posed } => {
                    drawn = true;
                    let Some(rgba) = draw(&posed).filter(|p| p.len() == (THUMBNAIL_PX * THUMBNAIL_PX * 4) as usize)
                    else {
                        self.failed.insert(id); // not tried again
                        continue;
                    };
                    if let Some(path) = cache {
                        // A cache that cannot be written only costs drawing it again next time.
                        let _ = write_png(&path, &rgba);
                    }
                    Thumbnail { id, rgba }
                }
                Made::Failed(id) => {
                    self.failed.insert(id); // not tried again
                    continue;
                }
            };
            new.push(thumbnail.id.clone());
            self.ready.insert(thumbnail.id.clone(), thumbnail);
        }
        new
    }
}

/// The worker's part for one artifact: the cached PNG, or the posed model.
fn make(library: &Library, budget: ResourceBudget, cache_dir: Option<&Path>, entry: &ArtifactEntry) -> Made {
    let id = entry.id.to_string();
    let cache = cache_dir.map(|d| d.join(format!("{:016x}.png", revision_hash(entry))));
    if let Some(rgba) = cache.as_deref().and_then(read_png) {
        return Made::Cached(Thumbnail { id, rgba });
    }
    if id == crate::diorama::DIORAMA_ID {
        // Made, not loaded: its tray with the bodies where they start.
        let screen = Screen::new(PanelSpec::TYPICAL_PHONE, DisplayRotation::Deg0);
        let scene = screen.ok().and_then(|s| crate::diorama::DioramaScene::new(&s).ok());
        return match scene.and_then(|s| pose(s.model().clone())) {
            Some(posed) => Made::Posed { id, cache, posed },
            None => Made::Failed(id),
        };
    }
    let progress = Progress::new();
    let loaded = match library.load_preview(&entry.id, budget, &progress) {
        Some(Ok(loaded)) => Ok(loaded),
        _ => library.load(&entry.id, budget, &progress),
    };
    let Ok(loaded) = loaded else {
        return Made::Failed(id);
    };
    let mut model = loaded.model;
    if !loaded.placed {
        // Turned upright as the phone shows it (the fit's scale does not matter here).
        let screen = Screen::new(PanelSpec::TYPICAL_PHONE, DisplayRotation::Deg0);
        if let Ok(screen) = screen {
            model.fit_to_diorama(&screen, &crate::model::DioramaFit::default());
        }
    }
    match pose(model) {
        Some(posed) => Made::Posed { id, cache, posed },
        None => Made::Failed(id),
    }
}

/// The artifact's id and its content's revision, hashed (FNV-1a): the cache file's name.
fn revision_hash(entry: &ArtifactEntry) -> u64 {
    let mut key = entry.id.to_string();
    match &entry.model_path {
        None => key.push_str(env!("CARGO_PKG_VERSION")),
        Some(path) => {
            // A Voyager folder changes with its scene file; a file with itself.
            let scene = path.join("scene.svx.json");
            let file = if path.is_dir() { scene.as_path() } else { path.as_path() };
            if let Ok(meta) = std::fs::metadata(file) {
                let modified = meta
                    .modified()
                    .ok()
                    .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
                    .map_or(0, |d| d.as_nanos());
                key.push_str(&format!("|{}|{modified}", meta.len()));
            }
        }
    }
    key.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// A cached thumbnail, if it is one of the right size.
fn read_png(path: &Path) -> Option<Vec<u8>> {
    let bytes = phantogram_files::read_regular_file(path, 1 << 20).ok()?;
    let image = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png).ok()?;
    let rgba = image.to_rgba8();
    (rgba.dimensions() == (THUMBNAIL_PX, THUMBNAIL_PX)).then(|| rgba.into_raw())
}

fn write_png(path: &Path, rgba: &[u8]) -> Result<(), Box<dyn std::error::Error>> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let png = crate::engine::encode_png(THUMBNAIL_PX, THUMBNAIL_PX, rgba)?;
    let mut file = phantogram_files::AtomicFile::create(path)?;
    std::io::Write::write_all(file.file(), &png)?;
    file.commit()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_posed_model_is_centred_scaled_and_seen_whole() {
        let lib = Library::new(None, None);
        let loaded = lib
            .load(
                &"builtin:amphora".parse().unwrap(),
                ResourceBudget::PHONE,
                &Progress::new(),
            )
            .unwrap();
        let posed = pose(loaded.model).unwrap();
        let b = posed.model.bounds().unwrap();
        let centre = (b.min + b.max) * 0.5;
        assert!(centre.length() < 1e-4, "centred: {centre}");
        let half = (b.max - b.min) * 0.5;
        assert!((half.x.max(half.y) - HALF_EXTENT_M).abs() < 1e-5, "{half}");
        // Every corner of the bounds projects inside the window, and the larger extent fills
        // most of it.
        let eye = view(posed.window_half_m).unwrap();
        let mut span = [f32::MAX, f32::MIN];
        for k in 0..8 {
            let corner = Vec3::new(
                if k & 1 == 0 { b.min.x } else { b.max.x },
                if k & 2 == 0 { b.min.y } else { b.max.y },
                if k & 4 == 0 { b.min.z } else { b.max.z },
            );
            let p = eye.project(corner).unwrap();
            assert!(p.ndc.x.abs() <= 1.0 && p.ndc.y.abs() <= 1.0, "{corner} → {:?}", p.ndc);
            span = [span[0].min(p.ndc.y), span[1].max(p.ndc.y)];
        }
        assert!(
            span[1] - span[0] > 1.4,
            "the amphora (taller than wide) fills the height: {span:?}"
        );
    }

    #[test]
    fn the_view_looks_down_from_the_lower_edge() {
        // Three cubes in the device frame: one on the glass, one above it (the artifact's top)
        // and one towards the screen's upper edge (away from the viewer).
        let mut mesh = crate::model::Mesh::default();
        for centre in [Vec3::ZERO, Vec3::new(0.0, 0.0, 0.05), Vec3::new(0.0, 0.05, 0.0)] {
            mesh.push_cube(centre, 0.005, [1.0; 4]);
        }
        let per_cube = mesh.vertices.len() / 3;
        let posed = pose(Model::from_painted_mesh("probe", mesh)).unwrap();
        let eye = view(posed.window_half_m).unwrap();
        let vertices = &posed.model.primitives[0].mesh.vertices;
        let seen: Vec<_> = vertices
            .chunks(per_cube)
            .map(|c| {
                let centre = c.iter().map(|v| Vec3::from_array(v.position)).sum::<Vec3>() / c.len() as f32;
                eye.project(centre).unwrap()
            })
            .collect();
        let [base, top, far] = [seen[0], seen[1], seen[2]];
        // Pixel y grows downwards: the top is drawn above the base, and so is the far cube
        // (seen from above); the far cube is farther from the eye (reverse-Z: smaller depth),
        // the top nearer (it leans towards the viewer).
        assert!(top.pixel.y < base.pixel.y && far.pixel.y < base.pixel.y, "{seen:?}");
        assert!(far.depth < base.depth && top.depth > base.depth, "{seen:?}");
    }

    #[test]
    fn the_cache_name_changes_with_the_file() {
        let dir = phantogram_testkit::Scratch::new("thumb-revision");
        let path = dir.join("a.glb");
        std::fs::write(&path, b"one").unwrap();
        let entry = |p: &Path| ArtifactEntry {
            id: "bundled:a.glb".parse().unwrap(),
            title: "A".into(),
            credit: None,
            licence: None,
            model_path: Some(p.to_path_buf()),
        };
        let first = revision_hash(&entry(&path));
        assert_eq!(first, revision_hash(&entry(&path)));
        std::fs::write(&path, b"longer").unwrap();
        assert_ne!(first, revision_hash(&entry(&path)), "a replaced file is drawn again");
    }
}
