// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.camera.camera2.interop; public final class Camera2CameraInfo { public static Camera2CameraInfo from(androidx.camera.core.CameraInfo i) { return null; } public <T> T getCameraCharacteristic(android.hardware.camera2.CameraCharacteristics.Key<T> key) { return null; } }
