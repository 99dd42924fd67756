//! The one piece of Android-only code: an `android.view.Surface` as an `ANativeWindow` that wgpu
//! can make a Vulkan (or GLES) surface for. Built on Android, and on the desktop only to
//! type-check it (`cargo check --workspace --features phantogram-android/android-typecheck`, which
//! `.ci/run` runs): no Android target can be installed on the build machine.

use std::sync::Arc;

use jni::Env;
use jni::objects::JObject;
use ndk::native_window::NativeWindow;
use phantogram::wgpu::rwh;

use crate::jni_bridge::{Kind, Thrown, fail};

/// An acquired `ANativeWindow`; dropping it releases the window (`ANativeWindow_release`),
/// which happens when the engine drops its surface in `nativeSurfaceDestroyed`.
struct AndroidWindow(NativeWindow);

impl rwh::HasWindowHandle for AndroidWindow {
    fn window_handle(&self) -> Result<rwh::WindowHandle<'_>, rwh::HandleError> {
        rwh::HasWindowHandle::window_handle(&self.0)
    }
}

impl rwh::HasDisplayHandle for AndroidWindow {
    fn display_handle(&self) -> Result<rwh::DisplayHandle<'_>, rwh::HandleError> {
        Ok(rwh::DisplayHandle::android())
    }
}

/// Acquires the native window behind `surface` (a reference the window holds until dropped).
pub(crate) fn native_window(
    env: &mut Env,
    surface: &JObject,
) -> Result<Arc<dyn phantogram::wgpu::DisplayAndWindowHandle>, Thrown> {
    // SAFETY: `env` is this thread's attached JNI environment and `surface` a live local
    // reference to an `android.view.Surface` (checked non-null by the caller); the returned
    // window holds its own reference (`ANativeWindow_fromSurface` acquires one).
    let window =
        unsafe { NativeWindow::from_surface(env.get_raw().cast(), surface.as_raw().cast()) }.ok_or_else(|| {
            fail(
                Kind::IllegalArgument,
                "the Surface has no native window (already released?)",
            )
        })?;
    Ok(Arc::new(AndroidWindow(window)))
}
