// The embeddable viewer as an Android library (AAR): `NativeBridge` (the JNI surface of the
// Rust core), the core itself as `libphantogram_android.so` for every ABI, the face-tracking
// models, and the Kotlin classes an activity wires up (RenderLoop, SensorForwarder,
// CameraForwarder). Another app depends on it as the museum app does:
// `implementation(project(":phantogram"))`, or the AAR from `assembleRelease`.
plugins {
    id("com.android.library")
    id("org.jetbrains.kotlin.android")
}

// The ABIs the core is built for (their Rust targets: `rustup target add aarch64-linux-android
// armv7-linux-androideabi x86_64-linux-android`).
val rustAbis = listOf("arm64-v8a", "armeabi-v7a", "x86_64")

android {
    namespace = "org.phantogram.viewer"
    compileSdk = 35
    // The NDK cargo-ndk links with (Android Studio offers to install it on sync);
    // `-Pphantogram.ndkVersion=…` names another one installed.
    ndkVersion = providers.gradleProperty("phantogram.ndkVersion").orNull ?: "27.2.12479018"

    defaultConfig {
        minSdk = 26
        // JNI finds the native methods by name: keep them in apps that minify.
        consumerProguardFiles("consumer-rules.pro")
        ndk {
            abiFilters += rustAbis
        }
    }
    compileOptions {
        sourceCompatibility = JavaVersion.VERSION_17
        targetCompatibility = JavaVersion.VERSION_17
    }
    kotlinOptions {
        jvmTarget = "17"
    }
    // The Rust core, built by `cargoNdk` below; the face models, copied by `cargo xtask android`
    // (from `cargo xtask models`), stored uncompressed and extracted once at start.
    sourceSets["main"].jniLibs.srcDir(layout.buildDirectory.dir("rustJniLibs"))
    androidResources {
        noCompress += "onnx"
    }
}

dependencies {
    val camerax = "1.4.1"
    implementation("androidx.camera:camera-core:$camerax")
    implementation("androidx.camera:camera-camera2:$camerax")
    // CameraForwarder binds to the caller's LifecycleOwner: part of this library's API.
    api("androidx.camera:camera-lifecycle:$camerax")
    api("androidx.lifecycle:lifecycle-runtime-ktx:2.8.7")
    implementation("androidx.core:core-ktx:1.15.0")
    // ScreenReader: the core's screens as TalkBack's virtual views (ExploreByTouchHelper).
    implementation("androidx.customview:customview:1.1.0")
}

/**
 * Builds the Rust core with cargo-ndk into build/rustJniLibs/<abi>/, before every build, so
 * that Android Studio's Run is one step. Cargo itself decides what is up to date, so the task
 * always runs (a no-op build takes about a second).
 *
 * `-Pphantogram.cargo=/path/to/cargo` picks cargo where Android Studio's PATH lacks
 * ~/.cargo/bin (apps started from a desktop launcher do not read the shell's profile);
 * `-Pphantogram.skipCargo=true` uses what is already in build/rustJniLibs.
 */
val cargoNdk = tasks.register<Exec>("cargoNdk") {
    group = "build"
    description = "Builds the Rust core (phantogram-android) for ${rustAbis.joinToString()} with cargo-ndk"
    val home = System.getProperty("user.home")
    val cargo = providers.gradleProperty("phantogram.cargo").orNull
        ?: listOf("$home/.cargo/bin/cargo", "$home/.cargo/bin/cargo.exe").firstOrNull { file(it).isFile }
        ?: "cargo"
    val out = layout.buildDirectory.dir("rustJniLibs").get().asFile
    // The Cargo workspace is the folder above android/.
    workingDir = rootDir.parentFile
    val abis = rustAbis.flatMap { listOf("-t", it) }
    commandLine(listOf(cargo, "ndk") + abis + listOf("--platform", "26", "-o", out.path, "build", "--release", "-p", "phantogram-android"))
    val ndk = androidComponents.sdkComponents.ndkDirectory
    doFirst {
        environment("ANDROID_NDK_HOME", ndk.get().asFile.path)
    }
    onlyIf { providers.gradleProperty("phantogram.skipCargo").orNull != "true" }
    outputs.upToDateWhen { false }
}
tasks.named("preBuild") { dependsOn(cargoNdk) }
