//! The per-device state that turns sensor events into what one frame needs: both eyes, their
//! off-axis projections, and the world-fixed light, all in the device frame.
//!
//! **Threading**: a [`Session`] belongs to the render thread. Sensor threads push through the
//! [`SensorInbox`] returned by [`Session::inbox`] (an `Arc`, `Send + Sync`); [`Session::frame`]
//! drains it. Nothing blocks.
//!
//! **Order of work per frame**: drain the inbox (sorted by time) → feed the orientation estimator
//! (the gyroscope/accelerometer/magnetometer fusion by default, the paper's low-pass on request:
//! [`EstimatorChoice`]) →
//! anchor the light the first time a full orientation is known → cyclopean eye from "up" and the
//! flat-angle reference → stereo pair → three projections (left, right, and the cyclopean one for
//! mono rendering).
//!
//! **Face tracking**: camera results given to [`Session::observe_face`] replace the tilt
//! approximation's eyes while a face is seen, carried to the frame's time by the phone's rotation
//! and blended without jumps when the face is lost or found ([`crate::eyetrack`]). Without any
//! camera result the eyes are exactly the tilt approximation's.

use std::sync::Arc;

use glam::{Quat, Vec3};
use thiserror::Error;

use crate::attitude::{LowPassAttitude, OrientationEstimator, device_to_world_from_up};
use crate::calibration::Calibration;
use crate::eyetrack::{EyeSource, EyeTrackParams, EyeTracker, FaceObservation};
use crate::fusion::{FusedOrientation, FusionParams};
use crate::sensors::{Rejection, SensorEvent, SensorInbox, SensorRanges, SensorStats};
use phantogram_geometry::eyes::{EyeModel, EyeModelError, StereoEyes};
use phantogram_geometry::light::WorldLight;
use phantogram_geometry::projection::{DepthRange, OffAxisProjection, ProjectionError};
use phantogram_geometry::screen::{PanelSpec, Screen};
use phantogram_geometry::viewpoint::Viewpoint;

/// Which orientation estimator drives the viewpoint and the light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EstimatorChoice {
    /// The paper's accelerometer (and magnetometer) low-pass, with this time constant in seconds.
    LowPass { tau_s: f32 },
    /// Gyroscope + accelerometer + magnetometer fusion ([`crate::fusion`]).
    Fused(FusionParams),
}

impl EstimatorChoice {
    pub fn build(&self) -> Box<dyn OrientationEstimator> {
        match self {
            Self::LowPass { tau_s } => Box::new(LowPassAttitude::new(*tau_s, *tau_s)),
            Self::Fused(params) => Box::new(FusedOrientation::new(*params)),
        }
    }
}

impl Default for EstimatorChoice {
    fn default() -> Self {
        Self::Fused(FusionParams::default())
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SessionConfig {
    pub screen: Screen,
    pub eyes: EyeModel,
    pub depth: DepthRange,
    pub estimator: EstimatorChoice,
    /// Where the world-fixed light appears when anchored, device frame (towards the light).
    pub light_toward_device: Vec3,
    pub inbox_capacity: usize,
    /// Once a pose was taken as straight on, let it follow slowly the pose the viewer settles
    /// into while no face is tracked (`crate::straight_on`; `None`: it stays where it was set,
    /// as the desktop replays keep it).
    pub straight_on: Option<crate::straight_on::StraightOnParams>,
}

impl Default for SessionConfig {
    fn default() -> Self {
        Self {
            screen: Screen::default(),
            eyes: EyeModel::default(),
            depth: DepthRange::default(),
            estimator: EstimatorChoice::default(),
            light_toward_device: WorldLight::DEFAULT_TOWARD_LIGHT_DEVICE,
            inbox_capacity: SensorInbox::DEFAULT_CAPACITY,
            straight_on: None,
        }
    }
}

#[derive(Debug, Error, PartialEq)]
pub enum SessionError {
    #[error(transparent)]
    EyeModel(#[from] EyeModelError),
    #[error(transparent)]
    Projection(#[from] ProjectionError),
    #[error("no accelerometer reading yet: cannot tell which way is up")]
    NoGravityYet,
}

/// Everything one frame needs, device frame, metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameView {
    /// Time stamp of the newest sensor event taken into account.
    pub sensor_t_ns: Option<i64>,
    pub eyes: StereoEyes,
    pub left: OffAxisProjection,
    pub right: OffAxisProjection,
    /// The cyclopean eye's projection, for mono rendering.
    pub mono: OffAxisProjection,
    /// Unit vector towards the world-fixed light.
    pub toward_light_device: Vec3,
    pub light_anchored: bool,
    /// The device → world orientation this frame used (predicted where asked), if known; world-
    /// fixed things (the environment light) turn with it.
    pub device_to_world: Option<Quat>,
}

impl FrameView {
    pub fn stereo_eyes_m(&self) -> [Vec3; 2] {
        [self.eyes.left_m, self.eyes.right_m]
    }
}

pub struct Session {
    config: SessionConfig,
    inbox: Arc<SensorInbox>,
    estimator: Box<dyn OrientationEstimator>,
    viewpoint: Viewpoint,
    light: WorldLight,
    batch: Vec<SensorEvent>,
    newest_t_ns: Option<i64>,
    eye_tracker: EyeTracker,
    eye_source: EyeSource,
    straight_on: Option<crate::straight_on::StraightOnAdapter>,
    /// "Reduce motion": the view turned by touch, not by tilt or the camera.
    turn_by_touch: Option<crate::turn_by_touch::TurnByTouch>,
    /// The newest accelerometer reading taken (time, specific force in the device frame).
    newest_accel: Option<(i64, Vec3)>,
}

impl std::fmt::Debug for Session {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Session")
            .field("config", &self.config)
            .field("viewpoint", &self.viewpoint)
            .field("light", &self.light)
            .field("newest_t_ns", &self.newest_t_ns)
            .finish_non_exhaustive()
    }
}

impl Session {
    /// A session with the estimator named in `config`.
    pub fn new(config: SessionConfig) -> Result<Self, SessionError> {
        Self::with_estimator(config, config.estimator.build())
    }

    pub fn with_estimator(
        config: SessionConfig,
        estimator: Box<dyn OrientationEstimator>,
    ) -> Result<Self, SessionError> {
        config.eyes.validate()?;
        // Fail early on a depth range no frame could use.
        OffAxisProjection::new(&config.screen, Vec3::Z * config.eyes.viewing_distance_m, config.depth)?;
        Ok(Self {
            inbox: Arc::new(SensorInbox::with_capacity(config.inbox_capacity)),
            light: WorldLight::new(config.light_toward_device),
            config,
            estimator,
            viewpoint: Viewpoint::default(),
            batch: Vec::new(),
            newest_t_ns: None,
            eye_tracker: EyeTracker::new(EyeTrackParams::default(), config.eyes.viewing_distance_m),
            eye_source: EyeSource::Tilt,
            straight_on: config.straight_on.map(crate::straight_on::StraightOnAdapter::new),
            turn_by_touch: None,
            newest_accel: None,
        })
    }

    pub fn config(&self) -> &SessionConfig {
        &self.config
    }

    /// The queue for sensor threads.
    pub fn inbox(&self) -> Arc<SensorInbox> {
        Arc::clone(&self.inbox)
    }

    /// Convenience for single-threaded callers (replay): validate and queue one event.
    pub fn push(&self, event: SensorEvent) -> Result<(), Rejection> {
        self.inbox.push(event)
    }

    pub fn stats(&self) -> SensorStats {
        self.inbox.stats()
    }

    /// Drains the inbox into the estimator; returns how many events were used.
    pub fn update(&mut self) -> usize {
        self.batch.clear();
        self.inbox.drain_into(&mut self.batch);
        for e in &self.batch {
            self.estimator.push(e);
            if e.kind == crate::sensors::SensorKind::Accelerometer {
                let v = Vec3::new(e.value[0], e.value[1], e.value[2]);
                if v.is_finite() && self.newest_accel.is_none_or(|(t, _)| e.t_ns >= t) {
                    self.newest_accel = Some((e.t_ns, v));
                }
            }
        }
        if let Some(last) = self.batch.last() {
            self.newest_t_ns = Some(self.newest_t_ns.map_or(last.t_ns, |t| t.max(last.t_ns)));
        }
        if !self.light.is_anchored() {
            if let Some(q) = self.device_to_world() {
                self.light.anchor(q);
            }
        }
        // The orientation history that carries late camera results to the frame's time.
        if let (Some(t), Some(q)) = (self.newest_t_ns, self.device_to_world()) {
            self.eye_tracker.record_orientation(t, q);
        }
        self.batch.len()
    }

    /// Takes a face-tracking result (from `phantogram::face` or any other tracker): the eyes in the
    /// device frame at the frame's capture time, on the sensor clock.
    pub fn observe_face(&mut self, observation: FaceObservation) {
        self.eye_tracker.observe(observation);
    }

    /// Where the last frame's eyes came from.
    pub fn eye_source(&self) -> EyeSource {
        self.eye_source
    }

    /// The orientation used for the light: the estimator's, or from gravity alone (arbitrary but
    /// fixed heading) when no magnetometer is available.
    fn device_to_world(&self) -> Option<Quat> {
        self.estimator
            .device_to_world()
            .or_else(|| device_to_world_from_up(self.estimator.up_device()?))
    }

    /// The newest accelerometer reading taken in (its time and specific force, device frame,
    /// m/s²): what the hand's own acceleration is read from (the Diorama's bodies feel it).
    pub fn newest_specific_force(&self) -> Option<(i64, Vec3)> {
        self.newest_accel
    }

    pub fn up_device(&self) -> Option<Vec3> {
        self.estimator.up_device()
    }

    /// "Reduce motion" on or off ([`crate::turn_by_touch`]): on, the eyes stay straight on and
    /// only [`Self::turn_by_touch`] turns the view; the light keeps its place of this moment.
    pub fn set_turn_by_touch(&mut self, on: bool) {
        if on == self.turn_by_touch.is_some() {
            return;
        }
        self.update();
        let distance_m = self.eye_tracker.distance_m();
        self.turn_by_touch = on.then(|| crate::turn_by_touch::TurnByTouch::new(self.device_to_world(), distance_m));
    }

    pub fn turning_by_touch(&self) -> bool {
        self.turn_by_touch.is_some()
    }

    /// How far a finger has turned the artifact (right, down; radians), while it does.
    pub fn touch_turn_rad(&self) -> Option<(f32, f32)> {
        self.turn_by_touch.as_ref().map(|t| t.angles_rad())
    }

    /// Turns the artifact by a drag (radians right and down); nothing while the view follows
    /// the tilt.
    pub fn turn_by_touch(&mut self, right_rad: f32, down_rad: f32) {
        if let Some(t) = &mut self.turn_by_touch {
            t.turn(right_rad, down_rad);
        }
    }

    /// Makes the current holding pose count as straight on.
    pub fn calibrate_flat_angle(&mut self) -> Result<(), SessionError> {
        self.update();
        let up = self.estimator.up_device().ok_or(SessionError::NoGravityYet)?;
        if self.viewpoint.calibrate_flat_angle(up) {
            if let Some(a) = &mut self.straight_on {
                a.reset();
            }
            Ok(())
        } else {
            Err(SessionError::NoGravityYet)
        }
    }

    pub fn reset_flat_angle(&mut self) {
        self.viewpoint.reset_flat_angle();
        if let Some(a) = &mut self.straight_on {
            a.reset();
        }
    }

    /// The "up" (device frame) of the pose that counts as straight on, to save with the
    /// calibration; `None` while lying flat is straight on.
    pub fn flat_up_device(&self) -> Option<Vec3> {
        self.viewpoint.flat_up_device()
    }

    /// Restores a saved flat angle ([`Self::flat_up_device`]); `None` resets it. Returns `false`
    /// and changes nothing if `up` is degenerate.
    pub fn set_flat_up_device(&mut self, up: Option<Vec3>) -> bool {
        if let Some(a) = &mut self.straight_on {
            a.reset();
        }
        match up {
            Some(up) => self.viewpoint.calibrate_flat_angle(up),
            None => {
                self.viewpoint.reset_flat_angle();
                true
            }
        }
    }

    /// One step of the straight-on pose's slow re-adaptation (`SessionConfig::straight_on`),
    /// at the newest sensor time, from the held "up" (not a prediction).
    fn adapt_straight_on(&mut self) {
        let (Some(adapter), Some(straight), Some(held), Some(t)) = (
            self.straight_on.as_mut(),
            self.viewpoint.flat_up_device(),
            self.estimator.up_device(),
            self.newest_t_ns,
        ) else {
            return;
        };
        let face = self.eye_source == EyeSource::Camera;
        let adapted = adapter.step(t, straight, held, face);
        if adapted != straight {
            self.viewpoint.calibrate_flat_angle(adapted);
        }
    }

    /// Ties the light's default direction to the room again, at the current pose.
    pub fn recalibrate_light(&mut self) -> Result<(), SessionError> {
        self.update();
        let q = self.device_to_world().ok_or(SessionError::NoGravityYet)?;
        self.light.anchor(q);
        Ok(())
    }

    /// The motion sensors' ranges as the platform declares them (see [`SensorRanges`]).
    pub fn set_sensor_ranges(&mut self, ranges: SensorRanges) {
        self.estimator.set_sensor_ranges(ranges);
    }

    /// After a display rotation or a surface resize.
    pub fn set_screen(&mut self, screen: Screen) {
        self.config.screen = screen;
    }

    pub fn set_eye_model(&mut self, eyes: EyeModel) -> Result<(), SessionError> {
        eyes.validate()?;
        self.config.eyes = eyes;
        self.eye_tracker.set_default_distance_m(eyes.viewing_distance_m);
        // A calibrated distance applies to the view turned by touch too.
        if let Some(t) = &mut self.turn_by_touch {
            t.set_distance_m(eyes.viewing_distance_m);
        }
        Ok(())
    }

    /// Puts a viewer's calibration into the session: IPD and viewing distance (the eye model),
    /// the calibrated pixel density over the platform's `panel` (at the current rotation), and
    /// the flat angle (none: lying flat is straight on). Each of the three is taken or refused
    /// whole (an IPD no eye model takes keeps the old IPD and distance); what is refused is said
    /// in the error, the rest applied.
    pub fn apply_calibration(&mut self, c: &Calibration, panel: PanelSpec) -> Result<(), String> {
        let mut refused = Vec::new();
        let mut eyes = self.config.eyes;
        eyes.ipd_m = c.ipd_m.unwrap_or(eyes.ipd_m);
        eyes.viewing_distance_m = c.viewing_distance_m.unwrap_or(eyes.viewing_distance_m);
        if let Err(e) = self.set_eye_model(eyes) {
            refused.push(e.to_string());
        }
        let panel = match c.density_dpi {
            Some(d) => PanelSpec {
                xdpi: d.x,
                ydpi: d.y,
                ..panel
            },
            None => panel,
        };
        match Screen::new(panel, self.config.screen.rotation()) {
            Ok(screen) => self.set_screen(screen),
            Err(e) => refused.push(format!("calibrated density: {e}")),
        }
        if !self.set_flat_up_device(c.flat_up_device) {
            refused.push("the flat angle's up vector is zero".into());
        }
        match refused.is_empty() {
            true => Ok(()),
            false => Err(refused.join("; ")),
        }
    }

    /// Drains pending sensor events and computes this frame's eyes, projections and light, for the
    /// newest sensor state.
    pub fn frame(&mut self) -> Result<FrameView, SessionError> {
        self.frame_at(None)
    }

    /// As [`Self::frame`], with the orientation predicted forward to `display_t_ns` (the time the
    /// frame will be on screen, in the sensor clock) where the estimator can predict.
    ///
    /// Motion-to-photon budget on a 60 Hz phone, and what prediction covers: sensor sampling
    /// ≤ 5 ms (200 Hz) + event delivery 2–10 ms + waiting for the frame ≤ 16.7 ms + rendering
    /// ≈ 16.7 ms + scan-out ≈ 8 ms: some 40–55 ms from a motion to its photons. The shell passes
    /// the expected presentation time (Choreographer's frame time plus the pipeline depth; Core
    /// Animation's `targetTimestamp`) and the gyroscope carries the orientation over that interval.
    pub fn frame_at(&mut self, display_t_ns: Option<i64>) -> Result<FrameView, SessionError> {
        // A shell's nonsense time (beyond the sensors' range) must not overflow the intervals
        // below: draw as if none were given.
        let display_t_ns = display_t_ns.filter(|&t| crate::sensors::time_in_range(t));
        self.update();
        self.adapt_straight_on();
        let predicted = display_t_ns.and_then(|t| self.estimator.predict_device_to_world(t));
        let up = match predicted {
            Some(q) => Some(q.inverse() * Vec3::Z),
            None => self.estimator.up_device(),
        };
        let device_to_world = match &self.turn_by_touch {
            Some(turned) => turned.device_to_world(),
            None => predicted.or_else(|| self.device_to_world()),
        };
        let cfg = &self.config;
        let (left_m, right_m) = if let Some(turned) = &self.turn_by_touch {
            // Turned by touch: neither the tilt nor the camera moves the eyes.
            self.eye_source = EyeSource::Tilt;
            let eye = turned.eye_m(cfg.screen.right_device(), cfg.screen.up_device());
            let pair = cfg.eyes.stereo_pair(&cfg.screen, eye);
            (pair.left_m, pair.right_m)
        } else {
            let tilt = |distance_m: f32| {
                let pair = cfg
                    .eyes
                    .stereo_pair(&cfg.screen, self.viewpoint.cyclopean_eye_m(up, distance_m));
                [pair.left_m, pair.right_m]
            };
            // Always through the tracker, so that a first camera result blends in from the tilt
            // model's eyes; without one its output is exactly the tilt model's.
            let t_ns = display_t_ns.or(self.newest_t_ns).unwrap_or(0);
            let tracked = self.eye_tracker.eyes_at(t_ns, device_to_world, tilt);
            self.eye_source = tracked.source;
            (tracked.left_m, tracked.right_m)
        };
        let eyes = StereoEyes {
            cyclopean_m: (left_m + right_m) * 0.5,
            left_m,
            right_m,
        };
        let project = |eye| OffAxisProjection::new(&cfg.screen, eye, cfg.depth);
        Ok(FrameView {
            sensor_t_ns: self.newest_t_ns,
            left: project(eyes.left_m)?,
            right: project(eyes.right_m)?,
            mono: project(eyes.cyclopean_m)?,
            eyes,
            toward_light_device: self.light.toward_light_device(device_to_world),
            light_anchored: self.light.is_anchored(),
            device_to_world,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_eyes_replace_the_tilt_eyes_and_blend_in() {
        let mut s = Session::new(SessionConfig::default()).unwrap();
        s.push(SensorEvent::accelerometer(0, Vec3::Z * 9.81)).unwrap();
        let before = s.frame_at(Some(0)).unwrap();
        assert_eq!(s.eye_source(), EyeSource::Tilt);
        // The viewer is 10 cm to the right of and 40 cm from the glass, eyes 60 mm apart.
        let seen = [Vec3::new(0.07, 0.0, 0.4), Vec3::new(0.13, 0.0, 0.4)];
        s.observe_face(FaceObservation {
            capture_t_ns: 0,
            eyes_m: Some(seen),
            confidence: 0.9,
            glasses: None,
        });
        let first = s.frame_at(Some(10_000_000)).unwrap();
        assert_eq!(s.eye_source(), EyeSource::Camera);
        // No jump on the first camera frame: the output starts where the tilt eyes were.
        assert!(first.eyes.left_m.distance(before.eyes.left_m) < 0.01);
        let mut last = first;
        for k in 2..200 {
            s.push(SensorEvent::accelerometer(k * 10_000_000, Vec3::Z * 9.81))
                .unwrap();
            s.observe_face(FaceObservation {
                capture_t_ns: k * 10_000_000,
                eyes_m: Some(seen),
                confidence: 0.9,
                glasses: None,
            });
            last = s.frame_at(Some(k * 10_000_000)).unwrap();
        }
        assert!(last.eyes.left_m.distance(seen[0]) < 1e-4 && last.eyes.right_m.distance(seen[1]) < 1e-4);
        // The stereo pair follows the tracked eyes, and the projection is built from them.
        assert!(last.left.eye_m.distance(seen[0]) < 1e-4, "{:?}", last.left.eye_m);
    }

    #[test]
    fn turned_by_touch_neither_the_tilt_nor_the_camera_moves_the_view() {
        let mut s = Session::new(SessionConfig::default()).unwrap();
        let tilted = |deg: f32| {
            let a = deg.to_radians();
            Vec3::new(0.0, a.sin(), a.cos()) * 9.81
        };
        s.push(SensorEvent::accelerometer(0, tilted(30.0))).unwrap();
        let following = s.frame_at(Some(0)).unwrap();
        s.set_turn_by_touch(true);
        assert!(s.turning_by_touch());
        let still = s.frame_at(Some(0)).unwrap();
        assert!(
            still.eyes.cyclopean_m.normalize().distance(Vec3::Z) < 1e-5,
            "straight on"
        );
        assert!(
            following.eyes.cyclopean_m.normalize().distance(Vec3::Z) > 0.3,
            "the tilt had moved it"
        );
        // The phone tilts, a face is seen: the picture stays.
        for k in 1..100 {
            s.push(SensorEvent::accelerometer(k * 10_000_000, tilted(60.0)))
                .unwrap();
        }
        s.observe_face(FaceObservation {
            capture_t_ns: 990_000_000,
            eyes_m: Some([Vec3::new(0.07, 0.0, 0.4), Vec3::new(0.13, 0.0, 0.4)]),
            confidence: 0.9,
            glasses: None,
        });
        let later = s.frame_at(Some(1_000_000_000)).unwrap();
        assert_eq!(later.eyes, still.eyes);
        assert_eq!(later.toward_light_device, still.toward_light_device, "the light stays");
        assert_eq!(s.eye_source(), EyeSource::Tilt);
        // A drag turns it; off again, the tilt takes over.
        s.turn_by_touch(0.4, 0.0);
        let turned = s.frame_at(Some(1_000_000_000)).unwrap();
        assert!(turned.eyes.cyclopean_m.x < -0.05, "{:?}", turned.eyes.cyclopean_m);
        s.set_turn_by_touch(false);
        s.turn_by_touch(0.4, 0.0);
        let tilt_again = s.frame_at(Some(1_000_000_000)).unwrap();
        assert!(tilt_again.eyes.cyclopean_m.x.abs() < 1e-4 && tilt_again.eyes.cyclopean_m.y > 0.1);
    }

    /// Time stamps from a damaged log or a faulty shell, at the ends of `i64`: each interval the
    /// estimators take from them would overflow (a panic in debug builds, nonsense in release).
    /// Rejected at the inbox, ignored by the tracker and the frame's prediction; what follows
    /// is used as usual.
    #[test]
    fn time_stamps_at_the_ends_of_i64_are_refused_not_overflowed() {
        let mut s = Session::new(SessionConfig::default()).unwrap();
        for t in [i64::MIN, i64::MAX, crate::sensors::MAX_ABS_T_NS + 1] {
            assert_eq!(
                s.push(SensorEvent::gyroscope(t, Vec3::ZERO)),
                Err(crate::sensors::Rejection::TimestampOutOfRange)
            );
            s.observe_face(FaceObservation {
                capture_t_ns: t,
                eyes_m: Some([Vec3::new(-0.03, 0.0, 0.4), Vec3::new(0.03, 0.0, 0.4)]),
                confidence: 0.9,
                glasses: None,
            });
            s.frame_at(Some(t)).unwrap();
        }
        assert_eq!(
            s.eye_source(),
            EyeSource::Tilt,
            "out-of-range camera results are ignored"
        );
        for k in 0..50 {
            s.push(SensorEvent::accelerometer(k * 10_000_000, Vec3::Y * 9.81))
                .unwrap();
            s.push(SensorEvent::gyroscope(k * 10_000_000, Vec3::ZERO)).unwrap();
        }
        let up = s.frame_at(Some(i64::MIN)).unwrap().device_to_world.unwrap().inverse() * Vec3::Z;
        assert!(up.distance(Vec3::Y) < 0.01, "{up}");
        assert_eq!(s.stats().rejected_out_of_range, 3);

        // The estimators on their own (as `phantogram eval` uses them) skip such events too.
        let mut fused = crate::fusion::FusedOrientation::default();
        let mut low_pass = crate::attitude::LowPassAttitude::default();
        for t in [i64::MIN, 0, 10_000_000, i64::MAX] {
            for e in [
                SensorEvent::accelerometer(t, Vec3::Z * 9.81),
                SensorEvent::gyroscope(t, Vec3::ZERO),
            ] {
                fused.push(&e);
                low_pass.push(&e);
            }
        }
        assert_eq!(fused.stats().ignored_non_finite, 4);
        assert!(fused.up_device().is_some_and(|u| u.distance(Vec3::Z) < 1e-3));
        assert!(low_pass.up_device().is_some_and(|u| u.distance(Vec3::Z) < 1e-3));
    }

    /// With `straight_on` configured, a pose taken as straight on follows, over a minute and a
    /// half, the pose the viewer settles into; without it, it stays where it was taken.
    #[test]
    fn the_straight_on_pose_follows_a_settled_pose_only_when_configured() {
        let held = |deg: f32| {
            let a = deg.to_radians();
            Vec3::new(0.0, a.sin(), a.cos())
        };
        for adapt in [true, false] {
            let mut s = Session::new(SessionConfig {
                straight_on: adapt.then(crate::straight_on::StraightOnParams::default),
                ..SessionConfig::default()
            })
            .unwrap();
            s.push(SensorEvent::accelerometer(0, held(35.0) * 9.81)).unwrap();
            s.calibrate_flat_angle().unwrap();
            // 90 s settled at 50°, 100 Hz, a frame every 20 ms.
            for k in 1..=9000i64 {
                s.push(SensorEvent::accelerometer(k * 10_000_000, held(50.0) * 9.81))
                    .unwrap();
                if k % 2 == 0 {
                    s.frame().unwrap();
                }
            }
            let straight = s.flat_up_device().unwrap();
            let to_new = straight.angle_between(held(50.0)).to_degrees();
            let to_old = straight.angle_between(held(35.0)).to_degrees();
            if adapt {
                assert!(to_new < 1.5, "{to_new}° from the settled pose after 90 s");
            } else {
                assert!(to_old < 1e-3, "moved {to_old}° without being asked to");
            }
        }
    }

    #[test]
    fn a_calibration_sets_eyes_density_and_flat_angle_and_names_what_it_refuses() {
        let mut s = Session::new(SessionConfig::default()).unwrap();
        let panel = s.config().screen.panel();
        let up = Vec3::new(0.0, 0.5, 0.8).normalize();
        let c = Calibration {
            ipd_m: Some(0.066),
            viewing_distance_m: Some(0.4),
            density_dpi: Some(glam::Vec2::new(460.0, 455.0)),
            flat_up_device: Some(up),
            ..Calibration::default()
        };
        s.apply_calibration(&c, panel).unwrap();
        assert_eq!(
            (s.config().eyes.ipd_m, s.config().eyes.viewing_distance_m),
            (0.066, 0.4)
        );
        assert_eq!(
            (s.config().screen.panel().xdpi, s.config().screen.panel().ydpi),
            (460.0, 455.0)
        );
        assert_eq!(s.config().screen.panel().width_px, panel.width_px);
        assert!(s.flat_up_device().unwrap().distance(up) < 1e-6);
        // An IPD no eye model takes and a zero "up": both named, the density still applied.
        let bad = Calibration {
            ipd_m: Some(0.5),
            density_dpi: Some(glam::Vec2::new(300.0, 300.0)),
            flat_up_device: Some(Vec3::ZERO),
            ..Calibration::default()
        };
        let refused = s.apply_calibration(&bad, panel).unwrap_err();
        assert!(
            refused.contains("interpupillary") && refused.contains("flat angle"),
            "{refused}"
        );
        assert_eq!(s.config().screen.panel().xdpi, 300.0);
        assert_eq!(
            s.config().eyes.ipd_m,
            0.066,
            "the refused IPD left the eye model as it was"
        );
    }

    #[test]
    fn frame_before_any_sensor_data_is_straight_on() {
        let mut s = Session::new(SessionConfig::default()).unwrap();
        let f = s.frame().unwrap();
        assert_eq!(f.eyes.cyclopean_m, Vec3::new(0.0, 0.0, 0.3));
        assert!(!f.light_anchored);
        assert_eq!(s.calibrate_flat_angle(), Err(SessionError::NoGravityYet));
    }

    #[test]
    fn light_anchors_without_a_magnetometer() {
        let mut s = Session::new(SessionConfig::default()).unwrap();
        s.push(SensorEvent::accelerometer(1, Vec3::Z * 9.81)).unwrap();
        let f = s.frame().unwrap();
        assert!(f.light_anchored);
        assert!(
            f.toward_light_device
                .distance(SessionConfig::default().light_toward_device.normalize())
                < 1e-5
        );
    }

    #[test]
    fn bad_configuration_is_refused() {
        let mut c = SessionConfig::default();
        c.eyes.ipd_m = -1.0;
        assert!(matches!(Session::new(c), Err(SessionError::EyeModel(_))));
        let mut c = SessionConfig::default();
        c.depth.far_m = 0.0;
        assert!(matches!(Session::new(c), Err(SessionError::Projection(_))));
    }
}
