//! The live room light as the engine runs it: camera frames go to a worker thread that blends
//! them into the room map (`phantogram_roomlight`) with the device's orientation at that moment,
//! and every [`UPDATE_INTERVAL_NS`] of camera time reduces the map to the image-based light: nine
//! SH coefficients and the specular levels' level 0 with the halvings the rough levels read,
//! packed as the GPU takes them, or — unless the render thread said its GPU convolves them
//! ([`RoomLightWorker::set_prefilter_on_gpu`]) — the rough levels too, tens of milliseconds on
//! the CPU. The render thread then only uploads
//! ([`crate::render::Renderer::set_environment_upload`], which dispatches the GPU's convolution, or
//! [`crate::render::Renderer::set_prefiltered_environment`]).
//!
//! **Colour and exposure**: a YUV frame (luma with its chroma planes, as the bridges hand it over)
//! is turned into colour here, on the worker, never on the camera's thread; a luma-only frame
//! lights in grey. A frame's exposure comes with it, or separately by its capture time
//! ([`RoomLightWorker::note_exposure`]: Camera2 reports it in a capture result that may arrive after
//! the image), or else the capture estimates it from the overlap with what the map has seen.
//!
//! **Level**: the camera gives radiance relative to its exposure (1 s at ISO 100 = 1), in units of
//! that phone's sensor and processing, and a lounge and daylight differ by a thousand in it; the
//! renderer's look (its exposure of 1, the world light) was made with a fixed environment. So each
//! update's map is scaled to the mean luminance of the light it replaces — the studio's or the
//! configured environment's ([`RoomLightWorker::spawn`]'s `level`) — and takes from the camera
//! what the camera knows: where the light comes from, its colour and contrast. That is what a
//! camera's averaging meter and the eye's adaptation do with a room, and it also keeps the level
//! steady while the map is young (along the shared `tilt-sweep` log in the apartment, the map
//! seen early had 3.7 times the room's mean before the unseen floor was filled). A desktop replay
//! whose synthetic camera looks into the configured environment itself gets its level back (a
//! gain of about 1 once most of it is seen).
//!
//! **Two cameras**: frames come from the front camera, and from the rear one where the platform
//! runs both at once ([`CameraFacing`]); each is placed with its own camera's pose on the device
//! ([`DeviceCameras`]) into the one map. Held as phantograms are, nearly flat, the front camera
//! sees the ceiling and the room behind the viewer while the rear one sees the floor and the room
//! in front: the floor, otherwise seen last and least, is seen from the start. Each camera has its
//! own slot for the frame waiting, and while both wait the worker takes them in turn, so neither
//! starves the other.
//!
//! **Threading**: [`RoomLightWorker::submit`], [`RoomLightWorker::note_exposure`] and
//! [`RoomLightWorker::set_orientation`] from any thread, never waiting for the worker (a frame
//! arriving while one of the same camera waits replaces it: the newest view of the room matters
//! most); [`RoomLightWorker::take_update`] on
//! the render thread. The worker stops when the handle drops. **Orientation**: the render
//! thread publishes each frame's fused device → world orientation; a camera frame is placed with
//! the newest one published (a frame or two old at 60 fps; while the phone turns fast that
//! smears the map slightly, which its blending averages). **Panics**: none; a frame the capture
//! refuses is counted and dropped.

use std::sync::{Arc, Condvar, Mutex};

use glam::Quat;
use phantogram_assets::ibl::{Environment, IrradianceSh, PrefilterSources, prefilter_base, prefiltered_levels};
use phantogram_render::prefilter_gpu::PrefilterUpload;
use phantogram_roomlight::{CaptureFrame, CaptureParams, RoomCapture, world_from_buffer_camera};
use phantogram_sensing::camera::{CameraFacing, DeviceCameras, Exposure, OwnedFrame};

/// Camera time between two updates of the image-based light: twice a second.
pub const UPDATE_INTERVAL_NS: i64 = 500_000_000;

/// Exposures reported apart from their frames that are kept to be matched (a second at 30 fps
/// from each camera).
const EXPOSURES_KEPT: usize = 64;

/// A new image-based light made from the room map.
pub struct RoomLightUpdate {
    pub specular: Specular,
    pub sh: IrradianceSh,
    /// Share of the sphere the map has seen, 0 to 1.
    pub coverage: f32,
    /// What the map's radiance was multiplied by to bring it to the level asked for
    /// ([`RoomLightWorker::spawn`]); 1 where none was asked for.
    pub gain: f32,
    /// Frames blended so far.
    pub frames: u64,
}

/// The specular image light of an update, as far as the worker reduced it.
pub enum Specular {
    /// Level 0 ([`prefilter_base`]) and its halvings ([`PrefilterSources`]), packed for upload
    /// ([`PrefilterUpload`]) here so that the render thread does not: the renderer's GPU
    /// convolves the rest.
    Upload(PrefilterUpload),
    /// Every level ([`prefiltered_levels`]), convolved on the worker.
    Levels(Vec<Environment>),
}

/// One camera frame waiting for the worker.
struct Pending {
    frame: OwnedFrame,
    /// The device's orientation when the frame was taken, where known with it; else the newest
    /// published.
    world_from_device: Option<Quat>,
}

#[derive(Default)]
struct Shared {
    /// The frame waiting from each camera ([`CameraFacing::index`]).
    pending: [Option<Pending>; 2],
    /// The camera whose frame was taken last (the other goes next while both wait).
    last_taken: Option<CameraFacing>,
    /// Exposures reported by camera and capture time, newest last.
    exposures: std::collections::VecDeque<(CameraFacing, i64, Exposure)>,
    world_from_device: Option<Quat>,
    update: Option<RoomLightUpdate>,
    refused: u64,
    /// Frames blended (from each camera) and updates made, for waiting in tests and tools.
    blended: u64,
    blended_from: [u64; 2],
    updates: u64,
    /// The share of the sphere seen, after the newest frame.
    coverage: f32,
    /// The newest update's [`RoomLightUpdate::gain`].
    gain: Option<f32>,
    /// A frame taken from `pending` is being blended.
    busy: bool,
    /// Off: frames handed over are dropped (the settings' studio light); the map is kept.
    off: bool,
    /// The renderer convolves the rough specular levels on its GPU: updates carry level 0 only.
    prefilter_on_gpu: bool,
    stop: bool,
}

/// The worker thread and its mailbox (see the module docs).
pub struct RoomLightWorker {
    shared: Arc<(Mutex<Shared>, Condvar)>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl RoomLightWorker {
    /// Starts the worker for the device's `cameras`. `level`: the mean luminance
    /// ([`Environment::mean_luminance`]) each update's map is scaled to — the level of the light
    /// it replaces (see the module docs, **Level**) — or `None` to keep the camera's own.
    pub fn spawn(
        cameras: DeviceCameras,
        params: CaptureParams,
        base_width: usize,
        level: Option<f32>,
    ) -> std::io::Result<Self> {
        let shared = Arc::new((Mutex::new(Shared::default()), Condvar::new()));
        let inner = shared.clone();
        let thread = std::thread::Builder::new()
            .name("room light".into())
            .spawn(move || run(&inner, cameras, params, base_width, level))?;
        Ok(Self {
            shared,
            thread: Some(thread),
        })
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Shared> {
        self.shared.0.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Hands a frame of the `facing` camera to the worker (RGBA, YUV or luma; its exposure with
    /// it when the platform reports it so), replacing one of that camera not yet started.
    /// Returns whether it was taken (not while the worker is off).
    pub fn submit(&self, frame: OwnedFrame, facing: CameraFacing) -> bool {
        self.submit_oriented(frame, facing, None)
    }

    /// The exposure of the `facing` camera's frame captured at `capture_t_ns` (sensor clock),
    /// reported apart from it; used for that frame when it comes without one.
    pub fn note_exposure(&self, facing: CameraFacing, capture_t_ns: i64, exposure: Exposure) {
        let mut s = self.lock();
        if s.exposures.len() == EXPOSURES_KEPT {
            s.exposures.pop_front();
        }
        s.exposures.push_back((facing, capture_t_ns, exposure));
    }

    /// As [`Self::submit`], with the device's orientation when the frame was taken (a desktop
    /// replay; a platform that tracks the camera's pose per frame), used instead of the newest
    /// published one.
    pub fn submit_oriented(&self, frame: OwnedFrame, facing: CameraFacing, world_from_device: Option<Quat>) -> bool {
        let mut s = self.lock();
        if s.off {
            return false;
        }
        s.pending[facing.index()] = Some(Pending {
            frame,
            world_from_device,
        });
        drop(s);
        self.shared.1.notify_all();
        true
    }

    /// Switches the worker on or off (off: frames are dropped and no updates are made; the map
    /// seen so far is kept for when it is on again).
    pub fn set_on(&self, on: bool) {
        let mut s = self.lock();
        s.off = !on;
        if !on {
            s.pending = [None, None];
            s.update = None;
        }
        drop(s);
        self.shared.1.notify_all();
    }

    pub fn is_on(&self) -> bool {
        !self.lock().off
    }

    /// Whether the render thread convolves the rough specular levels on its GPU
    /// ([`crate::render::Renderer::prefilters_on_gpu`]); until told so, the worker does.
    pub fn set_prefilter_on_gpu(&self, on_gpu: bool) {
        self.lock().prefilter_on_gpu = on_gpu;
    }

    /// The device's orientation now (device → world), for the frames that follow.
    pub fn set_orientation(&self, world_from_device: Quat) {
        self.lock().world_from_device = Some(world_from_device);
    }

    /// The newest image-based light made since the last call, if any.
    pub fn take_update(&self) -> Option<RoomLightUpdate> {
        self.lock().update.take()
    }

    /// The share of the sphere the room map has seen, 0 to 1.
    pub fn coverage(&self) -> f32 {
        self.lock().coverage
    }

    /// The newest update's [`RoomLightUpdate::gain`] (`None` before the first).
    pub fn gain(&self) -> Option<f32> {
        self.lock().gain
    }

    /// Frames blended, frames refused, updates made so far.
    pub fn counts(&self) -> (u64, u64, u64) {
        let s = self.lock();
        (s.blended, s.refused, s.updates)
    }

    /// Frames of the `facing` camera blended so far.
    pub fn blended_from(&self, facing: CameraFacing) -> u64 {
        self.lock().blended_from[facing.index()]
    }

    /// Waits up to `timeout` until every frame handed over has been blended (none waiting, none
    /// being blended) and `updates` updates were made (for tests and the desktop tools).
    /// Returns whether that happened.
    pub fn wait_until(&self, updates: u64, timeout: std::time::Duration) -> bool {
        let deadline = std::time::Instant::now() + timeout;
        let mut s = self.lock();
        while s.pending.iter().any(Option::is_some) || s.busy || s.updates < updates {
            let now = std::time::Instant::now();
            if now >= deadline {
                return false;
            }
            s = match self.shared.1.wait_timeout(s, deadline - now) {
                Ok((g, _)) => g,
                Err(p) => p.into_inner().0,
            };
        }
        true
    }
}

impl Drop for RoomLightWorker {
    fn drop(&mut self) {
        self.lock().stop = true;
        self.shared.1.notify_all();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn run(
    shared: &(Mutex<Shared>, Condvar),
    cameras: DeviceCameras,
    params: CaptureParams,
    base_width: usize,
    level: Option<f32>,
) {
    let lock = || shared.0.lock().unwrap_or_else(|p| p.into_inner());
    let mut capture = RoomCapture::new(params);
    let mut last_update_t_ns: Option<i64> = None;
    loop {
        let (pending, orientation) = {
            let mut s = lock();
            while s.pending.iter().all(Option::is_none) && !s.stop {
                s = match shared.1.wait(s) {
                    Ok(g) => g,
                    Err(p) => p.into_inner(),
                };
            }
            if s.stop {
                return;
            }
            s.busy = true;
            // Both waiting: the camera not taken last goes first.
            let facing = match (&s.pending, s.last_taken) {
                ([Some(_), Some(_)], Some(CameraFacing::Front)) | ([None, Some(_)], _) => CameraFacing::Rear,
                _ => CameraFacing::Front,
            };
            s.last_taken = Some(facing);
            let mut pending = s.pending[facing.index()].take();
            if let Some(p) = &mut pending
                && p.frame.exposure.is_none()
            {
                let t = p.frame.capture_t_ns;
                p.frame.exposure = s
                    .exposures
                    .iter()
                    .rev()
                    .find(|(from, at, _)| *from == facing && *at == t)
                    .map(|(_, _, e)| *e);
            }
            (pending.map(|p| (facing, p)), s.world_from_device)
        };
        let Some((facing, p)) = pending else {
            lock().busy = false;
            continue;
        };
        let Some(q) = p.world_from_device.or(orientation) else {
            // No orientation yet: the frame cannot be placed.
            let mut s = lock();
            s.refused += 1;
            s.busy = false;
            drop(s);
            shared.1.notify_all();
            continue;
        };
        // Colour where the frame has it (YUV converted here, off the camera's thread); else grey.
        let image = p.frame.into_colour();
        let frame = CaptureFrame {
            image: image.as_frame(),
            world_from_camera: world_from_buffer_camera(q, cameras.pose(facing), image.rotation_cw_deg),
            exposure: image.exposure.map(Exposure::relative),
        };
        let added = capture.add(&frame).is_ok();
        let t = image.capture_t_ns;
        // Either way: the two cameras' frames interleave a few milliseconds apart, and a clock
        // that went back (a camera restarted) must not stop the updates.
        let due = added && last_update_t_ns.is_none_or(|last| t.abs_diff(last) >= UPDATE_INTERVAL_NS as u64);
        let on_gpu = lock().prefilter_on_gpu;
        let update = due.then(|| {
            last_update_t_ns = Some(t);
            let mut env = capture.environment();
            let gain = level.map_or(1.0, |level| level_gain(level, env.mean_luminance()));
            if gain != 1.0 {
                for t in &mut env.texels {
                    *t = t.map(|c| c * gain);
                }
            }
            RoomLightUpdate {
                gain,
                sh: IrradianceSh::from_environment(&env),
                // Packed for the GPU here; should packing refuse the base (it cannot, being
                // prefilter_base's), the levels are convolved here instead.
                specular: on_gpu
                    .then(|| PrefilterUpload::new(PrefilterSources::new(prefilter_base(&env, base_width))).ok())
                    .flatten()
                    .map_or_else(
                        || Specular::Levels(prefiltered_levels(&env, base_width)),
                        Specular::Upload,
                    ),
                coverage: capture.coverage(),
                frames: capture.frames(),
            }
        });
        let coverage = capture.coverage();
        let mut s = lock();
        s.coverage = coverage;
        s.busy = false;
        if added {
            s.blended += 1;
            s.blended_from[facing.index()] += 1;
        } else {
            s.refused += 1;
        }
        // Switched off while this frame was blended: its light is not shown.
        if let Some(u) = update
            && !s.off
        {
            s.gain = Some(u.gain);
            s.update = Some(u);
            s.updates += 1;
        }
        drop(s);
        shared.1.notify_all();
    }
}

/// The factor that brings a map of mean luminance `mean` to `level`: 1 where either is not a
/// positive finite number (nothing seen yet but black: no level to go by, and a gain of millions
/// would show the camera's noise as light).
fn level_gain(level: f32, mean: f32) -> f32 {
    const DARKEST: f32 = 1e-6;
    let gain = level / mean;
    if level.is_finite() && level > 0.0 && mean.is_finite() && mean > DARKEST && gain.is_finite() {
        gain
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use phantogram_sensing::camera::{CameraPose, Intrinsics, PixelFormat};

    fn cameras() -> DeviceCameras {
        DeviceCameras {
            front: CameraPose::front(Vec3::ZERO),
            rear: CameraPose::rear(Vec3::ZERO),
        }
    }

    fn grey(t_ns: i64, code: u8) -> OwnedFrame {
        let (w, h) = (64u32, 48u32);
        OwnedFrame {
            width: w,
            height: h,
            row_stride: w as usize * 4,
            format: PixelFormat::Rgba8,
            data: vec![code; (w * h * 4) as usize],
            rotation_cw_deg: 0,
            intrinsics: Intrinsics::from_horizontal_fov(w, h, 1.2),
            capture_t_ns: t_ns,
            chroma: None,
            exposure: Exposure::new(1.0, 100.0),
        }
    }

    #[test]
    fn frames_become_updates_twice_a_second_of_camera_time() {
        let worker = RoomLightWorker::spawn(cameras(), CaptureParams::default(), 64, None).expect("thread");
        // Without an orientation a frame cannot be placed.
        worker.submit(grey(0, 118), CameraFacing::Front);
        assert!(worker.wait_until(0, std::time::Duration::from_secs(10)));
        assert_eq!(worker.counts(), (0, 1, 0));
        worker.set_orientation(Quat::IDENTITY);
        let mut made = 0;
        for k in 0..6i64 {
            worker.submit(grey(k * 200_000_000, 118), CameraFacing::Front);
            assert!(worker.wait_until(0, std::time::Duration::from_secs(10)));
            if let Some(u) = worker.take_update() {
                made += 1;
                // The first on the CPU, every level; then the renderer says its GPU convolves
                // them, and the second carries level 0 alone.
                match (made, &u.specular) {
                    (1, Specular::Levels(levels)) => {
                        assert_eq!(levels.len(), phantogram_assets::ibl::PREFILTER_LEVELS)
                    }
                    (2, Specular::Upload(upload)) => assert_eq!(upload.size(), (64, 32)),
                    _ => panic!("update {made} is not what was asked for"),
                }
                assert!(u.coverage > 0.05 && u.sh.irradiance(Vec3::Z)[0] > 0.0);
                worker.set_prefilter_on_gpu(true);
            }
        }
        // Frames at 0, 0.2, … 1.0 s: an update with the first, then at least 0.5 s later (0.6 s).
        let (blended, refused, updates) = worker.counts();
        assert_eq!((blended, refused), (6, 1));
        assert_eq!(updates, 2);
        assert_eq!(made, 2);
    }

    #[test]
    fn the_room_keeps_the_level_of_the_light_it_replaces_whatever_the_cameras_calibration() {
        // One grey room through a camera whose reported exposure is right, 100 times too long
        // and 100 times too short: the map's own level spans 10 000, the light handed on does not.
        let level = 0.18;
        let light = |time_s: f32| {
            let worker = RoomLightWorker::spawn(cameras(), CaptureParams::default(), 64, Some(level)).expect("thread");
            worker.set_orientation(Quat::IDENTITY);
            worker.submit(
                OwnedFrame {
                    exposure: Exposure::new(time_s, 100.0),
                    ..grey(5, 118)
                },
                CameraFacing::Front,
            );
            assert!(worker.wait_until(1, std::time::Duration::from_secs(10)));
            let update = worker.take_update().expect("an update");
            assert_eq!(worker.gain(), Some(update.gain));
            update
        };
        let mean = |u: &RoomLightUpdate| 0.282_095 * phantogram_geometry::srgb::luminance(u.sh.coefficients[0]);
        let right = light(1.0);
        assert!(
            (mean(&right) - level).abs() < 1e-3 * level,
            "{} against {level}",
            mean(&right)
        );
        for wrong in [light(100.0), light(0.01)] {
            assert!((mean(&wrong) - level).abs() < 1e-3 * level, "{}", mean(&wrong));
            assert!(
                (wrong.gain / right.gain).log10().abs() > 1.99,
                "{} against {}",
                wrong.gain,
                right.gain
            );
            for n in [Vec3::Z, Vec3::NEG_Z, Vec3::X] {
                let (a, b) = (wrong.sh.irradiance(n)[1], right.sh.irradiance(n)[1]);
                assert!((a - b).abs() < 1e-3 * b, "{n}: {a} against {b}");
            }
        }
        // Black: no level to go by; the map is kept as it is.
        assert_eq!(level_gain(level, 0.0), 1.0);
        assert_eq!(level_gain(level, f32::NAN), 1.0);
        assert_eq!(level_gain(f32::INFINITY, 1.0), 1.0);
        assert_eq!(level_gain(0.5, 2.0), 0.25);
    }

    #[test]
    fn an_exposure_reported_apart_is_matched_to_its_frame_by_time() {
        // The same grey frame, once with its exposure on it (1 s at ISO 100) and once without,
        // its exposure (twice as long) reported apart with a neighbour's: the second room is
        // half as bright, so the noted exposure was used, and only the one of its own time.
        let light = |frame: OwnedFrame, notes: &[(i64, Exposure)]| {
            let worker = RoomLightWorker::spawn(cameras(), CaptureParams::default(), 64, None).expect("thread");
            worker.set_orientation(Quat::IDENTITY);
            for (t, e) in notes {
                worker.note_exposure(CameraFacing::Front, *t, *e);
            }
            // The rear camera's exposure at the same time is not the front's.
            worker.note_exposure(CameraFacing::Rear, 5, Exposure::new(32.0, 100.0).expect("valid"));
            worker.submit(frame, CameraFacing::Front);
            assert!(worker.wait_until(1, std::time::Duration::from_secs(10)));
            worker.take_update().expect("an update").sh.irradiance(Vec3::NEG_Z)[0]
        };
        let reported = light(grey(5, 118), &[]);
        let unreported = OwnedFrame {
            exposure: None,
            ..grey(5, 118)
        };
        let two_s = Exposure::new(2.0, 100.0).expect("valid");
        let noted = light(
            unreported.clone(),
            &[(4, Exposure::new(8.0, 100.0).expect("valid")), (5, two_s), (6, two_s)],
        );
        assert!((noted / reported - 0.5).abs() < 0.01, "{noted} against {reported}");
        // With none noted for its time the capture estimates (a first frame: as if 1 s).
        let estimated = light(unreported, &[(4, two_s)]);
        assert!(
            (estimated / reported - 1.0).abs() < 0.01,
            "{estimated} against {reported}"
        );
    }

    /// An upright frame whose top half has code `top` and bottom half `bottom`.
    fn halves(t_ns: i64, top: u8, bottom: u8) -> OwnedFrame {
        let mut f = grey(t_ns, bottom);
        let half = f.data.len() / 2;
        f.data[..half].fill(top);
        f
    }

    #[test]
    fn each_cameras_frames_light_the_room_from_its_own_side() {
        // The phone lies face up, its top to the north (device = world: x east, y north, z up).
        // The front camera sees a dark ceiling; the rear one a bright floor, brighter still
        // towards the phone's top (its image's top half). Both are handed over before the
        // worker takes either: each camera keeps its own frame waiting.
        let worker = RoomLightWorker::spawn(cameras(), CaptureParams::default(), 64, None).expect("thread");
        worker.set_orientation(Quat::IDENTITY);
        let (front, rear) = (grey(0, 20), halves(1, 240, 120));
        assert!(worker.submit(front, CameraFacing::Front) && worker.submit(rear, CameraFacing::Rear));
        assert!(worker.wait_until(1, std::time::Duration::from_secs(10)));
        assert_eq!(worker.blended_from(CameraFacing::Front), 1);
        assert_eq!(worker.blended_from(CameraFacing::Rear), 1);
        // Updates come by camera time, every half second: the second frame (1 ns later) made
        // none; so a further one lights the whole map.
        assert!(worker.submit(halves(UPDATE_INTERVAL_NS + 2, 240, 120), CameraFacing::Rear));
        assert!(worker.wait_until(2, std::time::Duration::from_secs(10)));
        let mut sh = None;
        while let Some(u) = worker.take_update() {
            sh = Some(u.sh);
        }
        let sh = sh.expect("an update");
        let e = |n: Vec3| phantogram_geometry::srgb::luminance(sh.irradiance(n.normalize()));
        assert!(
            e(Vec3::NEG_Z) > 4.0 * e(Vec3::Z),
            "{} from below, {} from above",
            e(Vec3::NEG_Z),
            e(Vec3::Z)
        );
        let (north, south) = (e(Vec3::new(0.0, 1.0, -1.0)), e(Vec3::new(0.0, -1.0, -1.0)));
        // (The cosine lobe over a 70° view of the floor and the filled rest smooth the halves'
        // 4.6:1 in linear light to about 1.15:1; an image upside down would give about 1:1.15.)
        assert!(
            north > 1.08 * south,
            "the image's top is the phone's top: {north} north, {south} south"
        );
        let (east, west) = (e(Vec3::new(1.0, 0.0, -1.0)), e(Vec3::new(-1.0, 0.0, -1.0)));
        assert!((east / west - 1.0).abs() < 0.05, "{east} east, {west} west");
    }

    #[test]
    fn with_both_cameras_waiting_they_are_taken_in_turn() {
        // The worker is kept busy by frames from both cameras, handed over faster than it can
        // blend them: neither camera is starved.
        let worker = RoomLightWorker::spawn(cameras(), CaptureParams::default(), 64, None).expect("thread");
        worker.set_orientation(Quat::IDENTITY);
        for k in 0..40i64 {
            worker.submit(grey(2 * k, 118), CameraFacing::Front);
            worker.submit(grey(2 * k + 1, 118), CameraFacing::Rear);
        }
        assert!(worker.wait_until(0, std::time::Duration::from_secs(10)));
        let (front, rear) = (
            worker.blended_from(CameraFacing::Front),
            worker.blended_from(CameraFacing::Rear),
        );
        assert!(front >= 1 && rear >= 1, "{front} front, {rear} rear");
        assert!(front.abs_diff(rear) <= 1, "{front} front, {rear} rear");
    }
}
