// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.view; public class Surface { public static final int ROTATION_0 = 0, ROTATION_90 = 1, ROTATION_180 = 2, ROTATION_270 = 3; }
