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
