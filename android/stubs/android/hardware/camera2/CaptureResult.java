// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.hardware.camera2; public class CaptureResult {
  public static final class Key<T> {}
  public static final Key<Long> SENSOR_TIMESTAMP = new Key<>();
  public static final Key<Long> SENSOR_EXPOSURE_TIME = new Key<>();
  public static final Key<Integer> SENSOR_SENSITIVITY = new Key<>();
  public static final Key<Float> LENS_APERTURE = new Key<>();
  public <T> T get(Key<T> key) { return null; } }
