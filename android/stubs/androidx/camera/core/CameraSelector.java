// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.camera.core; public final class CameraSelector { public static final CameraSelector DEFAULT_FRONT_CAMERA = new CameraSelector();
  public static final int LENS_FACING_FRONT = 0; public static final int LENS_FACING_BACK = 1; }
