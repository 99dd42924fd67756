//! The device: instance, adapter, device and queue, headless (as on the phones) or for a display,
//! and window surface targets.
//!
//! **Important**: a device can be lost (a driver reset, a GPU hang, Android reclaiming it):
//! [`Gpu::is_lost`] says so, from wgpu's callback, and from then on nothing made on it draws.
//! What was made on it must be made again on a new device (the engine does:
//! `Engine::draw`). wgpu's errors outside an error scope still panic, as wgpu's own handler does
//! (a bug to be found), except on a lost device, where every call fails and each is only counted.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use super::RenderError;

/// An instance, adapter, device and queue.
pub struct Gpu {
    /// Kept to create window surfaces ([`crate::surface`]).
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// Whether the instance holds a display connection ([`Self::for_display`]); without one
    /// ([`Self::headless`], what the phones use) each window brings its own display handle.
    instance_has_display: bool,
    /// Set by wgpu's device-lost callback.
    lost: Arc<AtomicBool>,
    /// wgpu's errors outside any error scope after the device was lost.
    errors_after_loss: Arc<AtomicU64>,
}

impl Gpu {
    /// A device without any window, on the first adapter that works: hardware first, then a
    /// software fallback.
    pub fn headless() -> Result<Self, RenderError> {
        Self::headless_using(wgpu::Features::all())
    }

    /// [`Self::headless`], turning on of the optional features the renderer uses where offered
    /// (timestamp queries; ASTC, BC and ETC2 blocks) only those in `optional`: how the tests take
    /// each block format's path on an adapter that offers several.
    pub fn headless_using(optional: wgpu::Features) -> Result<Self, RenderError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        Self::open(instance, None, optional)
    }

    /// A window of any display as a surface target for this device's instance.
    pub(crate) fn window_target(
        &self,
        window: std::sync::Arc<dyn wgpu::DisplayAndWindowHandle>,
    ) -> wgpu::SurfaceTarget<'static> {
        window_target(window, self.instance_has_display)
    }

    /// A device able to present to windows of `display` (a winit event loop or window, an
    /// Android or iOS display handle): the instance keeps the display connection, and the adapter
    /// is chosen to present to `probe`, a window of that display, if given.
    ///
    /// **Important**: on OpenGL (wgpu's EGL) only a device made this way presents to a desktop
    /// window: without the display, Mesa's EGL opens its surfaceless platform, whose surfaces
    /// offer no format. (Android's EGL has one display, and a headless device presents there.)
    pub fn for_display(
        display: Box<dyn wgpu::wgt::WgpuHasDisplayHandle>,
        probe: Option<std::sync::Arc<dyn wgpu::DisplayAndWindowHandle>>,
    ) -> Result<Self, RenderError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(display));
        let surface = probe
            .map(|probe| {
                instance
                    .create_surface(window_target(probe, true))
                    .map_err(|e| RenderError::Device(format!("cannot create a surface for the window: {e}")))
            })
            .transpose()?;
        let mut gpu = Self::with_instance(instance.clone(), surface.as_ref())?;
        gpu.instance_has_display = true;
        drop(surface);
        Ok(gpu)
    }

    /// A device on `instance` whose adapter can present to `surface` (if given).
    pub fn with_instance(instance: wgpu::Instance, surface: Option<&wgpu::Surface<'_>>) -> Result<Self, RenderError> {
        Self::open(instance, surface, wgpu::Features::all())
    }

    fn open(
        instance: wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
        optional: wgpu::Features,
    ) -> Result<Self, RenderError> {
        let mut adapter = None;
        for force_fallback_adapter in [false, true] {
            let found = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                force_fallback_adapter,
                compatible_surface: surface,
                // Limit bucketing hides hardware from untrusted web content; not our case.
                apply_limit_buckets: false,
            }));
            if let Ok(a) = found {
                adapter = Some(a);
                break;
            }
        }
        let adapter = adapter.ok_or(RenderError::NoAdapter)?;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("phantogram"),
            // Timestamp queries where offered: the frame budget of big scans follows GPU time.
            // Block-compressed textures where offered: a quarter of RGBA8's memory.
            required_features: adapter.features()
                & optional
                & (wgpu::Features::TIMESTAMP_QUERY | crate::block_textures::FEATURES),
            required_limits: limits_for(
                &adapter.limits(),
                std::env::var_os("PHANTOGRAM_GPU_LIMITS").is_some_and(|v| v == "gles3"),
            ),
            ..Default::default()
        }))
        .map_err(|e| RenderError::Device(e.to_string()))?;
        let lost = Arc::new(AtomicBool::new(false));
        let errors_after_loss = Arc::new(AtomicU64::new(0));
        let flag = Arc::clone(&lost);
        device.set_device_lost_callback(move |_reason, _message| flag.store(true, Ordering::SeqCst));
        let (flag, count) = (Arc::clone(&lost), Arc::clone(&errors_after_loss));
        device.on_uncaptured_error(Arc::new(move |error| {
            if flag.load(Ordering::SeqCst) {
                count.fetch_add(1, Ordering::Relaxed);
            } else {
                // wgpu's own handler's behaviour: an error nobody scoped is a bug.
                panic!("wgpu error: {error}");
            }
        }));
        Ok(Self {
            instance,
            adapter,
            device,
            queue,
            instance_has_display: false,
            lost,
            errors_after_loss,
        })
    }

    /// Whether the device is known to be lost: nothing made on it draws any more (see the
    /// module docs). wgpu tells of a loss when it next looks at the device: [`Self::poll_lost`].
    pub fn is_lost(&self) -> bool {
        self.lost.load(Ordering::SeqCst)
    }

    /// Lets wgpu look at the device without waiting (it runs its callbacks, the device-lost one
    /// included), then [`Self::is_lost`]: once a frame, before anything is drawn.
    pub fn poll_lost(&self) -> bool {
        let _ = self.device.poll(wgpu::PollType::Poll);
        self.is_lost()
    }

    /// wgpu's errors on this device since it was lost (each call on a lost device fails).
    pub fn errors_after_loss(&self) -> u64 {
        self.errors_after_loss.load(Ordering::Relaxed)
    }

    /// How many layers to allocate for a 2D array texture of `layers` layers of `width` ×
    /// `height` that a shader reads as a `texture_2d_array`: `layers`, except on OpenGL (ES),
    /// where wgpu makes a texture of one layer a plain 2D texture and one of a multiple of six
    /// square layers a cube map, neither of which a `sampler2DArray` can read (it reads zeros):
    /// there one more layer, never read, keeps it an array.
    pub(crate) fn array_layers(&self, width: u32, height: u32, layers: u32) -> u32 {
        phantogram_assets::budget::array_layers(width, height, layers, self.is_opengl())
    }

    /// Whether the device is OpenGL (ES): Android's fallback, with its own texture rules.
    pub fn is_opengl(&self) -> bool {
        self.adapter.get_info().backend == wgpu::Backend::Gl
    }

    /// The adapter's name and backend, for logs.
    pub fn describe(&self) -> String {
        let info = self.adapter.get_info();
        format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type)
    }
}

/// A shared window as a surface target. wgpu needs the display connection once: from the
/// instance when it was made with one ([`Gpu::for_display`]; the window's must then be the same,
/// so it is left out), else from the window itself ([`Gpu::headless`], as on the phones: an
/// Android `ANativeWindow` or an iOS `UIView` brings its own). Leaving it out there made every
/// surface fail with "missing display handle".
pub(super) fn window_target(
    window: std::sync::Arc<dyn wgpu::DisplayAndWindowHandle>,
    instance_has_display: bool,
) -> wgpu::SurfaceTarget<'static> {
    struct SharedWindow(std::sync::Arc<dyn wgpu::DisplayAndWindowHandle>);
    impl wgpu::rwh::HasWindowHandle for SharedWindow {
        fn window_handle(&self) -> Result<wgpu::rwh::WindowHandle<'_>, wgpu::rwh::HandleError> {
            self.0.window_handle()
        }
    }
    impl wgpu::rwh::HasDisplayHandle for SharedWindow {
        fn display_handle(&self) -> Result<wgpu::rwh::DisplayHandle<'_>, wgpu::rwh::HandleError> {
            self.0.display_handle()
        }
    }
    if instance_has_display {
        struct WindowOnly(SharedWindow);
        impl wgpu::rwh::HasWindowHandle for WindowOnly {
            fn window_handle(&self) -> Result<wgpu::rwh::WindowHandle<'_>, wgpu::rwh::HandleError> {
                self.0.window_handle()
            }
        }
        wgpu::SurfaceTarget::Window(Box::new(WindowOnly(SharedWindow(window))))
    } else {
        wgpu::SurfaceTarget::DisplayAndWindow(Box::new(SharedWindow(window)))
    }
}

/// The limits asked of a device: wgpu's downlevel defaults (what every Vulkan phone, Metal and
/// OpenGL ES 3.1 give), or WebGL 2's where the adapter offers less — OpenGL ES 3.0, which has no
/// compute shaders or storage buffers, and on which asking for more opened no device at all —,
/// with the adapter's own texture sizes. Asking for a tier, not for all the adapter has, keeps
/// the tests here (lavapipe offers far more) within what a phone gives.
///
/// `forced_low` (`PHANTOGRAM_GPU_LIMITS=gles3`) asks for the lower tier on any adapter: how the
/// tests check that the renderer draws within OpenGL ES 3.0's limits (its CPU paths where
/// compute is missing), which no GPU here has.
fn limits_for(adapter: &wgpu::Limits, forced_low: bool) -> wgpu::Limits {
    let tier = wgpu::Limits::downlevel_defaults();
    let tier = if tier.check_limits(adapter) && !forced_low {
        tier
    } else {
        wgpu::Limits::downlevel_webgl2_defaults()
    };
    tier.using_resolution(adapter.clone())
}

#[cfg(test)]
mod tests {
    use super::limits_for;

    /// A GLES 3.0 adapter (WebGL 2's limits, larger textures) gets a device within them, not a
    /// request it must refuse; a GLES 3.1 or Vulkan one gets the downlevel defaults, unless the
    /// lower tier is forced. Texture sizes are the adapter's in every case.
    #[test]
    fn each_adapter_is_asked_for_limits_it_has() {
        let gles3 = wgpu::Limits {
            max_texture_dimension_2d: 4096,
            ..wgpu::Limits::downlevel_webgl2_defaults()
        };
        let asked = limits_for(&gles3, false);
        assert!(asked.check_limits(&gles3));
        assert_eq!(asked.max_storage_buffers_per_shader_stage, 0);
        assert_eq!(asked.max_texture_dimension_2d, 4096);

        let vulkan = wgpu::Limits {
            max_texture_dimension_2d: 8192,
            ..wgpu::Limits::default()
        };
        let asked = limits_for(&vulkan, false);
        assert_eq!(
            asked.max_storage_buffers_per_shader_stage,
            wgpu::Limits::downlevel_defaults().max_storage_buffers_per_shader_stage
        );
        assert_eq!(asked.max_texture_dimension_2d, 8192);
        assert_eq!(limits_for(&vulkan, true).max_storage_buffers_per_shader_stage, 0);
    }
}
