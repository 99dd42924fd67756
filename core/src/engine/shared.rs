//! [`SharedEngine`]: one [`Engine`] shared between the platform's threads (see the module docs
//! of [`crate::engine`], *Threading*).

use super::Engine;
#[cfg(feature = "face")]
use super::EngineError;
use super::EngineStats;
use crate::sensors::{Rejection, SensorEvent, SensorInbox};
use std::sync::{Arc, Mutex, MutexGuard};

/// An [`Engine`] shared between the render thread and the platform's producer threads; what the
/// bridges hold behind their handles. See the module docs for the threading contract.
pub struct SharedEngine {
    pub(super) inbox: Arc<SensorInbox>,
    #[cfg(feature = "face")]
    pub(super) face: Option<Arc<crate::face::FaceWorker>>,
    pub(super) room_light: Option<Arc<crate::room_light::RoomLightWorker>>,
    pub(super) camera_frames: std::sync::atomic::AtomicU64,
    pub(super) engine: Mutex<Engine>,
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

    /// From any thread, without waiting for inference: hands a front-camera frame to the face
    /// tracker (replacing one not yet started), and to the live room light when it is on; a
    /// rear-camera frame to the room light alone. `Ok(false)` when nothing took it: face
    /// tracking off (front), the room light off (rear).
    #[cfg(feature = "face")]
    pub fn camera_frame(
        &self,
        facing: crate::camera::CameraFacing,
        frame: crate::face::OwnedFrame,
    ) -> Result<bool, EngineError> {
        crate::face::UprightImage::new(frame.as_frame())?;
        let room = self.room_light.as_ref().filter(|room| room.is_on());
        if facing == crate::camera::CameraFacing::Rear {
            return Ok(room.is_some_and(|room| room.submit(frame, facing)));
        }
        if let Some(room) = room {
            room.submit(frame.clone(), facing);
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

    /// From any thread: the exposure of the `facing` camera's frame captured at `capture_t_ns`,
    /// where the platform reports it apart from the frame (Camera2's capture results); the room
    /// light matches it to its frame. Ignored when the room light is off.
    pub fn camera_exposure(
        &self,
        facing: crate::camera::CameraFacing,
        capture_t_ns: i64,
        exposure: crate::camera::Exposure,
    ) {
        if let Some(room) = &self.room_light {
            room.note_exposure(facing, capture_t_ns, exposure);
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
