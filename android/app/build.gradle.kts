plugins {
    id("com.android.application")
    id("org.jetbrains.kotlin.android")
}

android {
    namespace = "org.phantogram"
    compileSdk = 35

    defaultConfig {
        applicationId = "org.phantogram"
        // Vulkan 1.1 (wgpu's Android backend) is guaranteed from API 29 on 64-bit devices; GLES 3
        // is wgpu's fallback below that. 26 gives SystemClock.elapsedRealtimeNanos everywhere
        // and the sensor direct-report era's time stamps.
        minSdk = 26
        targetSdk = 35
        versionCode = 1
        versionName = "0.1.0"
        ndk {
            // What `cargo xtask android` builds into src/main/jniLibs.
            abiFilters += listOf("arm64-v8a", "armeabi-v7a", "x86_64")
        }
    }

    buildTypes {
        release {
            isMinifyEnabled = false
            // Signed with the debug key so that `adb install` works out of the box; replace for a
            // store release.
            signingConfig = signingConfigs.getByName("debug")
        }
    }
    compileOptions {
        sourceCompatibility = JavaVersion.VERSION_17
        targetCompatibility = JavaVersion.VERSION_17
    }
    kotlinOptions {
        jvmTarget = "17"
    }
    // The face models are copied here by `cargo xtask android` (from `cargo xtask models`) and
    // must stay uncompressed in the APK only for speed; they are extracted once at start.
    androidResources {
        noCompress += "onnx"
    }
}

dependencies {
    val camerax = "1.4.1"
    implementation("androidx.camera:camera-core:$camerax")
    implementation("androidx.camera:camera-camera2:$camerax")
    implementation("androidx.camera:camera-lifecycle:$camerax")
    implementation("androidx.core:core-ktx:1.15.0")
    implementation("androidx.activity:activity-ktx:1.9.3")
    implementation("androidx.lifecycle:lifecycle-runtime-ktx:2.8.7")
}
