// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.view; public final class WindowInsets { public static final class Type { public static int systemBars() { return 0; } } }
