// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.graphics; public final class Rect { public int left, top, right, bottom; public int width() { return right - left; } public int height() { return bottom - top; } }
