// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.hardware.camera2; public final class CaptureRequest {}
