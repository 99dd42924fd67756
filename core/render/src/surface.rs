//! The window surface and its lifecycle: what a platform shell drives so that the renderer draws
//! into a window (desktop), a `SurfaceView`'s `ANativeWindow` (Android) or a `CAMetalLayer` (iOS).
//!
//! ## The three callbacks (after Filament's `UiHelper`)
//! * [`SurfaceHost::resume`] — a drawable exists (winit `resumed`, Android `surfaceCreated` /
//!   `onNativeWindowCreated`, iOS view in a window): create the surface and configure it.
//! * [`SurfaceHost::resize`] — its size in physical pixels changed (rotation, split screen):
//!   reconfigure.
//! * [`SurfaceHost::suspend`] — the drawable is going away (Android `surfaceDestroyed` /
//!   `onPause`, app in background): drop the surface. **Important:** only the surface goes; the
//!   device, the model and every other GPU resource stay, so resuming is cheap.
//!
//! ## Frames
//! [`SurfaceHost::draw`] acquires the next texture and handles every outcome wgpu reports:
//! success draws and presents; *suboptimal* draws, presents and reconfigures; *timeout* and
//! *occluded* skip the frame; *outdated* reconfigures and tries once more; *lost* recreates the
//! surface from the window and tries once more; a validation failure is an error. Drawing while
//! suspended, or at a zero size (minimised), is a skipped frame, not an error.
//!
//! **Threading**: a host belongs to the render thread, with its renderer. The window handle is
//! shared (`Arc`) and must outlive the surface, which the host guarantees by holding it.

use std::sync::Arc;

use crate::{FrameInput, Gpu, RenderError, Renderer};
use phantogram_geometry::anaglyph::Method;

/// Where the host is in its lifecycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SurfaceState {
    /// No drawable: frames are skipped.
    Suspended,
    /// A configured surface of this many physical pixels.
    Active { width: u32, height: u32 },
}

/// What happened to one frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrawOutcome {
    Presented,
    /// Nothing drawn, for the reason given (suspended, zero-sized, occluded, timed out).
    Skipped(&'static str),
}

/// Counters of lifecycle events, for logs and tests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SurfaceStats {
    pub presented: u64,
    pub skipped: u64,
    pub reconfigured: u64,
    pub recreated: u64,
    pub resumed: u64,
    pub suspended: u64,
}

/// A window surface with an explicit lifecycle.
#[derive(Default)]
pub struct SurfaceHost {
    window: Option<Arc<dyn wgpu::DisplayAndWindowHandle>>,
    surface: Option<wgpu::Surface<'static>>,
    config: Option<wgpu::SurfaceConfiguration>,
    stats: SurfaceStats,
}

impl SurfaceHost {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn state(&self) -> SurfaceState {
        match (&self.surface, &self.config) {
            (Some(_), Some(c)) => SurfaceState::Active {
                width: c.width,
                height: c.height,
            },
            _ => SurfaceState::Suspended,
        }
    }

    /// The window drawn into, while there is one.
    pub fn window(&self) -> Option<Arc<dyn wgpu::DisplayAndWindowHandle>> {
        self.window.clone()
    }

    /// The size the surface was last configured at, physical pixels.
    pub fn size(&self) -> Option<(u32, u32)> {
        self.config.as_ref().map(|c| (c.width, c.height))
    }

    pub fn stats(&self) -> SurfaceStats {
        self.stats
    }

    /// A drawable appeared: create the surface for `window` and configure it at `width × height`
    /// physical pixels. Resuming an active host replaces its surface.
    pub fn resume(
        &mut self,
        gpu: &Gpu,
        window: Arc<dyn wgpu::DisplayAndWindowHandle>,
        width: u32,
        height: u32,
    ) -> Result<(), RenderError> {
        let surface = gpu
            .instance
            .create_surface(gpu.window_target(Arc::clone(&window)))
            .map_err(|e| RenderError::Device(format!("cannot create a surface for the window: {e}")))?;
        let caps = surface.get_capabilities(&gpu.adapter);
        // sRGB so the composition's linear output is encoded by the hardware, as offscreen.
        let format = caps
            .formats
            .iter()
            .copied()
            .find(wgpu::TextureFormat::is_srgb)
            .or_else(|| caps.formats.first().copied())
            .ok_or_else(|| RenderError::Device("the surface supports no format on this adapter".into()))?;
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: width.max(1),
            height: height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps
                .alpha_modes
                .first()
                .copied()
                .unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![],
            // Standard dynamic range sRGB: what the composition produces.
            color_space: wgpu::SurfaceColorSpace::Srgb,
        };
        self.window = Some(window);
        self.surface = Some(surface);
        self.config = Some(config);
        self.stats.resumed += 1;
        if width > 0 && height > 0 {
            self.configure(gpu);
        }
        Ok(())
    }

    /// The drawable is going away: drop the surface (and the window it borrows), keep everything else.
    pub fn suspend(&mut self) {
        if self.surface.take().is_some() {
            self.stats.suspended += 1;
        }
        self.config = None;
        self.window = None;
    }

    /// The drawable's size changed (physical pixels). Zero sizes (minimised) are remembered and
    /// skip frames until a real size arrives.
    pub fn resize(&mut self, gpu: &Gpu, width: u32, height: u32) {
        if let Some(c) = &mut self.config {
            c.width = width;
            c.height = height;
            if width > 0 && height > 0 {
                self.configure(gpu);
            }
        }
    }

    fn configure(&mut self, gpu: &Gpu) {
        if let (Some(s), Some(c)) = (&self.surface, &self.config) {
            s.configure(&gpu.device, c);
            self.stats.reconfigured += 1;
        }
    }

    /// Draws and presents one frame.
    pub fn draw(
        &mut self,
        renderer: &mut Renderer,
        input: &FrameInput,
        method: Method,
    ) -> Result<DrawOutcome, RenderError> {
        self.draw_with(renderer, input, method, |_, _, _, _| {})
    }

    /// As [`Self::draw`], calling `overlay(gpu, target, format, [width, height])` after the frame
    /// is drawn and before it is presented (the calibration screens paint there). Not called when
    /// the draw is skipped.
    pub fn draw_with(
        &mut self,
        renderer: &mut Renderer,
        input: &FrameInput,
        method: Method,
        overlay: impl FnOnce(&crate::Gpu, &wgpu::TextureView, wgpu::TextureFormat, [u32; 2]),
    ) -> Result<DrawOutcome, RenderError> {
        let mut overlay = Some(overlay);
        let Some(config) = self.config.clone() else {
            self.stats.skipped += 1;
            return Ok(DrawOutcome::Skipped("suspended"));
        };
        if config.width == 0 || config.height == 0 {
            self.stats.skipped += 1;
            return Ok(DrawOutcome::Skipped("zero-sized"));
        }
        for attempt in 0..2 {
            let Some(surface) = &self.surface else {
                return Ok(DrawOutcome::Skipped("suspended"));
            };
            let (texture, suboptimal) = match surface.get_current_texture() {
                wgpu::CurrentSurfaceTexture::Success(t) => (t, false),
                wgpu::CurrentSurfaceTexture::Suboptimal(t) => (t, true),
                wgpu::CurrentSurfaceTexture::Timeout => {
                    self.stats.skipped += 1;
                    return Ok(DrawOutcome::Skipped("timed out acquiring a frame"));
                }
                wgpu::CurrentSurfaceTexture::Occluded => {
                    self.stats.skipped += 1;
                    return Ok(DrawOutcome::Skipped("occluded"));
                }
                wgpu::CurrentSurfaceTexture::Outdated if attempt == 0 => {
                    self.configure(renderer.gpu());
                    continue;
                }
                wgpu::CurrentSurfaceTexture::Lost if attempt == 0 => {
                    let window = self
                        .window
                        .clone()
                        .ok_or_else(|| RenderError::Device("surface lost without a window".into()))?;
                    let (w, h) = (config.width, config.height);
                    self.resume(renderer.gpu(), window, w, h)?;
                    self.stats.recreated += 1;
                    continue;
                }
                other => {
                    return Err(RenderError::Gpu {
                        what: "the surface",
                        message: format!("could not acquire a frame: {}", describe(&other)),
                    });
                }
            };
            let view = texture.texture.create_view(&Default::default());
            renderer.render_to_view(input, method, &view, config.format, config.width, config.height)?;
            if let Some(paint) = overlay.take() {
                paint(renderer.gpu(), &view, config.format, [config.width, config.height]);
            }
            renderer.gpu().queue.present(texture);
            self.stats.presented += 1;
            if suboptimal {
                self.configure(renderer.gpu());
            }
            return Ok(DrawOutcome::Presented);
        }
        self.stats.skipped += 1;
        Ok(DrawOutcome::Skipped("surface still outdated after reconfiguring"))
    }
}

fn describe(t: &wgpu::CurrentSurfaceTexture) -> &'static str {
    match t {
        wgpu::CurrentSurfaceTexture::Success(_) => "success",
        wgpu::CurrentSurfaceTexture::Suboptimal(_) => "suboptimal",
        wgpu::CurrentSurfaceTexture::Timeout => "timeout",
        wgpu::CurrentSurfaceTexture::Occluded => "occluded",
        wgpu::CurrentSurfaceTexture::Outdated => "outdated twice",
        wgpu::CurrentSurfaceTexture::Lost => "lost twice",
        wgpu::CurrentSurfaceTexture::Validation => "validation error",
    }
}
