//! Fused orientation from gyroscope, accelerometer and magnetometer.
//!
//! ## Design
//!
//! The structure follows VQF (D. Laidig and T. Seel, "VQF: Highly accurate IMU orientation
//! estimation with bias estimation and magnetic disturbance rejection", Information Fusion 91,
//! 2023), implemented here from the paper's description rather than taken from a crate: the
//! reference implementation is C++/Python, and the phone needs asynchronous, unequal-rate,
//! fault-tolerant input, which a fixed-rate port would not give. The orientation is a product of
//! three parts,
//!
//! `device → world = R_z(δ) ⊗ q_acc ⊗ q_gyr`,
//!
//! * `q_gyr`: strapdown integration of the bias-corrected gyroscope, device → an "almost
//!   inertial" frame that drifts only slowly;
//! * `q_acc`: inclination correction. The accelerometer is rotated into the almost-inertial frame
//!   and low-passed *there* (second-order Butterworth, time constant [`FusionParams::tau_acc_s`]):
//!   gravity is constant in that frame while the hand's accelerations average out, and rotation
//!   is carried by the gyroscope, so the filter costs no lag while the phone turns. Each sample the
//!   correction rotates the filtered vector exactly onto the vertical;
//! * `δ`: heading offset about the vertical, pulled towards magnetic north by the tilt-compensated
//!   magnetometer with time constant [`FusionParams::tau_mag_s`], but only while the field's norm
//!   and dip match a learnt reference (a case magnet or a steel table fails the test, and heading
//!   then holds on the gyroscope). A new field that stays stable for
//!   [`FusionParams::mag_new_field_s`], or any field after [`FusionParams::mag_max_reject_s`], is
//!   adopted as the new reference.
//!
//! Gyroscope bias is estimated as VQF does, by a Kalman filter fed two kinds of measurement: at
//! rest (gyroscope and accelerometer both steady for [`FusionParams::rest_min_s`]) the gyroscope's
//! mean rate, and in motion the rate of the accelerometer's inclination corrections, which undo
//! exactly the drift that the horizontal part of the bias causes. A phone in the hand is rarely
//! at rest, and even the "calibrated" gyroscope of the recorded Nexus 5s keeps a residual bias: on
//! the six phone recordings the in-motion estimate lowered the inclination RMSE from 2.02° to 1.84°
//! on average and below Android's own rotation vector on each of them
//! (`benchmarks/orientation.md`); it uses VQF's published noise parameters, not ones fitted to
//! these recordings.
//!
//! ## Robustness
//!
//! Events are taken one at a time, in time order, from any mix of rates. Non-finite samples and
//! samples whose time stamp does not advance are ignored and counted. Readings are never dropped
//! for being large: the hand's acceleration averages out in the almost-inertial frame only if
//! both of its sides stay in the average. The former rule "ignore readings above 8 g" lost the
//! horizon by 15–21° on held-out BROAD recordings of vigorous motion (inclination RMSE 4.2° and
//! 7.8° against VQF's 0.54° and 0.61°; issue 15), and on the vigorous-motion set
//! (`tests/tests/integration/fusion_vigorous.rs`: 10–16 g shaking and jolts, 700 °/s, ±8 g parts) it gave
//! 13.5° RMSE, 27.8° at worst, and never came back within 1°. Screening instead
//! (`fusion/screen.rs`, where each choice is measured): readings beyond a sensor's range are
//! ignored; readings at its range (declared by the platform, or learnt) are reconstructed from
//! their neighbours; clipping that put back more than a degree's worth of velocity, or any
//! gyroscope clipping, keeps readings out of the filter until the motion calms and then starts a
//! fresh average; isolated spikes are replaced by their neighbours' line. On that set the
//! inclination RMSE is 0.6° and every bout ends back within 1° in at most 1.7 s (keeping clipped
//! readings as they are, as VQF does: 1.85° RMSE and up to 6.8 s); on BROAD's recordings clipped
//! artificially at ±3 g, 0.52° against 0.46° unclipped (kept: 0.97°). Nothing of it fires on the
//! recordings of `$PHANTOGRAM_DATA/imu` but one spike in the phone trials, so they score as
//! before. Readings come out of the screen a few samples late (three for the spike test, a clipped
//! run until two readings follow it); the gyroscope carries the attitude meanwhile.
//!
//! Tried and left out, measured on BROAD's tapping recording: an isolated-spike test with two
//! neighbours a side (the first swing of every tap's ringing passes it: 0.61° → 0.74°); holding
//! the filter at every clipped reading rather than severe clipping only (clipped at ±4 g:
//! 0.60° → 1.26°); a fresh average after any strong motion, clipped or not, 1–4 g (1.59°).
//!
//! A gap in the gyroscope stream is
//! bridged at the mean of the rates on either side (hand motion is smooth over a second); if the
//! gap is long or the rates either side disagree, the inclination filter also restarts with a
//! short averaging window and the heading is averaged afresh, so the estimate recovers within a
//! second or so instead of the filters' time constants. Gaps in the accelerometer or magnetometer alone need
//! no restart: the gyroscope carried the frame.
//! With no gyroscope (none yet, or none for [`FusionParams::gyro_timeout_s`]) the output falls back
//! to the paper's low-pass ([`crate::attitude::LowPassAttitude`]); with no magnetometer the heading
//! is simply not corrected (6-D).
//!
//! Internally f64: integrating thousands of small rotations per minute in f32 would add visible
//! drift, and the cost is negligible.

mod screen;

use glam::{DMat3, DQuat, DVec3, Quat, Vec3};

use self::screen::{Declipper, Pending, Range, RangeVerdict, Reading, Saturation, SpikeWindow};
use crate::attitude::{LowPassAttitude, OrientationEstimator};
use crate::clock::elapsed_s;
use crate::sensors::{SensorEvent, SensorKind};

/// Tuning of [`FusedOrientation`]. The defaults are VQF's published defaults where VQF has the
/// parameter (except [`Self::tau_mag_s`], see there), and chosen for handheld phones otherwise.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FusionParams {
    /// Time constant of the accelerometer low-pass in the almost-inertial frame, s (VQF: 3 s).
    pub tau_acc_s: f64,
    /// Time constant of the magnetometer heading correction, s. VQF uses 9 s; on the 14 BROAD
    /// trials provided the mean heading RMSE was 2.08° at 9 s, 1.67° at 20 s, 1.77° at 40 s and
    /// 1.91° at 80 s (`phantogram eval orientation`), so 20 s: field variations along the path
    /// matter more here than gyroscope drift.
    pub tau_mag_s: f64,
    /// Rest detection: largest gyroscope deviation from its recent mean, rad/s.
    pub rest_gyro_rad_s: f64,
    /// Rest detection: largest accelerometer deviation from its recent mean, m/s².
    pub rest_accel_m_s2: f64,
    /// Rest detection: how long both must stay steady, s.
    pub rest_min_s: f64,
    /// Gyroscope bias: standard deviation of the initial estimate, rad/s (VQF: 0.5 °/s).
    pub bias_sigma_init_rad_s: f64,
    /// Gyroscope bias: time for the estimate's variance to grow from 0 to (0.1 °/s)² without
    /// measurements, s (VQF: 100 s).
    pub bias_forgetting_time_s: f64,
    /// Gyroscope bias: standard deviation of the in-motion measurement (the accelerometer's
    /// inclination correction rate), rad/s (VQF: 0.1 °/s). Zero disables estimation in motion.
    pub bias_sigma_motion_rad_s: f64,
    /// Gyroscope bias: how much less the vertical bias component is pulled towards zero in
    /// motion than the horizontal ones are measured (VQF: 10⁻⁴; the accelerometer cannot see it).
    pub bias_vertical_forgetting_factor: f64,
    /// Gyroscope bias: standard deviation of the at-rest measurement, rad/s (VQF: 0.03 °/s).
    pub bias_sigma_rest_rad_s: f64,
    /// Largest plausible gyroscope bias per axis, rad/s (VQF: 2 °/s); estimates and the bias
    /// filter's measurement errors are clamped to it, and a mean rate beyond it is no rest.
    pub max_bias_rad_s: f64,
    /// Magnetic disturbance: largest relative deviation of the field norm from the reference.
    pub mag_norm_tolerance: f64,
    /// Magnetic disturbance: largest deviation of the dip angle from the reference, rad.
    pub mag_dip_tolerance_rad: f64,
    /// A disturbed field that stays this steady for this long becomes the new reference, s.
    pub mag_new_field_s: f64,
    /// ... and only if the device turned at least this much meanwhile, rad.
    pub mag_new_field_min_rotation_rad: f64,
    /// After rejecting the magnetometer this long, adopt the current field anyway, s.
    pub mag_max_reject_s: f64,
    /// The accelerometer's range per axis, m/s², as the platform declares it (Android's
    /// `Sensor.getMaximumRange()`, through `Engine::set_sensor_ranges`); infinite when unknown,
    /// and the ceiling is then learnt from the readings. Readings beyond it are glitches, readings at it saturated (`fusion/screen.rs`).
    pub accel_range_m_s2: f64,
    /// The gyroscope's range per axis, rad/s, as the platform declares it; infinite when
    /// unknown, and the ceiling is then learnt from the readings (readings beyond ±4000 °/s are
    /// glitches). Readings at the range are saturated: the attitude the gyroscope carried is
    /// then doubtful, and the inclination and heading start afresh once the motion calms.
    pub gyro_range_rad_s: f64,
    /// Longest interval integrated as one ordinary sample, s.
    pub max_gap_s: f64,
    /// Longer gyroscope gaps are bridged at the mean rate on either side; up to this length, and
    /// if the rates either side agree within [`Self::max_bridge_doubt_rad`], the filters carry on,
    /// else they restart, s.
    pub max_bridge_s: f64,
    /// Largest uncertainty |Δω|·Δt/2 of a bridged gap that the filters carry on through, rad.
    pub max_bridge_doubt_rad: f64,
    /// Averaging window after a start or a gap, s.
    pub reinit_window_s: f64,
    /// After a doubtful gap no longer than [`Self::max_bridge_s`], the bridged heading still
    /// counts as this many magnetometer samples in the fresh heading average (two seconds at
    /// 50 Hz): a second of motion cannot have turned it far, while the first magnetometer
    /// samples after the gap carry the local field's errors. After longer gaps the heading is
    /// averaged from scratch.
    pub heading_prior_after_short_gap: u32,
    /// With no gyroscope event for this long, fall back to the low-pass, s.
    pub gyro_timeout_s: f64,
}

impl Default for FusionParams {
    fn default() -> Self {
        Self {
            tau_acc_s: 3.0,
            tau_mag_s: 20.0,
            rest_gyro_rad_s: 2f64.to_radians(),
            rest_accel_m_s2: 0.5,
            rest_min_s: 1.5,
            bias_sigma_init_rad_s: 0.5f64.to_radians(),
            bias_forgetting_time_s: 100.0,
            bias_sigma_motion_rad_s: 0.1f64.to_radians(),
            bias_vertical_forgetting_factor: 1e-4,
            bias_sigma_rest_rad_s: 0.03f64.to_radians(),
            max_bias_rad_s: 2f64.to_radians(),
            mag_norm_tolerance: 0.1,
            mag_dip_tolerance_rad: 10f64.to_radians(),
            mag_new_field_s: 20.0,
            mag_new_field_min_rotation_rad: 90f64.to_radians(),
            mag_max_reject_s: 60.0,
            accel_range_m_s2: f64::INFINITY,
            gyro_range_rad_s: f64::INFINITY,
            max_gap_s: 0.2,
            max_bridge_s: 2.0,
            max_bridge_doubt_rad: 5f64.to_radians(),
            reinit_window_s: 0.5,
            heading_prior_after_short_gap: 100,
            gyro_timeout_s: 0.5,
        }
    }
}

/// Counters of ignored samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FusionStats {
    /// NaN or infinite values, or a time stamp beyond ±[`crate::sensors::MAX_ABS_T_NS`].
    pub ignored_non_finite: u64,
    pub ignored_stale_time: u64,
    /// Accelerometer readings beyond the range (declared, or ±16 g).
    pub ignored_accel_out_of_range: u64,
    /// Accelerometer readings at the range limit (see the module docs).
    pub accel_saturated: u64,
    /// Gyroscope readings at the range limit.
    pub gyro_saturated: u64,
    /// Isolated accelerometer spikes replaced by their neighbours' line.
    pub accel_spikes_replaced: u64,
    /// Fresh inclination averages after saturated readings of either sensor, once the motion
    /// calmed.
    pub restarts_after_saturation: u64,
    /// Gyroscope readings beyond the range (declared, or ±4000 °/s).
    pub ignored_gyro_glitch: u64,
    pub gaps_bridged: u64,
    pub restarts_after_gap: u64,
    pub mag_rejected: u64,
}

/// Second-order Butterworth low-pass on 3-vectors (direct form II transposed), coefficients from
/// the bilinear transform with cut-off `√2 / (2π τ)`, as VQF uses. Starts (and restarts) with a
/// running mean over an averaging window, then continues from that mean as its steady state.
#[derive(Clone, Debug)]
struct Butterworth3 {
    tau_s: f64,
    /// The interval the coefficients were computed for.
    period_s: f64,
    b: [f64; 3],
    a: [f64; 2],
    state: [DVec3; 2],
    mean_sum: DVec3,
    mean_n: u32,
    mean_until_s: f64,
    elapsed_s: f64,
    primed: bool,
}

impl Butterworth3 {
    fn new(tau_s: f64) -> Self {
        let mut f = Self {
            tau_s,
            period_s: 0.0,
            b: [0.0; 3],
            a: [0.0; 2],
            state: [DVec3::ZERO; 2],
            mean_sum: DVec3::ZERO,
            mean_n: 0,
            mean_until_s: 0.0,
            elapsed_s: 0.0,
            primed: false,
        };
        f.set_period(0.01);
        f
    }

    fn set_period(&mut self, period_s: f64) {
        self.period_s = period_s;
        let fc = std::f64::consts::SQRT_2 / (std::f64::consts::TAU * self.tau_s);
        let c = (std::f64::consts::PI * fc * period_s).tan();
        let d = c * c + std::f64::consts::SQRT_2 * c + 1.0;
        let b0 = c * c / d;
        self.b = [b0, 2.0 * b0, b0];
        self.a = [
            2.0 * (c * c - 1.0) / d,
            (1.0 - std::f64::consts::SQRT_2 * c + c * c) / d,
        ];
    }

    /// Starts a running mean lasting `window_s`.
    fn restart(&mut self, window_s: f64) {
        self.mean_sum = DVec3::ZERO;
        self.mean_n = 0;
        self.mean_until_s = window_s;
        self.elapsed_s = 0.0;
        self.primed = false;
    }

    fn update(&mut self, x: DVec3, dt_s: f64) -> DVec3 {
        // Discretise with this sample's own interval: phone time stamps jitter by tens of
        // percent, and a fixed-period filter would mis-weight the samples (measured: 0.01–0.04°
        // worse on every phone recording than per-sample coefficients).
        if dt_s > 0.0 && dt_s != self.period_s {
            self.set_period(dt_s);
        }
        self.elapsed_s += dt_s.max(0.0);
        if !self.primed {
            self.mean_sum += x;
            self.mean_n += 1;
            let mean = self.mean_sum / self.mean_n as f64;
            if self.elapsed_s >= self.mean_until_s {
                // Steady state for a constant input equal to the mean.
                self.state = [mean * (1.0 - self.b[0]), mean * (self.b[2] - self.a[1])];
                self.primed = true;
            }
            return mean;
        }
        let y = self.b[0] * x + self.state[0];
        self.state[0] = self.b[1] * x - self.a[0] * y + self.state[1];
        self.state[1] = self.b[2] * x - self.a[1] * y;
        y
    }
}

/// Gyroscope bias estimation as in VQF: a Kalman filter on the bias (device frame) with two kinds
/// of measurement. At rest the low-passed gyroscope rate is the bias. In motion the inclination
/// correction is the evidence: a bias `b` turns the almost-inertial frame at `R·b` (R: device →
/// 6-D earth), and the accelerometer correction undoes exactly that drift on the horizontal axes,
/// so its rate, plus the part of `R·b̂` already removed, measures the horizontal components of
/// `R·b`. Both sides are low-passed like the accelerometer so they describe the same interval.
/// The vertical component is unobservable from gravity and only weakly held towards zero.
///
/// Covariances are kept in (rad/s)²; VQF scales them to (0.01 °/s)², which changes no gain.
#[derive(Clone, Debug)]
struct BiasEstimator {
    p: DMat3,
    /// Rows of R, low-passed.
    r_lp: [Butterworth3; 3],
    /// `R·b̂` (x and y; z unused), low-passed.
    rb_lp: Butterworth3,
}

impl BiasEstimator {
    fn new(params: &FusionParams) -> Self {
        let mut f = Self {
            p: DMat3::from_diagonal(DVec3::splat(params.bias_sigma_init_rad_s.powi(2))),
            r_lp: std::array::from_fn(|_| Butterworth3::new(params.tau_acc_s)),
            rb_lp: Butterworth3::new(params.tau_acc_s),
        };
        f.restart(params.tau_acc_s);
        f
    }

    /// Restarts the low-passes (with the accelerometer's filter); the bias and its covariance
    /// stay.
    fn restart(&mut self, window_s: f64) {
        for f in &mut self.r_lp {
            f.restart(window_s);
        }
        self.rb_lp.restart(window_s);
    }

    /// One accelerometer step of `dt_s`. `up_before` is the filtered gravity direction in the
    /// 6-D earth frame before this step's correction, `q6` the device → 6-D earth attitude after
    /// it, `rest_rate` the low-passed gyroscope rate when the device is at rest.
    fn update(
        &mut self,
        params: &FusionParams,
        bias: &mut DVec3,
        dt_s: f64,
        up_before: DVec3,
        q6: DQuat,
        rest_rate: Option<DVec3>,
    ) {
        let device_to_earth = DMat3::from_quat(q6);
        let r = device_to_earth.transpose(); // rows of R as columns
        let rb = device_to_earth * *bias;
        let r_lp = DMat3::from_cols(
            self.r_lp[0].update(r.x_axis, dt_s),
            self.r_lp[1].update(r.y_axis, dt_s),
            self.r_lp[2].update(r.z_axis, dt_s),
        )
        .transpose();
        let rb_lp = self.rb_lp.update(rb, dt_s);

        // System noise: the variance grows by (0.1 °/s)² per forgetting time.
        let v = 0.1f64.to_radians().powi(2) * dt_s / params.bias_forgetting_time_s.max(1e-9);
        let p0 = params.bias_sigma_init_rad_s.powi(2);
        for i in 0..3 {
            if self.p.col(i)[i] < p0 {
                self.p.col_mut(i)[i] += v;
            }
        }
        // Measurement noise as VQF derives it from the forgetting rate.
        let w_of = |sigma: f64| {
            let p = sigma * sigma;
            p * p / v.max(f64::MIN_POSITIVE) + p
        };
        let (h, e, w) = if let Some(rate) = rest_rate {
            let w = w_of(params.bias_sigma_rest_rad_s);
            (DMat3::IDENTITY, rate - *bias, DVec3::splat(w))
        } else if params.bias_sigma_motion_rad_s > 0.0 && self.rb_lp.primed && self.r_lp[0].primed {
            let rb_hat = r_lp * *bias;
            let e = DVec3::new(
                -up_before.y / dt_s + rb_lp.x - rb_hat.x,
                up_before.x / dt_s + rb_lp.y - rb_hat.y,
                -rb_hat.z,
            );
            let wm = w_of(params.bias_sigma_motion_rad_s);
            let wv = wm / params.bias_vertical_forgetting_factor.max(1e-10);
            (r_lp, e, DVec3::new(wm, wm, wv))
        } else {
            return;
        };
        let clip = params.max_bias_rad_s;
        let e = e.clamp(DVec3::splat(-clip), DVec3::splat(clip));
        let s = DMat3::from_diagonal(w) + h * self.p * h.transpose();
        if s.determinant().abs() < f64::MIN_POSITIVE {
            return;
        }
        let k = self.p * h.transpose() * s.inverse();
        let next = *bias + k * e;
        if !next.is_finite() {
            return;
        }
        *bias = next.clamp(DVec3::splat(-clip), DVec3::splat(clip));
        self.p -= k * h * self.p;
    }
}

/// `[q]` rotating unit vector `v` onto +z along the shortest arc (VQF's inclination correction).
fn rotation_onto_z(v: DVec3) -> DQuat {
    let w = ((v.z + 1.0) * 0.5).max(0.0).sqrt();
    if w > 1e-6 {
        DQuat::from_xyzw(0.5 * v.y / w, -0.5 * v.x / w, 0.0, w)
    } else {
        DQuat::from_xyzw(1.0, 0.0, 0.0, 0.0)
    }
}

/// Seconds since a stream's previous sample (0 for its first); `None`, counted as stale, when the
/// time stamp does not advance.
fn interval_s(last_t_ns: Option<i64>, t_ns: i64, stats: &mut FusionStats) -> Option<f64> {
    match last_t_ns {
        Some(last) if t_ns <= last => {
            stats.ignored_stale_time += 1;
            None
        }
        Some(last) => Some(elapsed_s(last, t_ns)),
        None => Some(0.0),
    }
}

fn wrap_pi(a: f64) -> f64 {
    let t = (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU);
    t - std::f64::consts::PI
}

fn first_order_gain(dt_s: f64, tau_s: f64) -> f64 {
    if tau_s <= 0.0 { 1.0 } else { -(-dt_s / tau_s).exp_m1() }
}

#[derive(Clone, Debug, Default)]
struct MagReference {
    norm: f64,
    dip_rad: f64,
}

/// The fused estimator. See the module docs.
#[derive(Clone, Debug)]
pub struct FusedOrientation {
    params: FusionParams,
    q_gyr: DQuat,
    q_acc: DQuat,
    delta_rad: f64,
    bias: DVec3,
    bias_est: BiasEstimator,
    acc_lp: Butterworth3,
    acc_range: Range,
    gyr_range: Range,
    declip: Declipper,
    /// Readings the declipper released, reused between events.
    released: Vec<Reading>,
    spikes: SpikeWindow,
    saturation: Saturation,
    acc_ready: bool,
    last_acc_t_ns: Option<i64>,
    last_gyr: Option<(i64, DVec3)>,
    // Rest detection.
    rest_gyr_lp: Option<DVec3>,
    rest_acc_lp: Option<DVec3>,
    rest_gyr_steady_s: f64,
    rest_acc_steady_s: f64,
    // Magnetometer.
    last_mag_t_ns: Option<i64>,
    mag_ref: Option<MagReference>,
    mag_candidate: Option<MagReference>,
    mag_candidate_s: f64,
    rotation_since_candidate_rad: f64,
    mag_reject_s: f64,
    heading_corrections: u32,
    // Fallback without a gyroscope.
    fallback: LowPassAttitude,
    stats: FusionStats,
}

impl Default for FusedOrientation {
    fn default() -> Self {
        Self::new(FusionParams::default())
    }
}

impl FusedOrientation {
    pub fn new(params: FusionParams) -> Self {
        let mut acc_lp = Butterworth3::new(params.tau_acc_s);
        acc_lp.restart(params.tau_acc_s);
        Self {
            params,
            q_gyr: DQuat::IDENTITY,
            q_acc: DQuat::IDENTITY,
            delta_rad: 0.0,
            bias: DVec3::ZERO,
            bias_est: BiasEstimator::new(&params),
            acc_lp,
            acc_range: Range::new(
                params.accel_range_m_s2,
                screen::ASSUMED_MAX_ACCEL_M_S2,
                screen::MIN_ACCEL_RANGE_M_S2,
            ),
            gyr_range: Range::new(
                params.gyro_range_rad_s,
                screen::ASSUMED_MAX_GYRO_RAD_S,
                screen::MIN_GYRO_RANGE_RAD_S,
            ),
            declip: Declipper::default(),
            released: Vec::new(),
            spikes: SpikeWindow::default(),
            saturation: Saturation::default(),
            acc_ready: false,
            last_acc_t_ns: None,
            last_gyr: None,
            rest_gyr_lp: None,
            rest_acc_lp: None,
            rest_gyr_steady_s: 0.0,
            rest_acc_steady_s: 0.0,
            last_mag_t_ns: None,
            mag_ref: None,
            mag_candidate: None,
            mag_candidate_s: 0.0,
            rotation_since_candidate_rad: 0.0,
            mag_reject_s: 0.0,
            heading_corrections: 0,
            fallback: LowPassAttitude::default(),
            stats: FusionStats::default(),
        }
    }

    pub fn params(&self) -> &FusionParams {
        &self.params
    }

    pub fn stats(&self) -> FusionStats {
        self.stats
    }

    /// Current gyroscope bias estimate, rad/s, device frame.
    pub fn gyro_bias(&self) -> DVec3 {
        self.bias
    }

    /// Whether the device is currently considered at rest.
    pub fn at_rest(&self) -> bool {
        self.rest_gyr_steady_s >= self.params.rest_min_s && self.rest_acc_steady_s >= self.params.rest_min_s
    }

    /// Whether the magnetometer is currently being rejected as disturbed.
    pub fn magnetically_disturbed(&self) -> bool {
        self.mag_reject_s > 0.0
    }

    fn gyro_is_live(&self, t_ns: i64) -> bool {
        self.last_gyr
            .is_some_and(|(t, _)| elapsed_s(t, t_ns) <= self.params.gyro_timeout_s)
    }

    fn newest_t_ns(&self) -> Option<i64> {
        [self.last_acc_t_ns, self.last_gyr.map(|g| g.0), self.last_mag_t_ns]
            .into_iter()
            .flatten()
            .max()
    }

    fn fused_f64(&self) -> DQuat {
        (DQuat::from_rotation_z(self.delta_rad) * self.q_acc * self.q_gyr).normalize()
    }

    /// Whether the fused estimate is in use: the gyroscope is live and an accelerometer sample has
    /// set the inclination. Otherwise the paper's low-pass answers.
    fn using_gyro(&self) -> bool {
        self.acc_ready && self.newest_t_ns().is_some_and(|t| self.gyro_is_live(t))
    }

    /// Device → world, f64, as of the newest sample. Without a magnetometer the heading is
    /// arbitrary but steady (6-D). In low-pass fallback it needs a magnetometer, like
    /// [`LowPassAttitude`].
    pub fn device_to_world_f64(&self) -> Option<DQuat> {
        if self.using_gyro() {
            Some(self.fused_f64())
        } else {
            self.fallback.device_to_world().map(|q| q.as_dquat())
        }
    }

    /// The orientation predicted forward to `t_ns` (e.g. the frame's display time) with the last
    /// bias-corrected gyroscope rate; at most [`FusionParams::max_gap_s`] ahead.
    pub fn predict(&self, t_ns: i64) -> Option<Quat> {
        let q = self.device_to_world_f64()?;
        let (Some((t_gyr, w)), true) = (self.last_gyr, self.using_gyro()) else {
            return Some(q.as_quat());
        };
        let ahead_s = elapsed_s(t_gyr, t_ns).clamp(0.0, self.params.max_gap_s);
        Some(
            (q * DQuat::from_scaled_axis((w - self.bias) * ahead_s))
                .normalize()
                .as_quat(),
        )
    }

    /// `q_gyr` carried from the last gyroscope sample to `t_ns` with its rate, so that samples of
    /// the other (asynchronous) sensors are rotated with the attitude of their own time stamp.
    fn q_gyr_at(&self, t_ns: i64) -> DQuat {
        match self.last_gyr {
            Some((t, w)) => {
                let dt = elapsed_s(t, t_ns).clamp(-self.params.max_gap_s, self.params.max_gap_s);
                (self.q_gyr * DQuat::from_scaled_axis((w - self.bias) * dt)).normalize()
            }
            None => self.q_gyr,
        }
    }

    fn push_gyro(&mut self, t_ns: i64, raw: [f32; 3]) {
        let verdict = self.gyr_range.judge(raw);
        if verdict == RangeVerdict::OutOfRange {
            self.stats.ignored_gyro_glitch += 1;
            return;
        }
        let w = DVec3::from_array(raw.map(f64::from));
        if let Some((last_t, _)) = self.last_gyr {
            if t_ns <= last_t {
                self.stats.ignored_stale_time += 1;
                return;
            }
        }
        if matches!(verdict, RangeVerdict::Saturated { .. }) {
            self.stats.gyro_saturated += 1;
            self.saturation.gyro_saturated();
        }
        if let Some((last_t, _)) = self.last_gyr {
            let dt = elapsed_s(last_t, t_ns);
            let prev = self.last_gyr.map_or(w, |(_, p)| p);
            if dt <= self.params.max_gap_s {
                // The sample stands for the interval ending at its time stamp (trapezoidal
                // integration measured 0.15° worse on BROAD: these IMUs average over the
                // preceding interval).
                self.q_gyr = (self.q_gyr * DQuat::from_scaled_axis((w - self.bias) * dt)).normalize();
            } else {
                // A gap. Bridge it at the mean of the rates on either side: hand motion is
                // smooth over a second, and any guess beats assuming the phone stood still.
                self.q_gyr = (self.q_gyr * DQuat::from_scaled_axis((0.5 * (prev + w) - self.bias) * dt)).normalize();
                // The bridge is trustworthy when it is short and the two rates agree (its error is
                // at most about |Δω|·Δt/2); then no filter needs restarting (measured on a phone
                // trial: a 1 s dropout then stays within 1.4° of the undisturbed run, against
                // 6.7° when every gap restarts the filters). Otherwise restart the inclination
                // filter from fresh samples and average the heading afresh, rather than trust a
                // frame that may be far off.
                let doubt_rad = (w - prev).length() * dt * 0.5;
                if dt <= self.params.max_bridge_s && doubt_rad <= self.params.max_bridge_doubt_rad {
                    self.stats.gaps_bridged += 1;
                } else {
                    self.restart_inclination();
                    self.heading_corrections = if dt <= self.params.max_bridge_s {
                        self.heading_corrections.min(self.params.heading_prior_after_short_gap)
                    } else {
                        0
                    };
                    self.stats.restarts_after_gap += 1;
                }
            }
            let dt = dt.min(self.params.max_gap_s);
            self.update_rest_gyro(w, dt);
            self.rotation_since_candidate_rad += ((w - self.bias) * dt).length();
        }
        self.last_gyr = Some((t_ns, w));
    }

    fn update_rest_gyro(&mut self, w: DVec3, dt: f64) {
        let lp = self.rest_gyr_lp.get_or_insert(w);
        *lp += (w - *lp) * first_order_gain(dt, 0.5);
        let lp = *lp;
        if (w - lp).length() < self.params.rest_gyro_rad_s && lp.length() < self.params.max_bias_rad_s {
            self.rest_gyr_steady_s += dt;
        } else {
            self.rest_gyr_steady_s = 0.0;
        }
    }

    /// Starts the inclination filter (and the bias filter's low-passes) from a fresh average.
    fn restart_inclination(&mut self) {
        self.acc_lp.restart(self.params.reinit_window_s);
        self.bias_est.restart(self.params.reinit_window_s);
        self.declip.clear();
        self.spikes.clear();
        self.saturation.clear();
    }

    fn push_accel(&mut self, t_ns: i64, raw: [f32; 3]) {
        let verdict = self.acc_range.judge(raw);
        if verdict == RangeVerdict::OutOfRange {
            self.stats.ignored_accel_out_of_range += 1;
            return;
        }
        let a = DVec3::from_array(raw.map(f64::from));
        let Some(dt) = interval_s(self.last_acc_t_ns, t_ns, &mut self.stats) else {
            return;
        };
        // A gap in this stream alone needs no restart: the gyroscope carried the frame, so the
        // filter's memory of gravity is still valid (long gyroscope gaps restart it there).
        self.last_acc_t_ns = Some(t_ns);
        let dt = dt.min(self.params.max_gap_s);

        // Rest detection on the accelerometer.
        let lp = self.rest_acc_lp.get_or_insert(a);
        *lp += (a - *lp) * first_order_gain(dt, 0.5);
        if (a - *lp).length() < self.params.rest_accel_m_s2 {
            self.rest_acc_steady_s += dt;
        } else {
            self.rest_acc_steady_s = 0.0;
        }

        // Inclination correction from the accelerometer filtered in the almost-inertial frame,
        // which only exists while the gyroscope runs (without it the low-pass fallback answers).
        if !self.gyro_is_live(t_ns) {
            return;
        }
        let pinned = verdict.pinned_axes();
        let saturated = pinned.iter().any(|p| *p);
        if saturated {
            self.stats.accel_saturated += 1;
        }
        let frame_doubtful = self.saturation.frame_doubtful();
        if self
            .saturation
            .update(saturated, a.length(), dt, self.params.reinit_window_s)
        {
            self.restart_inclination();
            if frame_doubtful {
                // As after a doubtful gap: the first magnetometer samples weigh in at once.
                self.heading_corrections = self.heading_corrections.min(self.params.heading_prior_after_short_gap);
            }
            self.stats.restarts_after_saturation += 1;
        }
        if self.saturation.holding(self.params.tau_acc_s) {
            self.declip.clear();
            self.spikes.clear();
            return;
        }
        let q_gyr = self.q_gyr_at(t_ns);
        let reading = Reading {
            t_ns,
            dt_s: dt,
            raw,
            q_gyr,
            pinned,
        };
        let mut released = std::mem::take(&mut self.released);
        released.clear();
        self.declip.push(reading, &mut released);
        if !self.saturation.in_episode() && self.declip.is_idle() {
            self.declip.forget_lost_velocity();
        } else if self.declip.lost_velocity_m_s() >= screen::severe_lost_velocity_m_s(self.params.tau_acc_s) {
            self.saturation.mark_severe();
        }
        for r in released.drain(..) {
            let pending = Pending {
                t_ns: r.t_ns,
                dt_s: r.dt_s,
                inertial: r.q_gyr * DVec3::from_array(r.raw.map(f64::from)),
                q_gyr: r.q_gyr,
            };
            // Each reading is used a few readings late, once its neighbours have said whether it
            // is an isolated spike; the gyroscope carries the attitude meanwhile.
            if let Some((p, spike)) = self.spikes.push(pending) {
                if spike {
                    self.stats.accel_spikes_replaced += 1;
                }
                self.correct_inclination(p.inertial, p.dt_s, p.q_gyr);
            }
        }
        self.released = released;
    }

    /// `a_inertial`: the reading in the almost-inertial frame, `q_gyr` that frame's attitude at
    /// the reading's time stamp.
    fn correct_inclination(&mut self, a_inertial: DVec3, dt: f64, q_gyr: DQuat) {
        let filtered = self.acc_lp.update(a_inertial, dt);
        let Some(up) = (self.q_acc * filtered).try_normalize() else {
            return;
        };
        self.q_acc = (rotation_onto_z(up) * self.q_acc).normalize();
        self.acc_ready = true;
        // Bias evidence only from a settled inclination filter: while it still averages (after a
        // start or a doubtful gap) its corrections measure the initial error, not a drift rate.
        if dt > 0.0 && self.acc_lp.primed {
            let rest_rate = if self.at_rest() { self.rest_gyr_lp } else { None };
            let q6 = self.q_acc * q_gyr;
            self.bias_est
                .update(&self.params, &mut self.bias, dt, up, q6, rest_rate);
        }
    }

    fn push_mag(&mut self, t_ns: i64, m: DVec3) {
        let Some(dt) = interval_s(self.last_mag_t_ns, t_ns, &mut self.stats) else {
            return;
        };
        self.last_mag_t_ns = Some(t_ns);
        let dt = dt.min(self.params.max_gap_s);
        if !self.acc_ready || !self.gyro_is_live(t_ns) {
            return;
        }
        let m_level = self.q_acc * self.q_gyr_at(t_ns) * m; // inclination-corrected, no heading
        let norm = m_level.length();
        if norm < 1e-6 {
            return;
        }
        let dip = (-m_level.z / norm).clamp(-1.0, 1.0).asin();
        let here = MagReference { norm, dip_rad: dip };
        let p = self.params;
        let matches = |r: &MagReference| {
            (norm - r.norm).abs() <= p.mag_norm_tolerance * r.norm && (dip - r.dip_rad).abs() <= p.mag_dip_tolerance_rad
        };

        let reference = self.mag_ref.get_or_insert_with(|| here.clone());
        if matches(reference) {
            // Undisturbed: follow slow changes of the reference, correct the heading.
            let k = first_order_gain(dt, p.tau_mag_s);
            reference.norm += (norm - reference.norm) * k;
            reference.dip_rad += (dip - reference.dip_rad) * k;
            self.mag_reject_s = 0.0;
            self.mag_candidate = None;
        } else {
            self.stats.mag_rejected += 1;
            self.mag_reject_s += dt;
            // Is a new, steady field establishing itself?
            let steady = self.mag_candidate.as_ref().is_some_and(matches);
            if steady {
                self.mag_candidate_s += dt;
                if let Some(c) = &mut self.mag_candidate {
                    let k = first_order_gain(dt, 1.0);
                    c.norm += (norm - c.norm) * k;
                    c.dip_rad += (dip - c.dip_rad) * k;
                }
            } else {
                self.mag_candidate = Some(here.clone());
                self.mag_candidate_s = 0.0;
                self.rotation_since_candidate_rad = 0.0;
            }
            // A field that stayed consistent while the device turned is fixed in the room (an
            // attached magnet turns with the device and would not stay consistent).
            let new_field = self.mag_candidate_s >= p.mag_new_field_s
                && self.rotation_since_candidate_rad >= p.mag_new_field_min_rotation_rad;
            let adopt = new_field || self.mag_reject_s >= p.mag_max_reject_s;
            if !adopt {
                return;
            }
            // A new reference field: average the heading afresh.
            self.mag_ref = Some(here);
            self.mag_candidate = None;
            self.mag_reject_s = 0.0;
            self.heading_corrections = 0;
        }
        // Heading of the field in the levelled frame, clockwise from the y axis; δ makes it north.
        let psi = m_level.x.atan2(m_level.y);
        let err = wrap_pi(psi - self.delta_rad);
        // Average the first samples (fast start), then a first-order correction.
        self.heading_corrections = self.heading_corrections.saturating_add(1);
        let k = (1.0 / self.heading_corrections as f64).max(first_order_gain(dt, p.tau_mag_s));
        self.delta_rad = wrap_pi(self.delta_rad + k * err);
    }
}

impl OrientationEstimator for FusedOrientation {
    fn push(&mut self, event: &SensorEvent) {
        if !event.is_finite() || !event.time_in_range() {
            self.stats.ignored_non_finite += 1;
            return;
        }
        let v = event.vec3().as_dvec3();
        match event.kind {
            SensorKind::Gyroscope => self.push_gyro(event.t_ns, event.vec3().to_array()),
            SensorKind::Accelerometer => {
                self.fallback.push(event);
                self.push_accel(event.t_ns, event.vec3().to_array());
            }
            SensorKind::Magnetometer => {
                self.fallback.push(event);
                self.push_mag(event.t_ns, v);
            }
            _ => {}
        }
    }

    fn up_device(&self) -> Option<Vec3> {
        if self.using_gyro() {
            (self.fused_f64().inverse() * DVec3::Z).as_vec3().try_normalize()
        } else {
            self.fallback.up_device()
        }
    }

    fn device_to_world(&self) -> Option<Quat> {
        self.device_to_world_f64().map(|q| q.as_quat())
    }

    fn predict_device_to_world(&self, t_ns: i64) -> Option<Quat> {
        self.predict(t_ns)
    }

    fn reset(&mut self) {
        *self = Self::new(self.params);
    }

    /// A declared range replaces the learnt ceiling (and a withdrawn one brings learning back).
    fn set_sensor_ranges(&mut self, ranges: crate::sensors::SensorRanges) {
        let accel = ranges.accel_m_s2.map_or(f64::INFINITY, f64::from);
        let gyro = ranges.gyro_rad_s.map_or(f64::INFINITY, f64::from);
        if accel != self.params.accel_range_m_s2 {
            self.params.accel_range_m_s2 = accel;
            self.acc_range = Range::new(accel, screen::ASSUMED_MAX_ACCEL_M_S2, screen::MIN_ACCEL_RANGE_M_S2);
        }
        if gyro != self.params.gyro_range_rad_s {
            self.params.gyro_range_rad_s = gyro;
            self.gyr_range = Range::new(gyro, screen::ASSUMED_MAX_GYRO_RAD_S, screen::MIN_GYRO_RANGE_RAD_S);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::{ImuSpec, simulate, tilt_sweep, tilt_sweep_pose};

    fn run(events: &[SensorEvent]) -> FusedOrientation {
        let mut f = FusedOrientation::default();
        for e in events {
            f.push(e);
        }
        f
    }

    #[test]
    fn butterworth_has_unit_dc_gain_and_starts_from_the_mean() {
        let mut f = Butterworth3::new(3.0);
        f.restart(0.5);
        let mut y = DVec3::ZERO;
        for k in 0..2000 {
            let x = if k < 50 {
                DVec3::X * (1.0 + (k % 2) as f64)
            } else {
                DVec3::X * 1.5
            };
            y = f.update(x, 0.01);
        }
        assert!((y.x - 1.5).abs() < 1e-9, "{y}");
    }

    #[test]
    fn tracks_the_synthetic_sweep() {
        let events = tilt_sweep(&ImuSpec::default());
        let mut f = FusedOrientation::default();
        let mut worst = 0.0f64;
        for e in &events {
            f.push(e);
            if e.kind == SensorKind::GroundTruth && e.t_ns > 2_000_000_000 {
                let truth = e.quat().unwrap().as_dquat();
                let est = f.device_to_world_f64().unwrap();
                worst = worst.max(est.angle_between(truth).to_degrees());
            }
        }
        assert!(worst < 1.0, "worst error {worst}°");
    }

    #[test]
    fn estimates_gyro_bias_at_rest_and_ignores_faults() {
        let bias = DVec3::new(0.01, -0.02, 0.015);
        let pose = |_t: f64| tilt_sweep_pose(0.0);
        let mut events = simulate(&ImuSpec::default(), 20.0, 0, pose);
        for e in &mut events {
            if e.kind == SensorKind::Gyroscope {
                *e = SensorEvent::gyroscope(e.t_ns, e.vec3() + bias.as_vec3());
            }
        }
        // Faults: a shock, a NaN, a repeated time stamp, a gyro glitch.
        // (The spike replaces a reading, so that it would weigh as much as one.)
        let k = events
            .iter()
            .position(|e| e.kind == SensorKind::Accelerometer && e.t_ns > 1_000_000_000)
            .unwrap();
        events[k] = SensorEvent::accelerometer(events[k].t_ns, Vec3::splat(300.0));
        events.insert(200, SensorEvent::gyroscope(events[199].t_ns + 1, Vec3::NAN));
        let dup = events[300];
        events.insert(301, dup);
        events.insert(400, SensorEvent::gyroscope(events[399].t_ns + 1, Vec3::splat(100.0)));
        let f = run(&events);
        assert!(f.at_rest());
        assert!(
            (f.gyro_bias() - bias).length() < 2e-3,
            "bias {} vs {bias}",
            f.gyro_bias()
        );
        let s = f.stats();
        assert_eq!(
            (
                s.ignored_accel_out_of_range,
                s.ignored_non_finite,
                s.ignored_gyro_glitch
            ),
            (1, 1, 1)
        );
        assert!(s.ignored_stale_time >= 1);
        let truth = tilt_sweep_pose(0.0).as_dquat();
        assert!(f.device_to_world_f64().unwrap().angle_between(truth).to_degrees() < 1.0);
    }

    /// Glitches within the accelerometer's range, one reading at a time, while the phone sweeps:
    /// each is replaced by its neighbours' line, and the estimate stays with the clean run's.
    #[test]
    fn isolated_spikes_within_the_range_are_replaced() {
        let clean = tilt_sweep(&ImuSpec::default());
        let mut glitched = clean.clone();
        let mut injected = 0;
        let mut k_acc = 0;
        for e in &mut glitched {
            if e.kind != SensorKind::Accelerometer {
                continue;
            }
            k_acc += 1;
            // Every 0.37 s from 1 s on, 6–12 g in varying directions.
            if k_acc > 100 && k_acc % 37 == 0 {
                let dir = Vec3::new((k_acc as f32).sin(), (k_acc as f32 * 1.7).cos(), 0.5).normalize();
                *e = SensorEvent::accelerometer(e.t_ns, dir * (6.0 + (k_acc % 7) as f32) * 9.81);
                injected += 1;
            }
        }
        // Both runs side by side: the glitched one stays with the clean one all along.
        let (mut f, mut clean_f) = (FusedOrientation::default(), FusedOrientation::default());
        let mut worst = 0.0f64;
        for (e, c) in glitched.iter().zip(&clean) {
            f.push(e);
            clean_f.push(c);
            if let (Some(a), Some(b)) = (f.device_to_world_f64(), clean_f.device_to_world_f64()) {
                worst = worst.max(a.angle_between(b).to_degrees());
            }
        }
        assert!(worst < 0.1, "{worst}° from the clean run");
        assert_eq!(f.stats().accel_spikes_replaced, injected);
        assert_eq!(clean_f.stats().accel_spikes_replaced, 0);
    }

    /// A range the platform declares marks clipping from the first clipped reading; implausible
    /// figures count as undeclared.
    #[test]
    fn a_declared_range_marks_clipping_from_the_first_reading() {
        use crate::sensors::SensorRanges;
        let still = simulate(&ImuSpec::default(), 2.0, 0, |_| Quat::IDENTITY);
        let t = still.last().unwrap().t_ns + 10_000_000;
        let clipped = SensorEvent::accelerometer(t, Vec3::new(8.0 * 9.80665, 0.0, 9.8));
        let saturated = |ranges: SensorRanges| {
            let mut f = FusedOrientation::default();
            f.set_sensor_ranges(ranges);
            for e in &still {
                f.push(e);
            }
            f.push(&clipped);
            f.stats().accel_saturated
        };
        assert_eq!(saturated(SensorRanges::from_platform(8.0 * 9.80665, 34.9)), 1);
        // Learnt, one reading proves nothing.
        assert_eq!(saturated(SensorRanges::default()), 0);
        assert_eq!(SensorRanges::from_platform(0.0, f32::NAN), SensorRanges::default());
        assert_eq!(SensorRanges::from_platform(1e9, 0.1), SensorRanges::default());
        assert_eq!(
            SensorRanges::from_platform(19.6133, 4.3633),
            SensorRanges {
                accel_m_s2: Some(19.6133),
                gyro_rad_s: Some(4.3633)
            }
        );
    }

    /// A phone in the hand is never at rest: the bias must be learnt from the accelerometer's
    /// inclination corrections while it moves (VQF's motion bias estimation).
    fn bias_learnt_in_motion(params: FusionParams) -> (DVec3, DVec3, f64) {
        let bias = DVec3::new(0.01, -0.02, 0.015);
        let pose = |t: f64| {
            let t = t as f32;
            Quat::from_rotation_z(1.2 * (0.9 * t).sin())
                * Quat::from_rotation_x(0.7 + 0.5 * (1.3 * t).sin())
                * Quat::from_rotation_y(0.6 * (1.7 * t).sin())
        };
        let mut events = simulate(
            &ImuSpec {
                mag_hz: 0.0,
                ..ImuSpec::default()
            },
            180.0,
            0,
            pose,
        );
        for e in &mut events {
            if e.kind == SensorKind::Gyroscope {
                *e = SensorEvent::gyroscope(e.t_ns, e.vec3() + bias.as_vec3());
            }
        }
        let mut f = FusedOrientation::new(params);
        let mut worst_incl = 0.0f64;
        let mut ever_at_rest = false;
        for e in &events {
            f.push(e);
            ever_at_rest |= f.at_rest();
            if e.kind == SensorKind::GroundTruth && e.t_ns > 120_000_000_000 {
                let up_truth = e.quat().unwrap().as_dquat().inverse() * DVec3::Z;
                let up = f.up_device().unwrap().as_dvec3();
                worst_incl = worst_incl.max(up.angle_between(up_truth).to_degrees());
            }
        }
        assert!(!ever_at_rest, "the pose must keep moving");
        (f.gyro_bias(), bias, worst_incl)
    }

    #[test]
    fn estimates_gyro_bias_in_motion() {
        let (est, truth, worst_incl) = bias_learnt_in_motion(FusionParams::default());
        assert!((est - truth).length() < 0.2f64.to_radians(), "bias {est} vs {truth}");
        // Without the motion update the bias stays unknown and the inclination suffers.
        let off = FusionParams {
            bias_sigma_motion_rad_s: 0.0,
            ..FusionParams::default()
        };
        let (est_off, _, worst_off) = bias_learnt_in_motion(off);
        assert_eq!(est_off, DVec3::ZERO);
        assert!(worst_incl < 0.5 * worst_off, "{worst_incl}° vs {worst_off}° without");
    }

    #[test]
    fn falls_back_to_the_low_pass_without_a_gyroscope() {
        let spec = ImuSpec {
            gyro_hz: 0.0,
            ..ImuSpec::default()
        };
        let f = run(&simulate(&spec, 2.0, 0, |_| Quat::from_rotation_x(0.5)));
        let up = f.up_device().unwrap();
        let truth = Quat::from_rotation_x(0.5).inverse() * Vec3::Z;
        assert!(up.angle_between(truth).to_degrees() < 1.0);
    }

    #[test]
    fn magnet_does_not_swing_the_heading() {
        // Still phone; from 5 s to 15 s a magnet adds 60 µT along x.
        let spec = ImuSpec::default();
        let mut events = simulate(&spec, 20.0, 0, |_| Quat::IDENTITY);
        for e in &mut events {
            if e.kind == SensorKind::Magnetometer && (5_000_000_000..15_000_000_000).contains(&e.t_ns) {
                *e = SensorEvent::magnetometer(e.t_ns, e.vec3() + Vec3::X * 60.0);
            }
        }
        let mut f = FusedOrientation::default();
        let mut worst = 0.0f64;
        for e in &events {
            f.push(e);
            if e.t_ns > 3_000_000_000 && e.kind == SensorKind::Magnetometer {
                let q = f.device_to_world_f64().unwrap();
                worst = worst.max(q.angle_between(DQuat::IDENTITY).to_degrees());
            }
        }
        assert!(worst < 1.0, "heading swung {worst}°");
        assert!(f.stats().mag_rejected > 0);
    }

    #[test]
    fn prediction_extrapolates_with_the_gyroscope() {
        let w = 1.0; // rad/s about z
        let pose = move |t: f64| Quat::from_rotation_z((w * t) as f32);
        let spec = ImuSpec {
            gyro_noise_rad_s: 0.0,
            accel_noise_m_s2: 0.0,
            mag_hz: 0.0,
            ..ImuSpec::default()
        };
        let f = run(&simulate(&spec, 2.0, 0, pose));
        let now = f.device_to_world_f64().unwrap();
        let ahead = f.predict(2_050_000_000).unwrap().as_dquat();
        let turned = (now.inverse() * ahead).to_axis_angle();
        assert!((turned.1 - 0.05).abs() < 2e-3, "{turned:?}");
    }
}
