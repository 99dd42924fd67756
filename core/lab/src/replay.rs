//! Deterministic replay of a recorded event stream through a [`Session`], the way the desktop tests
//! and the CLI drive the core.
//!
//! Frames fall on a fixed grid of sensor time, `t₀ + k·interval` from the first event's time stamp;
//! a frame is computed once every event up to its time has been pushed. The output therefore
//! depends only on the events and the interval, never on the machine's speed; [`Pace::RealTime`]
//! only adds sleeps between frames.
//!
//! A gap of more than [`MAX_GAP_NS`] in the stream (a recorder paused, a clock reset) moves the
//! grid to the next event instead of emitting the empty frames in between.

use std::time::{Duration, Instant};

use thiserror::Error;

use crate::sensorlog::LogError;
use phantogram_sensing::sensors::{SensorEvent, SensorStats};
use phantogram_sensing::session::{FrameView, Session, SessionError};

/// Longest stretch without events that is filled with frames: one minute.
pub const MAX_GAP_NS: i64 = 60_000_000_000;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pace {
    AsFastAsPossible,
    /// Sleep so that frames come out at `speed` × the recording's pace.
    RealTime {
        speed: f64,
    },
}

#[derive(Debug, Error)]
pub enum ReplayError {
    #[error(transparent)]
    Log(#[from] LogError),
    #[error(transparent)]
    Session(#[from] SessionError),
    #[error("frame interval must be positive, got {0} ns")]
    BadInterval(i64),
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReplaySummary {
    pub events_read: u64,
    pub frames: u64,
    pub first_t_ns: Option<i64>,
    pub last_t_ns: Option<i64>,
    /// The session's inbox counters at the end (accepted, rejected, …).
    pub stats: SensorStats,
}

/// Replays `events` through `session`, calling `on_frame(session, frame_time_ns, view)` at every
/// frame; the callback may act on the session (e.g. calibrate) before the next events.
pub fn replay<I>(
    events: I,
    session: &mut Session,
    interval_ns: i64,
    pace: Pace,
    mut on_frame: impl FnMut(&mut Session, i64, &FrameView),
) -> Result<ReplaySummary, ReplayError>
where
    I: IntoIterator<Item = Result<SensorEvent, LogError>>,
{
    if interval_ns <= 0 {
        return Err(ReplayError::BadInterval(interval_ns));
    }
    let mut summary = ReplaySummary::default();
    let mut next_frame_ns: Option<i64> = None;
    let wall_start = Instant::now();
    let mut emit = |session: &mut Session, t_ns: i64, summary: &mut ReplaySummary| -> Result<(), ReplayError> {
        if let (Pace::RealTime { speed }, Some(t0)) = (pace, summary.first_t_ns) {
            if speed > 0.0 {
                let due = Duration::from_secs_f64(((t_ns - t0) as f64 * 1e-9 / speed).max(0.0));
                if let Some(wait) = due.checked_sub(wall_start.elapsed()) {
                    std::thread::sleep(wait);
                }
            }
        }
        let view = session.frame()?;
        on_frame(session, t_ns, &view);
        summary.frames += 1;
        Ok(())
    };
    for event in events {
        let event = event?;
        summary.events_read += 1;
        summary.first_t_ns.get_or_insert(event.t_ns);
        summary.last_t_ns = Some(summary.last_t_ns.map_or(event.t_ns, |t| t.max(event.t_ns)));
        let next = next_frame_ns.get_or_insert(event.t_ns);
        if event.t_ns - *next > MAX_GAP_NS {
            *next = event.t_ns;
        }
        while *next < event.t_ns {
            let t = *next;
            *next += interval_ns;
            emit(session, t, &mut summary)?;
        }
        // Rejected events are counted by the inbox; replay goes on, as the app would.
        let _ = session.push(event);
    }
    if let (Some(next), Some(last)) = (next_frame_ns, summary.last_t_ns) {
        let mut t = next;
        while t <= last {
            emit(session, t, &mut summary)?;
            t += interval_ns;
        }
    }
    summary.stats = session.stats();
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use phantogram_sensing::session::SessionConfig;

    fn events(times: &[i64]) -> Vec<Result<SensorEvent, LogError>> {
        times
            .iter()
            .map(|&t| Ok(SensorEvent::accelerometer(t, Vec3::Z * 9.81)))
            .collect()
    }

    #[test]
    fn frames_fall_on_a_grid_of_sensor_time() {
        let mut s = Session::new(SessionConfig::default()).unwrap();
        let mut frames = Vec::new();
        let summary = replay(
            events(&[100, 150, 260, 300]),
            &mut s,
            100,
            Pace::AsFastAsPossible,
            |_, t, _| frames.push(t),
        )
        .unwrap();
        assert_eq!(frames, [100, 200, 300]);
        assert_eq!(summary.events_read, 4);
        assert_eq!(summary.stats.accepted, 4);
    }

    #[test]
    fn long_gaps_do_not_flood_frames_and_bad_events_are_counted() {
        let mut s = Session::new(SessionConfig::default()).unwrap();
        let mut n = 0;
        let mut ev = events(&[0, 10, 10, 5, 10 + 3 * MAX_GAP_NS]);
        ev.push(Ok(SensorEvent::accelerometer(10 + 3 * MAX_GAP_NS + 1, Vec3::NAN)));
        let summary = replay(ev, &mut s, 1_000_000, Pace::AsFastAsPossible, |_, _, _| n += 1).unwrap();
        assert!(n < 10, "{n} frames");
        assert_eq!(summary.stats.rejected_duplicate, 1);
        assert_eq!(summary.stats.rejected_backward, 1);
        assert_eq!(summary.stats.rejected_non_finite, 1);
        assert!(matches!(
            replay(events(&[0]), &mut s, 0, Pace::AsFastAsPossible, |_, _, _| {}),
            Err(ReplayError::BadInterval(0))
        ));
    }
}
