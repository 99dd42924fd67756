// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.hardware; public class SensorEvent { public final float[] values = new float[5]; public Sensor sensor; public int accuracy; public long timestamp; }
