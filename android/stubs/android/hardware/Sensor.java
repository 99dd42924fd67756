// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.hardware; public final class Sensor { public static final int TYPE_ACCELEROMETER = 1; public static final int TYPE_MAGNETIC_FIELD = 2; public static final int TYPE_GYROSCOPE = 4; public static final int TYPE_ROTATION_VECTOR = 11; public int getType() { return 0; } }
