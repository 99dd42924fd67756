//! The face tracker's own thread: [`FaceWorker`] takes camera frames from any thread without
//! blocking (the newest wins) and publishes the newest observation for the render thread.

use std::sync::Arc;

use super::{FaceObservation, FaceTracker, OwnedFrame};

#[derive(Default)]
struct WorkerShared {
    pending: Option<OwnedFrame>,
    newest: Option<FaceObservation>,
    last_error: Option<String>,
    dropped_frames: u64,
    /// Frames the tracker could not process (bad frame, inference error).
    failed_frames: u64,
    /// The tracker panicked (a bug) and the thread ended: no more frames are processed.
    stopped_by_panic: bool,
    /// A new calibrated IPD for the tracker, taken with the next frame.
    ipd_update: Option<Option<f32>>,
    stop: bool,
}

/// Runs a [`FaceTracker`] on its own thread.
///
/// **Important:** [`Self::submit`] never blocks on inference: a frame that arrives while the
/// previous one is still being processed replaces it (the newest frame wins; the count of frames
/// dropped so is kept). [`Self::newest`] returns the newest observation without waiting. Dropping
/// the worker stops and joins its thread.
pub struct FaceWorker {
    shared: Arc<(std::sync::Mutex<WorkerShared>, std::sync::Condvar)>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl FaceWorker {
    pub fn spawn(mut tracker: FaceTracker) -> Self {
        let shared = Arc::new((
            std::sync::Mutex::new(WorkerShared::default()),
            std::sync::Condvar::new(),
        ));
        let theirs = Arc::clone(&shared);
        let thread = std::thread::Builder::new()
            .name("phantogram-face".into())
            .spawn(move || {
                let (lock, wake) = &*theirs;
                loop {
                    let frame = {
                        let mut s = lock.lock().unwrap_or_else(|p| p.into_inner());
                        while s.pending.is_none() && !s.stop {
                            s = wake.wait(s).unwrap_or_else(|p| p.into_inner());
                        }
                        if s.stop {
                            return;
                        }
                        if let Some(ipd_m) = s.ipd_update.take() {
                            tracker.ipd_m = ipd_m;
                        }
                        s.pending.take()
                    };
                    let Some(frame) = frame else { continue };
                    // A panic here is a bug; it must not vanish with the thread, unseen.
                    let result =
                        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| tracker.process(frame.as_frame())));
                    let mut s = lock.lock().unwrap_or_else(|p| p.into_inner());
                    match result {
                        Ok(Ok(obs)) => s.newest = Some(obs),
                        Ok(Err(e)) => {
                            s.failed_frames += 1;
                            s.last_error = Some(e.to_string());
                        }
                        Err(_) => {
                            s.failed_frames += 1;
                            s.stopped_by_panic = true;
                            s.last_error = Some("face tracking stopped: internal error (please report)".into());
                            return;
                        }
                    }
                }
            })
            .ok();
        Self { shared, thread }
    }

    /// Hands over a frame (replacing one not yet started).
    pub fn submit(&self, frame: OwnedFrame) {
        let (lock, wake) = &*self.shared;
        let mut s = lock.lock().unwrap_or_else(|p| p.into_inner());
        if s.pending.replace(frame).is_some() {
            s.dropped_frames += 1;
        }
        wake.notify_one();
    }

    /// The viewer's calibrated IPD ([`FaceTracker::ipd_m`]) for the frames after this call.
    pub fn set_ipd_m(&self, ipd_m: Option<f32>) {
        self.shared.0.lock().unwrap_or_else(|p| p.into_inner()).ipd_update = Some(ipd_m);
    }

    /// The newest observation, if any frame has been processed.
    pub fn newest(&self) -> Option<FaceObservation> {
        self.shared.0.lock().unwrap_or_else(|p| p.into_inner()).newest
    }

    /// The last error from a frame (bad frame, inference), if any.
    pub fn last_error(&self) -> Option<String> {
        self.shared
            .0
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .last_error
            .clone()
    }

    /// Frames replaced before they were processed.
    pub fn dropped_frames(&self) -> u64 {
        self.shared.0.lock().unwrap_or_else(|p| p.into_inner()).dropped_frames
    }

    /// Frames the tracker failed on ([`Self::last_error`] says why the last one did).
    pub fn failed_frames(&self) -> u64 {
        self.shared.0.lock().unwrap_or_else(|p| p.into_inner()).failed_frames
    }

    /// Whether frames are being processed: the thread could be started (it fails only when the
    /// OS refuses a thread) and has not stopped on an internal error.
    pub fn is_running(&self) -> bool {
        self.thread.is_some() && !self.shared.0.lock().unwrap_or_else(|p| p.into_inner()).stopped_by_panic
    }
}

impl Drop for FaceWorker {
    fn drop(&mut self) {
        let (lock, wake) = &*self.shared;
        lock.lock().unwrap_or_else(|p| p.into_inner()).stop = true;
        wake.notify_all();
        if let Some(t) = self.thread.take() {
            // A panic in the worker has already been reported by the panic hook.
            let _ = t.join();
        }
    }
}
