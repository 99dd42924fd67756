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
use phantogram_sensing::clock::{advance_ns, elapsed_ns, elapsed_s};
use phantogram_sensing::sensors::{SensorEvent, SensorStats};
use phantogram_sensing::session::{FrameView, Session, SessionError};

/// Longest stretch without events that is filled with frames: one minute.
pub const MAX_GAP_NS: i64 = 60_000_000_000;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pace {
    AsFastAsPossible,
    /// Sleep so that frames come out at `speed` × the recording's pace; `speed` within
    /// [`Pace::SPEEDS`].
    RealTime {
        speed: f64,
    },
}

impl Pace {
    /// The real-time speed factors a replay accepts: slower than a thousandth, a second of
    /// recording would take a quarter of an hour; faster than a thousandfold, pacing means
    /// nothing next to the time a frame takes.
    pub const SPEEDS: std::ops::RangeInclusive<f64> = 1e-3..=1e3;
}

#[derive(Debug, Error)]
pub enum ReplayError {
    #[error(transparent)]
    Log(#[from] LogError),
    #[error(transparent)]
    Session(#[from] SessionError),
    #[error("frame interval must be positive, got {0} ns")]
    BadInterval(i64),
    #[error("real-time speed factor must be within 0.001..=1000, got {0}")]
    BadSpeed(f64),
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

/// What a replay drives: a bare [`Session`] ([`replay`]), or anything that owns one, such as the
/// `phantogram` crate's `Engine` (the CLI's `render`), through [`drive`].
pub trait Replayed {
    /// Why a frame failed.
    type Error;
    /// One event; rejections are the target's to count (the session's inbox does).
    fn push(&mut self, event: SensorEvent);
    /// The frame at `t_ns`: every event up to it has been pushed.
    fn frame(&mut self, t_ns: i64) -> Result<(), Self::Error>;
}

/// Why [`drive`] stopped.
#[derive(Debug, Error)]
pub enum DriveError<E> {
    #[error(transparent)]
    Log(#[from] LogError),
    #[error("frame interval must be positive, got {0} ns")]
    BadInterval(i64),
    #[error("real-time speed factor must be within 0.001..=1000, got {0}")]
    BadSpeed(f64),
    #[error(transparent)]
    Frame(E),
}

/// Replays `events` into `target`, asking for a frame at every point of the grid (module docs).
/// The summary's `stats` are left at zero: they are the target's.
pub fn drive<I, T>(
    events: I,
    target: &mut T,
    interval_ns: i64,
    pace: Pace,
) -> Result<ReplaySummary, DriveError<T::Error>>
where
    I: IntoIterator<Item = Result<SensorEvent, LogError>>,
    T: Replayed,
{
    if interval_ns <= 0 {
        return Err(DriveError::BadInterval(interval_ns));
    }
    if let Pace::RealTime { speed } = pace
        && !Pace::SPEEDS.contains(&speed)
    {
        return Err(DriveError::BadSpeed(speed));
    }
    let mut summary = ReplaySummary::default();
    let mut next_frame_ns: Option<i64> = None;
    let wall_start = Instant::now();
    let emit = |target: &mut T, t_ns: i64, summary: &mut ReplaySummary| -> Result<(), DriveError<T::Error>> {
        if let (Pace::RealTime { speed }, Some(t0)) = (pace, summary.first_t_ns) {
            // Gaps longer than MAX_GAP_NS are skipped, so `due` stays within hours, but a
            // damaged stream must not panic the conversion either.
            let due = Duration::try_from_secs_f64((elapsed_s(t0, t_ns) / speed).max(0.0)).unwrap_or(Duration::ZERO);
            if let Some(wait) = due.checked_sub(wall_start.elapsed()) {
                std::thread::sleep(wait);
            }
        }
        target.frame(t_ns).map_err(DriveError::Frame)?;
        summary.frames += 1;
        Ok(())
    };
    for event in events {
        let event = event?;
        summary.events_read += 1;
        summary.first_t_ns.get_or_insert(event.t_ns);
        summary.last_t_ns = Some(summary.last_t_ns.map_or(event.t_ns, |t| t.max(event.t_ns)));
        let next = next_frame_ns.get_or_insert(event.t_ns);
        if elapsed_ns(*next, event.t_ns) > MAX_GAP_NS {
            *next = event.t_ns;
        }
        while *next < event.t_ns {
            let t = *next;
            // The grid ends at the last representable time: the event is then the last frame.
            *next = advance_ns(t, interval_ns).unwrap_or(event.t_ns);
            emit(target, t, &mut summary)?;
        }
        // Rejected events are counted by the target; replay goes on, as the app would.
        target.push(event);
    }
    if let (Some(next), Some(last)) = (next_frame_ns, summary.last_t_ns) {
        let mut t = Some(next);
        while let Some(at) = t.filter(|&at| at <= last) {
            emit(target, at, &mut summary)?;
            t = advance_ns(at, interval_ns);
        }
    }
    Ok(summary)
}

/// Replays `events` through `session`, calling `on_frame(session, frame_time_ns, view)` at every
/// frame; the callback may act on the session (e.g. calibrate) before the next events.
pub fn replay<I>(
    events: I,
    session: &mut Session,
    interval_ns: i64,
    pace: Pace,
    on_frame: impl FnMut(&mut Session, i64, &FrameView),
) -> Result<ReplaySummary, ReplayError>
where
    I: IntoIterator<Item = Result<SensorEvent, LogError>>,
{
    struct WithSession<'a, F> {
        session: &'a mut Session,
        on_frame: F,
    }
    impl<F: FnMut(&mut Session, i64, &FrameView)> Replayed for WithSession<'_, F> {
        type Error = SessionError;
        fn push(&mut self, event: SensorEvent) {
            let _ = self.session.push(event);
        }
        fn frame(&mut self, t_ns: i64) -> Result<(), SessionError> {
            let view = self.session.frame()?;
            (self.on_frame)(self.session, t_ns, &view);
            Ok(())
        }
    }
    let mut target = WithSession { session, on_frame };
    let mut summary = drive(events, &mut target, interval_ns, pace).map_err(|e| match e {
        DriveError::Log(e) => ReplayError::Log(e),
        DriveError::BadInterval(i) => ReplayError::BadInterval(i),
        DriveError::BadSpeed(v) => ReplayError::BadSpeed(v),
        DriveError::Frame(e) => ReplayError::Session(e),
    })?;
    summary.stats = target.session.stats();
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

    /// The three-line log that replayed "forever": two stamps 2⁶³ ns apart, whose difference
    /// wrapped to a negative number and slipped past the gap guard. Any stamps at all give a
    /// handful of frames.
    #[test]
    fn stamps_centuries_apart_give_a_few_frames_not_an_endless_run() {
        for times in [
            [-(1i64 << 62), 1i64 << 62],
            [i64::MIN, i64::MAX],
            [i64::MAX - 5, i64::MAX],
            [i64::MIN, i64::MIN + 1],
        ] {
            let mut s = Session::new(SessionConfig::default()).unwrap();
            let mut n = 0u64;
            let summary = replay(
                events(&times),
                &mut s,
                100_000_000,
                Pace::AsFastAsPossible,
                |_, _, _| {
                    n += 1;
                    assert!(n < 100, "{times:?}: runaway replay");
                },
            )
            .unwrap();
            assert!(summary.frames <= 3, "{times:?}: {} frames", summary.frames);
        }
    }

    #[test]
    fn real_time_speeds_outside_the_range_are_refused_not_slept_on() {
        let mut s = Session::new(SessionConfig::default()).unwrap();
        for speed in [1e-30, 0.0, -1.0, f64::NAN, f64::INFINITY, 1e9] {
            let result = replay(
                events(&[0, 1_000_000]),
                &mut s,
                1_000_000,
                Pace::RealTime { speed },
                |_, _, _| {},
            );
            assert!(matches!(result, Err(ReplayError::BadSpeed(_))), "{speed}: {result:?}");
        }
        let ok = replay(
            events(&[0, 1_000_000]),
            &mut s,
            1_000_000,
            Pace::RealTime { speed: 1000.0 },
            |_, _, _| {},
        );
        assert!(ok.is_ok(), "{ok:?}");
    }
}
