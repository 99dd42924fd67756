//! Sensor events and the thread-safe inbox the platform shells push them into.
//!
//! Events carry the sensor's own time stamp in nanoseconds (Android's `SensorEvent.timestamp`,
//! iOS's `CMLogItem.timestamp` converted) and values in the device frame and units of the crate
//! docs. The inbox validates each event as it arrives:
//! non-finite values, time stamps beyond ±[`MAX_ABS_T_NS`], and time stamps that repeat or go
//! backwards *for the same sensor*, are rejected and counted in [`SensorStats`], so a faulty
//! driver cannot corrupt the estimators.
//! Different sensors may interleave freely; [`SensorInbox::drain_into`] returns them sorted by
//! time.
//!
//! **Threading**: `SensorInbox` is `Send + Sync`; share it through an `Arc`. Any number of threads
//! may push while the render thread drains. Each call holds an internal mutex for a few
//! instructions. A poisoned mutex is recovered, since no code path can leave the queue half
//! updated.
//!
//! The queue is bounded ([`SensorInbox::DEFAULT_CAPACITY`]); if the consumer stalls (app paused),
//! the oldest events are dropped and counted, never the newest.

use std::collections::VecDeque;
use std::sync::Mutex;

use glam::{Quat, Vec3};
use thiserror::Error;

/// Which sensor an event comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SensorKind {
    /// m/s², device frame, including gravity (reads +9.81 on z lying face up).
    Accelerometer,
    /// rad/s, device frame, right-handed about each axis.
    Gyroscope,
    /// µT, device frame, calibrated (hard-iron offsets removed) where the platform offers it.
    Magnetometer,
    /// The platform's own fused orientation (Android `ROTATION_VECTOR`, iOS device motion),
    /// as a device → world quaternion. Only for comparison; the estimators do not use it.
    RotationVector,
    /// m/s², device frame, gravity removed (exports such as Sensor Logger's). Not usable for the
    /// viewpoint; kept so that nothing in an import is lost.
    LinearAcceleration,
    /// Reference orientation from motion capture, device → world quaternion. Only in recordings.
    GroundTruth,
}

impl SensorKind {
    pub const ALL: [SensorKind; 6] = [
        SensorKind::Accelerometer,
        SensorKind::Gyroscope,
        SensorKind::Magnetometer,
        SensorKind::RotationVector,
        SensorKind::LinearAcceleration,
        SensorKind::GroundTruth,
    ];

    /// Position in [`Self::ALL`], for per-sensor tables.
    pub fn index(self) -> usize {
        self as usize
    }

    /// Whether the value is a quaternion (x, y, z, w) rather than a vector (x, y, z).
    pub fn is_orientation(self) -> bool {
        matches!(self, SensorKind::RotationVector | SensorKind::GroundTruth)
    }
}

pub use crate::clock::{MAX_ABS_T_NS, time_in_range};

/// One timestamped sample. Vectors use `value[0..3]` (and `value[3] == 0`); orientations store a
/// quaternion as `[x, y, z, w]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorEvent {
    pub t_ns: i64,
    pub kind: SensorKind,
    pub value: [f32; 4],
}

impl SensorEvent {
    pub fn vector(kind: SensorKind, t_ns: i64, v: Vec3) -> Self {
        Self {
            t_ns,
            kind,
            value: [v.x, v.y, v.z, 0.0],
        }
    }

    pub fn orientation(kind: SensorKind, t_ns: i64, q: Quat) -> Self {
        Self {
            t_ns,
            kind,
            value: q.to_array(),
        }
    }

    pub fn accelerometer(t_ns: i64, v: Vec3) -> Self {
        Self::vector(SensorKind::Accelerometer, t_ns, v)
    }

    pub fn gyroscope(t_ns: i64, v: Vec3) -> Self {
        Self::vector(SensorKind::Gyroscope, t_ns, v)
    }

    pub fn magnetometer(t_ns: i64, v: Vec3) -> Self {
        Self::vector(SensorKind::Magnetometer, t_ns, v)
    }

    pub fn vec3(&self) -> Vec3 {
        Vec3::new(self.value[0], self.value[1], self.value[2])
    }

    /// The quaternion of an orientation event, normalised; `None` if it is degenerate.
    pub fn quat(&self) -> Option<Quat> {
        let q = Quat::from_array(self.value);
        let len = q.length();
        (len.is_finite() && len > 1e-6).then(|| q / len)
    }

    pub fn is_finite(&self) -> bool {
        let n = if self.kind.is_orientation() { 4 } else { 3 };
        self.value[..n].iter().all(|v| v.is_finite())
    }

    /// Whether the time stamp is within ±[`MAX_ABS_T_NS`].
    pub fn time_in_range(&self) -> bool {
        time_in_range(self.t_ns)
    }
}

/// The measuring ranges a platform declares for its motion sensors, per axis (Android's
/// `Sensor.getMaximumRange()`; iOS declares none). `None` where not declared or implausible.
/// The fused estimator treats readings at a declared range as saturated from the first one,
/// instead of learning the ceiling (`fusion/screen.rs`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SensorRanges {
    /// Accelerometer, m/s².
    pub accel_m_s2: Option<f32>,
    /// Gyroscope, rad/s.
    pub gyro_rad_s: Option<f32>,
}

impl SensorRanges {
    /// From the platform's figures: a range outside what motion sensors have (accelerometers
    /// about ±2–64 g, gyroscopes ±125–8000 °/s, with a margin below for rounding), zero,
    /// negative or not finite counts as not declared.
    pub fn from_platform(accel_m_s2: f32, gyro_rad_s: f32) -> Self {
        let within = |v: f32, lo: f32, hi: f32| (v.is_finite() && (lo..=hi).contains(&v)).then_some(v);
        Self {
            accel_m_s2: within(accel_m_s2, 1.9 * 9.80665, 64.0 * 9.80665),
            gyro_rad_s: within(gyro_rad_s, 100f32.to_radians(), 8000f32.to_radians()),
        }
    }
}

/// Why the inbox refused an event.
#[derive(Clone, Copy, Debug, Error, PartialEq, Eq)]
pub enum Rejection {
    #[error("sensor value is NaN or infinite")]
    NonFinite,
    #[error("time stamp repeats the previous event of the same sensor")]
    DuplicateTimestamp,
    #[error("time stamp goes backwards for this sensor")]
    BackwardTimestamp,
    #[error("time stamp is beyond ±(2^62 - 1) ns (146 years)")]
    TimestampOutOfRange,
}

/// Counters kept by the inbox; cheap to copy.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SensorStats {
    pub accepted: u64,
    pub rejected_non_finite: u64,
    pub rejected_duplicate: u64,
    pub rejected_backward: u64,
    /// Time stamps beyond ±[`MAX_ABS_T_NS`].
    pub rejected_out_of_range: u64,
    /// Accepted events dropped because the consumer did not drain in time.
    pub dropped_overflow: u64,
}

impl SensorStats {
    pub fn rejected(&self) -> u64 {
        self.rejected_non_finite + self.rejected_duplicate + self.rejected_backward + self.rejected_out_of_range
    }
}

#[derive(Debug)]
struct InboxState {
    queue: VecDeque<SensorEvent>,
    last_t_ns: [Option<i64>; SensorKind::ALL.len()],
    stats: SensorStats,
}

/// Multi-producer, single-consumer queue of validated sensor events.
#[derive(Debug)]
pub struct SensorInbox {
    capacity: usize,
    state: Mutex<InboxState>,
}

impl Default for SensorInbox {
    fn default() -> Self {
        Self::with_capacity(Self::DEFAULT_CAPACITY)
    }
}

impl SensorInbox {
    /// About two seconds of accelerometer, gyroscope and magnetometer at 200 Hz each.
    pub const DEFAULT_CAPACITY: usize = 4096;

    pub fn with_capacity(capacity: usize) -> Self {
        let capacity = capacity.max(1);
        Self {
            capacity,
            state: Mutex::new(InboxState {
                queue: VecDeque::with_capacity(capacity),
                last_t_ns: [None; SensorKind::ALL.len()],
                stats: SensorStats::default(),
            }),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, InboxState> {
        // Every critical section below leaves the state consistent, so a panic elsewhere while
        // holding the lock cannot have broken it: recover instead of propagating the poison.
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Validates and queues one event. Never blocks for longer than a queue append.
    pub fn push(&self, event: SensorEvent) -> Result<(), Rejection> {
        let mut guard = self.lock();
        let s = &mut *guard;
        if !event.is_finite() {
            s.stats.rejected_non_finite += 1;
            return Err(Rejection::NonFinite);
        }
        if !event.time_in_range() {
            s.stats.rejected_out_of_range += 1;
            return Err(Rejection::TimestampOutOfRange);
        }
        let slot = &mut s.last_t_ns[event.kind.index()];
        match *slot {
            Some(last) if event.t_ns == last => {
                s.stats.rejected_duplicate += 1;
                return Err(Rejection::DuplicateTimestamp);
            }
            Some(last) if event.t_ns < last => {
                s.stats.rejected_backward += 1;
                return Err(Rejection::BackwardTimestamp);
            }
            _ => *slot = Some(event.t_ns),
        }
        if s.queue.len() == self.capacity {
            s.queue.pop_front();
            s.stats.dropped_overflow += 1;
        }
        s.queue.push_back(event);
        s.stats.accepted += 1;
        Ok(())
    }

    /// Moves every queued event into `out` (appending), sorted by time stamp; events of equal time
    /// keep their arrival order.
    pub fn drain_into(&self, out: &mut Vec<SensorEvent>) {
        let start = out.len();
        {
            let mut s = self.lock();
            out.extend(s.queue.drain(..));
        }
        out[start..].sort_by_key(|e| e.t_ns);
    }

    pub fn stats(&self) -> SensorStats {
        self.lock().stats
    }

    /// Forgets the per-sensor time stamps (after the platform restarts its sensors, whose clock
    /// may then restart too). Queued events and counters stay.
    pub fn reset_clock(&self) {
        self.lock().last_t_ns = [None; SensorKind::ALL.len()];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    #[test]
    fn rejects_and_counts_bad_events_without_losing_good_ones() {
        let inbox = SensorInbox::default();
        assert!(inbox.push(SensorEvent::accelerometer(10, Vec3::Z)).is_ok());
        assert_eq!(
            inbox.push(SensorEvent::accelerometer(20, Vec3::new(f32::NAN, 0.0, 0.0))),
            Err(Rejection::NonFinite)
        );
        assert_eq!(
            inbox.push(SensorEvent::accelerometer(10, Vec3::Z)),
            Err(Rejection::DuplicateTimestamp)
        );
        assert_eq!(
            inbox.push(SensorEvent::accelerometer(5, Vec3::Z)),
            Err(Rejection::BackwardTimestamp)
        );
        // Another sensor may use an earlier time stamp: sensors interleave.
        assert!(inbox.push(SensorEvent::gyroscope(5, Vec3::ZERO)).is_ok());
        assert!(
            inbox
                .push(SensorEvent::gyroscope(6, Vec3::new(0.0, f32::INFINITY, 0.0)))
                .is_err()
        );
        let mut out = Vec::new();
        inbox.drain_into(&mut out);
        assert_eq!(out.len(), 2);
        assert_eq!(out[0].kind, SensorKind::Gyroscope, "sorted by time");
        let s = inbox.stats();
        assert_eq!(
            (
                s.accepted,
                s.rejected_non_finite,
                s.rejected_duplicate,
                s.rejected_backward
            ),
            (2, 2, 1, 1)
        );
    }

    #[test]
    fn reset_clock_accepts_a_restarted_sensor_clock() {
        let inbox = SensorInbox::default();
        inbox.push(SensorEvent::gyroscope(1_000, Vec3::ZERO)).unwrap();
        assert_eq!(
            inbox.push(SensorEvent::gyroscope(10, Vec3::ZERO)),
            Err(Rejection::BackwardTimestamp)
        );
        inbox.reset_clock();
        assert!(inbox.push(SensorEvent::gyroscope(10, Vec3::ZERO)).is_ok());
        assert_eq!(inbox.stats().rejected_backward, 1, "counters survive the reset");
    }

    #[test]
    fn overflow_drops_the_oldest() {
        let inbox = SensorInbox::with_capacity(3);
        for t in 0..5 {
            inbox.push(SensorEvent::gyroscope(t, Vec3::ZERO)).unwrap();
        }
        let mut out = Vec::new();
        inbox.drain_into(&mut out);
        assert_eq!(out.iter().map(|e| e.t_ns).collect::<Vec<_>>(), [2, 3, 4]);
        assert_eq!(inbox.stats().dropped_overflow, 2);
    }

    #[test]
    fn many_producers_one_consumer() {
        let inbox = Arc::new(SensorInbox::with_capacity(100_000));
        let handles: Vec<_> = [
            SensorKind::Accelerometer,
            SensorKind::Gyroscope,
            SensorKind::Magnetometer,
        ]
        .into_iter()
        .map(|kind| {
            let inbox = Arc::clone(&inbox);
            std::thread::spawn(move || {
                for t in 0..10_000 {
                    inbox.push(SensorEvent::vector(kind, t, Vec3::ONE)).unwrap();
                }
            })
        })
        .collect();
        let mut out = Vec::new();
        while handles.iter().any(|h| !h.is_finished()) {
            inbox.drain_into(&mut out);
        }
        for h in handles {
            h.join().unwrap();
        }
        inbox.drain_into(&mut out);
        assert_eq!(out.len(), 30_000);
        assert_eq!(inbox.stats().accepted, 30_000);
    }
}
