//! The viewer's calibration in the engine: applied at start and after each change, saved, the
//! calibration screens opened, the flat angle and the world light anchored.

#[cfg(feature = "ui")]
use super::screens::Page;
use super::{Engine, EngineError};
use crate::{calibration::Calibration, gesture::Gestures};

impl Engine {
    /// Puts the calibration into the session ([`Session::apply_calibration`]) over the platform's
    /// panel, and into the gestures (their slop) and the face tracker (its metric scale).
    pub(super) fn apply_calibration(&mut self) {
        if let Err(refused) = self.session.apply_calibration(&self.calibration, self.platform_panel) {
            self.calibration_warning = Some(format!("calibration not fully applied: {refused}"));
        }
        self.session.set_turn_by_touch(self.calibration.turn_by_touch);
        self.gestures = Gestures::new(self.session.config().screen.panel().xdpi);
        // The camera's metric scale: the viewer's own IPD, once calibrated.
        #[cfg(feature = "face")]
        if let Some(face) = &self.face {
            face.set_ipd_m(self.calibration.ipd_m);
        }
    }

    /// Saves the calibration where [`EngineConfig::calibration_path`] says (if anywhere); a
    /// failure becomes [`Self::calibration_warning`].
    pub(super) fn save_calibration(&mut self) {
        if let Some(path) = &self.calibration_path
            && let Err(e) = self.calibration.save(path)
        {
            self.calibration_warning = Some(format!("{}: {e}; the calibration was not saved", path.display()));
        }
    }

    /// The calibration in use (from the file, the screens and the gestures).
    pub fn calibration(&self) -> Calibration {
        self.calibration
    }

    pub fn calibration_warning(&self) -> Option<&str> {
        self.calibration_warning.as_deref()
    }

    /// Opens the calibration screens (also the three-finger tap). Returns `false` when this build
    /// has none (feature `ui` off).
    pub fn open_calibration(&mut self) -> bool {
        #[cfg(feature = "ui")]
        {
            let calibration = self.calibration;
            let page = Page::Calibration(crate::calibration_ui::CalibrationUi::with_calibration(calibration));
            let screens = self.screens();
            if !matches!(screens.page, Some(Page::Calibration(_))) {
                screens.page = Some(page);
            }
            true
        }
        #[cfg(not(feature = "ui"))]
        false
    }

    /// Makes the current holding pose count as straight on (and saves it with the calibration).
    pub fn calibrate_flat_angle(&mut self) -> Result<(), EngineError> {
        self.session.calibrate_flat_angle()?;
        self.calibration.flat_up_device = self.session.flat_up_device();
        self.save_calibration();
        Ok(())
    }

    /// Lying flat counts as straight on again (and the calibration file says so).
    pub fn reset_flat_angle(&mut self) {
        self.session.reset_flat_angle();
        self.calibration.flat_up_device = None;
        self.save_calibration();
    }

    /// Ties the light to the room again, at the current pose (as a long press does).
    pub fn anchor_light(&mut self) -> Result<(), EngineError> {
        Ok(self.session.recalibrate_light()?)
    }

    #[cfg(feature = "ui")]
    pub(super) fn apply_calibration_action(&mut self, action: crate::calibration_ui::CalibrationAction) {
        use crate::calibration_ui::CalibrationAction as A;
        match action {
            A::FlatAngleHere => {
                // Without gravity yet there is no pose to take; the screens stay as they are.
                let _ = self.calibrate_flat_angle();
            }
            A::ResetLight => {
                let _ = self.session.recalibrate_light();
            }
            A::Changed(c) => {
                // The screens do not set the flat angle; the session holds the current one.
                self.calibration = Calibration {
                    flat_up_device: self.calibration.flat_up_device,
                    glasses_swapped: self.calibration.glasses_swapped,
                    introduced: self.calibration.introduced,
                    ..c
                };
                self.apply_calibration();
                self.save_calibration();
            }
            A::Closed => self.set_page(None),
        }
    }
}
