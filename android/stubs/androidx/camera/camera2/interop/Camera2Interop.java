// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.camera.camera2.interop; public final class Camera2Interop {
  public static final class Extender<T> { public Extender(androidx.camera.core.ExtendableBuilder<T> baseBuilder) {}
    public Extender<T> setSessionCaptureCallback(android.hardware.camera2.CameraCaptureSession.CaptureCallback callback) { return this; } } }
