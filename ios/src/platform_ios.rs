//! The one piece of iOS-only code: a `UIView` (whose layer is a `CAMetalLayer`) as a window
//! handle wgpu can make a Metal surface for. It compiles on every platform, so that this host
//! type-checks it; [`view_window`] hands it out only on iOS.

use std::ffi::c_void;
use std::ptr::NonNull;
use std::sync::Arc;

use phantogram::wgpu::rwh;

/// A `UIView*` the shell keeps alive until the surface is dropped (`pg_suspend`).
struct UiView(NonNull<c_void>);

// SAFETY: the pointer is only read by wgpu when it creates the surface, which `pg_resume_view`
// does on the main thread as its contract requires; the shell keeps the view alive while the
// engine holds it. The wrapper itself holds no thread-affine state.
unsafe impl Send for UiView {}
// SAFETY: as above; shared references only hand out the raw pointer.
unsafe impl Sync for UiView {}

impl rwh::HasWindowHandle for UiView {
    fn window_handle(&self) -> Result<rwh::WindowHandle<'_>, rwh::HandleError> {
        let raw = rwh::RawWindowHandle::UiKit(rwh::UiKitWindowHandle::new(self.0));
        // SAFETY: the view is valid for as long as `self` lives (the shell's promise above).
        Ok(unsafe { rwh::WindowHandle::borrow_raw(raw) })
    }
}

impl rwh::HasDisplayHandle for UiView {
    fn display_handle(&self) -> Result<rwh::DisplayHandle<'_>, rwh::HandleError> {
        Ok(rwh::DisplayHandle::uikit())
    }
}

/// The view as a window for the engine; `None` off iOS or for a null pointer.
///
/// # Safety
/// `view` is a valid `UIView*` that stays alive until the engine's surface is dropped.
pub unsafe fn view_window(view: *mut c_void) -> Option<Arc<dyn phantogram::wgpu::DisplayAndWindowHandle>> {
    let view = NonNull::new(view)?;
    if cfg!(target_os = "ios") {
        Some(Arc::new(UiView(view)))
    } else {
        None
    }
}
