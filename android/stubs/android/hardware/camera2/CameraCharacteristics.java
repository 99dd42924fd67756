// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.hardware.camera2; public final class CameraCharacteristics {
  public static final class Key<T> {}
  public static final Key<android.graphics.Rect> SENSOR_INFO_ACTIVE_ARRAY_SIZE = new Key<>();
  public static final Key<android.graphics.Rect> SENSOR_INFO_PRE_CORRECTION_ACTIVE_ARRAY_SIZE = new Key<>();
  public static final Key<android.util.Size> SENSOR_INFO_PIXEL_ARRAY_SIZE = new Key<>();
  public static final Key<float[]> LENS_INTRINSIC_CALIBRATION = new Key<>();
  public static final Key<float[]> LENS_INFO_AVAILABLE_FOCAL_LENGTHS = new Key<>();
  public static final Key<android.util.SizeF> SENSOR_INFO_PHYSICAL_SIZE = new Key<>(); }
