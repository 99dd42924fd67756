//! The viewer's eyes: interpupillary distance, viewing distance, and the stereo pair placed about
//! the cyclopean eye.
//!
//! * **IPD** defaults to 63 mm, the adult mean reported by N. A. Dodgson, "Variation and extrema of
//!   human interpupillary distance", Proc. SPIE 5291, 2004 (mean 63 mm, most adults 50–75 mm). The
//!   paper assumed 65 mm; 63 mm is the better-founded population figure.
//! * **Viewing distance** defaults to 30 cm, the paper's assumption for a phone held in the hand.
//! * **Stereo pair**: left and right eyes sit at ∓IPD/2 along the *eye axis* through the cyclopean
//!   eye. The default axis is the displayed image's horizontal (so the pair turns with the display
//!   rotation); face tracking may supply the true axis. Each eye gets its own off-axis frustum
//!   ([`crate::projection`]); the cameras are never toed in.

use glam::Vec3;
use thiserror::Error;

use crate::screen::Screen;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EyeModel {
    pub ipd_m: f32,
    pub viewing_distance_m: f32,
    /// The viewer's left → right direction in the device frame, when known (face tracking).
    /// `None` uses the screen's horizontal.
    pub eye_axis_device: Option<Vec3>,
}

#[derive(Debug, Error, PartialEq)]
pub enum EyeModelError {
    #[error("interpupillary distance must be between 0 and 0.2 m, got {0} m")]
    BadIpd(f32),
    #[error("viewing distance must be between 0.05 and 5 m, got {0} m")]
    BadDistance(f32),
}

impl EyeModel {
    pub const DEFAULT_IPD_M: f32 = 0.063;
    pub const DEFAULT_VIEWING_DISTANCE_M: f32 = 0.30;

    pub fn validate(&self) -> Result<(), EyeModelError> {
        if !(self.ipd_m >= 0.0 && self.ipd_m <= 0.2) {
            return Err(EyeModelError::BadIpd(self.ipd_m));
        }
        if !(self.viewing_distance_m >= 0.05 && self.viewing_distance_m <= 5.0) {
            return Err(EyeModelError::BadDistance(self.viewing_distance_m));
        }
        Ok(())
    }

    /// The unit left → right axis used for the stereo pair: the supplied axis if usable, else the
    /// displayed image's horizontal. The horizontal lies in the glass plane, so both eyes stay as
    /// far in front of the glass as the cyclopean eye.
    pub fn eye_axis(&self, screen: &Screen) -> Vec3 {
        self.eye_axis_device
            .and_then(Vec3::try_normalize)
            .unwrap_or(screen.right_device())
    }

    pub fn stereo_pair(&self, screen: &Screen, cyclopean_m: Vec3) -> StereoEyes {
        let half = self.eye_axis(screen) * (self.ipd_m * 0.5);
        StereoEyes {
            cyclopean_m,
            left_m: cyclopean_m - half,
            right_m: cyclopean_m + half,
        }
    }
}

impl Default for EyeModel {
    fn default() -> Self {
        Self {
            ipd_m: Self::DEFAULT_IPD_M,
            viewing_distance_m: Self::DEFAULT_VIEWING_DISTANCE_M,
            eye_axis_device: None,
        }
    }
}

/// Eye positions in metres, device frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StereoEyes {
    pub cyclopean_m: Vec3,
    pub left_m: Vec3,
    pub right_m: Vec3,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::screen::{DisplayRotation, PanelSpec};

    #[test]
    fn pair_straddles_the_cyclopean_eye_along_the_display_horizontal() {
        let m = EyeModel::default();
        let c = Vec3::new(0.02, -0.05, 0.28);
        for (rot, axis) in [(DisplayRotation::Deg0, Vec3::X), (DisplayRotation::Deg90, -Vec3::Y)] {
            let s = Screen::new(PanelSpec::TYPICAL_PHONE, rot).unwrap();
            let e = m.stereo_pair(&s, c);
            assert!((e.left_m.distance(e.right_m) - 0.063).abs() < 1e-6);
            assert!(((e.left_m + e.right_m) * 0.5).distance(c) < 1e-6);
            // Along the displayed image's horizontal, left eye on the left; never toe-in.
            let across = (e.right_m - e.left_m).normalize();
            assert!(across.distance(axis) < 1e-6, "{rot:?}");
            assert_eq!(e.left_m.z, c.z);
        }
    }

    #[test]
    fn supplied_axis_is_used() {
        let m = EyeModel {
            eye_axis_device: Some(Vec3::new(1.0, 1.0, 0.0)),
            ..EyeModel::default()
        };
        let e = m.stereo_pair(&Screen::default(), Vec3::new(0.0, 0.0, 0.3));
        let across = (e.right_m - e.left_m).normalize();
        assert!(across.distance(Vec3::new(1.0, 1.0, 0.0).normalize()) < 1e-6);
    }

    #[test]
    fn validation() {
        assert!(EyeModel::default().validate().is_ok());
        let bad = EyeModel {
            ipd_m: f32::NAN,
            ..EyeModel::default()
        };
        assert!(bad.validate().is_err());
        let bad = EyeModel {
            viewing_distance_m: 0.0,
            ..EyeModel::default()
        };
        assert!(bad.validate().is_err());
    }
}
