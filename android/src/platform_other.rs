//! Off Android (the desktop JVM test): there are no `android.view.Surface`s; the shell's surface
//! calls fail clearly and tests draw offscreen.

use std::sync::Arc;

use jni::Env;
use jni::objects::JObject;

use crate::jni_bridge::{Kind, Thrown, fail};

pub(crate) fn native_window(
    _env: &mut Env,
    _surface: &JObject,
) -> Result<Arc<dyn phantogram::wgpu::DisplayAndWindowHandle>, Thrown> {
    Err(fail(
        Kind::Unsupported,
        "Android surfaces exist only on Android; draw offscreen with nativeResumeOffscreen",
    ))
}
