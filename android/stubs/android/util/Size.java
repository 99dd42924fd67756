// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.util; public final class Size { public int getWidth() { return 0; } public int getHeight() { return 0; } }
