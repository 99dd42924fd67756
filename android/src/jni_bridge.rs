//! The JNI bridge: the native methods of `org.phantogram.NativeBridge`
//! (`android/phantogram/src/main/java/org/phantogram/NativeBridge.java`, the one declaration of them,
//! compiled unchanged by the desktop JVM test).
//!
//! * **Handles**: `nativeCreate` returns a `long` owning a [`SharedEngine`]; every other method
//!   takes it first; `nativeDestroy` frees it. `0` is never a live handle and is reported as an
//!   `IllegalStateException`.
//! * **Errors and panics**: every entry point runs inside jni-rs's `with_env`, which catches
//!   panics; our errors become Java exceptions (`IllegalArgumentException` for bad arguments,
//!   `IllegalStateException` for calls in the wrong state, `UnsupportedOperationException` for
//!   what this platform cannot do, `RuntimeException` for load and GPU failures) and a panic a
//!   `RuntimeException` naming it. Nothing unwinds into the JVM. Rejected sensor samples are not
//!   errors (a throwing sensor callback would kill the app): `nativePushSensor` returns `false`.
//! * **Classes** are resolved once, in `JNI_OnLoad` (on the thread that loads the library, whose
//!   class loader sees them), and kept as global references, so throwing works on any thread.
//! * **Threads**: the JVM attaches the threads that call native methods (the sensor looper, the
//!   CameraX executor, the UI thread, the render thread); the bridge never starts threads that
//!   call into Java. **Important:** sensor and camera methods may run concurrently with drawing
//!   and never wait for a frame; `nativeSurfaceDestroyed` waits for a frame in progress and
//!   returns once the native window is released, as `surfaceDestroyed` requires. The caller
//!   guarantees that `nativeDestroy` races no other call on the same handle.

use std::ffi::c_void;
use std::sync::OnceLock;

use jni::errors::ThrowRuntimeExAndDefault;
use jni::objects::{JByteBuffer, JClass, JFloatArray, JIntArray, JObject, JString, JValue};
use jni::refs::Global;
use jni::strings::JNIString;
use jni::sys::{JNI_VERSION_1_6, jboolean, jfloat, jfloatArray, jint, jintArray, jlong, jlongArray};
use jni::{Env, EnvUnowned, JavaVM, jni_str};
use phantogram::anaglyph::Method;
use phantogram::camera::android::{Camera2Characteristics, PixelRect};
use phantogram::camera::{ChromaPlanes, Intrinsics, OwnedFrame};
use phantogram::engine::{Engine, EngineConfig, EngineError, ErrorKind, SharedEngine};
use phantogram::gesture::{Gesture, TouchPhase};
use phantogram::screen::{DisplayRotation, PanelSpec};
use phantogram::surface::DrawOutcome;

/// Which Java exception an error becomes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    IllegalArgument,
    IllegalState,
    Unsupported,
    Runtime,
}

/// An error on its way to Java.
pub(crate) enum Thrown {
    Java(Kind, String),
    /// A JNI call failed (usually an exception is already pending).
    Jni(jni::errors::Error),
}

impl From<jni::errors::Error> for Thrown {
    fn from(e: jni::errors::Error) -> Self {
        Self::Jni(e)
    }
}

impl From<EngineError> for Thrown {
    fn from(e: EngineError) -> Self {
        let kind = match e.kind() {
            ErrorKind::InvalidArgument => Kind::IllegalArgument,
            ErrorKind::InvalidState => Kind::IllegalState,
            ErrorKind::Unsupported => Kind::Unsupported,
            ErrorKind::Load | ErrorKind::Render => Kind::Runtime,
        };
        Self::Java(kind, e.to_string())
    }
}

pub(crate) fn fail(kind: Kind, message: impl Into<String>) -> Thrown {
    Thrown::Java(kind, message.into())
}

/// Exception classes and the classes the bridge makes, resolved in `JNI_OnLoad`.
struct Classes {
    illegal_argument: Global<JClass<'static>>,
    illegal_state: Global<JClass<'static>>,
    unsupported: Global<JClass<'static>>,
    runtime: Global<JClass<'static>>,
    /// `NativeBridge.AccessibilityNode`, found through the app's class loader (only
    /// `JNI_OnLoad`'s thread sees it).
    accessibility_node: Global<JClass<'static>>,
}

static CLASSES: OnceLock<Classes> = OnceLock::new();

fn cache_classes(env: &mut Env) -> jni::errors::Result<Classes> {
    let mut global = |name: &jni::strings::JNIStr| -> jni::errors::Result<Global<JClass<'static>>> {
        let class = env.find_class(name)?;
        env.new_global_ref(class)
    };
    Ok(Classes {
        illegal_argument: global(jni_str!("java/lang/IllegalArgumentException"))?,
        illegal_state: global(jni_str!("java/lang/IllegalStateException"))?,
        unsupported: global(jni_str!("java/lang/UnsupportedOperationException"))?,
        runtime: global(jni_str!("java/lang/RuntimeException"))?,
        accessibility_node: global(jni_str!("org/phantogram/NativeBridge$AccessibilityNode"))?,
    })
}

/// Resolves and caches the classes the bridge throws.
///
/// # Safety
/// Called by the JVM with its own `JavaVM` pointer when the library is loaded.
#[unsafe(no_mangle)]
pub unsafe extern "system" fn JNI_OnLoad(vm: *mut jni::sys::JavaVM, _reserved: *mut c_void) -> jint {
    let outcome = std::panic::catch_unwind(|| {
        // SAFETY: the JVM passes its own, valid `JavaVM` pointer.
        let vm = unsafe { JavaVM::from_raw(vm) };
        vm.attach_current_thread(|env| -> jni::errors::Result<()> {
            let classes = cache_classes(env)?;
            let _ = CLASSES.set(classes);
            Ok(())
        })
    });
    match outcome {
        Ok(Ok(())) => JNI_VERSION_1_6,
        // Loading fails with an `UnsatisfiedLinkError` rather than later with obscure errors.
        _ => jni::sys::JNI_ERR,
    }
}

fn throw(env: &mut Env, kind: Kind, message: &str) -> jni::errors::Result<()> {
    let message = JNIString::from(message);
    match CLASSES.get() {
        Some(c) => {
            let class = match kind {
                Kind::IllegalArgument => &c.illegal_argument,
                Kind::IllegalState => &c.illegal_state,
                Kind::Unsupported => &c.unsupported,
                Kind::Runtime => &c.runtime,
            };
            env.throw_new(class, message)
        }
        // Only if `JNI_OnLoad` did not run (a host loading the library oddly).
        None => env.throw_new(jni_str!("java/lang/RuntimeException"), message),
    }
}

/// Runs one native method's body: errors become Java exceptions (and `T::default()` the return
/// value Java ignores), panics are caught by `with_env` and become a `RuntimeException`.
fn run<'local, T: Default>(
    unowned: &mut EnvUnowned<'local>,
    body: impl FnOnce(&mut Env<'local>) -> Result<T, Thrown>,
) -> T {
    unowned
        .with_env(|env| -> jni::errors::Result<T> {
            match body(env) {
                Ok(v) => Ok(v),
                Err(Thrown::Java(kind, message)) => {
                    throw(env, kind, &message)?;
                    Ok(T::default())
                }
                Err(Thrown::Jni(e)) => Err(e),
            }
        })
        .resolve::<ThrowRuntimeExAndDefault>()
}

/// The engine behind a handle.
///
/// The handle is a `Box<SharedEngine>` leaked by `nativeCreate` and not yet freed (the caller's
/// contract, see the module docs); it is only ever shared, never mutated through this reference.
fn engine<'a>(handle: jlong) -> Result<&'a SharedEngine, Thrown> {
    let ptr = handle as usize as *const SharedEngine;
    // SAFETY: a non-zero handle is a live `Box<SharedEngine>` from `nativeCreate` that
    // `nativeDestroy` has not freed (the Java side's contract); `SharedEngine` is `Sync`.
    unsafe { ptr.as_ref() }.ok_or_else(|| fail(Kind::IllegalState, "the engine was destroyed (handle 0)"))
}

fn optional_string(env: &Env, s: &JString) -> Result<Option<String>, Thrown> {
    if s.is_null() {
        return Ok(None);
    }
    Ok(Some(s.try_to_string(env)?))
}

fn panel(width_px: jint, height_px: jint, xdpi: jfloat, ydpi: jfloat) -> Result<PanelSpec, Thrown> {
    let px = |v: jint, what: &str| {
        u32::try_from(v).map_err(|_| fail(Kind::IllegalArgument, format!("{what} must not be negative, got {v}")))
    };
    Ok(PanelSpec {
        width_px: px(width_px, "panel width")?,
        height_px: px(height_px, "panel height")?,
        xdpi,
        ydpi,
    })
}

fn rotation(value: jint) -> Result<DisplayRotation, Thrown> {
    DisplayRotation::from_android_surface_rotation(value).ok_or_else(|| {
        fail(
            Kind::IllegalArgument,
            format!("rotation must be a Surface.ROTATION_* value (0 to 3), got {value}"),
        )
    })
}

fn size(width: jint, height: jint) -> Result<(u32, u32), Thrown> {
    match (u32::try_from(width), u32::try_from(height)) {
        (Ok(w), Ok(h)) => Ok((w, h)),
        _ => Err(fail(
            Kind::IllegalArgument,
            format!("size must not be negative, got {width}×{height}"),
        )),
    }
}

fn method(name: &str) -> Result<Method, Thrown> {
    name.parse::<Method>()
        .map_err(|e| fail(Kind::IllegalArgument, e.to_string()))
}

#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeCreate<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    model_path: JString<'local>,
    face_models_dir: JString<'local>,
    panel_width_px: jint,
    panel_height_px: jint,
    xdpi: jfloat,
    ydpi: jfloat,
    rotation_value: jint,
    anaglyph: JString<'local>,
    calibration_path: JString<'local>,
    library_dir: JString<'local>,
    bundled_dir: JString<'local>,
    artifact: JString<'local>,
) -> jlong {
    run(&mut env, |env| {
        let config = EngineConfig {
            panel: panel(panel_width_px, panel_height_px, xdpi, ydpi)?,
            rotation: rotation(rotation_value)?,
            method: optional_string(env, &anaglyph)?
                .as_deref()
                .map(method)
                .transpose()?
                .unwrap_or_default(),
            model_path: optional_string(env, &model_path)?.map(Into::into),
            environment_path: None,
            // A room with a sun lights with it (`EngineConfig::sun_from_environment`).
            sun_from_environment: true,
            face_models_dir: optional_string(env, &face_models_dir)?.map(Into::into),
            camera_position_m: None,
            fit: Default::default(),
            floor: true,
            adapt_straight_on: true,
            calibration_path: optional_string(env, &calibration_path)?.map(Into::into),
            artifact: optional_string(env, &artifact)?
                .map(|id| id.parse())
                .transpose()
                .map_err(EngineError::from)?,
            library_dir: optional_string(env, &library_dir)?.map(Into::into),
            bundled_dir: optional_string(env, &bundled_dir)?.map(Into::into),
            // Off at start-up: the settings screen's "Light" switch turns it on (and the
            // calibration file remembers it); the room map's reduction costs a phone CPU time.
            room_light: false,
            side_hints: true,
        };
        let engine = Engine::new(config)?;
        Ok(Box::into_raw(Box::new(SharedEngine::new(engine))) as usize as jlong)
    })
}

#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeDestroy<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
) {
    run(&mut env, |_| {
        let ptr = handle as usize as *mut SharedEngine;
        if !ptr.is_null() {
            // SAFETY: the Box leaked by `nativeCreate`, freed once (the caller's contract).
            drop(unsafe { Box::from_raw(ptr) });
        }
        Ok(())
    })
}

/// `SensorEvent` of `android.hardware.Sensor.TYPE_*` `sensor_type` with its `timestamp` and
/// first values (`w` is NaN when absent). Returns `false` for rejected samples and unused types.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativePushSensor<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    sensor_type: jint,
    timestamp_ns: jlong,
    x: jfloat,
    y: jfloat,
    z: jfloat,
    w: jfloat,
) -> jboolean {
    run(&mut env, |_| {
        let engine = engine(handle)?;
        let values = [x, y, z, w];
        let n = if w.is_nan() { 3 } else { 4 };
        Ok(
            match crate::event_from_android(sensor_type, timestamp_ns, &values[..n]) {
                Some(event) => engine.push_sensor(event).is_ok(),
                None => false,
            },
        )
    })
}

/// A camera frame (CameraX `ImageProxy` in `YUV_420_888`) of the front (`camera` 0: face tracking
/// and the room light) or the rear camera (1: the room light): its Y plane (`planes[0]`, a
/// direct buffer, pixel stride 1) and, for the room light's colour, its Cb and Cr planes
/// (`planes[1]`, `planes[2]`, direct buffers with their shared row and pixel strides; both null
/// for luma only). Copied before returning, so the caller may close the image at once; the core
/// converts to colour on its own thread. Returns `false` when nothing took it (front: face
/// tracking off; rear: the room light off).
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeCameraFrame<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    camera: jint,
    luma: JByteBuffer<'local>,
    width: jint,
    height: jint,
    row_stride: jint,
    cb: JByteBuffer<'local>,
    cr: JByteBuffer<'local>,
    chroma_row_stride: jint,
    chroma_pixel_stride: jint,
    rotation_degrees: jint,
    fx_px: jfloat,
    fy_px: jfloat,
    cx_px: jfloat,
    cy_px: jfloat,
    timestamp_ns: jlong,
) -> jboolean {
    run(&mut env, |env| {
        let engine = engine(handle)?;
        let facing = phantogram::engine::camera_facing(camera.into())?;
        let (width, height) = size(width, height)?;
        let stride = |what: &str, value: jint| {
            usize::try_from(value).map_err(|_| {
                fail(
                    Kind::IllegalArgument,
                    format!("{what} must not be negative, got {value}"),
                )
            })
        };
        let row_stride = stride("row stride", row_stride)?;
        let rotation_cw_deg = u32::try_from(rotation_degrees).map_err(|_| {
            fail(
                Kind::IllegalArgument,
                format!("rotation must be 0, 90, 180 or 270, got {rotation_degrees}"),
            )
        })?;
        let intrinsics = Intrinsics::new(fx_px, fy_px, cx_px, cy_px);
        // SAFETY (for each call below): a direct buffer's memory is valid for its capacity while
        // the buffer is alive, which it is for this call; every plane is copied before returning.
        let luma = unsafe { direct_bytes(env, &luma, "luma") }?;
        let frame = match (cb.is_null(), cr.is_null()) {
            (true, true) => OwnedFrame::luma8(
                width,
                height,
                row_stride,
                luma,
                rotation_cw_deg,
                intrinsics,
                timestamp_ns,
            ),
            (false, false) => {
                // SAFETY: as above.
                let (cb, cr) = unsafe { (direct_bytes(env, &cb, "Cb")?, direct_bytes(env, &cr, "Cr")?) };
                let chroma = ChromaPlanes::separate(
                    cb,
                    cr,
                    stride("chroma row stride", chroma_row_stride)?,
                    stride("chroma pixel stride", chroma_pixel_stride)?,
                );
                OwnedFrame::yuv420(
                    width,
                    height,
                    row_stride,
                    luma,
                    chroma,
                    rotation_cw_deg,
                    intrinsics,
                    timestamp_ns,
                )
                .map_err(|e| fail(Kind::IllegalArgument, e.to_string()))?
            }
            _ => {
                return Err(fail(
                    Kind::IllegalArgument,
                    "give both chroma planes (Cb and Cr) or neither",
                ));
            }
        };
        Ok(engine.camera_frame(facing, frame)?)
    })
}

/// The bytes of a direct buffer, borrowed for the call.
///
/// # Safety
/// The returned slice must not outlive the JNI call that received `buffer` (the Java object
/// keeps the memory alive until then).
unsafe fn direct_bytes<'a>(env: &mut Env<'_>, buffer: &JByteBuffer<'_>, what: &str) -> Result<&'a [u8], Thrown> {
    if buffer.is_null() {
        return Err(fail(Kind::IllegalArgument, format!("the {what} buffer is null")));
    }
    let not_direct = || {
        fail(
            Kind::IllegalArgument,
            format!("the {what} buffer is not a direct buffer"),
        )
    };
    // jni-rs reports a heap buffer's missing address as an error of its own (found by the
    // random-call test: it reached Java as "Rust error: Null pointer …").
    let address = match env.get_direct_buffer_address(buffer) {
        Ok(address) => address,
        Err(jni::errors::Error::NullPtr(_)) => return Err(not_direct()),
        Err(e) => return Err(e.into()),
    };
    let capacity = env.get_direct_buffer_capacity(buffer)?;
    if address.is_null() {
        return Err(not_direct());
    }
    if capacity == 0 {
        return Ok(&[]);
    }
    // SAFETY: the caller keeps the buffer alive for the slice's life; a direct buffer's memory is
    // `capacity` bytes from `address`, which is not null.
    Ok(unsafe { std::slice::from_raw_parts(address, capacity) })
}

/// The exposure of the `camera`'s (0 front, 1 rear) frame captured at `timestampNs` (Camera2's
/// capture result: `SENSOR_EXPOSURE_TIME` in nanoseconds, `SENSOR_SENSITIVITY` as ISO and
/// `LENS_APERTURE` as an f-number, NaN when not reported), which arrives apart from the image;
/// the room light matches it to its frame. Unknown values (0, negative) are ignored (returns
/// `false`).
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeCameraExposure<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    camera: jint,
    timestamp_ns: jlong,
    exposure_time_ns: jlong,
    iso: jint,
    aperture: jfloat,
) -> jboolean {
    run(&mut env, |_| {
        let engine = engine(handle)?;
        let facing = phantogram::engine::camera_facing(camera.into())?;
        Ok(
            match phantogram::camera::Exposure::new(exposure_time_ns as f32 * 1e-9, iso as f32) {
                Some(exposure) => {
                    engine.camera_exposure(facing, timestamp_ns, exposure.with_f_number(aperture));
                    true
                }
                None => false,
            },
        )
    })
}

/// The intrinsics `[fx, fy, cx, cy]` of a `width × height` output image of the camera whose
/// Camera2 characteristics are given as the platform reports them (`phantogram::camera::android`
/// does the maths): `activeArray` and `preCorrection` are `Rect`s as `[left, top, right,
/// bottom]`, `pixelArray` `[width, height]`, `physicalSizeMm` `[width, height]`, `focalLengthMm`
/// NaN when not reported, `lensCalibration` `LENS_INTRINSIC_CALIBRATION` as reported; the
/// optional ones may be `null`. Throws `IllegalArgumentException` when they give no intrinsics.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeCameraIntrinsics<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    active_array: JIntArray<'local>,
    pre_correction: JIntArray<'local>,
    pixel_array: JIntArray<'local>,
    physical_size_mm: JFloatArray<'local>,
    focal_length_mm: jfloat,
    lens_calibration: JFloatArray<'local>,
    width: jint,
    height: jint,
) -> jfloatArray {
    run(&mut env, |env| {
        let rect = |a: Option<[jint; 4]>| {
            a.map(|[left, top, right, bottom]| PixelRect {
                left,
                top,
                right,
                bottom,
            })
        };
        let active_array = rect(leading::<_, 4>(env, &active_array, "activeArray", Length::Exactly)?)
            .ok_or_else(|| fail(Kind::IllegalArgument, "activeArray is null"))?;
        let positive = |v: jint| u32::try_from(v).ok().filter(|&v| v > 0);
        let characteristics = Camera2Characteristics {
            active_array,
            pre_correction_active_array: rect(leading::<_, 4>(env, &pre_correction, "preCorrection", Length::Exactly)?),
            pixel_array_px: leading::<_, 2>(env, &pixel_array, "pixelArray", Length::Exactly)?
                .and_then(|[w, h]| Some([positive(w)?, positive(h)?])),
            physical_size_mm: leading::<_, 2>(env, &physical_size_mm, "physicalSizeMm", Length::Exactly)?,
            focal_length_mm: Some(focal_length_mm).filter(|f| !f.is_nan()),
            lens_intrinsic_calibration: leading::<_, 4>(env, &lens_calibration, "lensCalibration", Length::AtLeast)?,
        };
        let (width, height) = size(width, height)?;
        let k = characteristics
            .image_intrinsics(width, height)
            .map_err(|e| fail(Kind::IllegalArgument, e.to_string()))?;
        let values = [k.fx_px, k.fy_px, k.cx_px, k.cy_px];
        let array = JFloatArray::new(env, values.len())?;
        array.set_region(env, 0, &values)?;
        Ok(array.into_raw())
    })
}

/// How many elements [`leading`] accepts.
#[derive(Clone, Copy, PartialEq)]
enum Length {
    Exactly,
    AtLeast,
}

/// The first `N` elements of a Java array of exactly (or at least) `N`; `None` when it is `null`.
fn leading<T, const N: usize>(
    env: &Env,
    array: &jni::objects::JPrimitiveArray<T>,
    name: &str,
    length: Length,
) -> Result<Option<[T; N]>, Thrown>
where
    T: jni::objects::TypeArray + Copy + Default,
{
    if array.is_null() {
        return Ok(None);
    }
    let len = array.len(env)?;
    let (ok, rule) = match length {
        Length::Exactly => (len == N, ""),
        Length::AtLeast => (len >= N, "at least "),
    };
    if !ok {
        return Err(fail(
            Kind::IllegalArgument,
            format!("{name} must have {rule}{N} elements, got {len}"),
        ));
    }
    let mut out = [T::default(); N];
    array.get_region(env, 0, &mut out)?;
    Ok(Some(out))
}

/// A `MotionEvent` pointer: phase 0 down, 1 move, 2 up, 3 cancel; position in physical pixels;
/// time on the sensor clock. Returns the gesture completed: 0 none, 1 straight on (double tap),
/// 2 light re-anchored (long press), 3 stereo toggled (two-finger tap).
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeTouch<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    phase: jint,
    pointer_id: jint,
    x_px: jfloat,
    y_px: jfloat,
    time_ns: jlong,
) -> jint {
    run(&mut env, |_| {
        let engine = engine(handle)?;
        let phase = TouchPhase::from_code(phase).ok_or_else(|| {
            fail(
                Kind::IllegalArgument,
                format!("touch phase must be 0 to 3, got {phase}"),
            )
        })?;
        Ok(Gesture::code(
            engine.lock().touch(phase, pointer_id, x_px, y_px, time_ns),
        ))
    })
}

/// `SurfaceHolder.Callback.surfaceCreated`/first `surfaceChanged`: draw into `surface` (an
/// `android.view.Surface`) at `width × height` physical pixels. Off Android:
/// `UnsupportedOperationException`.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeSurfaceCreated<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    surface: JObject<'local>,
    width: jint,
    height: jint,
) {
    run(&mut env, |env| {
        let engine = engine(handle)?;
        let (width, height) = size(width, height)?;
        if surface.is_null() {
            return Err(fail(Kind::IllegalArgument, "the surface is null"));
        }
        let window = crate::platform::native_window(env, &surface)?;
        engine.lock().resume_window(window, width, height)?;
        Ok(())
    })
}

/// Draw into an offscreen image instead (tests, snapshots); read it with `nativeReadFrame`.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeResumeOffscreen<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    width: jint,
    height: jint,
) {
    run(&mut env, |_| {
        let (width, height) = size(width, height)?;
        engine(handle)?.lock().resume_offscreen(width, height)?;
        Ok(())
    })
}

/// `surfaceChanged`: new size in physical pixels.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeSurfaceChanged<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    width: jint,
    height: jint,
) {
    run(&mut env, |_| {
        let (width, height) = size(width, height)?;
        engine(handle)?.lock().resize(width, height)?;
        Ok(())
    })
}

/// `surfaceDestroyed`: returns once the native window is released.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeSurfaceDestroyed<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
) {
    run(&mut env, |_| {
        engine(handle)?.lock().suspend();
        Ok(())
    })
}

/// Display metrics or rotation changed (`DisplayMetrics`, `Display.getRotation()`).
/// `IllegalArgumentException` (the screen kept as it was) for no pixels, a density that is not
/// positive, or one that makes a side shorter than 1 mm or longer than 100 m.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeSetDisplay<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    panel_width_px: jint,
    panel_height_px: jint,
    xdpi: jfloat,
    ydpi: jfloat,
    rotation_value: jint,
) {
    run(&mut env, |_| {
        let panel = panel(panel_width_px, panel_height_px, xdpi, ydpi)?;
        let rotation = rotation(rotation_value)?;
        engine(handle)?.lock().set_display(panel, rotation)?;
        Ok(())
    })
}

/// The motion sensors' ranges, `Sensor.getMaximumRange()` of the accelerometer (m/s²) and the
/// gyroscope (rad/s); 0 (or anything implausible) where the sensor is missing.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeSetSensorRanges<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    accel_max_range: jfloat,
    gyro_max_range: jfloat,
) {
    run(&mut env, |_| {
        engine(handle)?
            .lock()
            .set_sensor_ranges(phantogram::sensors::SensorRanges::from_platform(
                accel_max_range,
                gyro_max_range,
            ));
        Ok(())
    })
}

/// `dubois` (default), `dubois-green-magenta`, `dubois-amber-blue`, `half-color`, `optimized`,
/// `gray`, `color` or `mono`.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeSetAnaglyph<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    name: JString<'local>,
) {
    run(&mut env, |env| {
        let engine = engine(handle)?;
        let name =
            optional_string(env, &name)?.ok_or_else(|| fail(Kind::IllegalArgument, "the method name is null"))?;
        engine.lock().set_method(method(&name)?);
        Ok(())
    })
}

/// Draws the frame that will be on screen at `display_time_ns` (sensor clock; negative: no
/// prediction). `true` when drawn, `false` when skipped (no surface, zero size).
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeDrawFrame<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    display_time_ns: jlong,
) -> jboolean {
    run(&mut env, |_| {
        let t = (display_time_ns >= 0).then_some(display_time_ns);
        Ok(engine(handle)?.lock().draw(t)? == DrawOutcome::Presented)
    })
}

/// The last offscreen frame as `[width, height, pixels…]`, pixels as `0xAARRGGBB` (what
/// `Bitmap.createBitmap(int[], …)` takes), rows top to bottom.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeReadFrame<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
) -> jintArray {
    run(&mut env, |env| {
        let engine = engine(handle)?;
        let packed: Vec<jint> = {
            let guard = engine.lock();
            let (w, h, rgba) = guard.last_frame()?;
            let mut packed = Vec::with_capacity(2 + rgba.len() / 4);
            packed.push(w as jint);
            packed.push(h as jint);
            packed.extend(rgba.chunks_exact(4).map(|p| {
                (u32::from(p[3]) << 24 | u32::from(p[0]) << 16 | u32::from(p[1]) << 8 | u32::from(p[2])) as jint
            }));
            packed
        };
        let array = jni::objects::JIntArray::new(env, packed.len())?;
        array.set_region(env, 0, &packed)?;
        Ok(array.into_raw())
    })
}

/// `[framesDrawn, framesSkipped, resumed, suspended, sensorsAccepted, sensorsRejected,
/// cameraFrames, gestures, eyesFromCamera]`.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeStats<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
) -> jlongArray {
    run(&mut env, |env| {
        let s = engine(handle)?.stats();
        let values = [
            s.frames_drawn,
            s.frames_skipped,
            s.resumed,
            s.suspended,
            s.sensors.accepted,
            s.sensors.rejected(),
            s.camera_frames,
            s.gestures,
            u64::from(s.eyes_from_camera),
        ]
        .map(|v| v as jlong);
        let array = jni::objects::JLongArray::new(env, values.len())?;
        array.set_region(env, 0, &values)?;
        Ok(array.into_raw())
    })
}

/// Why the calibration file could not be read, applied or saved, for the app's log; `null` when
/// all is well. The engine runs on regardless.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeCalibrationWarning<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
) -> jni::sys::jstring {
    run(&mut env, |env| {
        let warning = engine(handle)?.lock().calibration_warning().map(str::to_owned);
        Ok(match warning {
            Some(w) => env.new_string(w)?.into_raw(),
            None => std::ptr::null_mut(),
        })
    })
}

/// Imports a file the user opened (its display name and bytes: `.glb`, `.gltf`, `.stl`, `.ply`, `.obj` or `.zip`), in
/// the background; see `nativeImportArtifactFd` for large files.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeImportArtifact<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    name: JString<'local>,
    bytes: jni::objects::JByteArray<'local>,
) {
    run(&mut env, |env| {
        let engine = engine(handle)?;
        let name = optional_string(env, &name)?.ok_or_else(|| fail(Kind::IllegalArgument, "the name is null"))?;
        if bytes.is_null() {
            return Err(fail(Kind::IllegalArgument, "the bytes are null"));
        }
        let data = env.convert_byte_array(&bytes)?;
        if data.is_empty() {
            return Err(fail(Kind::IllegalArgument, "the file is empty"));
        }
        engine.lock().import_artifact(&name, data);
        Ok(())
    })
}

/// Imports the file behind `fd` (`ParcelFileDescriptor.detachFd()` of a `content://` document:
/// the library takes the descriptor over and closes it), read on the loader's thread so that a
/// large scan never passes through the Java heap nor blocks the caller; at most the phone
/// budget's bytes.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeImportArtifactFd<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    name: JString<'local>,
    fd: jint,
) {
    run(&mut env, |env| {
        let engine = engine(handle)?;
        let name = optional_string(env, &name)?.ok_or_else(|| fail(Kind::IllegalArgument, "the name is null"))?;
        let file = crate::owned_fd_file(fd).map_err(|e| fail(Kind::IllegalArgument, format!("{name}: {e}")))?;
        engine
            .lock()
            .import_artifact_from(&name, phantogram::artifacts::FileSource::Reader(Box::new(file)));
        Ok(())
    })
}

/// Starts showing an artifact of the library by id (`builtin:amphora`, `imported:…`).
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeSelectArtifact<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    id: JString<'local>,
) {
    run(&mut env, |env| {
        let engine = engine(handle)?;
        let id = optional_string(env, &id)?.ok_or_else(|| fail(Kind::IllegalArgument, "the id is null"))?;
        let id = id.parse().map_err(EngineError::from)?;
        engine.lock().select_artifact(id);
        Ok(())
    })
}

/// The id of the artifact on screen, to save for `nativeCreate` next time; `null` for a file
/// given by path.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeCurrentArtifact<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
) -> jni::sys::jstring {
    run(&mut env, |env| {
        let id = engine(handle)?
            .lock()
            .model_info()
            .artifact
            .as_ref()
            .map(|a| a.id.to_string());
        Ok(match id {
            Some(id) => env.new_string(id)?.into_raw(),
            None => std::ptr::null_mut(),
        })
    })
}

/// The system's font scale (`Configuration.fontScale`): the core's screens scale their text
/// and controls by it (0.85 to 2, clamped). Call at start and on configuration changes.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeSetTextScale<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    scale: jni::sys::jfloat,
) {
    run(&mut env, |_| Ok(engine(handle)?.lock().set_text_scale(scale)?))
}

/// The app has no camera permission yet and may ask: the core shows its camera page first and
/// asks through `nativeTakeShellRequest` (2) when the user wants the camera.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeCameraPermissionNeeded<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
) {
    run(&mut env, |_| {
        engine(handle)?.lock().camera_permission_needed();
        Ok(())
    })
}

/// Opens the menu (the artifact gallery, opening a file, calibration), as a single tap does.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeOpenMenu<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
) {
    run(&mut env, |_| {
        engine(handle)?.lock().open_menu();
        Ok(())
    })
}

/// The oldest request of the core's screens not yet taken: 0 none, 1 open a file (start
/// `ACTION_OPEN_DOCUMENT`, then `nativeImportArtifactFd`), 2 ask for the camera permission
/// (the core has shown why), 3 or 4 share the view (`nativeSnapshotPng` kind 0 or 1 through
/// the share sheet), 5 or 6 run the rear camera beside the front one where the device can, or
/// stop it (the room light was switched on or off; asked at start too when it is on). Call after
/// each frame.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeTakeShellRequest<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
) -> jint {
    run(&mut env, |_| {
        Ok(engine(handle)?
            .lock()
            .take_shell_request()
            .map_or(0, phantogram::engine::ShellRequest::code))
    })
}

/// `[state, fraction]`: state 0 idle, 1 loading (fraction 0 to 1), 2 the last load failed (the
/// core's banner says why).
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeLoadingState<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
) -> jni::sys::jfloatArray {
    run(&mut env, |env| {
        let values = match engine(handle)?.lock().loading_status() {
            phantogram::engine::LoadStatus::Idle => [0.0, 0.0],
            phantogram::engine::LoadStatus::Loading { fraction, .. } => [1.0, fraction],
            phantogram::engine::LoadStatus::Failed { .. } => [2.0, 0.0],
        };
        let array = jni::objects::JFloatArray::new(env, values.len())?;
        array.set_region(env, 0, &values)?;
        Ok(array.into_raw())
    })
}

/// The current view as PNG bytes for the share sheet: kind 0 the anaglyph as on screen, 1 the
/// stereo pair side by side (left eye on the left).
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeSnapshotPng<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    kind: jint,
) -> jni::sys::jbyteArray {
    run(&mut env, |env| {
        let kind = match kind {
            0 => phantogram::engine::Snapshot::Composed,
            1 => phantogram::engine::Snapshot::SideBySide,
            other => {
                return Err(fail(
                    Kind::IllegalArgument,
                    format!("snapshot kind {other}: expected 0 (anaglyph) or 1 (side by side)"),
                ));
            }
        };
        let png = engine(handle)?.lock().snapshot_png(kind)?;
        Ok(env.byte_array_from_slice(&png)?.into_raw())
    })
}

/// What a screen reader can land on in the last frame, as `NativeBridge.AccessibilityNode`s
/// in reading order (see `phantogram::calibration_ui::accessibility`).
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeAccessibilityNodes<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
) -> jni::sys::jobjectArray {
    run(&mut env, |env| {
        // Copied out so that the engine is not held while Java objects are made.
        let nodes = engine(handle)?.lock().accessibility_nodes().to_vec();
        let class = &CLASSES
            .get()
            .ok_or_else(|| fail(Kind::IllegalState, "the library was loaded without JNI_OnLoad"))?
            .accessibility_node;
        let len = i32::try_from(nodes.len()).map_err(|_| fail(Kind::Runtime, "too many accessibility nodes"))?;
        let array = env.new_object_array(len, class, JObject::null())?;
        for (i, n) in nodes.iter().enumerate() {
            // The same numbers as `NativeBridge.AccessibilityNode`'s ROLE_ and FLAG_ constants.
            let (role, flags) = (n.role as jint, n.flags() as jint);
            // A frame per node: a gallery of many artifacts must not fill the local
            // reference table.
            env.with_local_frame(4, |env| -> Result<(), Thrown> {
                let label = env.new_string(&n.label)?;
                let value = match &n.value {
                    Some(v) => JObject::from(env.new_string(v)?),
                    None => JObject::null(),
                };
                let [left, top, right, bottom] = n.bounds_px;
                let node = env.new_object(
                    class,
                    jni::jni_sig!("(IIIFFFFLjava/lang/String;Ljava/lang/String;)V"),
                    &[
                        JValue::Int(n.id),
                        JValue::Int(role),
                        JValue::Int(flags),
                        JValue::Float(left),
                        JValue::Float(top),
                        JValue::Float(right),
                        JValue::Float(bottom),
                        JValue::Object(&label),
                        JValue::Object(&value),
                    ],
                )?;
                array.set_element(env, i, &node)?;
                Ok(())
            })?;
        }
        Ok(array.into_raw())
    })
}

/// Changes whenever `nativeAccessibilityNodes` would return something else.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeAccessibilityGeneration<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
) -> jlong {
    run(&mut env, |_| {
        // A count of changes: far below i64::MAX in any app's life.
        Ok(engine(handle)?.lock().accessibility_generation() as jlong)
    })
}

/// A screen reader's activation of node `id` (acts in the next frame, as a tap would).
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeAccessibilityClick<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    id: jint,
) -> jboolean {
    run(&mut env, |_| Ok(engine(handle)?.lock().accessibility_click(id)))
}

/// A screen reader's step up (`steps` > 0) or down on slider `id`.
#[unsafe(no_mangle)]
pub extern "system" fn Java_org_phantogram_NativeBridge_nativeAccessibilityAdjust<'local>(
    mut env: EnvUnowned<'local>,
    _class: JClass<'local>,
    handle: jlong,
    id: jint,
    steps: jint,
) -> jboolean {
    run(&mut env, |_| Ok(engine(handle)?.lock().accessibility_adjust(id, steps)))
}

/// Names of the native methods this library implements, for the test that keeps them and
/// `NativeBridge.java` in step.
pub const NATIVE_METHODS: [&str; 32] = [
    "nativeCreate",
    "nativeDestroy",
    "nativePushSensor",
    "nativeCameraFrame",
    "nativeCameraExposure",
    "nativeCameraIntrinsics",
    "nativeTouch",
    "nativeSurfaceCreated",
    "nativeResumeOffscreen",
    "nativeSurfaceChanged",
    "nativeSurfaceDestroyed",
    "nativeSetDisplay",
    "nativeSetAnaglyph",
    "nativeSetSensorRanges",
    "nativeDrawFrame",
    "nativeReadFrame",
    "nativeStats",
    "nativeCalibrationWarning",
    "nativeImportArtifact",
    "nativeImportArtifactFd",
    "nativeCameraPermissionNeeded",
    "nativeSetTextScale",
    "nativeSelectArtifact",
    "nativeCurrentArtifact",
    "nativeOpenMenu",
    "nativeTakeShellRequest",
    "nativeLoadingState",
    "nativeSnapshotPng",
    "nativeAccessibilityNodes",
    "nativeAccessibilityGeneration",
    "nativeAccessibilityClick",
    "nativeAccessibilityAdjust",
];
