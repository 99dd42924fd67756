//! Random call sequences through the JNI bridge, guided by coverage. The bridge
//! (`android/src/jni_bridge.rs`) is linked into this process, instrumented, and registered as
//! `org.phantogram.NativeBridge`'s native methods in a JVM started here; the calls are made by
//! `android/tests/java/RandomCalls.java`, the driver of the JVM test's seeded runs, with its
//! random draws taken from libFuzzer's bytes (`RandomCalls.fuzz`). So what is fuzzed is the whole
//! path a shell's call takes: Java arguments (null, empty, damaged strings, arrays of the wrong
//! length, heap and direct buffers) through the bridge's conversions into the engine, and its
//! errors back as Java exceptions.
//!
//! A finding is a Rust panic (libFuzzer's hook aborts; a panic inside the physics engine, which
//! the Diorama catches and recovers from by design, is let through), an exception the bridge does
//! not document (`RandomCalls` raises an `AssertionError` naming the calls before it, and this
//! target panics with it), a JVM crash, a hang or runaway memory.
//!
//! Needs a JDK (`$JAVA_HOME`, else Debian's OpenJDK 17, else the one `javac` on the PATH
//! belongs to) and a GPU adapter (lavapipe). The JVM uses signals itself (`SIGSEGV` for null
//! checks and safepoints), so libFuzzer must leave those to it: `cargo xtask fuzz jni` passes
//! `-handle_segv=0 -handle_bus=0 -handle_fpe=0 -handle_ill=0`; the JVM then reports a real crash
//! itself (an `hs_err` file) and aborts.
#![no_main]

use std::ffi::c_void;
use std::path::Path;
use std::sync::OnceLock;

use jni::objects::{JClass, JObjectArray, JString, JValue};
use jni::refs::Global;
use jni::strings::JNIString;
use jni::sys::jlong;
use jni::{InitArgsBuilder, JNIVersion, JavaVM, NativeMethod, jni_sig, jni_str};
use libfuzzer_sys::fuzz_target;
use phantogram_android::jni_bridge::*;

#[path = "../../android/tests/support/jdk.rs"]
mod jdk;
#[path = "physics_panics.rs"]
mod physics_panics;
#[path = "scratch.rs"]
mod scratch;

/// The bridge's native methods, by name: `RegisterNatives` binds them to the class's declarations.
fn native_functions() -> Vec<(&'static str, *mut c_void)> {
    macro_rules! natives {
        ($($name:ident => $function:ident),* $(,)?) => {
            vec![$((stringify!($name), $function as *mut c_void)),*]
        };
    }
    natives![
        nativeCreate => Java_org_phantogram_NativeBridge_nativeCreate,
        nativeDestroy => Java_org_phantogram_NativeBridge_nativeDestroy,
        nativePushSensor => Java_org_phantogram_NativeBridge_nativePushSensor,
        nativeCameraFrame => Java_org_phantogram_NativeBridge_nativeCameraFrame,
        nativeCameraExposure => Java_org_phantogram_NativeBridge_nativeCameraExposure,
        nativeCameraIntrinsics => Java_org_phantogram_NativeBridge_nativeCameraIntrinsics,
        nativeTouch => Java_org_phantogram_NativeBridge_nativeTouch,
        nativeSurfaceCreated => Java_org_phantogram_NativeBridge_nativeSurfaceCreated,
        nativeResumeOffscreen => Java_org_phantogram_NativeBridge_nativeResumeOffscreen,
        nativeSurfaceChanged => Java_org_phantogram_NativeBridge_nativeSurfaceChanged,
        nativeSurfaceDestroyed => Java_org_phantogram_NativeBridge_nativeSurfaceDestroyed,
        nativeSetDisplay => Java_org_phantogram_NativeBridge_nativeSetDisplay,
        nativeSetSensorRanges => Java_org_phantogram_NativeBridge_nativeSetSensorRanges,
        nativeSetAnaglyph => Java_org_phantogram_NativeBridge_nativeSetAnaglyph,
        nativeDrawFrame => Java_org_phantogram_NativeBridge_nativeDrawFrame,
        nativeReadFrame => Java_org_phantogram_NativeBridge_nativeReadFrame,
        nativeStats => Java_org_phantogram_NativeBridge_nativeStats,
        nativeCalibrationWarning => Java_org_phantogram_NativeBridge_nativeCalibrationWarning,
        nativeImportArtifact => Java_org_phantogram_NativeBridge_nativeImportArtifact,
        nativeImportArtifactFd => Java_org_phantogram_NativeBridge_nativeImportArtifactFd,
        nativeSelectArtifact => Java_org_phantogram_NativeBridge_nativeSelectArtifact,
        nativeCurrentArtifact => Java_org_phantogram_NativeBridge_nativeCurrentArtifact,
        nativeSetTextScale => Java_org_phantogram_NativeBridge_nativeSetTextScale,
        nativeCameraPermissionNeeded => Java_org_phantogram_NativeBridge_nativeCameraPermissionNeeded,
        nativeOpenMenu => Java_org_phantogram_NativeBridge_nativeOpenMenu,
        nativeTakeShellRequest => Java_org_phantogram_NativeBridge_nativeTakeShellRequest,
        nativeLoadingState => Java_org_phantogram_NativeBridge_nativeLoadingState,
        nativeSnapshotPng => Java_org_phantogram_NativeBridge_nativeSnapshotPng,
        nativeAccessibilityNodes => Java_org_phantogram_NativeBridge_nativeAccessibilityNodes,
        nativeAccessibilityGeneration => Java_org_phantogram_NativeBridge_nativeAccessibilityGeneration,
        nativeAccessibilityClick => Java_org_phantogram_NativeBridge_nativeAccessibilityClick,
        nativeAccessibilityAdjust => Java_org_phantogram_NativeBridge_nativeAccessibilityAdjust,
    ]
}

/// What every input drives: the JVM (the `JavaVM` singleton), the driver class, the live engine's
/// handle and the folder imports go to.
struct Driver {
    class: Global<JClass<'static>>,
    handle: jlong,
    library_dir: Global<JString<'static>>,
}

fn driver() -> &'static Driver {
    static DRIVER: OnceLock<Driver> = OnceLock::new();
    DRIVER.get_or_init(|| {
        physics_panics::tolerate();
        let home = jdk::java_homes()
            .find(|home| home.join("lib/server/libjvm.so").is_file())
            .expect("no JDK found: set JAVA_HOME");
        let scratch = scratch::dir("jni");
        let classes = scratch.join("classes");
        let library = scratch.join("library");
        std::fs::create_dir_all(&library).expect("library folder");
        let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        jdk::compile_driver(&workspace, &home, "RandomCalls", &classes);
        let args = InitArgsBuilder::new()
            .version(JNIVersion::V1_8)
            .option(format!("-Djava.class.path={}", classes.display()))
            // The JVM leaves SIGINT/SIGTERM to libFuzzer, and stays small beside the engine.
            .option("-Xrs")
            .option("-Xmx128m")
            .option("-Xcheck:jni")
            // PHANTOGRAM_JNI_TRACE=1: each call an input makes, with its time, on stderr.
            .option(format!(
                "-Dphantogram.trace={}",
                std::env::var_os("PHANTOGRAM_JNI_TRACE").is_some()
            ))
            .build()
            .expect("JVM options");
        let vm = JavaVM::with_libjvm(args, || Ok(home.join("lib/server/libjvm.so"))).expect("starting the JVM");
        // SAFETY: what the JVM does when it loads the library: its own `JavaVM` pointer.
        let version = unsafe { JNI_OnLoad(vm.get_raw(), std::ptr::null_mut()) };
        assert_eq!(version, jni::sys::JNI_VERSION_1_6, "JNI_OnLoad failed");
        let functions = native_functions();
        vm.attach_current_thread(|env| -> jni::errors::Result<Driver> {
            let class = env.find_class(jni_str!("RandomCalls"))?;
            let bridge = env.find_class(jni_str!("org/phantogram/NativeBridge"))?;
            let declared = env
                .call_static_method(
                    &class,
                    jni_str!("nativeMethods"),
                    jni_sig!("()[Ljava/lang/String;"),
                    &[],
                )?
                .l()?;
            let declared = JObjectArray::<JString>::cast_local(env, declared)?;
            let mut names = Vec::new();
            for i in 0..declared.len(env)? {
                let entry = declared.get_element(env, i)?.try_to_string(env)?;
                let (name, descriptor) = entry.split_once(' ').expect("name and descriptor");
                names.push((JNIString::from(name), JNIString::from(descriptor)));
            }
            assert_eq!(
                names.len(),
                functions.len(),
                "NativeBridge's natives and this list differ"
            );
            let methods: Vec<NativeMethod> = names
                .iter()
                .map(|(name, descriptor)| {
                    let f = functions
                        .iter()
                        .find(|(n, _)| *n == name.to_str())
                        .unwrap_or_else(|| panic!("{} is not in native_functions", name.to_str()));
                    // SAFETY: `f` is the bridge's function for this method (same name), declared
                    // with the parameters of the Java declaration's descriptor (the JVM test
                    // calls the same functions through the same declarations).
                    unsafe { NativeMethod::from_raw_parts(name, descriptor, f.1) }
                })
                .collect();
            // SAFETY: each pointer matches its descriptor (above).
            unsafe { env.register_native_methods(&bridge, &methods)? };
            let library_dir = env.new_string(library.to_string_lossy())?;
            let handle = env
                .call_static_method(
                    &class,
                    jni_str!("start"),
                    jni_sig!("(Ljava/lang/String;)J"),
                    &[JValue::Object(&library_dir)],
                )?
                .j()?;
            Ok(Driver {
                class: env.new_global_ref(class)?,
                handle,
                library_dir: env.new_global_ref(library_dir)?,
            })
        })
        .unwrap_or_else(|e| panic!("setting up the driver: {e}"))
    })
}

/// Counts the Rust heap (its own global allocator): one input may not grow it by more than 1 GiB.
#[path = "heap_limit.rs"]
mod heap_limit;

fuzz_target!(|data: &[u8]| {
    heap_limit::input_begins();
    let driver = driver();
    let vm = JavaVM::singleton().expect("the JVM");
    let outcome = vm.attach_current_thread(|env| -> jni::errors::Result<()> {
        let bytes = env.byte_array_from_slice(data)?;
        env.call_static_method(
            &driver.class,
            jni_str!("fuzz"),
            jni_sig!("(J[BLjava/lang/String;)V"),
            &[
                JValue::Long(driver.handle),
                JValue::Object(&bytes),
                JValue::Object(&driver.library_dir),
            ],
        )?;
        Ok(())
    });
    if let Err(e) = outcome {
        panic!("a call through JNI ended in an undocumented way: {e}");
    }
});
