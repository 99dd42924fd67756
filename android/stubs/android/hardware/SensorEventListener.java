// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.hardware; public interface SensorEventListener { void onSensorChanged(SensorEvent event); void onAccuracyChanged(Sensor sensor, int accuracy); }
