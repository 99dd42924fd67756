//! `--environment-from-camera LOG`: the live room light replayed on the desktop. A synthetic
//! front camera (`phantogram_lab::synthetic_camera`), with `--rear-camera` a rear one too,
//! follows the orientation fused from LOG,
//! looking into the `--environment` HDR as into a room, every other frame the short one of an
//! exposure bracket (exposures reported, as the phones' camera APIs report theirs); the frames go
//! into the engine's room light, which then lights the artifact instead of the HDR itself.

use std::path::Path;
use std::time::Duration;

use anyhow::{Context, Result, bail};
use phantogram::camera::CameraFacing;
use phantogram::engine::Engine;
use phantogram::ibl::Environment;
use phantogram::{Session, SessionConfig};
use phantogram_lab::replay::{Pace, replay};
use phantogram_lab::synthetic_camera::{Metering, SyntheticCamera};

/// Camera frames per second of the log (a phone's camera gives 30; ten are plenty to sweep).
const CAMERA_INTERVAL_NS: i64 = 100_000_000;
/// The bracket's short frame: highlights below clipping, down to 1/10 000 of the average exposure.
const BRACKET: Metering = Metering::Highlights { min_ratio: 1e-4 };
/// The longest a frame may take the room light's worker (a 66 ms prefilter in release builds).
const WORKER_TIMEOUT: Duration = Duration::from_secs(60);

/// The camera's sweep, read before any GPU work: the room and the orientations along the log.
pub struct RoomSweep {
    room: Environment,
    room_path: std::path::PathBuf,
    log: std::path::PathBuf,
    /// (camera time, device → world) every [`CAMERA_INTERVAL_NS`].
    poses: Vec<(i64, phantogram::glam::Quat)>,
    /// The rear camera looks too.
    rear: bool,
}

impl RoomSweep {
    /// Loads the room and fuses the orientations along `log` (errors name the file).
    pub fn prepare(room_path: &Path, log: &Path, rear: bool) -> Result<Self> {
        let room = Environment::load(room_path)?;
        let events = phantogram_lab::sensorlog::read_all(log, crate::open_events(log)?)?;
        if events.is_empty() {
            bail!("{}: the log has no events", log.display());
        }
        let mut session = Session::new(SessionConfig::default())?;
        let mut poses = Vec::new();
        replay(
            events.into_iter().map(Ok),
            &mut session,
            CAMERA_INTERVAL_NS,
            Pace::AsFastAsPossible,
            |_, t, view| {
                if let Some(q) = view.device_to_world {
                    poses.push((t, q));
                }
            },
        )
        .with_context(|| format!("replaying {}", log.display()))?;
        if poses.is_empty() {
            bail!(
                "{}: no orientation could be fused from the log (no gravity?)",
                log.display()
            );
        }
        Ok(Self {
            room,
            room_path: room_path.to_path_buf(),
            log: log.to_path_buf(),
            poses,
            rear,
        })
    }

    /// Feeds the engine's room light with the frames the front camera (and the rear one) would
    /// see along the log in the room. Returns the share of the sphere seen.
    pub fn feed(&self, engine: &Engine) -> Result<f32> {
        let mut cameras = vec![(CameraFacing::Front, SyntheticCamera::phone_front())];
        if self.rear {
            cameras.push((CameraFacing::Rear, SyntheticCamera::phone_rear()));
        }
        let Some(worker) = engine.room_light().filter(|w| w.is_on()) else {
            bail!("the engine's room light is off");
        };
        let bar = indicatif::ProgressBar::new(self.poses.len() as u64);
        for (k, (t, q)) in self.poses.iter().enumerate() {
            let metering = if k % 2 == 1 { BRACKET } else { Metering::Average };
            for (facing, camera) in &cameras {
                let (frame, _) = camera.capture(&self.room, *q, metering, *t);
                // As a phone hands its frames over: YUV 4:2:0, turned into colour by the worker.
                engine.room_light_frame_oriented(phantogram_lab::synthetic_camera::as_yuv420(&frame), *facing, *q);
                // One at a time: the worker would drop frames arriving faster than it blends
                // them, and the result would depend on this machine's speed.
                if !worker.wait_until(0, WORKER_TIMEOUT) {
                    bail!(
                        "the room light's worker took over {} s for a frame",
                        WORKER_TIMEOUT.as_secs()
                    );
                }
            }
            bar.inc(1);
        }
        bar.finish_and_clear();
        let (blended, refused, _) = worker.counts();
        let from = if self.rear {
            format!(
                " ({} front, {} rear)",
                worker.blended_from(CameraFacing::Front),
                worker.blended_from(CameraFacing::Rear)
            )
        } else {
            String::new()
        };
        // The newest update goes to the renderer with the next frame drawn.
        let coverage = worker.coverage();
        let level = worker
            .gain()
            .map(|g| format!(", its light scaled by {g:.2} to the studio's level"))
            .unwrap_or_default();
        eprintln!(
            "room light: {blended} camera frames{from} of {} along {} ({refused} refused), {:.0} % of the room seen{level}",
            self.room_path.display(),
            self.log.display(),
            coverage * 100.0
        );
        Ok(coverage)
    }
}
