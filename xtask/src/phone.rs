//! `cargo xtask android`, `cargo xtask ios` and `cargo xtask header`: the phone builds. Each
//! checks what it needs first and, when something is missing, says exactly what and how to get
//! it, instead of failing halfway.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};

use crate::{cargo, run, workspace_root};

/// The Android ABIs the APK carries, with their Rust targets.
const ANDROID_ABIS: [(&str, &str); 3] = [
    ("arm64-v8a", "aarch64-linux-android"),
    ("armeabi-v7a", "armv7-linux-androideabi"),
    ("x86_64", "x86_64-linux-android"),
];

const IOS_TARGETS: [&str; 3] = ["aarch64-apple-ios", "aarch64-apple-ios-sim", "x86_64-apple-ios"];

fn succeeds(program: &str, args: &[&str]) -> bool {
    Command::new(program)
        .args(args)
        .output()
        .is_ok_and(|o| o.status.success())
}

fn installed_targets() -> Vec<String> {
    Command::new("rustup")
        .args(["target", "list", "--installed"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).lines().map(str::to_owned).collect())
        .unwrap_or_default()
}

fn env_dir(names: &[&str]) -> Option<PathBuf> {
    names
        .iter()
        .filter_map(std::env::var_os)
        .map(PathBuf::from)
        .find(|p| p.is_dir())
}

/// The NDK: `$ANDROID_NDK_HOME`/`$ANDROID_NDK_ROOT`, else the newest under `$ANDROID_HOME/ndk`.
fn android_ndk(sdk: Option<&Path>) -> Option<PathBuf> {
    env_dir(&["ANDROID_NDK_HOME", "ANDROID_NDK_ROOT"]).or_else(|| {
        let mut versions: Vec<PathBuf> = std::fs::read_dir(sdk?.join("ndk"))
            .ok()?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_dir())
            .collect();
        versions.sort();
        versions.pop()
    })
}

/// The face models, copied next to the app's resources (tilt-only without them).
fn copy_face_models(to: &Path) -> Result<()> {
    let Some(from) = phantogram_sensing::storage::face_models_dir().filter(|d| d.is_dir()) else {
        println!("note: no face models found (run `cargo xtask models`); the app will track tilt only");
        return Ok(());
    };
    std::fs::create_dir_all(to).with_context(|| format!("creating {}", to.display()))?;
    for name in [
        "face_detection_short_range.onnx",
        "face_landmark.onnx",
        "iris_landmark.onnx",
    ] {
        let src = from.join(name);
        if !src.is_file() {
            println!("note: {} is missing; the app will track tilt only", src.display());
            return Ok(());
        }
        std::fs::copy(&src, to.join(name)).with_context(|| format!("copying {}", src.display()))?;
    }
    println!("face models copied into {}", to.display());
    Ok(())
}

/// A museum's own scans (`--artifacts DIR`: `.glb`/`.gltf`/`.stl`/`.ply`/`.obj` files and Voyager folders), each
/// loaded as the phone will load it (`phantogram check-artifacts`: the library, the phone
/// budget) and copied to `to`, where the app bundles them; without a folder, `to` is emptied
/// (no artifacts of an earlier build linger).
fn copy_artifacts(from: Option<&Path>, to: &Path) -> Result<()> {
    if to.exists() {
        std::fs::remove_dir_all(to).with_context(|| format!("removing {}", to.display()))?;
    }
    let Some(from) = from else { return Ok(()) };
    // The check is the CLI's, so that xtask itself links no model loader.
    cargo(&[
        "run",
        "-q",
        "--release",
        "-p",
        "phantogram-cli",
        "--",
        "check-artifacts",
        &from.display().to_string(),
    ])
    .with_context(|| format!("the artifacts in {} would not all open on a phone", from.display()))?;
    let mut count = 0;
    for entry in std::fs::read_dir(from).with_context(|| format!("reading {}", from.display()))? {
        let entry = entry?;
        if entry.file_name().to_string_lossy().starts_with('.') {
            continue;
        }
        copy_tree(&entry.path(), &to.join(entry.file_name()))?;
        count += 1;
    }
    println!("{count} artifacts copied into {}", to.display());
    Ok(())
}

/// Copies a file, or a folder with everything in it but hidden files.
fn copy_tree(from: &Path, to: &Path) -> Result<()> {
    if from.is_dir() {
        std::fs::create_dir_all(to).with_context(|| format!("creating {}", to.display()))?;
        for entry in std::fs::read_dir(from).with_context(|| format!("reading {}", from.display()))? {
            let entry = entry?;
            if entry.file_name().to_string_lossy().starts_with('.') {
                continue;
            }
            copy_tree(&entry.path(), &to.join(entry.file_name()))?;
        }
    } else {
        if let Some(parent) = to.parent() {
            std::fs::create_dir_all(parent).with_context(|| format!("creating {}", parent.display()))?;
        }
        std::fs::copy(from, to).with_context(|| format!("copying {}", from.display()))?;
    }
    Ok(())
}

/// An NDK's version (`Pkg.Revision` in its `source.properties`), as Gradle's `ndkVersion` names it.
fn ndk_revision(ndk: &Path) -> Option<String> {
    let text = std::fs::read_to_string(ndk.join("source.properties")).ok()?;
    text.lines().find_map(|l| {
        let (key, value) = l.split_once('=')?;
        (key.trim() == "Pkg.Revision").then(|| value.trim().to_owned())
    })
}

pub fn android(artifacts: Option<&Path>) -> Result<()> {
    let root = workspace_root();
    // First, so that a curator learns whether the scans will open before any SDK is needed.
    copy_artifacts(artifacts, &root.join("android/app/src/main/assets/artifacts"))?;
    let sdk = env_dir(&["ANDROID_HOME", "ANDROID_SDK_ROOT"]);
    let ndk = android_ndk(sdk.as_deref());
    let targets = installed_targets();
    let mut missing = Vec::new();
    if sdk.is_none() {
        missing.push(
            "the Android SDK: install Android Studio or the command-line tools \
             (https://developer.android.com/studio#command-line-tools-only), then \
             `sdkmanager \"platforms;android-35\" \"build-tools;35.0.0\"` and set ANDROID_HOME"
                .to_owned(),
        );
    }
    if ndk.is_none() {
        missing.push(
            "the Android NDK: `sdkmanager \"ndk;27.2.12479018\"` (or set ANDROID_NDK_HOME to an NDK r26+)".to_owned(),
        );
    }
    if !succeeds("cargo", &["ndk", "--version"]) {
        missing.push("cargo-ndk: `cargo install cargo-ndk --locked`".to_owned());
    }
    let absent: Vec<&str> = ANDROID_ABIS
        .iter()
        .map(|(_, t)| *t)
        .filter(|t| !targets.iter().any(|i| i == t))
        .collect();
    if !absent.is_empty() {
        missing.push(format!("the Rust targets: `rustup target add {}`", absent.join(" ")));
    }
    if !succeeds("java", &["-version"]) {
        missing.push("a JDK 17 (`apt-get install openjdk-17-jdk-headless`)".to_owned());
    }
    if !missing.is_empty() {
        bail!(
            "cannot build the Android app on this machine; missing:\n  - {}",
            missing.join("\n  - ")
        );
    }
    // The face models go into the viewer library's assets; Gradle builds the Rust core for every
    // ABI itself (`:phantogram:cargoNdk`, as Android Studio's Run does) and then the APK. The
    // committed wrapper fetches the pinned Gradle on its first run (android/gradlew).
    copy_face_models(&root.join("android/phantogram/src/main/assets/models"))?;
    let mut gradle = Command::new("sh");
    gradle
        .arg(root.join("android/gradlew"))
        .arg(":app:assembleRelease")
        .current_dir(root.join("android"));
    // The cargo running this, wherever it is installed, and the NDK found (Gradle pins one
    // version, the one `sdkmanager` installs below, unless told another).
    if let Ok(cargo) = std::env::var("CARGO") {
        gradle.arg(format!("-Pphantogram.cargo={cargo}"));
    }
    if let Some(revision) = ndk.as_deref().and_then(ndk_revision) {
        gradle.arg(format!("-Pphantogram.ndkVersion={revision}"));
    }
    run(&mut gradle)?;
    let apk = root.join("android/app/build/outputs/apk/release/app-release.apk");
    println!(
        "built {}\ninstall on a phone (USB debugging on): adb install -r {}",
        apk.display(),
        apk.display()
    );
    Ok(())
}

pub fn ios(artifacts: Option<&Path>) -> Result<()> {
    copy_artifacts(artifacts, &workspace_root().join("ios/build/artifacts"))?;
    if !cfg!(target_os = "macos") {
        return ios_device_library_elsewhere();
    }
    let root = workspace_root();
    let targets = installed_targets();
    let mut missing = Vec::new();
    if !succeeds("xcodebuild", &["-version"]) {
        missing.push("Xcode 15 or newer (App Store), then `sudo xcode-select -s /Applications/Xcode.app`".to_owned());
    }
    let absent: Vec<&str> = IOS_TARGETS
        .iter()
        .copied()
        .filter(|t| !targets.iter().any(|i| i == t))
        .collect();
    if !absent.is_empty() {
        missing.push(format!("the Rust targets: `rustup target add {}`", absent.join(" ")));
    }
    if !missing.is_empty() {
        bail!("cannot build for iOS; missing:\n  - {}", missing.join("\n  - "));
    }
    for target in IOS_TARGETS {
        cargo(&["build", "--release", "-p", "phantogram-ios", "--target", target])?;
    }
    let lib = |t: &str| root.join("target").join(t).join("release/libphantogram_ios.a");
    let build = root.join("ios/build");
    let _ = std::fs::remove_dir_all(&build);
    let headers = build.join("headers");
    write_xcframework_headers(&root.join("ios/include/phantogram.h"), &headers)?;
    let simulator = build.join("libphantogram_ios-simulator.a");
    run(Command::new("lipo")
        .arg("-create")
        .arg(lib("aarch64-apple-ios-sim"))
        .arg(lib("x86_64-apple-ios"))
        .arg("-output")
        .arg(&simulator))?;
    run(Command::new("xcodebuild")
        .arg("-create-xcframework")
        .arg("-library")
        .arg(lib("aarch64-apple-ios"))
        .arg("-headers")
        .arg(&headers)
        .arg("-library")
        .arg(&simulator)
        .arg("-headers")
        .arg(&headers)
        .arg("-output")
        .arg(build.join("PhantogramCore.xcframework")))?;
    copy_face_models(&build.join("models"))?;
    println!(
        "built {}; open the app with `xcodegen generate` in ios/App (or add the package to an Xcode app target)",
        build.join("PhantogramCore.xcframework").display()
    );
    Ok(())
}

/// The XCFramework's `Headers` folder: the header and its module map in a folder named for the
/// module (`Headers/PhantogramCore/`). Xcode copies every XCFramework's headers into one include
/// folder, so a `module.modulemap` at the top would collide with another framework's ("multiple
/// commands produce …/module.modulemap"); inside its own folder it cannot, and Clang still finds
/// it by searching one level down.
fn write_xcframework_headers(header: &Path, headers: &Path) -> Result<()> {
    let module = headers.join("PhantogramCore");
    std::fs::create_dir_all(&module).with_context(|| format!("creating {}", module.display()))?;
    std::fs::copy(header, module.join("phantogram.h")).with_context(|| format!("copying {}", header.display()))?;
    std::fs::write(
        module.join("module.modulemap"),
        "module PhantogramCore {\n    header \"phantogram.h\"\n    export *\n}\n",
    )?;
    Ok(())
}

/// Regenerates `ios/include/phantogram.h` (the header test writes it when blessed).
pub fn header() -> Result<()> {
    let cargo_bin = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    run(Command::new(cargo_bin)
        .args(["test", "-p", "phantogram-ios", "--test", "header"])
        .env("PHANTOGRAM_BLESS", "1")
        .current_dir(workspace_root()))?;
    println!("wrote ios/include/phantogram.h");
    Ok(())
}

/// Away from macOS: the device static library (`aarch64-apple-ios`), built with Debian's clang
/// for tract's C kernels and an empty `SDKROOT` (a static library is archived, never linked, so
/// no Apple SDK is needed), and its exported `pg_` functions checked against the header. What
/// is left for macOS is the simulator slices, the XCFramework and the app.
fn ios_device_library_elsewhere() -> Result<()> {
    const TARGET: &str = "aarch64-apple-ios";
    let root = workspace_root();
    let mut missing = Vec::new();
    if !installed_targets().iter().any(|t| t == TARGET) {
        missing.push(format!("the Rust target: `rustup target add {TARGET}`"));
    }
    for (tool, package) in [("clang", "clang"), ("llvm-ar", "llvm"), ("llvm-nm", "llvm")] {
        if !succeeds(tool, &["--version"]) {
            missing.push(format!("`{tool}` (`apt-get install {package}`)"));
        }
    }
    if !missing.is_empty() {
        bail!(
            "cannot build the iOS device library on {}; missing:\n  - {}",
            std::env::consts::OS,
            missing.join("\n  - ")
        );
    }
    let sdkroot = root.join("target/empty-sdkroot");
    std::fs::create_dir_all(&sdkroot).with_context(|| format!("creating {}", sdkroot.display()))?;
    let var = TARGET.replace('-', "_");
    let cargo_bin = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    println!("building the {TARGET} static library (release; tens of minutes on a small machine)");
    run(Command::new(cargo_bin)
        .args([
            "build",
            "--release",
            "--lib",
            "-p",
            "phantogram-ios",
            "--target",
            TARGET,
        ])
        .env(format!("CC_{var}"), "clang")
        .env(format!("CFLAGS_{var}"), "--target=arm64-apple-ios15.0")
        .env(format!("AR_{var}"), "llvm-ar")
        .env("SDKROOT", &sdkroot)
        .current_dir(&root))?;
    let lib = root.join("target").join(TARGET).join("release/libphantogram_ios.a");
    let nm = Command::new("llvm-nm")
        // `--no-llvm-bc`: the standard library's objects also carry LLVM bitcode, newer than an
        // older llvm-nm reads; the Mach-O symbol tables are what the linker sees.
        .args([
            "--no-llvm-bc",
            "--extern-only",
            "--defined-only",
            "--format=just-symbols",
        ])
        .arg(&lib)
        .output()
        .with_context(|| format!("running llvm-nm on {}", lib.display()))?;
    if !nm.status.success() {
        bail!(
            "llvm-nm failed on {}: {}",
            lib.display(),
            String::from_utf8_lossy(&nm.stderr)
        );
    }
    check_macho_arm64(&lib)?;
    // Mach-O prefixes C symbols with an underscore.
    let exported: std::collections::BTreeSet<String> = String::from_utf8_lossy(&nm.stdout)
        .lines()
        .filter_map(|s| s.trim().strip_prefix("_pg_"))
        .map(|s| format!("pg_{s}"))
        .collect();
    let header_path = root.join("ios/include/phantogram.h");
    let header = std::fs::read_to_string(&header_path).with_context(|| format!("reading {}", header_path.display()))?;
    let declared = header_functions(&header);
    let absent: Vec<&String> = declared.difference(&exported).collect();
    let undeclared: Vec<&String> = exported.difference(&declared).collect();
    if !absent.is_empty() || !undeclared.is_empty() {
        bail!(
            "{} does not match {}:\n  declared but not exported: {absent:?}\n  exported but not declared: {undeclared:?}",
            lib.display(),
            header_path.display()
        );
    }
    println!(
        "built {} (Mach-O arm64): exports the header's {} functions.\n\
         The simulator slices, the XCFramework and the app need macOS with Xcode: run `cargo xtask ios` there.",
        lib.display(),
        declared.len()
    );
    Ok(())
}

/// Checks that the library's own objects are Mach-O 64-bit arm64 (magic `0xfeedfacf`, CPU type
/// `CPU_TYPE_ARM64`), reading the first one with `llvm-ar`.
fn check_macho_arm64(lib: &Path) -> Result<()> {
    let list = Command::new("llvm-ar")
        .arg("t")
        .arg(lib)
        .output()
        .context("running llvm-ar")?;
    let members = String::from_utf8_lossy(&list.stdout);
    let member = members
        .lines()
        .find(|m| m.starts_with("phantogram_ios") && m.ends_with(".o"))
        .with_context(|| format!("{} holds no phantogram_ios object", lib.display()))?;
    let object = Command::new("llvm-ar")
        .arg("p")
        .arg(lib)
        .arg(member)
        .output()
        .context("running llvm-ar")?;
    let header = object.stdout.get(..8).unwrap_or_default();
    if header != [0xcf, 0xfa, 0xed, 0xfe, 0x0c, 0x00, 0x00, 0x01] {
        bail!(
            "{member} in {} is not a Mach-O arm64 object (header {header:02x?})",
            lib.display()
        );
    }
    Ok(())
}

/// The names of the functions a C header declares with the `pg_` prefix (`pg_name(`).
fn header_functions(header: &str) -> std::collections::BTreeSet<String> {
    let mut names = std::collections::BTreeSet::new();
    let mut rest = header;
    while let Some(at) = rest.find("pg_") {
        let before_ok = at == 0 || !rest.as_bytes()[at - 1].is_ascii_alphanumeric() && rest.as_bytes()[at - 1] != b'_';
        let tail = &rest[at..];
        let len = tail
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(tail.len());
        if before_ok && tail[len..].starts_with('(') {
            names.insert(tail[..len].to_owned());
        }
        rest = &tail[len..];
    }
    names
}

#[cfg(test)]
mod tests {
    use super::{header_functions, write_xcframework_headers};

    #[test]
    fn the_module_map_sits_in_a_folder_named_for_the_module() {
        let dir = std::env::temp_dir().join(format!("xtask-headers-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let header = dir.join("phantogram.h");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(&header, "void pg_x(void);\n").unwrap();
        write_xcframework_headers(&header, &dir.join("Headers")).unwrap();
        let mut top: Vec<String> = std::fs::read_dir(dir.join("Headers"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        top.sort();
        assert_eq!(top, ["PhantogramCore"], "nothing at the top of Headers/");
        let map = std::fs::read_to_string(dir.join("Headers/PhantogramCore/module.modulemap")).unwrap();
        assert!(map.contains("module PhantogramCore") && map.contains("header \"phantogram.h\""));
        assert!(dir.join("Headers/PhantogramCore/phantogram.h").is_file());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn header_functions_are_the_called_pg_names() {
        let header = "typedef struct pg_engine pg_engine;\n\
                      pg_status pg_engine_new(const char *p, pg_engine **out);\n\
                      void pg_engine_free(pg_engine *e);\n/* see xpg_not(a) */\n";
        let names: Vec<String> = header_functions(header).into_iter().collect();
        assert_eq!(names, ["pg_engine_free", "pg_engine_new"]);
    }
}
