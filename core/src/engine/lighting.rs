//! The artifact's appearance (material sliders, presets) and the room's own light captured from
//! the camera, as the engine shows them.

use super::{Engine, EngineError, appearance_key};

impl Engine {
    /// Why the calibration file could not be read, applied or written, if it could not: for the
    /// shell's log. The engine runs on with the defaults (or what it could apply).
    /// Changes the material of the artifact on screen (the material screen's sliders and
    /// presets; sanitised): shown from the next frame, remembered for this artifact (written to
    /// the library's `appearances.json`). A failure to write is returned; the change still shows.
    pub fn set_appearance(&mut self, appearance: crate::render::Appearance) -> Result<(), EngineError> {
        let appearance = appearance.sanitised();
        self.renderer.appearance = appearance;
        self.appearances
            .set(&appearance_key(&self.model_info), appearance)
            .map_err(|source| EngineError::Io {
                what: "the material change could not be saved",
                source,
            })
    }

    /// Hands a frame of the `facing` camera to the live room light (RGBA, YUV or luma; with its
    /// exposure when the platform reports it); from any thread through
    /// [`SharedEngine::camera_frame`](super::SharedEngine::camera_frame) too. Returns `false` when
    /// the room light is off ([`EngineConfig::room_light`](super::EngineConfig::room_light)).
    pub fn room_light_frame(&self, frame: crate::camera::OwnedFrame, facing: crate::camera::CameraFacing) -> bool {
        match &self.room_light {
            Some(worker) => worker.submit(frame, facing),
            None => false,
        }
    }

    /// As [`Self::room_light_frame`], with the device's orientation (device → world) when the
    /// frame was taken: a desktop replay whose camera follows a log of its own.
    pub fn room_light_frame_oriented(
        &self,
        frame: crate::camera::OwnedFrame,
        facing: crate::camera::CameraFacing,
        world_from_device: glam::Quat,
    ) -> bool {
        match &self.room_light {
            Some(worker) => worker.submit_oriented(frame, facing, Some(world_from_device)),
            None => false,
        }
    }

    /// Switches the room's own light on or off (off: the studio's, or the configured
    /// environment's, from the next frame; the map seen so far is kept for when it is on again).
    /// Not saved: the settings screen saves its choice.
    pub fn set_room_light(&mut self, on: bool) {
        let Some(worker) = &self.room_light else { return };
        let was_on = worker.is_on();
        worker.set_on(on);
        if was_on != on {
            self.requests.push(super::ShellRequest::RearCamera(on));
        }
        if was_on && !on && self.stats.room_light_updates > 0 {
            // A failed upload keeps the room's light; the next switch tries again.
            let _ = self
                .renderer
                .set_environment_or_studio(self.static_environment.as_ref());
        }
    }

    /// Whether the room's own light is on.
    pub fn room_light_on(&self) -> bool {
        self.room_light.as_ref().is_some_and(|w| w.is_on())
    }

    /// The anaglyph glasses the front camera saw on the viewer with the newest face (colour camera
    /// frames and face tracking needed): which filter is over which eye. The first-run glasses
    /// check says it beside its question.
    pub fn glasses_seen(&self) -> Option<phantogram_sensing::glasses::GlassesSeen> {
        self.last_glasses
    }

    /// The live room light's worker (its counts, waiting for it; on or off).
    pub fn room_light(&self) -> Option<&crate::room_light::RoomLightWorker> {
        self.room_light.as_deref()
    }

    /// Tells the room light where the device looks now and lights the scene with its newest
    /// update (an upload only: the worker did the work).
    pub(super) fn update_room_light(&mut self, device_to_world: Option<glam::Quat>) {
        let Some(worker) = &self.room_light else { return };
        if let Some(q) = device_to_world {
            worker.set_orientation(q);
        }
        if let Some(update) = worker.take_update() {
            // Where the GPU convolves the specular levels, the worker leaves them to it from
            // the next update on (asked here, not at start-up: it makes a compute pipeline).
            worker.set_prefilter_on_gpu(self.renderer.prefilters_on_gpu());
            self.stats.room_light_updates += 1;
            self.stats.room_light_coverage = update.coverage;
            self.stats.room_light_gain = Some(update.gain);
            light_with_room(&mut self.renderer, &update);
            self.room_light_shown = Some(update);
        }
    }

    /// Shows `appearance` on the artifact on screen without remembering it (the command line's
    /// `--material`, a preview); the next artifact comes with its own.
    pub fn show_appearance(&mut self, appearance: crate::render::Appearance) {
        self.renderer.appearance = appearance.sanitised();
    }

    /// The material of the artifact on screen (the default: as its glTF says).
    pub fn appearance(&self) -> crate::render::Appearance {
        self.renderer.appearance
    }
}

/// Lights `renderer`'s scene with the room light `update`. A failed upload keeps the light there
/// was; the next update tries again.
pub(super) fn light_with_room(renderer: &mut crate::render::Renderer, update: &crate::room_light::RoomLightUpdate) {
    let _ = match &update.specular {
        crate::room_light::Specular::Upload(upload) => renderer.set_environment_upload(upload, &update.sh),
        crate::room_light::Specular::Levels(levels) => renderer.set_prefiltered_environment(levels, &update.sh),
    };
}
