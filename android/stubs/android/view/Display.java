// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.view; public final class Display { public int getRotation() { return 0; } public void getRealMetrics(android.util.DisplayMetrics m) {} public float getRefreshRate() { return 60f; } }
