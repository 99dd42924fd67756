//! `phantogram`: the desktop command-line tool.
//!
//! * `phantogram replay LOG` replays a sensor log (the project's format, or any export that
//!   [`phantogram_lab::sensorlog::import`] recognises) and prints, at a chosen interval of sensor time,
//!   the cyclopean eye position (mm, device frame) and the direction towards the world-fixed light.
//! * `phantogram import SRC --out FILE` converts an export into the project's log format.
//! * `phantogram info LOG` summarises a log: duration, events and rate per sensor.
//! * `phantogram eval orientation PATH…` scores the orientation estimators on recordings;
//!   `phantogram eval face IMAGE… [--json]` finds faces, eye centres and distances in images.

use std::io::{BufWriter, Write};
use std::path::PathBuf;

mod check_artifacts;
mod face_eval;
mod output;
mod render_frames;
mod room_capture;
mod scene;
mod viewer;

use output::outln;
use scene::SceneArgs;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use phantogram::attitude::{LowPassAttitude, OrientationEstimator};
use phantogram::clock::elapsed_s;
use phantogram::eyes::EyeModel;
use phantogram::sensors::{SensorEvent, SensorKind};
use phantogram::session::EstimatorChoice;
use phantogram::{Session, SessionConfig};
use phantogram_lab::replay::{Pace, replay};
use phantogram_lab::sensorlog::{self, LogError, LogReader, import::SourceFormat};

#[derive(Parser)]
#[command(
    name = "phantogram",
    version,
    about = "Handheld phantogram tools: replay and convert sensor logs"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Replay a sensor log and print the eye position and light direction over time.
    Replay {
        /// A phantogram log, a BROAD CSV, or a recording folder (Android raw, Sensor Logger, phyphox).
        log: PathBuf,
        /// Interval between printed rows, milliseconds of sensor time (at least 1).
        #[arg(long, default_value_t = 100.0, value_parser = interval_ms)]
        every_ms: f64,
        /// Print comma-separated values instead of a table.
        #[arg(long)]
        csv: bool,
        /// Pace the replay at the recording's speed (times this factor) instead of as fast as possible.
        #[arg(long, value_name = "SPEED")]
        realtime: Option<f64>,
        /// Use the paper's low-pass viewpoint with this time constant, seconds (the paper's c = 0.1
        /// at 100 Hz is 0.095 s) instead of the fused estimator; with `--estimator low-pass`, its
        /// time constant (0.095 s when omitted).
        #[arg(long, value_name = "SECONDS", value_parser = time_constant_s)]
        tau_s: Option<f32>,
        /// Viewing distance, centimetres.
        // Rounded to 0.1 mm so that the help shows "30", not f32's "30.000002".
        #[arg(long, default_value_t = (EyeModel::DEFAULT_VIEWING_DISTANCE_M * 1000.0).round() / 10.0)]
        distance_cm: f32,
        /// Make the pose at this many seconds into the log count as "straight on" (flat-angle calibration).
        #[arg(long, value_name = "SECONDS", value_parser = seconds_into_log)]
        flat_at_s: Option<f64>,
        /// Instead of the eye/light table, print the orientation (device → world quaternion
        /// w x y z) after each input sample time, as estimated by NAME.
        #[arg(long, value_name = "NAME", conflicts_with_all = ["every_ms", "realtime", "distance_cm", "flat_at_s"])]
        estimator: Option<EstimatorName>,
    },
    /// Open a window showing the phantogram; drag to tilt the virtual phone, or replay a log.
    View {
        #[command(flatten)]
        scene: SceneArgs,
        /// Replay this sensor log in real time instead of tilting with the mouse.
        #[arg(long)]
        log: Option<PathBuf>,
        /// Anaglyph method (keys 1-8 switch while running).
        #[arg(long, default_value = "dubois")]
        anaglyph: phantogram::anaglyph::Method,
        /// Close after presenting this many frames.
        #[arg(long)]
        frames: Option<u64>,
        /// Exercise suspend, resume and resize while running (a self-test of the surface lifecycle).
        #[arg(long)]
        lifecycle_test: bool,
        /// Open the calibration screens at start (also key `c`): eye distance by the mirror,
        /// viewing distance by the blind spot, screen size by a bank card, flat angle, light.
        #[arg(long)]
        calibration: bool,
        /// Open the artifacts menu at start (also key `a`, or a click).
        #[arg(long, conflicts_with = "calibration")]
        menu: bool,
        /// With --frames: once they are presented, print "ready" and keep the window showing
        /// the last frame this many seconds before closing (for a screenshot of the window).
        #[arg(long, requires = "frames", value_name = "SECONDS")]
        linger_s: Option<f32>,
    },
    /// Render a sensor log as phantogram frames (PNG), headless.
    Render {
        #[command(flatten)]
        scene: SceneArgs,
        /// The sensor log to replay (any format `replay` accepts).
        #[arg(long)]
        log: PathBuf,
        /// Folder for the frames (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Frame size in pixels, WxH, with the screen's aspect ratio (1080:2400 for the default phone).
        #[arg(long, default_value = "540x1200")]
        size: String,
        /// Anaglyph method: dubois, dubois-green-magenta, dubois-amber-blue, half-color, optimized, gray, color, mono.
        #[arg(long, default_value = "dubois")]
        anaglyph: phantogram::anaglyph::Method,
        /// Write the stereo pair side by side instead (left eye's image on the left, each of
        /// --size: frames twice as wide), for parallel viewing and stereo tools.
        #[arg(long, conflicts_with = "anaglyph")]
        side_by_side: bool,
        /// Interval between frames, milliseconds of sensor time (at least 1).
        #[arg(long, default_value_t = 100.0, value_parser = interval_ms)]
        every: f64,
        /// Make the pose at this many seconds into the log count as "straight on".
        #[arg(long, value_name = "SECONDS", value_parser = seconds_into_log)]
        flat_at_s: Option<f64>,
    },
    /// Convert a recording into the phantogram log format (gzip when OUT ends in .gz).
    Import {
        src: PathBuf,
        #[arg(long)]
        out: PathBuf,
    },
    /// Summarise a log: duration, events and rate per sensor.
    Info { log: PathBuf },
    /// Load every artifact in a folder (.glb/.gltf/.stl/.ply/.obj files, Voyager folders) as a phone will, as
    /// `cargo xtask android|ios --artifacts FOLDER` does before bundling them.
    CheckArtifacts { folder: PathBuf },
    /// Score estimators against recorded ground truth.
    Eval {
        #[command(subcommand)]
        what: EvalWhat,
    },
}

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum EstimatorName {
    /// The paper's low-pass (time constant from --tau-s).
    LowPass,
    /// Gyroscope + accelerometer + magnetometer fusion.
    Fused,
    /// The platform's own rotation vector, where the log has one.
    RotationVector,
}

#[derive(Subcommand)]
enum EvalWhat {
    /// Inclination/heading/total RMSE (BROAD's definitions) per trial and estimator, and means.
    Orientation {
        /// BROAD CSVs, phone recording folders, or folders containing them.
        #[arg(required = true)]
        paths: Vec<PathBuf>,
        /// Score only these of our estimators (repeatable; all when omitted).
        #[arg(long = "estimator", value_enum)]
        estimators: Vec<EstimatorName>,
        /// Also score another program's orientation tracks: NAME=DIR, with DIR/TRIAL.csv (TRIAL:
        /// the recording's name) holding `t_ns,w,x,y,z` rows (what
        /// `benchmarks/vqf/vqf_reference.py` writes). Repeatable.
        #[arg(long = "reference", value_name = "NAME=DIR", value_parser = reference_arg)]
        references: Vec<(String, PathBuf)>,
    },
    /// Faces in images: each face's two eye centres (pixels, left/right as seen in the image)
    /// and its distance from the iris size, assuming a field of view.
    Face {
        #[arg(required = true)]
        images: Vec<PathBuf>,
        /// One JSON object per image: {"image", "faces": [{"left_eye", "right_eye",
        /// "distance_mm", "confidence"}]}.
        #[arg(long)]
        json: bool,
        /// The camera's horizontal field of view, degrees (images carry no intrinsics), more
        /// than 1 and less than 179.
        #[arg(long, default_value_t = 60.0, value_parser = field_of_view_deg)]
        hfov_deg: f32,
        /// Folder with the ONNX models (default: where `cargo xtask models` puts them).
        #[arg(long)]
        models: Option<PathBuf>,
    },
}

fn main() {
    // Parsed first: on bad arguments clap exits the process, which would leave the folder behind.
    let cli = Cli::parse();
    let runtime_dir = ensure_runtime_dir();
    let result = run(cli);
    if let Some(dir) = runtime_dir {
        let _ = std::fs::remove_dir_all(dir);
    }
    // Output cut short by a closed pipe is not a failure (see `output`).
    let result = result.and_then(|()| output::flush().map_err(anyhow::Error::from));
    if let Err(e) = result
        && !output::is_broken_pipe(&e)
    {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

/// Without `XDG_RUNTIME_DIR` (containers, CI, ssh sessions) the Vulkan loader's window-system
/// probe prints "error: XDG_RUNTIME_DIR is invalid or not set", which reads like a failure of
/// ours. Point it at a private folder of our own instead; returns it, for removal at exit.
fn ensure_runtime_dir() -> Option<PathBuf> {
    if std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_dir()) {
        return None;
    }
    let dir = std::env::temp_dir().join(format!("phantogram-runtime-{}", std::process::id()));
    #[cfg(unix)]
    let created = {
        use std::os::unix::fs::DirBuilderExt;
        std::fs::DirBuilder::new().mode(0o700).create(&dir).is_ok()
    };
    #[cfg(not(unix))]
    let created = false;
    if created {
        // SAFETY: called from `main` before any other thread exists (parsing the arguments
        // starts none), so nothing can read the environment concurrently.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
        return Some(dir);
    }
    None
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Replay {
            log,
            csv,
            tau_s,
            estimator: Some(name),
            ..
        } => orientation_command(&log, name, tau_s.unwrap_or(LowPassAttitude::DEFAULT_TAU_S), csv),
        Command::Replay {
            log,
            every_ms,
            csv,
            realtime,
            tau_s,
            distance_cm,
            flat_at_s,
            estimator: None,
        } => replay_command(&log, every_ms, csv, realtime, tau_s, distance_cm, flat_at_s),
        Command::Import { src, out } => {
            let imported = sensorlog::import::import(&src)?;
            sensorlog::write_log(&out, &imported.meta, &imported.events)?;
            eprintln!("wrote {} events to {}", imported.events.len(), out.display());
            Ok(())
        }
        Command::Info { log } => info_command(&log),
        Command::CheckArtifacts { folder } => check_artifacts::check_artifacts_command(&folder),
        Command::View {
            scene,
            log,
            anaglyph,
            frames,
            lifecycle_test,
            calibration,
            menu,
            linger_s,
        } => {
            let log = match log {
                Some(path) => Some(sensorlog::read_all(&path, open_events(&path)?)?),
                None => None,
            };
            // The calibration is the user's, kept where the desktop tools keep it. The window's
            // event loop is made with the engine, once its files are read.
            let mut event_loop = None;
            let mut engine = scene.engine(
                anaglyph,
                phantogram::calibration::Calibration::default_path(),
                true,
                Some(&mut event_loop),
            )?;
            let event_loop = event_loop.context("the engine opened no window display")?;
            // A device lost while the window is open is opened again for its display.
            let display = event_loop.owned_display_handle();
            engine.set_device_reopener(move || phantogram::render::Gpu::for_display(Box::new(display.clone()), None));
            viewer::run(
                event_loop,
                viewer::ViewerArgs {
                    engine,
                    log,
                    frames,
                    lifecycle_test,
                    calibration,
                    menu,
                    linger_s,
                },
            )
        }
        Command::Render {
            scene,
            log,
            out,
            size,
            anaglyph,
            side_by_side,
            every,
            flat_at_s,
        } => render_frames::render_command(render_frames::RenderArgs {
            scene: &scene,
            log: &log,
            out_dir: &out,
            size: &size,
            method: anaglyph,
            side_by_side,
            every_ms: every,
            flat_at_s,
        }),
        Command::Eval {
            what:
                EvalWhat::Orientation {
                    paths,
                    estimators,
                    references,
                },
        } => eval_orientation_command(&paths, &estimators, &references),
        Command::Eval {
            what:
                EvalWhat::Face {
                    images,
                    json,
                    hfov_deg,
                    models,
                },
        } => face_eval::eval_face_command(face_eval::EvalFaceArgs {
            images: &images,
            json,
            hfov_deg,
            models: models.as_deref(),
        }),
    }
}

/// Events from any source: streamed for the project's own format, imported whole otherwise.
fn open_events(path: &std::path::Path) -> Result<Box<dyn Iterator<Item = Result<SensorEvent, LogError>>>> {
    Ok(match sensorlog::import::detect(path)? {
        SourceFormat::Phantogram => Box::new(LogReader::open(path)?),
        _ => Box::new(sensorlog::import::import(path)?.events.into_iter().map(Ok)),
    })
}

fn replay_command(
    log: &std::path::Path,
    every_ms: f64,
    csv: bool,
    realtime: Option<f64>,
    tau_s: Option<f32>,
    distance_cm: f32,
    flat_at_s: Option<f64>,
) -> Result<()> {
    if let Some(speed) = realtime
        && !Pace::SPEEDS.contains(&speed)
    {
        bail!(
            "--realtime must be a speed factor from {} to {}, got {speed}",
            Pace::SPEEDS.start(),
            Pace::SPEEDS.end()
        );
    }
    let mut config = SessionConfig::default();
    if let Some(tau_s) = tau_s {
        config.estimator = EstimatorChoice::LowPass { tau_s };
    }
    config.eyes.viewing_distance_m = distance_cm / 100.0;
    let mut session = Session::new(config).context("invalid settings")?;
    let events = open_events(log)?;
    let pace = realtime.map_or(Pace::AsFastAsPossible, |speed| Pace::RealTime { speed });
    let interval_ns = (every_ms * 1e6).round() as i64;

    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    if csv {
        writeln!(out, "t_s,eye_x_mm,eye_y_mm,eye_z_mm,light_x,light_y,light_z")?;
    } else {
        writeln!(
            out,
            "{:>9} {:>9} {:>9} {:>9}   {:>7} {:>7} {:>7}",
            "t_s", "eye_x_mm", "eye_y_mm", "eye_z_mm", "light_x", "light_y", "light_z"
        )?;
    }
    let mut t0 = None;
    let mut flat_pending = flat_at_s;
    let mut flat_error = None;
    let mut write_error = None;
    let summary = replay(events, &mut session, interval_ns, pace, |session, t_ns, view| {
        let t0 = *t0.get_or_insert(t_ns);
        let t_s = elapsed_s(t0, t_ns);
        // Takes effect from the next frame, as a tap on the phone would.
        if flat_pending.is_some_and(|at| t_s >= at) {
            flat_pending = None;
            if let Err(e) = session.calibrate_flat_angle() {
                flat_error = Some(e);
            }
        }
        let e = view.eyes.cyclopean_m * 1000.0;
        let l = view.toward_light_device;
        let row = if csv {
            writeln!(
                out,
                "{t_s:.3},{:.2},{:.2},{:.2},{:.4},{:.4},{:.4}",
                e.x, e.y, e.z, l.x, l.y, l.z
            )
        } else {
            writeln!(
                out,
                "{t_s:>9.3} {:>9.2} {:>9.2} {:>9.2}   {:>7.4} {:>7.4} {:>7.4}",
                e.x, e.y, e.z, l.x, l.y, l.z
            )
        };
        if let Err(err) = row {
            write_error.get_or_insert(err);
        }
    })?;
    if let Some(e) = flat_error {
        bail!("flat-angle calibration failed: {e}");
    }
    if let Some(at) = flat_pending {
        bail!("--flat-at-s {at} is beyond the end of the log");
    }
    // A closed pipe ends quietly in `main`; any other write error is reported.
    if let Some(err) = write_error {
        return Err(err.into());
    }
    out.flush()?;
    let s = summary.stats;
    eprintln!(
        "{} events ({} accepted, {} rejected: {} non-finite, {} duplicate, {} backward and {} out-of-range time stamps), {} frames",
        summary.events_read,
        s.accepted,
        s.rejected(),
        s.rejected_non_finite,
        s.rejected_duplicate,
        s.rejected_backward,
        s.rejected_out_of_range,
        summary.frames
    );
    Ok(())
}

fn info_command(path: &std::path::Path) -> Result<()> {
    let mut counts = [0u64; SensorKind::ALL.len()];
    let mut span: [Option<(i64, i64)>; SensorKind::ALL.len()] = [None; SensorKind::ALL.len()];
    let mut non_finite = 0u64;
    for event in open_events(path)? {
        let e = event?;
        let i = e.kind.index();
        counts[i] += 1;
        non_finite += u64::from(!e.is_finite());
        span[i] = Some(span[i].map_or((e.t_ns, e.t_ns), |(a, b)| (a.min(e.t_ns), b.max(e.t_ns))));
    }
    outln!("{:<20} {:>9} {:>10} {:>9}", "sensor", "events", "duration_s", "rate_hz");
    for (i, kind) in SensorKind::ALL.iter().enumerate() {
        let Some((a, b)) = span[i] else { continue };
        let dur = elapsed_s(a, b);
        let rate = if dur > 0.0 { (counts[i] - 1) as f64 / dur } else { 0.0 };
        outln!(
            "{:<20} {:>9} {:>10.3} {:>9.1}",
            format!("{kind:?}"),
            counts[i],
            dur,
            rate
        );
    }
    if non_finite > 0 {
        outln!("{non_finite} events hold NaN or infinite values");
    }
    Ok(())
}

/// Recordings under `paths`: each path itself if it is one, else the recordings directly inside it.
fn expand_recordings(paths: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for p in paths {
        if sensorlog::import::detect(p).is_ok() {
            out.push(p.clone());
            continue;
        }
        if !p.is_dir() {
            // Not a folder: let detection explain what is wrong with it.
            sensorlog::import::detect(p)?;
        }
        let mut inside: Vec<PathBuf> = std::fs::read_dir(p)
            .with_context(|| format!("reading {}", p.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|c| sensorlog::import::detect(c).is_ok())
            .collect();
        if inside.is_empty() {
            bail!(
                "{}: no recordings found (expected BROAD CSVs or phone recording folders)",
                p.display()
            );
        }
        inside.sort();
        out.extend(inside);
    }
    Ok(out)
}

/// `--reference NAME=DIR`.
fn reference_arg(text: &str) -> Result<(String, PathBuf), String> {
    match text.split_once('=') {
        Some((name, dir)) if !name.trim().is_empty() && !dir.is_empty() => {
            Ok((name.trim().to_owned(), PathBuf::from(dir)))
        }
        _ => Err(format!("expected NAME=DIR, got {text:?}")),
    }
}

fn eval_orientation_command(
    paths: &[PathBuf],
    estimators: &[EstimatorName],
    references: &[(String, PathBuf)],
) -> Result<()> {
    use phantogram_lab::orientation_eval::{
        CONVERGENCE_S, RecordedTrack, Score, Selection, Trial, TruthFrame, score, score_selected,
    };
    let recordings = expand_recordings(paths)?;
    for (name, dir) in references {
        if !dir.is_dir() {
            bail!("--reference {name}: {} is not a folder", dir.display());
        }
    }
    let selection = if estimators.is_empty() {
        Selection::ALL
    } else {
        Selection {
            low_pass: estimators.iter().any(|e| matches!(e, EstimatorName::LowPass)),
            fused: estimators.iter().any(|e| matches!(e, EstimatorName::Fused)),
            platform: estimators.iter().any(|e| matches!(e, EstimatorName::RotationVector)),
        }
    };
    // "-" where there is nothing to score (no heading in the estimate, or no truth in that period).
    let fmt = |v: Option<f64>| {
        v.filter(|x| x.is_finite())
            .map_or("     -".to_owned(), |x| format!("{x:6.2}"))
    };
    // "-" for a replayed track, whose run time is not ours to measure.
    let fmt_ns = |ns: f64| {
        if ns.is_finite() {
            format!("{ns:7.0}")
        } else {
            "      -".to_owned()
        }
    };
    outln!(
        "{:<46} {:<28} {:>6} {:>6} {:>6} | {:>6} {:>6} | {:>7}",
        "trial",
        "estimator",
        "incl",
        "head",
        "total",
        "c.incl",
        "c.head",
        "ns/evt"
    );
    // Per estimator: sums for the means, of the trials where each figure exists.
    #[derive(Default)]
    struct Sums {
        trials: usize,
        incl: (usize, f64),
        head: (usize, f64),
        ns: f64,
    }
    let mut sums: Vec<(String, Sums)> = Vec::new();
    // A recording that cannot be read is reported and skipped: the others are still scored.
    let mut failures = 0;
    let mut missing_tracks = 0;
    for (i, path) in recordings.iter().enumerate() {
        eprintln!("[{}/{}] {}", i + 1, recordings.len(), path.display());
        let trial = match Trial::load(path) {
            Ok(trial) => trial,
            Err(e) => {
                eprintln!("error: {e}");
                failures += 1;
                continue;
            }
        };
        let mut scores = score_selected(&trial, selection);
        for (name, dir) in references {
            let path = dir.join(format!("{}.csv", trial.name));
            match RecordedTrack::load(&path) {
                // Replaying a track costs nothing worth reporting: its own run time is unknown.
                Ok(mut track) => scores.push(Score {
                    ns_per_event: f64::NAN,
                    ..score(&trial, name, &mut track)
                }),
                Err(e) => {
                    eprintln!("error: --reference {name}: {e}");
                    missing_tracks += 1;
                }
            }
        }
        for s in scores {
            outln!(
                "{:<46} {:<28} {:>6} {:>6} {:>6} | {:>6} {:>6} | {:>7}",
                trial.name,
                s.estimator,
                fmt(Some(s.main.inclination_deg)),
                fmt(s.main.heading_deg),
                fmt(s.main.total_deg),
                fmt(Some(s.convergence.inclination_deg)),
                fmt(s.convergence.heading_deg),
                fmt_ns(s.ns_per_event)
            );
            // "low-pass c=… (best)" rows are grouped as one estimator for the means.
            let key = if s.estimator.ends_with("(best)") {
                "low-pass best c".to_owned()
            } else {
                s.estimator.clone()
            };
            // By the folder the recording came from (imu/broad, imu/broad-extra, imu/phone keep
            // their figures apart), else by the kind of truth, not by what the estimator gave (a
            // headless one gives no heading).
            let group = path
                .parent()
                .and_then(|p| p.file_name())
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| match trial.truth_frame {
                    TruthFrame::EastNorthUp => "BROAD".to_owned(),
                    TruthFrame::ArbitraryHeading => "phone".to_owned(),
                });
            let key = format!("{group}: {key}");
            let entry = match sums.iter_mut().position(|e| e.0 == key) {
                Some(i) => &mut sums[i].1,
                None => {
                    sums.push((key, Sums::default()));
                    &mut sums.last_mut().expect("just pushed").1
                }
            };
            entry.trials += 1;
            entry.ns += s.ns_per_event;
            let add = |sum: &mut (usize, f64), value: Option<f64>| {
                if let Some(v) = value.filter(|v| v.is_finite()) {
                    *sum = (sum.0 + 1, sum.1 + v);
                }
            };
            add(&mut entry.incl, Some(s.main.inclination_deg));
            add(&mut entry.head, s.main.heading_deg);
        }
    }
    outln!();
    outln!("means over trials (main rows: after the first {CONVERGENCE_S} s, movement phases where marked):");
    outln!(
        "{:<46} {:>7} {:>6} {:>6} {:>7}",
        "estimator",
        "trials",
        "incl",
        "head",
        "ns/evt"
    );
    let mean = |(n, sum): (usize, f64)| (n > 0).then(|| sum / n as f64);
    for (key, s) in &sums {
        outln!(
            "{key:<46} {:>7} {:>6} {:>6} {:>7}",
            s.trials,
            fmt(mean(s.incl)),
            fmt(mean(s.head)),
            fmt_ns(s.ns / s.trials as f64)
        );
    }
    if failures > 0 {
        bail!("{failures} of {} recording(s) could not be scored", recordings.len());
    }
    if missing_tracks > 0 {
        bail!("{missing_tracks} reference track(s) could not be read");
    }
    Ok(())
}

fn orientation_command(log: &std::path::Path, name: EstimatorName, tau_s: f32, csv: bool) -> Result<()> {
    let events: Vec<SensorEvent> = sensorlog::read_all(log, open_events(log)?)?;
    if matches!(name, EstimatorName::RotationVector) && !events.iter().any(|e| e.kind == SensorKind::RotationVector) {
        bail!(
            "{}: the log has no rotation vector (the platform's own orientation) to print",
            log.display()
        );
    }
    let mut estimator: Box<dyn OrientationEstimator> = match name {
        EstimatorName::LowPass => Box::new(LowPassAttitude::new(tau_s, tau_s)),
        EstimatorName::Fused => Box::new(phantogram::fusion::FusedOrientation::default()),
        EstimatorName::RotationVector => Box::new(phantogram_lab::orientation_eval::PlatformRotationVector::default()),
    };
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    let sep = if csv { "," } else { " " };
    if csv {
        writeln!(out, "t_s,w,x,y,z")?;
    } else {
        writeln!(out, "{:>14} {:>10} {:>10} {:>10} {:>10}", "t_s", "w", "x", "y", "z")?;
    }
    let row = |out: &mut BufWriter<_>, t_ns: i64, est: &dyn OrientationEstimator| -> std::io::Result<()> {
        let t = t_ns as f64 * 1e-9;
        match est.device_to_world() {
            Some(q) if csv => writeln!(out, "{t:.6}{sep}{}{sep}{}{sep}{}{sep}{}", q.w, q.x, q.y, q.z),
            Some(q) => writeln!(out, "{t:>14.6} {:>10.6} {:>10.6} {:>10.6} {:>10.6}", q.w, q.x, q.y, q.z),
            None if csv => writeln!(out, "{t:.6}{sep}NaN{sep}NaN{sep}NaN{sep}NaN"),
            None => writeln!(out, "{t:>14.6} {:>10} {:>10} {:>10} {:>10}", "-", "-", "-", "-"),
        }
    };
    // One row per distinct input time stamp, after every event of that time (BROAD rows carry
    // three sensors at once). Ground truth is not an input.
    let mut pending_t: Option<i64> = None;
    for e in events {
        if e.kind == SensorKind::GroundTruth {
            continue;
        }
        if let Some(t) = pending_t.filter(|t| *t != e.t_ns)
            && let Err(err) = row(&mut out, t, estimator.as_ref())
        {
            return broken_pipe_is_fine(err);
        }
        estimator.push(&e);
        pending_t = Some(e.t_ns);
    }
    if let Some(t) = pending_t
        && let Err(err) = row(&mut out, t, estimator.as_ref())
    {
        return broken_pipe_is_fine(err);
    }
    out.flush().or_else(broken_pipe_is_fine)
}

/// Output cut short by a closed pipe (`| head`) is not an error.
fn broken_pipe_is_fine(err: std::io::Error) -> Result<()> {
    if err.kind() == std::io::ErrorKind::BrokenPipe {
        Ok(())
    } else {
        Err(err.into())
    }
}

/// `--every`, `--every-ms`: milliseconds of sensor time between frames, at least 1 (a finer
/// step only multiplies identical frames: no sensor here runs faster than 1 kHz).
fn interval_ms(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(ms) if ms.is_finite() && ms >= 1.0 => Ok(ms),
        _ => Err(format!("expected a number of milliseconds, at least 1, got {text:?}")),
    }
}

/// `--flat-at-s`: seconds from the start of the log.
fn seconds_into_log(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(s) if s.is_finite() && s >= 0.0 => Ok(s),
        _ => Err(format!(
            "expected a number of seconds from the start of the log, got {text:?}"
        )),
    }
}

/// `--hfov-deg`: a camera's horizontal field of view; 0° or 180° make no camera.
fn field_of_view_deg(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(deg) if deg.is_finite() && deg > 1.0 && deg < 179.0 => Ok(deg),
        _ => Err(format!(
            "expected a field of view in degrees, more than 1 and less than 179, got {text:?}"
        )),
    }
}

/// `--tau-s`: the low-pass time constant; 0 means no smoothing.
fn time_constant_s(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(s) if s.is_finite() && s >= 0.0 => Ok(s),
        _ => Err(format!("expected a time constant of 0 seconds or more, got {text:?}")),
    }
}
