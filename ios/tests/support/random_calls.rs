//! Random call sequences through the C ABI (`ios/include/phantogram.h`), read from bytes: sensors
//! with any time stamps and values, camera frames of any shape, touches, display and sensor-range
//! changes, anaglyph names, offscreen lifecycles and draws, read-back into buffers of any size,
//! the menu and the screen reader's nodes (snapshots read and freed, activations and slider steps
//! on any id), stats and error messages. Every call returns a status; none may panic, hang or
//! corrupt memory.
//!
//! Shared (with `#[path]`) by the seeded test `tests/random_calls.rs`, which every `cargo test`
//! runs (so the workspace's clippy and tests keep it compiling), and by the coverage-guided fuzz
//! target `fuzz/fuzz_targets/c_abi.rs`. (The JNI bridge drives the same `SharedEngine` and the
//! same `Engine` calls; its argument conversion has its own random calls:
//! `android/tests/java/RandomCalls.java`.)

use std::ffi::CString;

use phantogram_ios::ffi::*;

/// Reads the input as typed fields; past its end, zeros.
pub struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        let n = N.min(self.0.len());
        out[..n].copy_from_slice(&self.0[..n]);
        self.0 = &self.0[n..];
        out
    }
    fn u8(&mut self) -> u8 {
        self.take::<1>()[0]
    }
    fn i32(&mut self) -> i32 {
        i32::from_le_bytes(self.take())
    }
    fn i64(&mut self) -> i64 {
        i64::from_le_bytes(self.take())
    }
    fn f32(&mut self) -> f32 {
        f32::from_le_bytes(self.take())
    }
    fn f64(&mut self) -> f64 {
        f64::from_le_bytes(self.take())
    }
    fn small(&mut self, max: u32) -> u32 {
        u32::from(u16::from_le_bytes(self.take())) % (max + 1)
    }
}

/// Every status is an acceptable answer to random input but one: `Panic` is a panic the boundary
/// caught, still a bug.
fn check(status: PgStatus) {
    assert_ne!(status, PgStatus::Panic, "a call panicked: {}", last_error());
}

/// `pg_last_error`'s message.
fn last_error() -> String {
    let mut message = [0 as std::ffi::c_char; 512];
    // SAFETY: a writable buffer of the size passed.
    unsafe {
        pg_last_error(message.as_mut_ptr(), message.len());
        std::ffi::CStr::from_ptr(message.as_ptr())
            .to_string_lossy()
            .into_owned()
    }
}

/// Up to 64 calls on the engine `e`, read from `data` (a byte selects the call, the following
/// bytes its arguments; past the end, zeros).
///
/// # Safety
/// `e` must be a live engine from `pg_engine_create`, not destroyed while this runs.
pub unsafe fn run(e: *const PgEngine, data: &[u8]) {
    let mut b = Bytes(data);
    let mut pixels = vec![0u8; 64 * 1024];
    // At most 64 calls per input.
    for _ in 0..64 {
        if b.0.is_empty() {
            break;
        }
        // SAFETY (every call): `e` is a live handle; pointers are null or valid for the sizes
        // passed; strings are NUL-terminated.
        unsafe {
            match b.u8() % 19 {
                0 => check(pg_push_accelerometer(e, b.f64(), b.f64(), b.f64(), b.f64())),
                1 => check(pg_push_gyroscope(e, b.f64(), b.f64(), b.f64(), b.f64())),
                2 => check(pg_push_magnetometer(e, b.f64(), b.f64(), b.f64(), b.f64())),
                3 => check(pg_push_device_motion(e, b.f64(), b.f64(), b.f64(), b.f64(), b.f64())),
                4 => check(pg_push_sensor_si(e, b.i32(), b.i64(), b.f32(), b.f32(), b.f32())),
                5 => {
                    let (w, h) = (b.small(96), b.small(96));
                    let stride = (w as usize + b.small(16) as usize).max(1);
                    let luma = vec![b.u8(); stride * h as usize];
                    // Colour half the time: an interleaved CbCr plane of its own stride, as
                    // large as that stride and the luma's height say (the ABI's contract).
                    let colour = b.u8() % 2 == 0;
                    let cbcr_stride = (w as usize + b.small(16) as usize).max(1);
                    let cbcr = vec![b.u8(); cbcr_stride * (h as usize).div_ceil(2)];
                    let (cbcr_ptr, cbcr_stride) = if colour {
                        (cbcr.as_ptr(), cbcr_stride)
                    } else {
                        (std::ptr::null(), 0)
                    };
                    check(pg_camera_frame(
                        e,
                        b.small(3),
                        luma.as_ptr(),
                        w,
                        h,
                        stride,
                        cbcr_ptr,
                        cbcr_stride,
                        b.small(360),
                        b.f32(),
                        b.f32(),
                        b.f32(),
                        b.f32(),
                        b.f64(),
                        b.f64(),
                        b.f64(),
                        b.f64(),
                    ));
                }
                6 => {
                    let mut gesture = 0i32;
                    check(pg_touch(
                        e,
                        b.i32() % 5,
                        b.i32() % 4,
                        b.f32(),
                        b.f32(),
                        b.f64(),
                        &mut gesture,
                    ));
                }
                7 => check(pg_set_display(
                    e,
                    b.small(4000),
                    b.small(4000),
                    b.f32(),
                    b.f32(),
                    b.i32() % 6,
                )),
                8 => check(pg_set_sensor_ranges(e, b.f32(), b.f32())),
                9 => {
                    let name: Vec<u8> = (0..b.small(24)).map(|_| b.u8().max(1)).collect();
                    let name = CString::new(name).expect("no NUL");
                    check(pg_set_anaglyph(e, name.as_ptr()));
                }
                10 => check(pg_resume_offscreen(e, b.small(72), b.small(160))),
                11 => check(pg_resize(e, b.small(72), b.small(160))),
                12 => check(pg_suspend(e)),
                13 => {
                    let mut presented = 0u8;
                    check(pg_draw(e, b.f64(), &mut presented));
                }
                14 => {
                    let capacity = (b.small(u16::MAX as u32) as usize).min(pixels.len());
                    let (mut w, mut h) = (0u32, 0u32);
                    check(pg_read_frame(e, pixels.as_mut_ptr(), capacity, &mut w, &mut h));
                }
                15 => check(pg_open_menu(e)),
                16 => {
                    // The screen reader's nodes: a snapshot, one node read through, freed.
                    let mut snapshot = std::ptr::null_mut();
                    let mut generation = 0u64;
                    if pg_accessibility_snapshot(e, &mut snapshot, &mut generation) == PgStatus::Ok {
                        let mut node = std::mem::zeroed::<PgAccessNode>();
                        let index = b.small(64) as usize;
                        if pg_access_snapshot_node(snapshot, index, &mut node) == PgStatus::Ok {
                            assert!(index < pg_access_snapshot_len(snapshot));
                            assert!(!std::ffi::CStr::from_ptr(node.label).to_bytes().is_empty());
                        }
                        pg_access_snapshot_free(snapshot);
                    }
                }
                17 => {
                    let mut acted = 0u8;
                    let id = b.i32() % 64;
                    if b.u8() % 2 == 0 {
                        check(pg_accessibility_click(e, id, &mut acted));
                    } else {
                        check(pg_accessibility_adjust(e, id, b.i32() % 8, &mut acted));
                    }
                }
                _ => {
                    let mut stats = std::mem::zeroed::<PgStats>();
                    check(pg_stats(e, &mut stats));
                    let mut message = [0 as std::ffi::c_char; 64];
                    let capacity = b.small(64) as usize;
                    pg_last_error(message.as_mut_ptr(), capacity);
                }
            }
        }
    }
}
