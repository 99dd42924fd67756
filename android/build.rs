//! Ships the NDK's C++ runtime beside the library on Android.
//!
//! The core's mesh simplifier (meshoptimizer, in `phantogram-detail`) is C++; this links the
//! library against the NDK's shared C++ runtime, `libc++_shared.so`, which the app must then
//! carry in the same `jniLibs/<abi>/` folder. Under cargo-ndk (the Gradle `cargoNdk` task and
//! `cargo xtask android`), this copies it there, as cargo-ndk's documentation advises. Android's
//! loader finds it in the app's library folder by itself (API 23+; the app needs 26). Other
//! builds (the desktop, clippy for the phone targets) copy nothing.

use std::path::PathBuf;

fn main() {
    println!("cargo:rerun-if-env-changed=CARGO_NDK_OUTPUT_PATH");
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("android") {
        return;
    }
    // meshoptimizer's build links the NDK's `libstdc++` (a system stub with `new` and `delete`
    // only); the rest of the C++ runtime it uses (std::vector's exceptions) is libc++'s.
    println!("cargo:rustc-link-lib=c++_shared");
    let (Some(output), Some(sysroot_libs), Some(abi)) = (
        std::env::var_os("CARGO_NDK_OUTPUT_PATH"),
        std::env::var_os("CARGO_NDK_SYSROOT_LIBS_PATH"),
        std::env::var_os("CARGO_NDK_ANDROID_TARGET"),
    ) else {
        return;
    };
    let from = PathBuf::from(sysroot_libs).join("libc++_shared.so");
    let dir = PathBuf::from(output).join(abi);
    let to = dir.join("libc++_shared.so");
    // A build without the runtime beside the library would crash the app at start: fail here.
    if let Err(e) = std::fs::create_dir_all(&dir).and_then(|_| std::fs::copy(&from, &to)) {
        panic!("copying {} to {}: {e}", from.display(), to.display());
    }
}
