//! A lost GPU device replaced (a driver reset, a GPU hang, the system reclaiming it): a new
//! device, and on it everything the old one held made again from the CPU's copies — the
//! artifact (or the Diorama's scene), its impostors (planned again, baked a few a frame as at
//! first), the window's surface, the screens' painter — with the appearance, the lamp, the
//! lighting and the room's live light (its last update, while it is on) as they were.
//!
//! Called by [`Engine::draw`] on the render thread when [`Gpu::is_lost`]; a device that cannot
//! be opened again is an error of that draw, tried again at the next.

use super::lighting::light_with_room;
use super::{Engine, EngineError, Target, impostors_for};
use crate::render::{Gpu, RenderError, Renderer};
use crate::surface::SurfaceHost;

impl Engine {
    /// How a new device is opened when the one drawing is lost: [`Gpu::headless`] unless set
    /// (a window's display, as the desktop viewer's: [`Gpu::for_display`]).
    pub fn set_device_reopener(&mut self, reopen: impl Fn() -> Result<Gpu, RenderError> + Send + Sync + 'static) {
        self.reopen_gpu = Box::new(reopen);
    }

    /// Replaces the lost device (see the module docs).
    pub(super) fn recover_lost_device(&mut self) -> Result<(), EngineError> {
        let gpu = (self.reopen_gpu)()?;
        let model = match self.diorama.as_deref() {
            Some(scene) => scene.model(),
            None => &self.model,
        };
        let mut renderer = Renderer::with_environment(gpu, model, self.static_environment.as_ref())?;
        renderer.lighting = self.renderer.lighting;
        renderer.appearance = self.renderer.appearance;
        renderer.lamp = self.renderer.lamp;
        if self.diorama.is_none() {
            self.impostors = impostors_for(
                &self.model,
                self.detail.as_mut(),
                self.loader.budget().memory_bytes,
                &renderer,
            );
        }
        if let Target::Window(host) = &self.target
            && let (Some(window), Some((width, height))) = (host.window(), host.size())
        {
            let mut fresh = SurfaceHost::new();
            fresh.resume(renderer.gpu(), window, width, height)?;
            self.target = Target::Window(Box::new(fresh));
        }
        self.renderer = renderer;
        if self.room_light_on()
            && let Some(update) = &self.room_light_shown
        {
            light_with_room(&mut self.renderer, update);
        }
        // The screens' painter was on the old device; a fresh egui context sends every texture
        // (fonts, the gallery's pictures) again, so the next frame shows them whole.
        #[cfg(feature = "ui")]
        if let Some(screens) = self.screens.as_deref_mut() {
            screens.overlay = crate::calibration_ui::OverlayHost::new();
            self.fresh_screens_context();
        }
        self.last_frame = None;
        self.stats.devices_recovered += 1;
        Ok(())
    }
}
