//! The Android side of the phantogram core: the JNI bridge the Kotlin shell calls
//! ([`jni_bridge`]), the `Surface` → `ANativeWindow` step (`platform_android.rs`; elsewhere
//! `platform_other.rs`), and the mapping from Android's sensor API to the core's sensor events
//! (below).
//!
//! Built as a cdylib (`libphantogram_android.so`, loaded by `System.loadLibrary`); the desktop
//! JVM test loads the host build of the same library.
//!
//! Why a `SurfaceView` with its holder callbacks and `ndk::NativeWindow` rather than GameActivity
//! through android-activity: the shell stays an ordinary Kotlin Activity (CameraX, the
//! permission flow and Choreographer are plain Android APIs there), the native side needs only
//! `ANativeWindow_fromSurface`, and that code type-checks on this Linux host (ndk-sys's `test`
//! feature), where android-activity stops with a `compile_error!`.
//!
//! Android's sensor frame *is* the core's device frame and its units are the core's (m/s² with
//! gravity, rad/s, µT; `SensorEvent.timestamp` in ns), so values pass through unchanged; only the
//! sensor type numbers need mapping.

use phantogram::glam::{Quat, Vec3};
use phantogram::sensors::{SensorEvent, SensorKind};

pub mod jni_bridge;

#[cfg(any(target_os = "android", feature = "android-typecheck"))]
#[path = "platform_android.rs"]
mod platform;
#[cfg(not(any(target_os = "android", feature = "android-typecheck")))]
#[path = "platform_other.rs"]
mod platform;

/// The file behind a descriptor the shell hands over (`ParcelFileDescriptor.detachFd()`): the
/// descriptor is owned from here on and closed when the file is dropped.
#[cfg(unix)]
pub fn owned_fd_file(fd: i32) -> std::io::Result<std::fs::File> {
    use std::os::fd::{FromRawFd, OwnedFd};
    // SAFETY: `fcntl(F_GETFD)` only reads the descriptor's flags; any integer is a valid
    // argument (a closed or negative one fails with EBADF).
    let open = fd >= 0 && unsafe { libc::fcntl(fd, libc::F_GETFD) } != -1;
    if !open {
        // Owning a closed descriptor would close it (or, by then, someone else's) on drop.
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("file descriptor {fd} is not open"),
        ));
    }
    // SAFETY: the caller's contract (`nativeImportArtifactFd`): `fd` is an open descriptor (just
    // checked) that the caller detached and no longer uses or closes; it is owned by the `File`
    // from here on.
    Ok(std::fs::File::from(unsafe { OwnedFd::from_raw_fd(fd) }))
}

/// `android.hardware.Sensor.TYPE_*` values the shell forwards.
pub mod sensor_type {
    pub const ACCELEROMETER: i32 = 1;
    pub const MAGNETIC_FIELD: i32 = 2;
    pub const GYROSCOPE: i32 = 4;
    pub const LINEAR_ACCELERATION: i32 = 10;
    pub const ROTATION_VECTOR: i32 = 11;
    pub const GAME_ROTATION_VECTOR: i32 = 15;
}

/// The core's kind for an Android sensor type; `None` for types the core does not use.
pub fn sensor_kind(android_type: i32) -> Option<SensorKind> {
    match android_type {
        sensor_type::ACCELEROMETER => Some(SensorKind::Accelerometer),
        sensor_type::MAGNETIC_FIELD => Some(SensorKind::Magnetometer),
        sensor_type::GYROSCOPE => Some(SensorKind::Gyroscope),
        sensor_type::LINEAR_ACCELERATION => Some(SensorKind::LinearAcceleration),
        sensor_type::ROTATION_VECTOR => Some(SensorKind::RotationVector),
        _ => None,
    }
}

/// Builds a core event from an Android `SensorEvent` (`timestamp`, `values`). `None` for unused
/// types or too few values. The rotation vector's `values` are `x, y, z[, w]`; older devices omit
/// `w`, which is then recovered from the unit norm.
pub fn event_from_android(android_type: i32, timestamp_ns: i64, values: &[f32]) -> Option<SensorEvent> {
    let kind = sensor_kind(android_type)?;
    if values.len() < 3 {
        return None;
    }
    let v = Vec3::new(values[0], values[1], values[2]);
    if kind.is_orientation() {
        let w = values
            .get(3)
            .copied()
            .unwrap_or_else(|| (1.0 - v.length_squared()).max(0.0).sqrt());
        Some(SensorEvent::orientation(
            kind,
            timestamp_ns,
            Quat::from_xyzw(v.x, v.y, v.z, w),
        ))
    } else {
        Some(SensorEvent::vector(kind, timestamp_ns, v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_handed_over_descriptor_is_read_and_a_negative_one_refused() {
        use std::io::Read;
        use std::os::fd::IntoRawFd;
        let path = std::env::temp_dir().join(format!("phantogram-fd-{}", std::process::id()));
        std::fs::write(&path, b"glTF bytes").unwrap();
        let fd = std::fs::File::open(&path).unwrap().into_raw_fd();
        let mut text = String::new();
        owned_fd_file(fd).unwrap().read_to_string(&mut text).unwrap();
        assert_eq!(text, "glTF bytes");
        let _ = std::fs::remove_file(&path);
        assert!(owned_fd_file(-1).unwrap_err().to_string().contains("not open"));
        // A descriptor that is not open is refused, not owned (dropping it would close it: std
        // aborts on that, found by the random JNI calls). A number no process has open, rather
        // than one just closed, which another test thread could reopen meanwhile.
        assert!(
            owned_fd_file(i32::MAX - 7)
                .unwrap_err()
                .to_string()
                .contains("not open")
        );
    }

    #[test]
    fn maps_types_and_values() {
        let e = event_from_android(sensor_type::ACCELEROMETER, 42, &[0.0, 0.0, 9.81]).unwrap();
        assert_eq!(
            (e.kind, e.t_ns, e.vec3()),
            (SensorKind::Accelerometer, 42, Vec3::new(0.0, 0.0, 9.81))
        );
        assert!(event_from_android(sensor_type::GAME_ROTATION_VECTOR, 0, &[0.0; 4]).is_none());
        assert!(event_from_android(sensor_type::GYROSCOPE, 0, &[0.0; 2]).is_none());
        // Rotation vector without w: w from the unit norm.
        let half = std::f32::consts::FRAC_PI_4;
        let e = event_from_android(sensor_type::ROTATION_VECTOR, 0, &[half.sin(), 0.0, 0.0]).unwrap();
        assert!(
            e.quat()
                .unwrap()
                .angle_between(Quat::from_rotation_x(std::f32::consts::FRAC_PI_2))
                < 1e-5
        );
    }
}
