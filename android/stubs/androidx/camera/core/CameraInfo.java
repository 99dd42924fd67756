// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.camera.core; public interface CameraInfo { int getLensFacing(); CameraSelector getCameraSelector(); }
