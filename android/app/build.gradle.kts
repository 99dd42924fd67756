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
    // The museum's own scans, copied into src/main/assets/artifacts by
    // `cargo xtask android --artifacts DIR`: stored as they are (glb and jpg are compressed
    // already), extracted to app storage when the app is installed or updated.
    androidResources {
        noCompress += listOf("glb", "zip")
    }
}

dependencies {
    // The viewer: native core, JNI bridge, sensor/camera/render forwarding, face models.
    implementation(project(":phantogram"))
    implementation("androidx.core:core-ktx:1.15.0")
    implementation("androidx.activity:activity-ktx:1.9.3")
}
