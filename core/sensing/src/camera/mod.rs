//! Camera frames as the platforms deliver them, and the pinhole intrinsics that go with them.
//!
//! Plain data (no networks, no GPU): the face tracker (`phantogram_vision`) consumes it, the
//! bridges build it, and the intrinsics are derived here from what each platform reports
//! ([`android`]: Camera2's characteristics; iOS delivers the matrix of each buffer, which is
//! passed on as it is), so that no camera maths lives in a shell.
//!
//! **Image frame**: pixels with x right, y down, origin at the top-left corner of the buffer as
//! delivered (before [`CameraFrame::rotation_cw_deg`] turns it upright).

pub mod android;
pub mod yuv;

use glam::{Quat, Vec3};

/// Pinhole intrinsics, pixels, of the image they are given with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Intrinsics {
    pub fx_px: f32,
    pub fy_px: f32,
    pub cx_px: f32,
    pub cy_px: f32,
}

impl Intrinsics {
    pub const fn new(fx_px: f32, fy_px: f32, cx_px: f32, cy_px: f32) -> Self {
        Self {
            fx_px,
            fy_px,
            cx_px,
            cy_px,
        }
    }

    /// Square pixels, principal point at the centre, horizontal field of view `hfov_rad`.
    pub fn from_horizontal_fov(width_px: u32, height_px: u32, hfov_rad: f32) -> Self {
        let f = width_px as f32 * 0.5 / (hfov_rad * 0.5).tan();
        Self {
            fx_px: f,
            fy_px: f,
            cx_px: width_px as f32 * 0.5,
            cy_px: height_px as f32 * 0.5,
        }
    }

    /// The intrinsics of the image turned clockwise by `quarter_turns` × 90° (`width`/`height`
    /// are the unturned image's).
    pub fn turned_cw(self, width: u32, height: u32, quarter_turns: u32) -> Self {
        let (w, h) = (width as f32, height as f32);
        match quarter_turns % 4 {
            0 => self,
            // (x, y) → (h − y, x)
            1 => Self {
                fx_px: self.fy_px,
                fy_px: self.fx_px,
                cx_px: h - self.cy_px,
                cy_px: self.cx_px,
            },
            // (x, y) → (w − x, h − y)
            2 => Self {
                cx_px: w - self.cx_px,
                cy_px: h - self.cy_px,
                ..self
            },
            // (x, y) → (y, w − x)
            _ => Self {
                fx_px: self.fy_px,
                fy_px: self.fx_px,
                cx_px: self.cy_px,
                cy_px: w - self.cx_px,
            },
        }
    }
}

/// How a frame's bytes are laid out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelFormat {
    /// One byte per pixel (the Y plane of a YUV frame).
    Luma8,
    /// Four bytes per pixel, R G B A.
    Rgba8,
}

impl PixelFormat {
    pub fn bytes_per_pixel(self) -> usize {
        match self {
            Self::Luma8 => 1,
            Self::Rgba8 => 4,
        }
    }
}

/// One camera frame as the platform delivers it.
#[derive(Clone, Copy, Debug)]
pub struct CameraFrame<'a> {
    pub width: u32,
    pub height: u32,
    /// Bytes from one row to the next (≥ width × bytes per pixel).
    pub row_stride: usize,
    pub format: PixelFormat,
    pub data: &'a [u8],
    /// Clockwise rotation (0, 90, 180, 270) that makes the image upright in the device's natural
    /// orientation (Android's `ImageInfo.rotationDegrees` for a natural-orientation display).
    pub rotation_cw_deg: u32,
    /// Intrinsics of the buffer as delivered (before the rotation).
    pub intrinsics: Intrinsics,
    /// When the exposure happened, on the sensor clock, nanoseconds.
    pub capture_t_ns: i64,
    /// The chroma planes of a `Luma8` frame delivered as YUV 4:2:0 (checked to fit it), for
    /// whoever wants colour at a few places ([`CameraFrame::rgb8_at`]); the networks read luma.
    pub chroma: Option<ChromaView<'a>>,
}

/// The chroma planes of a YUV frame, borrowed ([`ChromaPlanes::view`]).
#[derive(Clone, Copy, Debug)]
pub struct ChromaView<'a> {
    pub cb: &'a [u8],
    pub cr: &'a [u8],
    pub row_stride: usize,
    pub pixel_stride: usize,
}

impl<'a> CameraFrame<'a> {
    /// An upright image of packed RGBA rows (a still photograph, a test frame): no turn, no
    /// chroma planes, captured at 0. `data` is not checked here; consumers check the size.
    pub fn upright_rgba(width: u32, height: u32, data: &'a [u8], intrinsics: Intrinsics) -> Self {
        Self {
            width,
            height,
            row_stride: 4 * width as usize,
            format: PixelFormat::Rgba8,
            data,
            rotation_cw_deg: 0,
            intrinsics,
            capture_t_ns: 0,
            chroma: None,
        }
    }
}

impl CameraFrame<'_> {
    /// The sRGB colour of buffer pixel `(x, y)` (as delivered, before the turn): from RGBA, or
    /// from luma and chroma; `None` for a luma-only frame or a pixel outside the frame.
    pub fn rgb8_at(&self, x: u32, y: u32) -> Option<[u8; 3]> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let at = y as usize * self.row_stride + x as usize * self.format.bytes_per_pixel();
        match (self.format, self.chroma) {
            (PixelFormat::Rgba8, _) => Some([*self.data.get(at)?, *self.data.get(at + 1)?, *self.data.get(at + 2)?]),
            (PixelFormat::Luma8, Some(c)) => {
                let ca = (y / 2) as usize * c.row_stride + (x / 2) as usize * c.pixel_stride;
                Some(yuv::rgb_from_ycbcr(*self.data.get(at)?, *c.cb.get(ca)?, *c.cr.get(ca)?))
            }
            (PixelFormat::Luma8, None) => None,
        }
    }
}

/// Which of the device's cameras a frame comes from (Android's `LENS_FACING`, AVFoundation's
/// `AVCaptureDevice.Position`). The front camera feeds the face tracker and the room light; the
/// rear camera, where the platform runs both at once, only the room light.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CameraFacing {
    /// On the screen's side, looking at the viewer (and the room behind them).
    Front,
    /// On the back, looking where the screen's back faces (the room in front of the viewer).
    Rear,
}

impl CameraFacing {
    /// The bridges' code: 0 front, 1 rear; `None` for any other.
    pub fn from_code(code: u32) -> Option<Self> {
        match code {
            0 => Some(Self::Front),
            1 => Some(Self::Rear),
            _ => None,
        }
    }

    /// 0 front, 1 rear: an index for per-camera state.
    pub fn index(self) -> usize {
        match self {
            Self::Front => 0,
            Self::Rear => 1,
        }
    }
}

/// The device's two cameras, where each sits and looks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DeviceCameras {
    pub front: CameraPose,
    pub rear: CameraPose,
}

impl DeviceCameras {
    pub fn pose(&self, facing: CameraFacing) -> &CameraPose {
        match facing {
            CameraFacing::Front => &self.front,
            CameraFacing::Rear => &self.rear,
        }
    }
}

/// Where the camera sits in the device frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraPose {
    pub position_m: Vec3,
    /// Rotation taking camera-frame vectors (of the upright image) to the device frame.
    pub device_from_camera: Quat,
}

impl CameraPose {
    /// A front camera at `position_m` looking out of the screen, its upright image not mirrored:
    /// image right is the device's −x (the camera faces the viewer), image down is −y, the
    /// optical axis is +z. That is a half turn about z.
    pub fn front(position_m: Vec3) -> Self {
        Self {
            position_m,
            device_from_camera: Quat::from_rotation_z(std::f32::consts::PI),
        }
    }

    /// A rear camera at `position_m` looking out of the device's back: image right is the
    /// device's +x, image down is −y, the optical axis is −z. That is a half turn about x.
    pub fn rear(position_m: Vec3) -> Self {
        Self {
            position_m,
            device_from_camera: Quat::from_rotation_x(std::f32::consts::PI),
        }
    }
}

/// A frame's exposure as the platform reports it (Camera2's `SENSOR_EXPOSURE_TIME` and
/// `SENSOR_SENSITIVITY`; the EXIF `ExposureTime` and `ISOSpeedRatings` of an AVFoundation
/// buffer): what turns its pixel values back into relative radiance.
///
/// The lens's f-number (Camera2's `LENS_APERTURE`, EXIF `FNumber`) matters where two cameras
/// light one map: a phone's rear lens (f/1.5–1.9) gathers 1.5–2 times the light of its front
/// one (f/2.0–2.4) at the same time and gain. A camera's aperture is fixed on almost every
/// phone, so with one camera it only scales the map, which the room light's level removes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Exposure {
    pub time_s: f32,
    /// Sensor gain as an ISO speed (100 = unity on most phones).
    pub iso: f32,
    /// The lens's f-number, where reported.
    pub f_number: Option<f32>,
}

/// The f-number [`Exposure::relative`] takes for a lens that does not report its own: a
/// typical phone camera's, so that a camera reporting it and one not differ by little.
pub const TYPICAL_F_NUMBER: f32 = 2.0;

impl Exposure {
    /// `None` unless both are finite and positive (platforms report 0 or leave a field out when
    /// they do not know). No f-number: [`Self::with_f_number`].
    pub fn new(time_s: f32, iso: f32) -> Option<Self> {
        (time_s.is_finite() && time_s > 0.0 && iso.is_finite() && iso > 0.0).then_some(Self {
            time_s,
            iso,
            f_number: None,
        })
    }

    /// With the lens's f-number, when it is finite and positive (else as it was: platforms
    /// report 0 or NaN when they do not know).
    pub fn with_f_number(self, f_number: f32) -> Self {
        Self {
            f_number: (f_number.is_finite() && f_number > 0.0)
                .then_some(f_number)
                .or(self.f_number),
            ..self
        }
    }

    /// Exposure time × gain × the aperture's light relative to f/[`TYPICAL_F_NUMBER`] (seconds
    /// at ISO 100 and f/2): pixel value ∝ radiance × this.
    pub fn relative(self) -> f32 {
        let aperture = self.f_number.map_or(1.0, |n| (TYPICAL_F_NUMBER / n).powi(2));
        self.time_s * self.iso / 100.0 * aperture
    }
}

/// The chroma planes of a 4:2:0 frame beside its luma plane (copied as delivered: Android's
/// `YUV_420_888` planes 1 and 2, iOS's interleaved CbCr plane), half the frame's size in each
/// direction. [`OwnedFrame::into_colour`] turns the pair into colour.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ChromaPlanes {
    /// Both planes; Cb is `data[cb]`, Cr `data[cr]` (overlapping when interleaved).
    data: Vec<u8>,
    cb: std::ops::Range<usize>,
    cr: std::ops::Range<usize>,
    /// Bytes from one chroma row to the next (both planes).
    pub row_stride: usize,
    /// Bytes from one chroma sample to the next in a row (1 planar, 2 interleaved).
    pub pixel_stride: usize,
}

impl ChromaPlanes {
    /// Two planes (Android's planes 1 and 2), each copied.
    pub fn separate(cb: &[u8], cr: &[u8], row_stride: usize, pixel_stride: usize) -> Self {
        let mut data = Vec::with_capacity(cb.len() + cr.len());
        data.extend_from_slice(cb);
        data.extend_from_slice(cr);
        Self {
            cb: 0..cb.len(),
            cr: cb.len()..data.len(),
            data,
            row_stride,
            pixel_stride,
        }
    }

    /// One interleaved plane, Cb first (iOS's bi-planar plane 1, Android's NV12 layout), copied.
    pub fn interleaved(cbcr: &[u8], row_stride: usize) -> Self {
        Self {
            data: cbcr.to_vec(),
            cb: 0..cbcr.len(),
            cr: 1.min(cbcr.len())..cbcr.len(),
            row_stride,
            pixel_stride: 2,
        }
    }

    pub fn cb(&self) -> &[u8] {
        &self.data[self.cb.clone()]
    }

    pub fn cr(&self) -> &[u8] {
        &self.data[self.cr.clone()]
    }

    pub fn view(&self) -> ChromaView<'_> {
        ChromaView {
            cb: self.cb(),
            cr: self.cr(),
            row_stride: self.row_stride,
            pixel_stride: self.pixel_stride,
        }
    }
}

/// An owned camera frame, for handing to the face tracker's and the room light's worker threads.
#[derive(Clone, Debug)]
pub struct OwnedFrame {
    pub width: u32,
    pub height: u32,
    pub row_stride: usize,
    pub format: PixelFormat,
    pub data: Vec<u8>,
    pub rotation_cw_deg: u32,
    pub intrinsics: Intrinsics,
    pub capture_t_ns: i64,
    /// The chroma planes of a `Luma8` frame delivered as YUV (checked to fit the frame).
    pub chroma: Option<ChromaPlanes>,
    pub exposure: Option<Exposure>,
}

impl OwnedFrame {
    /// An upright image of packed RGBA rows, owned (a still photograph, a test frame): no turn,
    /// no chroma planes, no exposure reported ([`CameraFrame::upright_rgba`], borrowed).
    pub fn upright_rgba(width: u32, height: u32, data: Vec<u8>, intrinsics: Intrinsics, capture_t_ns: i64) -> Self {
        Self {
            width,
            height,
            row_stride: 4 * width as usize,
            format: PixelFormat::Rgba8,
            data,
            rotation_cw_deg: 0,
            intrinsics,
            capture_t_ns,
            chroma: None,
            exposure: None,
        }
    }

    /// A luma plane (Android's YUV_420_888 plane 0, iOS's bi-planar plane 0) as the bridges
    /// receive it, copied.
    #[allow(clippy::too_many_arguments)]
    pub fn luma8(
        width: u32,
        height: u32,
        row_stride: usize,
        data: &[u8],
        rotation_cw_deg: u32,
        intrinsics: Intrinsics,
        capture_t_ns: i64,
    ) -> Self {
        Self {
            width,
            height,
            row_stride,
            format: PixelFormat::Luma8,
            data: data.to_vec(),
            rotation_cw_deg,
            intrinsics,
            capture_t_ns,
            chroma: None,
            exposure: None,
        }
    }

    /// A YUV 4:2:0 frame as the bridges receive it: the luma plane and the chroma planes, copied;
    /// an error when the planes are too short for `width × height` or a stride is too narrow.
    #[allow(clippy::too_many_arguments)]
    pub fn yuv420(
        width: u32,
        height: u32,
        row_stride: usize,
        luma: &[u8],
        chroma: ChromaPlanes,
        rotation_cw_deg: u32,
        intrinsics: Intrinsics,
        capture_t_ns: i64,
    ) -> Result<Self, yuv::YuvError> {
        yuv::Yuv420 {
            width,
            height,
            y: luma,
            y_row_stride: row_stride,
            cb: chroma.cb(),
            cr: chroma.cr(),
            chroma_row_stride: chroma.row_stride,
            chroma_pixel_stride: chroma.pixel_stride,
        }
        .check()?;
        Ok(Self {
            chroma: Some(chroma),
            ..Self::luma8(
                width,
                height,
                row_stride,
                luma,
                rotation_cw_deg,
                intrinsics,
                capture_t_ns,
            )
        })
    }

    /// The same frame with its exposure, as reported.
    pub fn with_exposure(self, exposure: Option<Exposure>) -> Self {
        Self { exposure, ..self }
    }

    /// The frame's planes when it is YUV (luma with chroma).
    fn yuv(&self) -> Option<yuv::Yuv420<'_>> {
        let chroma = self.chroma.as_ref()?;
        (self.format == PixelFormat::Luma8).then(|| yuv::Yuv420 {
            width: self.width,
            height: self.height,
            y: &self.data,
            y_row_stride: self.row_stride,
            cb: chroma.cb(),
            cr: chroma.cr(),
            chroma_row_stride: chroma.row_stride,
            chroma_pixel_stride: chroma.pixel_stride,
        })
    }

    /// The frame in colour where it has colour: a YUV frame converted to `Rgba8` (rows packed,
    /// no chroma); an RGBA or a luma-only frame as it is (no copy), and so is a YUV frame whose
    /// chroma planes were changed after [`Self::yuv420`] checked them and no longer fit (grey).
    pub fn into_colour(self) -> Self {
        let Some(Ok(data)) = self.yuv().map(|planes| planes.to_rgba8()) else {
            return self;
        };
        Self {
            width: self.width,
            height: self.height,
            row_stride: self.width as usize * 4,
            format: PixelFormat::Rgba8,
            data,
            rotation_cw_deg: self.rotation_cw_deg,
            intrinsics: self.intrinsics,
            capture_t_ns: self.capture_t_ns,
            chroma: None,
            exposure: self.exposure,
        }
    }

    pub fn as_frame(&self) -> CameraFrame<'_> {
        CameraFrame {
            width: self.width,
            height: self.height,
            row_stride: self.row_stride,
            format: self.format,
            data: &self.data,
            rotation_cw_deg: self.rotation_cw_deg,
            intrinsics: self.intrinsics,
            capture_t_ns: self.capture_t_ns,
            chroma: self
                .chroma
                .as_ref()
                .filter(|_| self.format == PixelFormat::Luma8)
                .map(ChromaPlanes::view),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_camera_looks_out_of_its_own_side_with_its_image_upright() {
        // Device frame: x right, y up the screen, z out of the screen towards the viewer.
        let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-6;
        let front = CameraPose::front(Vec3::ZERO).device_from_camera;
        assert!(close(front * Vec3::Z, Vec3::Z), "the front camera looks at the viewer");
        assert!(
            close(front * Vec3::Y, Vec3::NEG_Y),
            "its image's down is the device's down"
        );
        assert!(
            close(front * Vec3::X, Vec3::NEG_X),
            "facing the viewer, its right is the device's left"
        );
        let rear = CameraPose::rear(Vec3::ZERO).device_from_camera;
        assert!(
            close(rear * Vec3::Z, Vec3::NEG_Z),
            "the rear camera looks out of the back"
        );
        assert!(
            close(rear * Vec3::Y, Vec3::NEG_Y),
            "its image's down is the device's down"
        );
        assert!(
            close(rear * Vec3::X, Vec3::X),
            "looking the way the viewer does, its right is theirs"
        );
        let cameras = DeviceCameras {
            front: CameraPose::front(Vec3::ZERO),
            rear: CameraPose::rear(Vec3::ZERO),
        };
        assert_eq!(cameras.pose(CameraFacing::Rear).device_from_camera, rear);
        assert_eq!(CameraFacing::from_code(1), Some(CameraFacing::Rear));
        assert_eq!(CameraFacing::from_code(2), None);
    }

    #[test]
    fn a_wider_aperture_is_a_longer_exposure() {
        let e = Exposure::new(0.01, 400.0).expect("valid");
        assert!((e.relative() - 0.04).abs() < 1e-7);
        // f/2 is the default: the same; f/1.4 lets in twice the light of f/2.
        assert_eq!(e.with_f_number(2.0).relative(), e.relative());
        assert!((e.with_f_number(2.0 / 2f32.sqrt()).relative() / e.relative() - 2.0).abs() < 1e-5);
        // Unknown f-numbers are ignored, keeping one reported before.
        assert_eq!(e.with_f_number(f32::NAN), e);
        assert_eq!(e.with_f_number(1.8).with_f_number(0.0).f_number, Some(1.8));
    }
}
