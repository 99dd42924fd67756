//! Calibration: the viewer's interpupillary distance and head offset from the eye-reflection
//! slider, the viewing distance from the blind spot, the screen's true pixel density from an
//! ID-1 card, and the small versioned file they are kept in.
//!
//! ## The eye-reflection slider, physically
//! The glass is a plane mirror. The reflection of a pupil, seen by that same pupil, lies on the
//! line through the pupil perpendicular to the glass (the mirror image is at `(x, y, −z)`, and the
//! line from `(x, y, z)` to it meets the glass at `(x, y, 0)`), whatever the distance. So when the
//! viewer moves each target onto the reflection that *the same, open* eye sees straight ahead, the
//! targets sit at the feet of the perpendiculars from the pupils: their separation is the IPD and
//! their midpoint is where the eyes are across the screen, at any viewing distance. The distance
//! itself cannot be recovered from a plane mirror (the paper's claim that it can does not hold);
//! [`blind_spot_distance_m`] or the face tracker provides it. The recovered IPD is the eyes'
//! separation *parallel to the glass*: a head turned by α about the vertical reads IPD·cos α.
//!
//! ## The blind spot ("Virtual Chinrest", Li et al., Scientific Reports 2020)
//! With one eye closed, the viewer fixates a mark and moves a dot away from it, temporally, until
//! the dot vanishes into the optic disc, about 13.5° from fixation. With the eye in front of the
//! mark, `d = s / tan 13.5°` for a mark–dot separation `s`. [`BlindSpotBudget`] states the error.

use std::path::Path;

use glam::{Vec2, Vec3};

use phantogram_geometry::screen::{PanelSpec, Screen};

/// Where the glass shows `viewer_eye` the reflection of `eye` (device frame, the glass is z = 0):
/// the ray from the viewer's eye to the mirror image `(x, y, −z)` crosses the glass there.
pub fn reflection_on_glass(eye: Vec3, viewer_eye: Vec3) -> Vec3 {
    let image = Vec3::new(eye.x, eye.y, -eye.z);
    let t = viewer_eye.z / (viewer_eye.z - image.z);
    let p = viewer_eye + (image - viewer_eye) * t;
    Vec3::new(p.x, p.y, 0.0)
}

/// What the slider yields: IPD and the eyes' midpoint across the screen (device frame, metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EyeReflectionResult {
    pub ipd_m: f32,
    pub centre_device_m: Vec2,
}

/// From the two targets' positions on the screen (display pixels) once each sits on its own
/// eye's reflection.
pub fn from_reflection_targets(screen: &Screen, left_px: Vec2, right_px: Vec2) -> EyeReflectionResult {
    let l = screen.glass_point_of_pixel(left_px);
    let r = screen.glass_point_of_pixel(right_px);
    EyeReflectionResult {
        ipd_m: l.distance(r),
        centre_device_m: Vec2::new((l.x + r.x) * 0.5, (l.y + r.y) * 0.5),
    }
}

/// The blind spot's mean angle from fixation, degrees (Li et al. 2020 use 13.5°).
pub const BLIND_SPOT_DEG: f32 = 13.5;

/// Viewing distance from the separation between the fixation mark and the point where the dot
/// vanished, assuming the eye in front of the mark.
pub fn blind_spot_distance_m(separation_m: f32) -> Option<f32> {
    (separation_m.is_finite() && separation_m > 0.0).then(|| separation_m / BLIND_SPOT_DEG.to_radians().tan())
}

/// The error budget of [`blind_spot_distance_m`], as relative errors of the distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlindSpotBudget {
    /// From the spread of the blind spot's position between people: an assumed ±1.3° about
    /// 13.5°, about one standard deviation of the optic disc's position in perimetry studies
    /// (an assumption of this budget, not a figure from Li et al.).
    pub anatomy: f32,
    /// From reading the vanishing point to ±`dot_px` pixels.
    pub reading: f32,
    /// From the eye sitting `offset_m` to the side of the mark instead of in front of it.
    pub eye_offset: f32,
}

impl BlindSpotBudget {
    /// For a viewer at `distance_m`, a screen of `px_per_m`, a reading uncertainty of `dot_px`
    /// pixels and the eye `offset_m` from the perpendicular through the mark.
    pub fn at(distance_m: f32, px_per_m: f32, dot_px: f32, offset_m: f32) -> Self {
        let a = BLIND_SPOT_DEG.to_radians();
        let spread = 1.3f32.to_radians();
        let s = distance_m * a.tan();
        let anatomy = ((a + spread).tan() / a.tan() - 1.0).abs();
        let reading = (dot_px / px_per_m) / s;
        // With the eye offset sideways, the true separation for 13.5° changes; its relative change
        // is the relative error of the distance read from it.
        let true_s = distance_m * ((offset_m / distance_m).atan() + a).tan() - offset_m;
        let eye_offset = (true_s / s - 1.0).abs();
        Self {
            anatomy,
            reading,
            eye_offset,
        }
    }

    /// Root-sum-square of the independent terms.
    pub fn total(&self) -> f32 {
        (self.anatomy.powi(2) + self.reading.powi(2) + self.eye_offset.powi(2)).sqrt()
    }
}

/// ISO/IEC 7810 ID-1 card (bank cards, ID cards): 85.60 × 53.98 mm.
pub const ID1_CARD_M: Vec2 = Vec2::new(0.085_60, 0.053_98);

/// The panel's true pixel density from a drawn card that the user matched to a real ID-1 card,
/// `card_px` its size in panel pixels (long side along the panel's x axis when `landscape_card`).
pub fn density_from_card(panel: PanelSpec, card_px: Vec2, landscape_card: bool) -> Option<PanelSpec> {
    let (w_m, h_m) = if landscape_card {
        (ID1_CARD_M.x, ID1_CARD_M.y)
    } else {
        (ID1_CARD_M.y, ID1_CARD_M.x)
    };
    let ok = |v: f32| v.is_finite() && v > 0.0;
    if !ok(card_px.x) || !ok(card_px.y) {
        return None;
    }
    Some(PanelSpec {
        xdpi: card_px.x / w_m * 0.0254,
        ydpi: card_px.y / h_m * 0.0254,
        ..panel
    })
}

/// What is kept between runs. Missing values mean "not calibrated": use the defaults.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Calibration {
    pub ipd_m: Option<f32>,
    pub head_offset_m: Option<Vec2>,
    pub viewing_distance_m: Option<f32>,
    /// Corrected pixel density (xdpi, ydpi) from the card check.
    pub density_dpi: Option<Vec2>,
    /// "Up" in the device frame in the pose calibrated as straight on.
    pub flat_up_device: Option<Vec3>,
    /// The viewer's glasses have the left eye's filter on the right (found by the glasses
    /// check): each eye's image goes to the other filter's colour.
    pub glasses_swapped: bool,
    /// The first-run screens were completed (they are not shown again).
    pub introduced: bool,
    /// Settings chosen in the menu (`None`: the app's default): the glasses' colours (the
    /// anaglyph method; mono for none), the diorama floor, the fraction of a loaded model in
    /// front of the glass, and whether loaded models keep their true size.
    pub method: Option<phantogram_geometry::anaglyph::Method>,
    pub floor: Option<bool>,
    pub protrude_fraction: Option<f32>,
    pub true_size: bool,
    /// Surface mode: flat artifacts at true size with their front in the glass.
    pub surface: bool,
    /// "Reduce motion": the artifact is turned by touch, not by tilting the phone
    /// (`crate::turn_by_touch`).
    pub turn_by_touch: bool,
    /// The light: the room's own, from the camera (`true`), or the studio's (`None`: the app's
    /// default).
    pub room_light: Option<bool>,
}

/// First line of a calibration file.
pub const CALIBRATION_MAGIC: &str = "phantogram-calibration 1";

impl Calibration {
    /// The file's text: a versioned header, then `key value…` lines (units in the key names).
    pub fn to_text(&self) -> String {
        let mut s = format!("{CALIBRATION_MAGIC}\n");
        if let Some(v) = self.ipd_m {
            s += &format!("ipd_m {v}\n");
        }
        if let Some(v) = self.head_offset_m {
            s += &format!("head_offset_m {} {}\n", v.x, v.y);
        }
        if let Some(v) = self.viewing_distance_m {
            s += &format!("viewing_distance_m {v}\n");
        }
        if let Some(v) = self.density_dpi {
            s += &format!("density_dpi {} {}\n", v.x, v.y);
        }
        if let Some(v) = self.flat_up_device {
            s += &format!("flat_up_device {} {} {}\n", v.x, v.y, v.z);
        }
        if self.glasses_swapped {
            s += "glasses_swapped 1\n";
        }
        if self.introduced {
            s += "introduced 1\n";
        }
        if let Some(m) = self.method {
            s += &format!("anaglyph {m}\n");
        }
        if let Some(f) = self.floor {
            s += &format!("floor {}\n", u8::from(f));
        }
        if let Some(p) = self.protrude_fraction {
            s += &format!("protrude_fraction {p}\n");
        }
        if self.true_size {
            s += "true_size 1\n";
        }
        if self.surface {
            s += "surface 1\n";
        }
        if self.turn_by_touch {
            s += "turn_by_touch 1\n";
        }
        if let Some(on) = self.room_light {
            s += &format!("room_light {}\n", u8::from(on));
        }
        s
    }

    /// Parses the file's text; `Err` names the line that is wrong.
    pub fn from_text(text: &str) -> Result<Self, String> {
        let mut lines = phantogram_files::text::strip_bom(text).lines();
        match lines.next().map(str::trim) {
            Some(CALIBRATION_MAGIC) => {}
            Some(other) => {
                return Err(format!(
                    "line 1: expected {CALIBRATION_MAGIC:?}, found {}",
                    phantogram_files::text::excerpt(other)
                ));
            }
            None => return Err("empty file".into()),
        }
        let mut c = Calibration::default();
        for (i, line) in lines.enumerate() {
            let line_no = i + 2;
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let mut words = line.split_whitespace();
            let key = words.next().unwrap_or_default();
            // The one setting that is a word, not numbers.
            if key == "anaglyph" {
                let name = words.next().unwrap_or_default();
                c.method = Some(name.parse().map_err(|e| format!("line {line_no}: {e}"))?);
                continue;
            }
            let values: Vec<f32> = words
                .map(|w| w.parse::<f32>().ok().filter(|v| v.is_finite()))
                .collect::<Option<_>>()
                .ok_or_else(|| format!("line {line_no}: values must be finite numbers"))?;
            let want = |n: usize| -> Result<(), String> {
                if values.len() == n {
                    Ok(())
                } else {
                    Err(format!(
                        "line {line_no}: {key} takes {n} values, found {}",
                        values.len()
                    ))
                }
            };
            match key {
                "ipd_m" => {
                    want(1)?;
                    if !(0.04..=0.09).contains(&values[0]) {
                        return Err(format!("line {line_no}: an IPD of {} m is not a human one", values[0]));
                    }
                    c.ipd_m = Some(values[0]);
                }
                "head_offset_m" => {
                    want(2)?;
                    c.head_offset_m = Some(Vec2::new(values[0], values[1]));
                }
                "viewing_distance_m" => {
                    want(1)?;
                    c.viewing_distance_m = Some(values[0]);
                }
                "density_dpi" => {
                    want(2)?;
                    c.density_dpi = Some(Vec2::new(values[0], values[1]));
                }
                "flat_up_device" => {
                    want(3)?;
                    c.flat_up_device = Some(Vec3::new(values[0], values[1], values[2]));
                }
                "glasses_swapped" => {
                    want(1)?;
                    c.glasses_swapped = values[0] != 0.0;
                }
                "introduced" => {
                    want(1)?;
                    c.introduced = values[0] != 0.0;
                }
                "floor" => {
                    want(1)?;
                    c.floor = Some(values[0] != 0.0);
                }
                "protrude_fraction" => {
                    want(1)?;
                    if !(0.0..=1.0).contains(&values[0]) {
                        return Err(format!("line {line_no}: protrude_fraction must be between 0 and 1"));
                    }
                    c.protrude_fraction = Some(values[0]);
                }
                "true_size" => {
                    want(1)?;
                    c.true_size = values[0] != 0.0;
                }
                "surface" => {
                    want(1)?;
                    c.surface = values[0] != 0.0;
                }
                "turn_by_touch" => {
                    want(1)?;
                    c.turn_by_touch = values[0] != 0.0;
                }
                "room_light" => {
                    want(1)?;
                    c.room_light = Some(values[0] != 0.0);
                }
                // Keys from newer versions are skipped, so a downgrade keeps what it understands.
                _ => {}
            }
        }
        Ok(c)
    }

    /// Loads a calibration file. Never fails: a missing file (not calibrated yet, as on the first
    /// run) gives the defaults; an unreadable or damaged one the defaults and a warning to show
    /// the user.
    pub fn load(path: &Path) -> (Self, Option<String>) {
        // A calibration is a few hundred bytes; a megabyte is not one.
        let text = phantogram_files::read_regular_file(path, 1 << 20).and_then(|bytes| {
            String::from_utf8(bytes).map_err(|_| std::io::Error::new(std::io::ErrorKind::InvalidData, "not UTF-8 text"))
        });
        match text {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => (Self::default(), None),
            Ok(text) => match Self::from_text(&text) {
                Ok(c) => (c, None),
                Err(e) => (
                    Self::default(),
                    Some(format!("{}: {e}; using the default calibration", path.display())),
                ),
            },
            Err(e) => (
                Self::default(),
                Some(format!("{}: {e}; using the default calibration", path.display())),
            ),
        }
    }

    /// Where the desktop tools keep it: `$PHANTOGRAM_CALIBRATION` if set, else
    /// `$XDG_CONFIG_HOME/phantogram/calibration.txt`, else `~/.config/phantogram/calibration.txt`.
    /// The phone shells pass their app-private folder instead.
    pub fn default_path() -> Option<std::path::PathBuf> {
        crate::storage::user_path(
            "PHANTOGRAM_CALIBRATION",
            "XDG_CONFIG_HOME",
            ".config",
            "calibration.txt",
        )
    }

    /// Writes the file atomically ([`phantogram_files::AtomicFile`]), so a crash or a full disk
    /// cannot leave a corrupt calibration. Creates the folder if needed.
    pub fn save(&self, path: &Path) -> std::io::Result<()> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)?;
        }
        let mut file = phantogram_files::AtomicFile::create(path)?;
        std::io::Write::write_all(file.file(), self.to_text().as_bytes())?;
        file.commit()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mirror test: ray-trace the glass for viewers at several distances and head offsets; each
    /// target placed where an eye sees its own reflection recovers the IPD within 1 mm, however
    /// far the viewer is, and the head offset too.
    #[test]
    fn reflection_slider_recovers_ipd_at_any_distance() {
        let screen = Screen::default();
        let ipd = 0.0637;
        for distance in [0.15f32, 0.25, 0.35, 0.45, 0.60] {
            for offset in [Vec2::ZERO, Vec2::new(0.012, -0.02)] {
                let centre = offset.extend(distance);
                let left = centre - Vec3::X * ipd / 2.0;
                let right = centre + Vec3::X * ipd / 2.0;
                // Each eye looks at its own reflection: that is where its target goes.
                let lt = screen.pixel_of_glass_point(reflection_on_glass(left, left));
                let rt = screen.pixel_of_glass_point(reflection_on_glass(right, right));
                let r = from_reflection_targets(&screen, lt, rt);
                assert!((r.ipd_m - ipd).abs() < 0.001, "at {distance} m: IPD {}", r.ipd_m);
                assert!(r.centre_device_m.distance(offset) < 0.001);
                // Aligning with the *other* eye's reflection would be wrong: it lies half-way.
                let crossed = reflection_on_glass(right, left);
                assert!((crossed.x - centre.x).abs() < 1e-4, "seen across: {crossed}");
            }
        }
    }

    #[test]
    fn blind_spot_geometry_and_budget() {
        // Forward: an eye 40 cm in front of the mark loses the dot 40·tan 13.5° = 9.60 cm away.
        let d = 0.40f32;
        let s = d * BLIND_SPOT_DEG.to_radians().tan();
        assert!((s - 0.0960).abs() < 1e-4);
        assert!((blind_spot_distance_m(s).unwrap() - d).abs() < 1e-5);
        assert_eq!(blind_spot_distance_m(0.0), None);
        // The budget at 40 cm on a 420 dpi phone, the dot read to ±5 px, the eye 2 cm off the mark.
        let b = BlindSpotBudget::at(d, 420.0 / 0.0254, 5.0, 0.02);
        assert!((0.09..0.12).contains(&b.anatomy), "{b:?}");
        assert!(b.reading < 0.01);
        assert!(b.eye_offset < 0.05, "{b:?}");
        // About ±4.5 cm at 40 cm: the scale of the 2.4–3.3 cm mean errors Li et al. report.
        let cm = b.total() * d * 100.0;
        assert!((3.0..6.0).contains(&cm), "{cm} cm");
    }

    #[test]
    fn card_check_corrects_a_misreported_density() {
        // A panel that claims 420 dpi but really has 400: a real card spans 85.6 mm = 1348 px.
        let claimed = PanelSpec::TYPICAL_PHONE;
        let true_px = Vec2::new(ID1_CARD_M.x / 0.0254 * 400.0, ID1_CARD_M.y / 0.0254 * 400.0);
        let fixed = density_from_card(claimed, true_px, true).unwrap();
        assert!((fixed.xdpi - 400.0).abs() < 0.01 && (fixed.ydpi - 400.0).abs() < 0.01);
        let portrait = density_from_card(claimed, Vec2::new(true_px.y, true_px.x), false).unwrap();
        assert!((portrait.xdpi - 400.0).abs() < 0.01);
        assert!(density_from_card(claimed, Vec2::new(0.0, 10.0), true).is_none());
    }

    #[test]
    fn calibration_file_round_trips_and_bad_files_give_defaults() {
        let dir = phantogram_testkit::Scratch::new("unit-calibration");
        let path = dir.join("calibration.txt");
        let c = Calibration {
            ipd_m: Some(0.0615),
            head_offset_m: Some(Vec2::new(0.01, -0.02)),
            viewing_distance_m: Some(0.33),
            density_dpi: Some(Vec2::new(401.5, 402.0)),
            flat_up_device: Some(Vec3::new(0.0, 0.57, 0.82)),
            glasses_swapped: true,
            introduced: true,
            method: Some(phantogram_geometry::anaglyph::Method::DuboisAmberBlue),
            floor: Some(false),
            protrude_fraction: Some(0.25),
            true_size: true,
            surface: true,
            turn_by_touch: true,
            room_light: Some(false),
        };
        c.save(&path).unwrap();
        assert_eq!(Calibration::load(&path), (c, None));

        for (text, needle) in [
            ("not a calibration\n", "line 1"),
            ("phantogram-calibration 1\nipd_m abc\n", "line 2"),
            ("phantogram-calibration 1\nipd_m 0.5\n", "not a human"),
            ("phantogram-calibration 1\nhead_offset_m 1\n", "takes 2 values"),
            ("", "empty"),
        ] {
            std::fs::write(&path, text).unwrap();
            let (got, warning) = Calibration::load(&path);
            assert_eq!(got, Calibration::default());
            let warning = warning.expect("a warning");
            assert!(warning.contains(needle), "{warning}");
        }
        // Not calibrated yet is no cause for a warning; a file that cannot be read is.
        let (got, warning) = Calibration::load(&dir.join("missing.txt"));
        assert_eq!(got, Calibration::default());
        assert_eq!(warning, None);
        let (got, warning) = Calibration::load(&dir);
        assert_eq!(got, Calibration::default());
        assert!(warning.is_some_and(|w| w.contains("using the default calibration")));
        // Unknown keys from newer versions are skipped.
        let newer = Calibration::from_text("phantogram-calibration 1\nfuture_key 1 2 3\nipd_m 0.063\n").unwrap();
        assert_eq!(newer.ipd_m, Some(0.063));
    }
}
