//! `phantogram render`: a sensor log replayed through an [`Engine`] drawing offscreen, one PNG per
//! frame — the phones' frame pipeline (sensor inbox → orientation → eyes → containment →
//! stereo render → anaglyph), on the desktop.

use std::path::Path;

use anyhow::{Context, Result, bail};
use phantogram::anaglyph::Method;
use phantogram::clock::{elapsed_ns, elapsed_s};
use phantogram::engine::Engine;
use phantogram::sensors::{SensorEvent, SensorInbox};
use phantogram::surface::DrawOutcome;
use phantogram_lab::replay::{DriveError, Pace, Replayed, drive};

use crate::scene::SceneArgs;

pub struct RenderArgs<'a> {
    pub scene: &'a SceneArgs,
    pub log: &'a Path,
    pub out_dir: &'a Path,
    pub size: &'a str,
    pub method: Method,
    /// The stereo pair side by side instead of `method`'s composition.
    pub side_by_side: bool,
    pub every_ms: f64,
    pub flat_at_s: Option<f64>,
}

pub fn render_command(args: RenderArgs) -> Result<()> {
    let RenderArgs {
        scene,
        log,
        out_dir,
        size,
        method,
        side_by_side,
        every_ms,
        flat_at_s,
    } = args;
    // Side by side, the engine's own frame is only the containment's and gestures' clock: mono is
    // the cheapest to draw.
    let method = if side_by_side { Method::Mono } else { method };
    let (width, height) = parse_size(size)?;
    // The engine's screen (SceneArgs::engine keeps the default panel and rotation), known before
    // anything is loaded.
    let defaults = phantogram::engine::EngineConfig::default();
    let screen = phantogram::screen::Screen::new(defaults.panel, defaults.rotation)?;
    let aspect = width as f64 / height as f64;
    let screen_aspect = screen.width_m() as f64 / screen.height_m() as f64;
    if (aspect / screen_aspect - 1.0).abs() > 0.02 {
        bail!(
            "--size {width}x{height} does not match the screen's aspect ratio {}:{} (the image would be stretched)",
            screen.width_px(),
            screen.height_px()
        );
    }
    let events: Vec<SensorEvent> = phantogram_lab::sensorlog::read_all(log, crate::open_events(log)?)?;
    let (Some(first), Some(last)) = (events.first(), events.last()) else {
        bail!("{}: the log has no events", log.display());
    };
    let interval_ns = (every_ms * 1e6).round() as i64;
    if let Some(at) = flat_at_s.filter(|at| *at > elapsed_s(first.t_ns, last.t_ns)) {
        // Known now, before any frame is drawn.
        bail!("--flat-at-s {at} is beyond the end of the log");
    }
    // A progress bar's length only: gaps of more than a minute are skipped by the replay.
    let frames_expected = (elapsed_ns(first.t_ns, last.t_ns) / interval_ns)
        .saturating_add(1)
        .max(1) as u64;
    let t0 = first.t_ns;
    if out_dir.exists() && !out_dir.is_dir() {
        bail!("--out {}: exists and is not a folder", out_dir.display());
    }
    // The frames are the defaults' (no calibration file): reproducible on any machine.
    let mut engine = scene.engine(method, None, false, None)?;
    std::fs::create_dir_all(out_dir).with_context(|| format!("creating {}", out_dir.display()))?;
    // The frames go to a folder of their own inside `out_dir` and replace an earlier run's only
    // once all are written: a run that fails (a GPU error, a full disk) leaves the earlier frames
    // as they were, and never a truncated PNG among them.
    let staging = Staging::create(out_dir)?;
    engine.resume_offscreen(width, height)?;

    let bar = indicatif::ProgressBar::new(frames_expected);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} frames, {elapsed} elapsed, ETA {eta}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let mut frames = Frames {
        inbox: engine.inbox(),
        engine,
        out_dir: &staging.dir,
        index: 0,
        t0,
        flat_pending: flat_at_s,
        side_by_side,
        bar,
    };
    let replayed = drive(
        events.into_iter().map(Ok),
        &mut frames,
        interval_ns,
        Pace::AsFastAsPossible,
    );
    frames.bar.finish_and_clear();
    match replayed {
        Ok(_) => {}
        Err(DriveError::Frame(e)) => return Err(e),
        Err(e) => return Err(anyhow::anyhow!("{e}")),
    }
    if let Some(at) = frames.flat_pending {
        bail!("--flat-at-s {at} is beyond the end of the log");
    }
    let index = frames.index;
    staging.commit(out_dir)?;
    let what = if side_by_side {
        format!("{}x{height}, left and right eye side by side", width * 2)
    } else {
        format!("{width}x{height}, {method}")
    };
    eprintln!(
        "wrote {index} frame{} ({what}) to {}",
        if index == 1 { "" } else { "s" },
        out_dir.display()
    );
    Ok(())
}

/// The engine's side of the replay: events into its inbox, a PNG per frame.
struct Frames<'a> {
    engine: Engine,
    inbox: std::sync::Arc<SensorInbox>,
    out_dir: &'a Path,
    index: u64,
    t0: i64,
    flat_pending: Option<f64>,
    side_by_side: bool,
    bar: indicatif::ProgressBar,
}

impl Replayed for Frames<'_> {
    type Error = anyhow::Error;

    fn push(&mut self, event: SensorEvent) {
        // Rejected events are counted by the inbox; the replay goes on, as the app would.
        let _ = self.inbox.push(event);
    }

    fn frame(&mut self, t_ns: i64) -> Result<()> {
        if self.flat_pending.is_some_and(|at| elapsed_s(self.t0, t_ns) >= at) {
            self.flat_pending = None;
            self.engine
                .calibrate_flat_angle()
                .context("flat-angle calibration failed")?;
        }
        if let DrawOutcome::Skipped(why) = self.engine.draw(Some(t_ns))? {
            // Never an old frame under a new name.
            bail!("the frame at {:.3} s was not drawn ({why})", elapsed_s(self.t0, t_ns));
        }
        let pair;
        let (width, height, pixels) = if self.side_by_side {
            pair = self.engine.snapshot(phantogram::engine::Snapshot::SideBySide)?;
            (pair.0, pair.1, pair.2.as_slice())
        } else {
            self.engine.last_frame()?
        };
        let path = self.out_dir.join(frame_name(self.index));
        let png = phantogram::engine::encode_png(width, height, pixels).context("encoding a frame as PNG")?;
        // Written and flushed to the disk now: a full disk is an error here, and the swap in
        // `Staging::commit` only renames.
        std::fs::File::create(&path)
            .and_then(|mut f| {
                std::io::Write::write_all(&mut f, &png)?;
                f.sync_all()
            })
            .with_context(|| format!("writing {}", path.display()))?;
        self.index += 1;
        self.bar.inc(1);
        Ok(())
    }
}

fn parse_size(text: &str) -> Result<(u32, u32)> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .with_context(|| format!("--size {text:?}: expected WxH, e.g. 540x1200"))?;
    let parse = |v: &str| v.trim().parse::<u32>().ok().filter(|n| *n > 0);
    match (parse(w), parse(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => bail!("--size {text:?}: expected two positive whole numbers, WxH"),
    }
}

fn frame_name(index: u64) -> String {
    format!("frame_{index:05}.png")
}

/// Whether `name` is one `render` writes (`frame_NNNNN.png`).
fn is_frame(name: &str) -> bool {
    name.strip_prefix("frame_")
        .and_then(|rest| rest.strip_suffix(".png"))
        .is_some_and(|n| n.len() >= 5 && n.bytes().all(|b| b.is_ascii_digit()))
}

/// A run's frames while it renders: a hidden folder inside the output folder (the same file
/// system, so that [`Staging::commit`] only renames), removed with whatever is in it unless
/// committed.
struct Staging {
    dir: std::path::PathBuf,
}

impl Staging {
    fn create(out_dir: &Path) -> Result<Self> {
        let dir = out_dir.join(format!(".phantogram-render-{}", std::process::id()));
        // A folder of that name is a crashed run's of the same process id: nothing to keep.
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir(&dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(Self { dir })
    }

    /// Puts the new frames (each already on the disk) in place of an earlier run's.
    fn commit(&self, out_dir: &Path) -> Result<()> {
        remove_earlier_frames(out_dir)?;
        for entry in std::fs::read_dir(&self.dir).with_context(|| format!("reading {}", self.dir.display()))? {
            let entry = entry.with_context(|| format!("reading {}", self.dir.display()))?;
            let to = out_dir.join(entry.file_name());
            std::fs::rename(entry.path(), &to).with_context(|| format!("moving a frame to {}", to.display()))?;
        }
        Ok(())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Removes the frames (`frame_NNNNN.png`, the names `render` writes) of an earlier run from
/// `dir`: a shorter run would otherwise leave the old run's last frames after its own, and a
/// video made of the folder would end with them. Other files are left alone.
fn remove_earlier_frames(dir: &std::path::Path) -> Result<()> {
    let mut removed = 0;
    for entry in std::fs::read_dir(dir).with_context(|| format!("reading {}", dir.display()))? {
        let path = entry.with_context(|| format!("reading {}", dir.display()))?.path();
        if path.file_name().and_then(|n| n.to_str()).is_some_and(is_frame) {
            std::fs::remove_file(&path).with_context(|| format!("removing {}", path.display()))?;
            removed += 1;
        }
    }
    if removed > 0 {
        let s = if removed == 1 { "" } else { "s" };
        eprintln!("removed {removed} frame{s} of an earlier run from {}", dir.display());
    }
    Ok(())
}
