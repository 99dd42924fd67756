//! Off-axis perspective projection through the screen rectangle (Kooima, "Generalized Perspective
//! Projection", 2008): the frustum's apex is the eye, its sides pass through the edges of the
//! glass, so any point in the device frame lands on exactly the pixel where the ray from the eye to
//! it crosses the glass.
//!
//! * The view matrix maps the device frame into screen-aligned eye space (x along the display's
//!   right, y along its up, z out of the glass, origin at the eye); no toe-in, whatever the eye.
//! * The **near plane** lies between the eye and the glass ([`DepthRange::near_m`] from the eye,
//!   never beyond 90 % of the way to the glass), so geometry may stand out in front of the glass
//!   towards the viewer: the paper's "imaginary screen plane".
//! * **Reverse-Z** ([`crate`] docs): depth 1 at the near plane, 0 at the far plane (or at infinity
//!   when `far_m` is infinite), in wgpu's `[0, 1]` clip-space depth. With a 32-bit float depth
//!   buffer this keeps precision nearly uniform over the diorama.
//! * The matrices are `glam` column-major `Mat4`s, ready for a uniform buffer.

use glam::{Mat4, Vec2, Vec3, Vec4};
use thiserror::Error;

use crate::screen::Screen;

/// Where the frustum starts and ends, measured from the eye along the screen normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthRange {
    pub near_m: f32,
    /// May be `f32::INFINITY` for an infinite reverse-Z projection.
    pub far_m: f32,
}

impl Default for DepthRange {
    /// 2 cm from the eye (nothing real comes closer), 10 m far: reverse-Z float depth keeps the
    /// diorama well resolved at this ratio.
    fn default() -> Self {
        Self {
            near_m: 0.02,
            far_m: 10.0,
        }
    }
}

#[derive(Debug, Error, PartialEq)]
pub enum ProjectionError {
    #[error("eye {eye_m:?} is not in front of the glass (distance {distance_m} m)")]
    EyeNotInFront { eye_m: [f32; 3], distance_m: f32 },
    #[error("bad depth range: near {near_m} m, far {far_m} m (need 0 < near < far)")]
    BadDepthRange { near_m: f32, far_m: f32 },
}

/// A point mapped to the display.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProjectedPoint {
    /// Display pixel coordinates (crate docs: top-left origin, y down).
    pub pixel: Vec2,
    /// Reverse-Z depth: 1 at the near plane, 0 at the far plane; outside `[0, 1]` means clipped.
    pub depth: f32,
    /// Normalised device coordinates x, y in `[-1, 1]` inside the frustum.
    pub ndc: Vec2,
}

/// One eye's view and projection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OffAxisProjection {
    pub eye_m: Vec3,
    pub view: Mat4,
    pub proj: Mat4,
    pub view_proj: Mat4,
    /// The near plane actually used, metres from the eye (after clamping in front of the glass).
    pub near_m: f32,
    pub far_m: f32,
    width_px: f32,
    height_px: f32,
}

impl OffAxisProjection {
    /// The eye must be at least 1 mm in front of the glass.
    pub fn new(screen: &Screen, eye_m: Vec3, depth: DepthRange) -> Result<Self, ProjectionError> {
        let DepthRange { near_m, far_m } = depth;
        if !(near_m > 0.0 && far_m > near_m && !far_m.is_nan()) {
            return Err(ProjectionError::BadDepthRange { near_m, far_m });
        }
        let corners = screen.corners();
        let vr = screen.right_device();
        let vu = screen.up_device();
        let vn = vr.cross(vu); // +z: towards the viewer
        let va = corners.lower_left - eye_m;
        let vb = corners.lower_right - eye_m;
        let vc = corners.upper_left - eye_m;
        let d = -va.dot(vn); // eye–glass distance
        if !d.is_finite() || d < 1e-3 || !eye_m.is_finite() {
            return Err(ProjectionError::EyeNotInFront {
                eye_m: eye_m.to_array(),
                distance_m: d,
            });
        }
        let n = near_m.min(0.9 * d);
        let f = far_m.max(n * 2.0);
        let scale = n / d;
        let l = vr.dot(va) * scale;
        let r = vr.dot(vb) * scale;
        let b = vu.dot(va) * scale;
        let t = vu.dot(vc) * scale;
        let proj = reverse_z_frustum(l, r, b, t, n, f);
        // Rotate device → screen-aligned axes, then move the eye to the origin.
        let rotation = Mat4::from_cols(vr.extend(0.0), vu.extend(0.0), vn.extend(0.0), Vec4::W).transpose();
        let view = rotation * Mat4::from_translation(-eye_m);
        Ok(Self {
            eye_m,
            view,
            proj,
            view_proj: proj * view,
            near_m: n,
            far_m: f,
            width_px: screen.width_px() as f32,
            height_px: screen.height_px() as f32,
        })
    }

    /// The size of the image [`Self::project`]'s pixels are in: the glass's pixels (the panel's,
    /// as the displayed image is oriented), whatever size a frame is rendered at.
    pub fn image_px(&self) -> Vec2 {
        Vec2::new(self.width_px, self.height_px)
    }

    /// Projects a device-frame point. `None` for points at or behind the eye's plane.
    pub fn project(&self, p_m: Vec3) -> Option<ProjectedPoint> {
        let clip = self.view_proj * p_m.extend(1.0);
        if clip.w.is_nan() || clip.w <= 0.0 {
            return None;
        }
        let ndc = Vec2::new(clip.x, clip.y) / clip.w;
        let pixel = Vec2::new(
            (ndc.x + 1.0) * 0.5 * self.width_px,
            (1.0 - ndc.y) * 0.5 * self.height_px,
        );
        Some(ProjectedPoint {
            pixel,
            depth: clip.z / clip.w,
            ndc,
        })
    }
}

/// Perspective frustum for a camera looking down −z, mapping depth `near → 1`, `far → 0` (or
/// infinity → 0 when `f` is infinite).
fn reverse_z_frustum(l: f32, r: f32, b: f32, t: f32, n: f32, f: f32) -> Mat4 {
    let (a, c) = if f.is_infinite() {
        (0.0, n)
    } else {
        (n / (f - n), n * f / (f - n))
    };
    Mat4::from_cols(
        Vec4::new(2.0 * n / (r - l), 0.0, 0.0, 0.0),
        Vec4::new(0.0, 2.0 * n / (t - b), 0.0, 0.0),
        Vec4::new((r + l) / (r - l), (t + b) / (t - b), a, -1.0),
        Vec4::new(0.0, 0.0, c, 0.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::screen::{DisplayRotation, PanelSpec};

    #[test]
    fn corners_of_the_glass_map_to_corners_of_the_display() {
        for rot in [DisplayRotation::Deg0, DisplayRotation::Deg90, DisplayRotation::Deg270] {
            let s = Screen::new(PanelSpec::TYPICAL_PHONE, rot).unwrap();
            let p = OffAxisProjection::new(&s, Vec3::new(0.05, -0.03, 0.25), DepthRange::default()).unwrap();
            let ul = p.project(s.corners().upper_left).unwrap();
            assert!(ul.pixel.length() < 1e-2, "{rot:?} {:?}", ul.pixel);
            let lr = p.project(s.corners().lower_right).unwrap();
            let size = Vec2::new(s.width_px() as f32, s.height_px() as f32);
            assert!(lr.pixel.distance(size) < 1e-2);
        }
    }

    #[test]
    fn reverse_z_maps_near_to_one_and_far_to_zero() {
        let s = Screen::default();
        let eye = Vec3::new(0.0, 0.0, 0.3);
        let depth = DepthRange {
            near_m: 0.05,
            far_m: 2.0,
        };
        let p = OffAxisProjection::new(&s, eye, depth).unwrap();
        let at = |dist: f32| p.project(eye - Vec3::Z * dist).unwrap().depth;
        assert!((at(0.05) - 1.0).abs() < 1e-5);
        assert!(at(2.0).abs() < 1e-5);
        assert!(at(0.1) > at(0.3), "closer is greater");
        let inf = OffAxisProjection::new(
            &s,
            eye,
            DepthRange {
                near_m: 0.05,
                far_m: f32::INFINITY,
            },
        )
        .unwrap();
        assert!(inf.project(eye - Vec3::Z * 1e6).unwrap().depth < 1e-6);
    }

    #[test]
    fn near_plane_is_clamped_in_front_of_the_glass() {
        let s = Screen::default();
        let p = OffAxisProjection::new(
            &s,
            Vec3::new(0.0, 0.0, 0.04),
            DepthRange {
                near_m: 0.5,
                far_m: 3.0,
            },
        )
        .unwrap();
        assert!(p.near_m < 0.04);
    }

    #[test]
    fn rejects_eyes_behind_the_glass_and_bad_ranges() {
        let s = Screen::default();
        assert!(matches!(
            OffAxisProjection::new(&s, Vec3::new(0.0, 0.0, -0.1), DepthRange::default()),
            Err(ProjectionError::EyeNotInFront { .. })
        ));
        assert!(OffAxisProjection::new(&s, Vec3::NAN, DepthRange::default()).is_err());
        assert!(matches!(
            OffAxisProjection::new(
                &s,
                Vec3::Z,
                DepthRange {
                    near_m: 1.0,
                    far_m: 0.5
                }
            ),
            Err(ProjectionError::BadDepthRange { .. })
        ));
    }
}
