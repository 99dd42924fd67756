// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.widget; public class Toast { public static final int LENGTH_LONG = 1; public static Toast makeText(android.content.Context c, int resId, int duration) { return null; } public void show() {} }
