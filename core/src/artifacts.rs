//! Changing the artifact on screen while the engine runs: the [`crate::library`] on a worker
//! thread, with progress and cancel, and the result handed to the render thread.
//!
//! * One load at a time, on one long-lived thread: a new request cancels the one under way (its
//!   result, if it still comes, is dropped by its generation number).
//! * The artifact on screen stays until the new one is ready: the worker loads, fits and floors
//!   the model (CPU work) into a [`Prepared`]; the render thread only uploads it.
//! * An artifact with a lighter scan (a Voyager folder's "Thumb" beside its best scan) is shown
//!   in it first, marked [`ModelInfo::preview`], while its best scan loads: a museum download's
//!   full scan takes seconds to decode on a phone. If the best scan then fails, the preview stays
//!   on screen with the failure's message.
//! * A failure (a damaged file, an unknown id, over the budget) becomes
//!   [`LoadStatus::Failed`] with a message for the screen; a cancelled load becomes
//!   [`LoadStatus::Idle`] again, not an error.
//!
//! **Threading**: a [`Loader`] lives on the render thread (inside the engine's mutex); the loads
//! run on its thread `artifact-loader` (started with the first), sharing only the request, an
//! `Arc<Progress>` and channels; a file given as a reader is read first on a short-lived
//! `artifact-reader` thread. **Panics**: a panic inside a load (a bug) is caught on its
//! thread and reported as that load's failure.

use std::sync::Arc;
use std::sync::mpsc::{Receiver, Sender, channel};
use std::time::Duration;

use crate::budget::ResourceBudget;
use crate::containment::Aabb;
use crate::library::{ArtifactEntry, ArtifactId, Library, LibraryError, LoadedArtifact};
use crate::model::{DioramaFit, Model};
use crate::progress::Progress;
use crate::screen::Screen;

/// What was loaded, for the gallery, logs and the desktop tools.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelInfo {
    /// The model's name (a loaded file's stem: it tells which scan a Voyager folder gave).
    pub name: String,
    pub triangles: usize,
    pub materials: usize,
    pub images: usize,
    /// What the loader could not honour but worked around (an unsupported extension, …).
    pub warnings: Vec<String>,
    /// The library's entry (title, credit, licence); `None` for a file given by path.
    pub artifact: Option<ArtifactEntry>,
    /// The publisher's points of interest, in the device frame (fitted with the model); each is
    /// drawn as a marker ([`Model::add_annotation_pins`]) and read by tapping it.
    pub annotations: Vec<crate::model::Annotation>,
    /// A lighter scan shown while the artifact's best scan loads (see the module docs).
    pub preview: bool,
}

impl ModelInfo {
    /// What `model` is, as the library's `entry` (not a preview).
    pub fn of(model: &Model, entry: Option<ArtifactEntry>) -> Self {
        Self {
            name: model.name.clone(),
            triangles: model.triangle_count(),
            materials: model.materials.len(),
            images: model.images.len(),
            warnings: model.warnings.clone(),
            artifact: entry,
            annotations: model.annotations.clone(),
            preview: false,
        }
    }
}

/// The folder, inside the library's storage, where big scans' parts and levels are kept.
pub const DETAIL_CACHE_DIR: &str = "detail-cache";

/// A model ready to upload: fitted into the diorama, floored, its bounds known.
#[derive(Debug)]
pub struct Prepared {
    pub model: Model,
    /// The artifact's bounds without the floor (what containment keeps in the front frustum).
    pub bounds: Aabb,
    pub info: ModelInfo,
    /// A big scan's per-frame choice of levels (`None`: drawn whole), and what the viewer will
    /// have seen of it: both summarise every triangle, so they are made here, off the render
    /// thread.
    pub detail: Option<phantogram_detail::Detail>,
    pub seen: phantogram_detail::seen::SeenSides,
}

/// How the worker places what it loads (the engine's settings when the load starts).
#[derive(Clone, Copy, Debug)]
pub struct Placing {
    pub screen: Screen,
    pub fit: DioramaFit,
    pub floor: bool,
    /// The artifact's memory budget (`ResourceBudget::memory_bytes`): a big scan's levels of
    /// detail are made only where they fit in it beside the model.
    pub memory_bytes: u64,
}

/// Fits (unless the artifact comes placed), measures and floors a loaded model, and gives a big
/// scan its parts and levels of detail (`progress` goes from where it is to 0.95 meanwhile),
/// kept in and taken from `detail_cache` when given ([`phantogram_detail::cache`]).
pub fn prepare(
    mut model: Model,
    entry: Option<ArtifactEntry>,
    placed: bool,
    placing: &Placing,
    progress: &Progress,
    detail_cache: Option<&std::path::Path>,
) -> Result<Prepared, crate::render::RenderError> {
    if !placed {
        model.fit_to_diorama(&placing.screen, &placing.fit);
    } else if placing.fit.placement == crate::model::Placement::Surface
        && let Some(b) = model.bounds()
    {
        // Built-ins come placed at their true size: in surface mode their front goes to the
        // glass.
        model.transform(glam::Mat4::from_translation(glam::Vec3::Z * -b.max.z));
    }
    let bounds = model.bounds().ok_or(crate::render::RenderError::EmptyModel)?;
    let mut info = ModelInfo::of(&model, entry);
    // A big scan: parts with levels of detail, made here on the loader thread (seconds for
    // millions of triangles), in the diorama's frame so that their errors are in its metres.
    // The coarser levels' indices (about a third more) and the vertices the parts share at
    // their borders count against the artifact's memory budget: a scan that fits only whole
    // is drawn whole (slower, the same picture), with a warning.
    let span = crate::progress::Span::new(progress, progress.fraction(), 0.95);
    let whole_bytes = crate::budget::model_bytes(&model);
    let report = phantogram_detail::prepare_cached(
        &mut model,
        &phantogram_detail::DetailParams::default(),
        detail_cache,
        |f| span.advance(f),
    );
    let with_levels_bytes = crate::budget::model_bytes(&model);
    if report.parts > 0 && with_levels_bytes > placing.memory_bytes.max(whole_bytes) {
        for p in &mut model.primitives {
            p.lods.clear();
        }
        let mib = |b: u64| b as f64 / f64::from(1u32 << 20);
        let warning = format!(
            "levels of detail left out: with them the scan would take {:.0} MiB, over the budget of {:.0} MiB; it is drawn whole",
            mib(with_levels_bytes),
            mib(placing.memory_bytes)
        );
        model.warnings.push(warning.clone());
        info.warnings.push(warning);
    }
    if placing.floor {
        model.add_floor(&placing.screen, Model::FLOOR_REACH);
    }
    model.add_annotation_pins();
    let detail = phantogram_detail::Detail::new(&model, crate::engine::DEFAULT_FRAME_TARGET_S);
    let seen = phantogram_detail::seen::SeenSides::new(&model);
    Ok(Prepared {
        model,
        bounds,
        info,
        detail,
        seen,
    })
}

/// What the shells show about loading.
#[derive(Clone, Debug, PartialEq)]
pub enum LoadStatus {
    /// Nothing under way, nothing to report.
    Idle,
    /// Loading `title` (or the file's name while importing): `fraction` 0 to 1.
    Loading { title: String, fraction: f32 },
    /// The last load failed; the previous artifact is still on screen.
    Failed { title: String, message: String },
}

/// What to load.
#[derive(Debug)]
pub enum Request {
    /// An artifact of the library.
    Select(ArtifactId),
    /// A file the user opened: its display name and content, imported into the library.
    Import { name: String, source: FileSource },
}

/// The content of an opened file.
pub enum FileSource {
    Bytes(Vec<u8>),
    /// Read on a thread of its own, at most the budget's memory: an Android `content://`
    /// document's descriptor, read without passing through the Java heap. **Important:** a
    /// source that blocks forever (a stalled pipe) holds that reader thread until the process
    /// ends; the loads that follow are not held up.
    Reader(Box<dyn std::io::Read + Send>),
}

impl std::fmt::Debug for FileSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Bytes(b) => write!(f, "Bytes({} bytes)", b.len()),
            Self::Reader(_) => f.write_str("Reader"),
        }
    }
}

impl FileSource {
    /// The content, at most `max_bytes` (more is [`LibraryError::TooLarge`]).
    fn into_bytes(self, name: &str, max_bytes: u64) -> Result<Vec<u8>, LoadError> {
        let too_large = || {
            LoadError::Library(LibraryError::TooLarge {
                name: phantogram_files::text::excerpt(name),
                max_bytes,
            })
        };
        match self {
            Self::Bytes(b) if b.len() as u64 > max_bytes => Err(too_large()),
            Self::Bytes(b) => Ok(b),
            Self::Reader(r) => {
                use std::io::Read;
                let mut bytes = Vec::new();
                r.take(max_bytes.saturating_add(1))
                    .read_to_end(&mut bytes)
                    .map_err(|error| LoadError::Read {
                        name: phantogram_files::text::excerpt(name),
                        error,
                    })?;
                if bytes.len() as u64 > max_bytes {
                    return Err(too_large());
                }
                Ok(bytes)
            }
        }
    }
}

/// A load's result, by its request's generation. A preview ([`Library::load_preview`]) comes
/// before the final result of the same request, never instead of it.
struct Outcome {
    generation: u64,
    preview: bool,
    result: Result<Prepared, String>,
}

/// A load for the loader thread.
struct Work {
    generation: u64,
    request: Request,
    placing: Placing,
    progress: Arc<Progress>,
}

/// The loader thread: one load at a time, the newest request first (older ones waiting were
/// superseded), each result tagged with its request's generation. One long-lived thread keeps
/// each switch's allocations in one place (a thread per load left the allocator's per-thread
/// arenas holding freed models: resident memory crept up over many switches). Ends when the
/// loader is dropped.
fn load_loop(jobs: Receiver<Work>, library: Library, budget: ResourceBudget, results: Sender<Outcome>) {
    crate::background::lower_current_thread_priority();
    while let Ok(mut work) = jobs.recv() {
        while let Ok(newer) = jobs.try_recv() {
            work = newer;
        }
        if work.progress.is_cancelled() {
            continue;
        }
        let Work {
            generation,
            request,
            placing,
            progress,
        } = work;
        // A lighter scan first, when the artifact has one: the visitor sees the artifact within
        // a fraction of the full load and watches it sharpen. Its own progress, so the bar
        // tracks the full load; a cancel is seen when the preview is done (a fraction of a
        // second), and a preview that fails just is not shown.
        if let Request::Select(id) = &request {
            let preview = || {
                let loaded = library.load_preview(id, budget, &Progress::new())?.ok()?;
                let mut prepared = prepare(
                    loaded.model,
                    Some(loaded.entry),
                    loaded.placed,
                    &placing,
                    &Progress::new(),
                    None,
                )
                .ok()?;
                prepared.info.preview = true;
                Some(prepared)
            };
            if let Ok(Some(prepared)) = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                crate::background::in_background_pool(preview)
            })) {
                if progress.is_cancelled() {
                    continue;
                }
                let outcome = Outcome {
                    generation,
                    preview: true,
                    result: Ok(prepared),
                };
                if results.send(outcome).is_err() {
                    return;
                }
            }
        }
        let run = || -> Result<Prepared, LoadError> {
            let loaded: LoadedArtifact = match request {
                Request::Select(id) => library.load(&id, budget, &progress)?,
                Request::Import { name, source } => {
                    let bytes = source.into_bytes(&name, budget.memory_bytes)?;
                    library.import(&name, &bytes, budget, &progress)?
                }
            };
            if progress.is_cancelled() {
                return Err(LoadError::Cancelled);
            }
            let cache = library.storage().map(|d| d.join(DETAIL_CACHE_DIR));
            let prepared = prepare(
                loaded.model,
                Some(loaded.entry),
                loaded.placed,
                &placing,
                &progress,
                cache.as_deref(),
            )?;
            progress.advance_to(0.95);
            Ok(prepared)
        };
        let result = match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            crate::background::in_background_pool(run)
        })) {
            Ok(Ok(p)) => Ok(p),
            Ok(Err(e)) if e.is_cancelled() => continue,
            Ok(Err(e)) => Err(e.to_string()),
            Err(_) => Err("the loader failed unexpectedly (a bug); the artifact stays as it was".into()),
        };
        let outcome = Outcome {
            generation,
            preview: false,
            result,
        };
        // The engine may be gone: then nobody wants the result.
        if results.send(outcome).is_err() {
            return;
        }
    }
}

struct Job {
    generation: u64,
    title: String,
    progress: Arc<Progress>,
}

/// Loads artifacts off the render thread (see the module docs).
pub struct Loader {
    library: Library,
    budget: ResourceBudget,
    generation: u64,
    job: Option<Job>,
    failed: Option<(String, String)>,
    tx: Sender<Outcome>,
    rx: Receiver<Outcome>,
    /// The loader thread's queue, once started.
    worker: Option<Sender<Work>>,
}

impl std::fmt::Debug for Loader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Loader")
            .field("generation", &self.generation)
            .field("loading", &self.job.as_ref().map(|j| &j.title))
            .finish_non_exhaustive()
    }
}

impl Loader {
    pub fn new(library: Library, budget: ResourceBudget) -> Self {
        let (tx, rx) = channel();
        Self {
            library,
            budget,
            generation: 0,
            job: None,
            failed: None,
            tx,
            rx,
            worker: None,
        }
    }

    pub fn library(&self) -> &Library {
        &self.library
    }

    /// What one artifact may take.
    pub fn budget(&self) -> ResourceBudget {
        self.budget
    }

    /// Loads synchronously, on the calling thread (the engine's first artifact).
    pub fn load_now(&self, id: &ArtifactId, placing: &Placing) -> Result<Prepared, LoadError> {
        let loaded = self.library.load(id, self.budget, &Progress::new())?;
        let cache = self.library.storage().map(|d| d.join(DETAIL_CACHE_DIR));
        Ok(prepare(
            loaded.model,
            Some(loaded.entry),
            loaded.placed,
            placing,
            &Progress::new(),
            cache.as_deref(),
        )?)
    }

    /// Starts loading `request`, cancelling a load under way.
    pub fn start(&mut self, request: Request, placing: Placing) {
        self.cancel();
        self.failed = None;
        self.generation += 1;
        let generation = self.generation;
        let title = match &request {
            Request::Select(id) => self
                .library
                .entry(id)
                .map(|e| e.title)
                .unwrap_or_else(|_| id.to_string()),
            Request::Import { name, .. } => display_name(name),
        };
        let progress = Arc::new(Progress::new());
        let work = Work {
            generation,
            request,
            placing,
            progress: Arc::clone(&progress),
        };
        match self.queue(work) {
            Ok(()) => {
                self.job = Some(Job {
                    generation,
                    title,
                    progress,
                })
            }
            Err(e) => self.failed = Some((title, format!("could not start loading: {e}"))),
        }
    }

    /// Hands `work` to the loader thread (started with the first load). A file to be read from
    /// a reader is read on a short-lived thread of its own first, so that a stalled source holds
    /// only that thread, never the loads that follow.
    fn queue(&mut self, work: Work) -> std::io::Result<()> {
        if self.worker.is_none() {
            let (tx, rx) = channel::<Work>();
            let (library, budget, results) = (self.library.clone(), self.budget, self.tx.clone());
            std::thread::Builder::new()
                .name("artifact-loader".into())
                .spawn(move || load_loop(rx, library, budget, results))?;
            self.worker = Some(tx);
        }
        let Some(worker) = self.worker.clone() else {
            return Ok(());
        };
        match work.request {
            Request::Import {
                name,
                source: FileSource::Reader(reader),
            } => {
                let (max_bytes, results) = (self.budget.memory_bytes, self.tx.clone());
                let (generation, placing, progress) = (work.generation, work.placing, work.progress);
                std::thread::Builder::new()
                    .name("artifact-reader".into())
                    .spawn(move || match FileSource::Reader(reader).into_bytes(&name, max_bytes) {
                        Ok(bytes) => {
                            let request = Request::Import {
                                name,
                                source: FileSource::Bytes(bytes),
                            };
                            let _ = worker.send(Work {
                                generation,
                                request,
                                placing,
                                progress,
                            });
                        }
                        Err(e) => {
                            let _ = results.send(Outcome {
                                generation,
                                preview: false,
                                result: Err(e.to_string()),
                            });
                        }
                    })?;
            }
            request => {
                let _ = worker.send(Work { request, ..work });
            }
        }
        Ok(())
    }

    /// Gives up the load under way, if any; the artifact on screen stays.
    pub fn cancel(&mut self) {
        if let Some(job) = self.job.take() {
            job.progress.cancel();
        }
    }

    /// Forgets a failure once the user has read it.
    pub fn dismiss(&mut self) {
        self.failed = None;
    }

    /// The newest finished load of the current request, if one finished: `Some` to upload (a
    /// preview, after which the load goes on, or its final result), `None` if nothing new or
    /// it failed (the failure is kept for [`Self::status`]).
    pub fn poll(&mut self) -> Option<Prepared> {
        self.take(None, true)
    }

    /// Waits up to `timeout` for the final result of the load under way (a preview that comes
    /// meanwhile is dropped): as [`Self::poll`] otherwise.
    pub fn wait(&mut self, timeout: Duration) -> Option<Prepared> {
        self.take(Some(timeout), false)
    }

    fn take(&mut self, timeout: Option<Duration>, previews: bool) -> Option<Prepared> {
        let deadline = timeout.map(|t| std::time::Instant::now() + t);
        loop {
            let received = match deadline {
                Some(d) if self.job.is_some() => self
                    .rx
                    .recv_timeout(d.saturating_duration_since(std::time::Instant::now()))
                    .ok(),
                _ => self.rx.try_recv().ok(),
            };
            let outcome = received?;
            let Some(job) = self.job.as_ref().filter(|j| j.generation == outcome.generation) else {
                continue; // a superseded or cancelled load's result
            };
            if outcome.preview {
                match outcome.result {
                    Ok(p) if previews => return Some(p),
                    _ => continue,
                }
            }
            let title = job.title.clone();
            self.job = None;
            return match outcome.result {
                Ok(p) => Some(p),
                Err(message) => {
                    self.failed = Some((title, message));
                    None
                }
            };
        }
    }

    /// Records a failure found after the worker (uploading the model).
    pub fn fail(&mut self, title: String, message: String) {
        self.failed = Some((title, message));
    }

    pub fn status(&self) -> LoadStatus {
        if let Some(job) = &self.job {
            return LoadStatus::Loading {
                title: job.title.clone(),
                fraction: job.progress.fraction(),
            };
        }
        match &self.failed {
            Some((title, message)) => LoadStatus::Failed {
                title: title.clone(),
                message: message.clone(),
            },
            None => LoadStatus::Idle,
        }
    }
}

/// A file name as a title on screen: control characters dropped, at most 80 characters.
fn display_name(name: &str) -> String {
    let clean: String = name.chars().filter(|c| !c.is_control()).collect();
    if clean.chars().count() <= 80 && clean.trim().is_empty() {
        "a file".to_owned()
    } else {
        phantogram_files::text::truncate_chars(&clean, 80)
    }
}

/// Why a load failed.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    #[error(transparent)]
    Library(#[from] LibraryError),
    #[error(transparent)]
    Render(#[from] crate::render::RenderError),
    #[error("cancelled")]
    Cancelled,
    #[error("{name}: {error}")]
    Read { name: String, error: std::io::Error },
}

impl LoadError {
    fn is_cancelled(&self) -> bool {
        match self {
            Self::Cancelled => true,
            Self::Library(e) => e.is_cancelled(),
            Self::Render(_) | Self::Read { .. } => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn surface_mode_puts_a_built_ins_front_in_the_glass() {
        let screen = Screen::default();
        let placing = |placement| Placing {
            screen,
            fit: DioramaFit {
                placement,
                ..DioramaFit::default()
            },
            floor: true,
            memory_bytes: crate::budget::ResourceBudget::PHONE.memory_bytes,
        };
        let medal = || (crate::builtin::built_in("medal").expect("medal").make)();
        let placed = prepare(
            medal(),
            None,
            true,
            &placing(crate::model::Placement::Auto),
            &Progress::new(),
            None,
        )
        .expect("prepared");
        assert!(
            placed.bounds.max.z > 1e-4,
            "as made, it stands a little out of the glass"
        );
        let surface = prepare(
            medal(),
            None,
            true,
            &placing(crate::model::Placement::Surface),
            &Progress::new(),
            None,
        )
        .expect("prepared");
        assert!(
            surface.bounds.max.z.abs() < 1e-6,
            "front in the glass: {:?}",
            surface.bounds
        );
        let size = |b: &Aabb| b.max - b.min;
        assert!(
            size(&surface.bounds).distance(size(&placed.bounds)) < 1e-6,
            "true size kept"
        );
    }
}
