//! Where the viewer's eyes are *now*: camera observations of the eyes (late and at 30 Hz) carried
//! to the frame's time with the phone's own rotation, falling back to the tilt approximation when
//! the face is lost, and blending between the two without jumps.
//!
//! * **Latency**: a camera result describes the eyes at its capture time `t_c`, 50–100 ms before
//!   it arrives. The viewer's head is taken as fixed in the room over that interval and the
//!   phone's rotation since `t_c` is undone: `p_now = q_now⁻¹ · q(t_c) · p(t_c)` with `q` the
//!   device → world orientation, interpolated from the history recorded by
//!   [`EyeTracker::record_orientation`]. The phone's translation is not observable from the
//!   gyroscope and is ignored (a hand moving the phone 5 cm/s moves the eyes 4 mm in 80 ms).
//! * **Lost face**: no observation with eyes, or none for [`EyeTrackParams::stale_after_s`]: the
//!   eyes come from the tilt approximation at the **last good distance** (not the 30 cm default).
//! * **No jumps**: when the source changes, the difference between the old output and the new
//!   source is kept as an offset that decays with time constant `blend_tau_s` and at most
//!   `max_blend_speed_m_per_s`; the output therefore moves by at most the source's own motion
//!   plus `max_blend_speed_m_per_s × Δt` per frame (8.3 mm per 60 Hz frame by default).
//! * **Jitter**: camera eyes are smoothed by a One Euro filter (Casiez, Roussel & Vogel, CHI
//!   2012) in the room-fixed frame (where a still head is still): strong smoothing at rest, little
//!   lag when the head moves.
//! * The stereo eye axis follows the tracked eyes: [`TrackedEyes::eye_axis`] goes to
//!   [`phantogram_geometry::eyes::EyeModel::eye_axis_device`].
//!
//! Frames: device frame, metres; times on the sensor clock, nanoseconds (see the crate docs).
//! Threading: plain data, owned by the render thread; the face worker hands it
//! [`FaceObservation`]s. Panics: none.

use crate::clock::{elapsed_ns, elapsed_s};
use glam::{Quat, Vec3};
use std::collections::VecDeque;

/// One camera result, as the face tracker produces it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceObservation {
    /// When the frame was exposed, sensor clock.
    pub capture_t_ns: i64,
    /// The viewer's left and right eye, device frame, metres, at the capture time; `None` when
    /// no face was found.
    pub eyes_m: Option<[Vec3; 2]>,
    /// In [0, 1]; 0 without a face.
    pub confidence: f32,
    /// Anaglyph glasses on the viewer's face, when the frame had colour and they were seen.
    pub glasses: Option<crate::glasses::GlassesSeen>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EyeTrackParams {
    /// An observation older than this (by capture time) no longer counts as a face.
    pub stale_after_s: f32,
    /// Observations below this confidence count as no face.
    pub min_confidence: f32,
    pub blend_tau_s: f32,
    pub max_blend_speed_m_per_s: f32,
    /// Orientation history kept for latency compensation.
    pub history_s: f32,
    /// One Euro filter on the camera eyes: cutoff at rest, and its rise per m/s of eye speed.
    pub smoothing_min_cutoff_hz: f32,
    pub smoothing_beta_hz_per_m_s: f32,
}

impl Default for EyeTrackParams {
    fn default() -> Self {
        Self {
            stale_after_s: 0.3,
            min_confidence: 0.5,
            blend_tau_s: 0.15,
            max_blend_speed_m_per_s: 0.5,
            history_s: 1.0,
            smoothing_min_cutoff_hz: 1.0,
            smoothing_beta_hz_per_m_s: 20.0,
        }
    }
}

/// Where the eyes came from this frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EyeSource {
    Camera,
    Tilt,
}

/// The eyes for one frame, device frame, metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackedEyes {
    pub left_m: Vec3,
    pub right_m: Vec3,
    pub source: EyeSource,
    /// True while the output is still converging after a change of source.
    pub blending: bool,
    /// The distance used for the tilt approximation (the last distance the camera measured).
    pub distance_m: f32,
}

impl TrackedEyes {
    pub fn cyclopean_m(&self) -> Vec3 {
        (self.left_m + self.right_m) * 0.5
    }

    /// Unit left → right axis, if the eyes are apart.
    pub fn eye_axis(&self) -> Option<Vec3> {
        (self.right_m - self.left_m).try_normalize()
    }
}

/// One Euro filter state for one 3-D point.
#[derive(Clone, Copy, Debug)]
struct OneEuro {
    t_ns: i64,
    x: Vec3,
    dx: Vec3,
}

impl OneEuro {
    /// Cutoff of the speed estimate itself (the paper's d_cutoff).
    const SPEED_CUTOFF_HZ: f32 = 1.0;

    fn alpha(cutoff_hz: f32, dt_s: f32) -> f32 {
        1.0 / (1.0 + 1.0 / (std::f32::consts::TAU * cutoff_hz * dt_s))
    }

    fn update(&mut self, x: Vec3, t_ns: i64, min_cutoff_hz: f32, beta: f32) -> Vec3 {
        let dt_s = elapsed_s(self.t_ns, t_ns) as f32;
        if dt_s <= 0.0 {
            return self.x;
        }
        let raw_speed = (x - self.x) / dt_s;
        self.dx += (raw_speed - self.dx) * Self::alpha(Self::SPEED_CUTOFF_HZ, dt_s);
        let cutoff = min_cutoff_hz + beta * self.dx.length();
        self.x += (x - self.x) * Self::alpha(cutoff, dt_s);
        self.t_ns = t_ns;
        self.x
    }
}

/// The fusion state: orientation history, newest observation, blend offset.
#[derive(Clone, Debug)]
pub struct EyeTracker {
    params: EyeTrackParams,
    history: VecDeque<(i64, Quat)>,
    /// Newest usable observation: capture time, eyes (device frame at capture) and the
    /// orientation at capture, if the history covered it.
    newest: Option<(i64, [Vec3; 2], Option<Quat>)>,
    /// Smoothing of the camera eyes (room-fixed frame when the orientation is known); reset
    /// when the face is lost.
    smoothing: Option<[OneEuro; 2]>,
    /// Whether the newest observation (of any kind) had a face.
    face_present: bool,
    distance_m: f32,
    source: Option<EyeSource>,
    offset: [Vec3; 2],
    last: Option<(i64, [Vec3; 2])>,
}

impl EyeTracker {
    pub fn new(params: EyeTrackParams, default_distance_m: f32) -> Self {
        Self {
            params,
            history: VecDeque::new(),
            newest: None,
            smoothing: None,
            face_present: false,
            distance_m: default_distance_m,
            source: None,
            offset: [Vec3::ZERO; 2],
            last: None,
        }
    }

    /// The last distance the camera measured (or the default until it has).
    pub fn distance_m(&self) -> f32 {
        self.distance_m
    }

    /// Changes the distance used before the camera has measured one (a new calibration); a
    /// measured distance is kept.
    pub fn set_default_distance_m(&mut self, distance_m: f32) {
        if self.newest.is_none() {
            self.distance_m = distance_m;
        }
    }

    /// Records the device → world orientation at `t_ns` (call once per frame or per gyro batch).
    pub fn record_orientation(&mut self, t_ns: i64, device_to_world: Quat) {
        if !device_to_world.is_finite() {
            return;
        }
        if let Some(&(t_last, _)) = self.history.back() {
            if t_ns <= t_last {
                return;
            }
        }
        self.history.push_back((t_ns, device_to_world.normalize()));
        let keep_ns = (self.params.history_s as f64 * 1e9) as i64;
        while self
            .history
            .front()
            .is_some_and(|&(t, _)| t < t_ns.saturating_sub(keep_ns))
        {
            self.history.pop_front();
        }
    }

    /// Orientation at `t_ns`, interpolated in the history (clamped to its ends).
    fn orientation_at(&self, t_ns: i64) -> Option<Quat> {
        let i = self.history.partition_point(|&(t, _)| t <= t_ns);
        match (i.checked_sub(1).and_then(|j| self.history.get(j)), self.history.get(i)) {
            (Some(&(t0, q0)), Some(&(t1, q1))) => {
                let s = (elapsed_s(t0, t_ns) / elapsed_s(t0, t1).max(1e-9)) as f32;
                Some(q0.slerp(q1, s))
            }
            (Some(&(_, q)), None) | (None, Some(&(_, q))) => Some(q),
            (None, None) => None,
        }
    }

    /// Takes a camera result. Results older than the newest one taken are ignored.
    pub fn observe(&mut self, obs: FaceObservation) {
        // A capture time beyond the sensors' range would overflow the intervals taken below.
        let in_range = crate::sensors::time_in_range(obs.capture_t_ns);
        if !in_range || self.newest.is_some_and(|(t, _, _)| obs.capture_t_ns < t) {
            return;
        }
        let eyes = obs
            .eyes_m
            .filter(|e| e.iter().all(|p| p.is_finite() && p.z > 0.0) && obs.confidence >= self.params.min_confidence);
        self.face_present = eyes.is_some();
        let Some(eyes) = eyes else {
            self.smoothing = None;
            return;
        };
        let t = obs.capture_t_ns;
        let q_c = self.orientation_at(t);
        // Smooth where a still head stands still: turned into the room by the capture-time
        // orientation (the device frame itself turns with the hand).
        let to_room = q_c.unwrap_or(Quat::IDENTITY);
        let room = eyes.map(|p| to_room * p);
        let (min_cutoff, beta) = (
            self.params.smoothing_min_cutoff_hz,
            self.params.smoothing_beta_hz_per_m_s,
        );
        let smoothed = match self.smoothing.as_mut() {
            Some(filters) => [
                filters[0].update(room[0], t, min_cutoff, beta),
                filters[1].update(room[1], t, min_cutoff, beta),
            ],
            None => {
                self.smoothing = Some(room.map(|x| OneEuro {
                    t_ns: t,
                    x,
                    dx: Vec3::ZERO,
                }));
                room
            }
        };
        let eyes = smoothed.map(|p| to_room.inverse() * p);
        self.distance_m = ((eyes[0] + eyes[1]) * 0.5).length();
        self.newest = Some((t, eyes, q_c));
    }

    /// The eyes for a frame at `t_ns` with the device → world orientation `now` (`None`: no
    /// orientation yet, no compensation). `tilt_eyes(distance_m)` gives the tilt approximation's
    /// left and right eye at a distance.
    pub fn eyes_at(&mut self, t_ns: i64, now: Option<Quat>, tilt_eyes: impl Fn(f32) -> [Vec3; 2]) -> TrackedEyes {
        let stale_ns = (self.params.stale_after_s as f64 * 1e9) as i64;
        let camera = self
            .newest
            .filter(|&(t, _, _)| self.face_present && elapsed_ns(t, t_ns) <= stale_ns)
            .map(|(_, at_capture, q_capture)| {
                match (q_capture, now.or_else(|| self.orientation_at(t_ns))) {
                    (Some(q_c), Some(q_now)) => {
                        let turn = q_now.inverse() * q_c;
                        at_capture.map(|p| turn * p)
                    }
                    // No orientation known: nothing to compensate with.
                    _ => at_capture,
                }
            });
        let (source, target) = match camera {
            Some(e) => (EyeSource::Camera, e),
            None => (EyeSource::Tilt, tilt_eyes(self.distance_m)),
        };
        let dt_s = self.last.map_or(0.0, |(t, _)| elapsed_s(t, t_ns).max(0.0) as f32);
        if self.source.is_some_and(|s| s != source) {
            if let Some((_, previous)) = self.last {
                // Keep the output where it was; the offset decays from here.
                self.offset = [previous[0] - target[0], previous[1] - target[1]];
            }
        } else {
            let decay = 1.0 - (-dt_s / self.params.blend_tau_s).exp();
            let cap = self.params.max_blend_speed_m_per_s * dt_s;
            for o in &mut self.offset {
                let shrink = (o.length() * decay).min(cap);
                *o -= o.normalize_or_zero() * shrink;
                if o.length() < 1e-5 {
                    *o = Vec3::ZERO;
                }
            }
        }
        self.source = Some(source);
        let out = [target[0] + self.offset[0], target[1] + self.offset[1]];
        self.last = Some((t_ns, out));
        TrackedEyes {
            left_m: out[0],
            right_m: out[1],
            source,
            blending: self.offset.iter().any(|o| *o != Vec3::ZERO),
            distance_m: self.distance_m,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: i64 = 1_000_000;

    fn eyes(d: f32) -> [Vec3; 2] {
        [Vec3::new(-0.0315, 0.0, d), Vec3::new(0.0315, 0.0, d)]
    }

    #[test]
    fn late_observation_is_carried_by_the_rotation_since_capture() {
        let mut t = EyeTracker::new(EyeTrackParams::default(), 0.3);
        // The phone turned 10° about y between capture (t = 0) and now (t = 80 ms).
        let q0 = Quat::IDENTITY;
        let q1 = Quat::from_rotation_y(10f32.to_radians());
        t.record_orientation(0, q0);
        t.record_orientation(80 * MS, q1);
        t.observe(FaceObservation {
            capture_t_ns: 0,
            eyes_m: Some(eyes(0.4)),
            confidence: 0.9,
            glasses: None,
        });
        let out = t.eyes_at(80 * MS, Some(q1), |_| unreachable!("the face is present"));
        let want = eyes(0.4).map(|p| q1.inverse() * p);
        assert!(out.left_m.distance(want[0]) < 1e-5 && out.right_m.distance(want[1]) < 1e-5);
        assert_eq!(out.source, EyeSource::Camera);
        assert!((t.distance_m() - 0.4).abs() < 1e-3);
    }

    #[test]
    fn losing_the_face_blends_to_tilt_at_the_last_distance_without_a_jump() {
        let mut t = EyeTracker::new(EyeTrackParams::default(), 0.3);
        let tilted = |d: f32| [Vec3::new(-0.0315, 0.05, d), Vec3::new(0.0315, 0.05, d)];
        t.observe(FaceObservation {
            capture_t_ns: 0,
            eyes_m: Some(eyes(0.45)),
            confidence: 0.9,
            glasses: None,
        });
        let first = t.eyes_at(16 * MS, None, tilted);
        assert_eq!(first.source, EyeSource::Camera);
        t.observe(FaceObservation {
            capture_t_ns: 30 * MS,
            eyes_m: None,
            confidence: 0.0,
            glasses: None,
        });
        let mut previous = first.left_m;
        let mut last = first;
        for k in 2..120 {
            let out = t.eyes_at(k * 16 * MS, None, tilted);
            assert_eq!(out.source, EyeSource::Tilt);
            let step = out.left_m.distance(previous);
            assert!(step <= 0.5 * 0.016 + 1e-5, "frame {k}: step {step}");
            previous = out.left_m;
            last = out;
        }
        // Converged onto the tilt approximation at the camera's last distance, 45 cm.
        assert!(!last.blending);
        assert!(last.left_m.distance(tilted(0.45)[0]) < 1e-4, "{:?}", last.left_m);
    }

    #[test]
    fn camera_jitter_is_smoothed_at_rest_and_a_moving_head_is_followed() {
        let mut t = EyeTracker::new(EyeTrackParams::default(), 0.3);
        let mut noise = crate::synthetic::Noise::new(7);
        let frame_ns = 33 * MS;
        let (mut raw_sq, mut out_sq, mut n) = (0.0f32, 0.0f32, 0);
        // 3 s of a still head at 40 cm seen with 3 mm of noise per frame.
        for k in 0..90 {
            let jitter = noise.vec3(0.003);
            t.observe(FaceObservation {
                capture_t_ns: k * frame_ns,
                eyes_m: Some(eyes(0.4).map(|p| p + jitter)),
                confidence: 0.9,
                glasses: None,
            });
            let out = t.eyes_at(k * frame_ns, None, eyes);
            if k >= 30 {
                raw_sq += jitter.length_squared();
                out_sq += out.left_m.distance_squared(eyes(0.4)[0]);
                n += 1;
            }
        }
        let (raw, out) = ((raw_sq / n as f32).sqrt(), (out_sq / n as f32).sqrt());
        assert!(out < 0.5 * raw, "jitter {out} m after smoothing vs {raw} m");
        // The head then moves 10 cm sideways at 0.5 m/s: followed within 1 cm once it stops
        // and within 2 mm 0.3 s later.
        let start = 90 * frame_ns;
        let mut last = Vec3::ZERO;
        for k in 0..30 {
            let t_ns = start + k * frame_ns;
            let moved = (k as f32 * 0.033 * 0.5).min(0.1);
            t.observe(FaceObservation {
                capture_t_ns: t_ns,
                eyes_m: Some(eyes(0.4).map(|p| p + Vec3::X * moved)),
                confidence: 0.9,
                glasses: None,
            });
            last = t.eyes_at(t_ns, None, eyes).left_m;
            // The head arrives at k = 7 (7 × 33 ms × 0.5 m/s ≥ 10 cm).
            if k == 7 {
                let lag = last.distance(eyes(0.4)[0] + Vec3::X * 0.1);
                println!("still-head jitter {raw:.4} m → {out:.4} m; lag on arrival {lag:.4} m");
                assert!(lag < 0.01, "lagging: {lag} m");
            }
        }
        assert!(last.distance(eyes(0.4)[0] + Vec3::X * 0.1) < 0.002, "{last}");
    }

    #[test]
    fn a_stale_or_unconfident_observation_is_no_face() {
        let mut t = EyeTracker::new(EyeTrackParams::default(), 0.3);
        t.observe(FaceObservation {
            capture_t_ns: 0,
            eyes_m: Some(eyes(0.4)),
            confidence: 0.2,
            glasses: None,
        });
        assert_eq!(t.eyes_at(10 * MS, None, eyes).source, EyeSource::Tilt);
        t.observe(FaceObservation {
            capture_t_ns: 20 * MS,
            eyes_m: Some([Vec3::NAN; 2]),
            confidence: 1.0,
            glasses: None,
        });
        assert_eq!(t.eyes_at(30 * MS, None, eyes).source, EyeSource::Tilt);
        t.observe(FaceObservation {
            capture_t_ns: 40 * MS,
            eyes_m: Some(eyes(0.4)),
            confidence: 1.0,
            glasses: None,
        });
        assert_eq!(t.eyes_at(50 * MS, None, eyes).source, EyeSource::Camera);
        // The camera stopped delivering: after `stale_after_s` the tilt takes over.
        assert_eq!(t.eyes_at(400 * MS, None, eyes).source, EyeSource::Tilt);
    }
}
