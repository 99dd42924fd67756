//! The physical screen: its size in metres from pixels and pixel density, its place in the device
//! frame (the glass is the plane `z = 0`, the rectangle centred on the origin) and the display
//! rotation that decides which device axes the displayed image's right and up point along.
//!
//! Invariants: a [`Screen`] always has a size a display can have, [`Screen::MIN_SIDE_M`] to
//! [`Screen::MAX_SIDE_M`] a side; its `right_device`/`up_device` axes are unit vectors in the
//! glass plane with `right × up = +z`.

use glam::{Vec2, Vec3};
use thiserror::Error;

const METRES_PER_INCH: f32 = 0.0254;

/// The panel as the platform reports it in the device's *natural* (portrait for phones)
/// orientation: pixel counts along device x and y, and pixels per inch along each
/// (Android's `DisplayMetrics.xdpi`/`ydpi`, iOS's native scale and points-per-inch).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PanelSpec {
    pub width_px: u32,
    pub height_px: u32,
    pub xdpi: f32,
    pub ydpi: f32,
}

impl PanelSpec {
    /// A typical 6.3-inch phone panel (1080 × 2400 at 420 dpi: 65.3 mm × 145.1 mm), used as the
    /// desktop default.
    pub const TYPICAL_PHONE: PanelSpec = PanelSpec {
        width_px: 1080,
        height_px: 2400,
        xdpi: 420.0,
        ydpi: 420.0,
    };
}

/// How the displayed image is rotated relative to the panel's natural orientation, with Android's
/// meaning of `Surface.ROTATION_*`: the rotation of the drawn graphics, which is opposite to the
/// physical rotation of the device. `Deg90` is a phone turned a quarter turn counter-clockwise
/// (its top edge now on the left), showing a landscape image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DisplayRotation {
    #[default]
    Deg0,
    Deg90,
    Deg180,
    Deg270,
}

impl DisplayRotation {
    /// From Android's `Display.getRotation()` value (0..=3).
    pub fn from_android_surface_rotation(value: i32) -> Option<Self> {
        match value {
            0 => Some(Self::Deg0),
            1 => Some(Self::Deg90),
            2 => Some(Self::Deg180),
            3 => Some(Self::Deg270),
            _ => None,
        }
    }
}

#[derive(Debug, Error, PartialEq)]
pub enum ScreenError {
    #[error("screen size must be at least 1×1 pixel, got {width_px}×{height_px}")]
    EmptyPanel { width_px: u32, height_px: u32 },
    #[error("pixel density must be positive and finite, got xdpi {xdpi}, ydpi {ydpi}")]
    BadDensity { xdpi: f32, ydpi: f32 },
    #[error(
        "a display of {width_m} m × {height_m} m (xdpi {xdpi}, ydpi {ydpi}) is outside what any screen measures \
         ({min} m to {max} m a side): the pixel density is wrong",
        min = Screen::MIN_SIDE_M,
        max = Screen::MAX_SIDE_M
    )]
    ImplausibleSize {
        width_m: f32,
        height_m: f32,
        xdpi: f32,
        ydpi: f32,
    },
}

/// The screen rectangle in the device frame plus the display's pixel grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Screen {
    panel: PanelSpec,
    rotation: DisplayRotation,
}

/// Three corners of the displayed image in the device frame, as Kooima's generalized perspective
/// projection wants them: lower-left, lower-right, upper-left (as the viewer sees the image).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenCorners {
    pub lower_left: Vec3,
    pub lower_right: Vec3,
    pub upper_left: Vec3,
}

impl Screen {
    /// The smallest side a display has: below a watch's centimetres by a factor of ten.
    pub const MIN_SIDE_M: f32 = 1e-3;
    /// The largest side a display has: beyond a stadium's video wall.
    pub const MAX_SIDE_M: f32 = 100.0;

    /// The screen of `panel`, shown at `rotation`. Refused: no pixels, a density that is not a
    /// positive number, or one that makes a side shorter than [`Self::MIN_SIDE_M`] or longer than
    /// [`Self::MAX_SIDE_M`] — a density a platform or a caller got wrong, which would put the
    /// eyes, the projection and the Diorama's tray at scales no display has (a 10⁻²⁷ m by
    /// 10¹⁷ m tray, from random display calls, held one physics step for over 45 s).
    pub fn new(panel: PanelSpec, rotation: DisplayRotation) -> Result<Self, ScreenError> {
        if panel.width_px == 0 || panel.height_px == 0 {
            return Err(ScreenError::EmptyPanel {
                width_px: panel.width_px,
                height_px: panel.height_px,
            });
        }
        let ok = |d: f32| d.is_finite() && d > 0.0;
        if !ok(panel.xdpi) || !ok(panel.ydpi) {
            return Err(ScreenError::BadDensity {
                xdpi: panel.xdpi,
                ydpi: panel.ydpi,
            });
        }
        let screen = Self { panel, rotation };
        let (width_m, height_m) = (screen.panel_width_m(), screen.panel_height_m());
        let plausible = |side_m: f32| (Self::MIN_SIDE_M..=Self::MAX_SIDE_M).contains(&side_m);
        if !plausible(width_m) || !plausible(height_m) {
            return Err(ScreenError::ImplausibleSize {
                width_m,
                height_m,
                xdpi: panel.xdpi,
                ydpi: panel.ydpi,
            });
        }
        Ok(screen)
    }

    pub fn panel(&self) -> PanelSpec {
        self.panel
    }

    pub fn rotation(&self) -> DisplayRotation {
        self.rotation
    }

    /// Physical extent of the panel along device x.
    pub fn panel_width_m(&self) -> f32 {
        self.panel.width_px as f32 / self.panel.xdpi * METRES_PER_INCH
    }

    /// Physical extent of the panel along device y.
    pub fn panel_height_m(&self) -> f32 {
        self.panel.height_px as f32 / self.panel.ydpi * METRES_PER_INCH
    }

    /// Half extents of the glass rectangle along device x and y.
    pub fn half_extent_device_m(&self) -> Vec2 {
        Vec2::new(self.panel_width_m(), self.panel_height_m()) * 0.5
    }

    fn is_quarter_turn(&self) -> bool {
        matches!(self.rotation, DisplayRotation::Deg90 | DisplayRotation::Deg270)
    }

    /// Unit vector along the displayed image's rightward axis, in the device frame.
    pub fn right_device(&self) -> Vec3 {
        match self.rotation {
            DisplayRotation::Deg0 => Vec3::X,
            DisplayRotation::Deg90 => -Vec3::Y,
            DisplayRotation::Deg180 => -Vec3::X,
            DisplayRotation::Deg270 => Vec3::Y,
        }
    }

    /// Unit vector along the displayed image's upward axis, in the device frame.
    pub fn up_device(&self) -> Vec3 {
        match self.rotation {
            DisplayRotation::Deg0 => Vec3::Y,
            DisplayRotation::Deg90 => Vec3::X,
            DisplayRotation::Deg180 => -Vec3::Y,
            DisplayRotation::Deg270 => -Vec3::X,
        }
    }

    /// Width of the displayed image in metres (along [`Self::right_device`]).
    pub fn width_m(&self) -> f32 {
        if self.is_quarter_turn() {
            self.panel_height_m()
        } else {
            self.panel_width_m()
        }
    }

    /// Height of the displayed image in metres (along [`Self::up_device`]).
    pub fn height_m(&self) -> f32 {
        if self.is_quarter_turn() {
            self.panel_width_m()
        } else {
            self.panel_height_m()
        }
    }

    /// Width of the displayed image in pixels.
    pub fn width_px(&self) -> u32 {
        if self.is_quarter_turn() {
            self.panel.height_px
        } else {
            self.panel.width_px
        }
    }

    /// Height of the displayed image in pixels.
    pub fn height_px(&self) -> u32 {
        if self.is_quarter_turn() {
            self.panel.width_px
        } else {
            self.panel.height_px
        }
    }

    pub fn corners(&self) -> ScreenCorners {
        let r = self.right_device() * (self.width_m() * 0.5);
        let u = self.up_device() * (self.height_m() * 0.5);
        ScreenCorners {
            lower_left: -r - u,
            lower_right: r - u,
            upper_left: -r + u,
        }
    }

    /// Display pixel coordinates (see the crate docs) of a point on the glass, given in the device
    /// frame. The z component is ignored.
    pub fn pixel_of_glass_point(&self, p: Vec3) -> Vec2 {
        let u = p.dot(self.right_device()) / self.width_m() + 0.5;
        let v = 0.5 - p.dot(self.up_device()) / self.height_m();
        Vec2::new(u * self.width_px() as f32, v * self.height_px() as f32)
    }

    /// The point on the glass (device frame, z = 0) under display pixel coordinates `px`.
    pub fn glass_point_of_pixel(&self, px: Vec2) -> Vec3 {
        let u = px.x / self.width_px() as f32 - 0.5;
        let v = 0.5 - px.y / self.height_px() as f32;
        self.right_device() * (u * self.width_m()) + self.up_device() * (v * self.height_m())
    }

    /// Whether a point of the glass plane lies within the screen rectangle (inclusive).
    pub fn contains_glass_point(&self, p: Vec3) -> bool {
        let h = self.half_extent_device_m();
        p.x.abs() <= h.x && p.y.abs() <= h.y
    }
}

impl Default for Screen {
    fn default() -> Self {
        Self {
            panel: PanelSpec::TYPICAL_PHONE,
            rotation: DisplayRotation::Deg0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [DisplayRotation; 4] = [
        DisplayRotation::Deg0,
        DisplayRotation::Deg90,
        DisplayRotation::Deg180,
        DisplayRotation::Deg270,
    ];

    #[test]
    fn physical_size_from_density() {
        let s = Screen::new(
            PanelSpec {
                width_px: 1000,
                height_px: 2000,
                xdpi: 500.0,
                ydpi: 400.0,
            },
            DisplayRotation::Deg0,
        )
        .unwrap();
        // 1000 px at 500 dpi = 2 in = 50.8 mm; 2000 px at 400 dpi = 5 in = 127 mm.
        assert!((s.panel_width_m() - 0.0508).abs() < 1e-6);
        assert!((s.panel_height_m() - 0.127).abs() < 1e-6);
    }

    #[test]
    fn display_axes_are_right_handed_and_in_the_glass() {
        for r in ALL {
            let s = Screen::new(PanelSpec::TYPICAL_PHONE, r).unwrap();
            let (right, up) = (s.right_device(), s.up_device());
            assert_eq!(right.cross(up), Vec3::Z, "{r:?}");
            assert_eq!(right.z, 0.0);
        }
    }

    #[test]
    fn quarter_turn_swaps_extent_but_not_the_rectangle() {
        let p = Screen::new(PanelSpec::TYPICAL_PHONE, DisplayRotation::Deg0).unwrap();
        let l = Screen::new(PanelSpec::TYPICAL_PHONE, DisplayRotation::Deg90).unwrap();
        assert_eq!((l.width_px(), l.height_px()), (2400, 1080));
        assert_eq!(l.width_m(), p.height_m());
        // Turned counter-clockwise, the top-left of the landscape image is the panel's top-right.
        let c = l.corners();
        let top_left = c.upper_left;
        assert!((top_left - Vec3::new(p.panel_width_m(), p.panel_height_m(), 0.0) * 0.5).length() < 1e-6);
    }

    #[test]
    fn pixel_mapping_round_trips_and_hits_corners() {
        for r in ALL {
            let s = Screen::new(PanelSpec::TYPICAL_PHONE, r).unwrap();
            let c = s.corners();
            assert!(s.pixel_of_glass_point(c.upper_left).distance(Vec2::ZERO) < 1e-3);
            let lr = s.pixel_of_glass_point(c.lower_right);
            assert!(lr.distance(Vec2::new(s.width_px() as f32, s.height_px() as f32)) < 1e-3);
            let px = Vec2::new(123.5, 456.5);
            assert!(s.pixel_of_glass_point(s.glass_point_of_pixel(px)).distance(px) < 1e-3);
        }
    }

    #[test]
    fn every_kind_of_display_is_a_screen_and_wrong_densities_are_not() {
        let panel = |width_px, height_px, xdpi, ydpi| PanelSpec {
            width_px,
            height_px,
            xdpi,
            ydpi,
        };
        for (what, p) in [
            ("a watch (41 mm)", panel(352, 430, 326.0, 326.0)),
            ("a phone", PanelSpec::TYPICAL_PHONE),
            ("a 100-inch 4K television", panel(3840, 2160, 44.0, 44.0)),
            ("a 4-pixel test surface at 100 dpi (1 mm)", panel(4, 4, 100.0, 100.0)),
        ] {
            assert!(Screen::new(p, DisplayRotation::Deg0).is_ok(), "{what}");
        }
        // The display calls the C ABI's fuzzing made before its Diorama step hung: 10^-27 m wide,
        // 10^17 m tall.
        for (what, p) in [
            ("1 px at 1.4e25 dpi", panel(1, 1000, 1.4e25, 400.0)),
            ("1000 px at 9.4e-20 dpi", panel(1080, 1000, 400.0, 9.4e-20)),
            ("a 4-pixel panel at 420 dpi (0.24 mm)", panel(4, 4, 420.0, 420.0)),
            ("a 4-billion-pixel panel at 1 dpi", panel(u32::MAX, 1000, 1.0, 400.0)),
        ] {
            assert!(
                matches!(
                    Screen::new(p, DisplayRotation::Deg0),
                    Err(ScreenError::ImplausibleSize { .. })
                ),
                "{what}"
            );
        }
    }

    #[test]
    fn rejects_bad_panels() {
        let mut p = PanelSpec::TYPICAL_PHONE;
        p.width_px = 0;
        assert!(matches!(
            Screen::new(p, DisplayRotation::Deg0),
            Err(ScreenError::EmptyPanel { .. })
        ));
        let mut p = PanelSpec::TYPICAL_PHONE;
        p.ydpi = f32::NAN;
        assert!(matches!(
            Screen::new(p, DisplayRotation::Deg0),
            Err(ScreenError::BadDensity { .. })
        ));
        assert_eq!(DisplayRotation::from_android_surface_rotation(4), None);
    }
}
