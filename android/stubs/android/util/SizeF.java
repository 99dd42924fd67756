// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.util; public final class SizeF { public float getWidth() { return 0; } public float getHeight() { return 0; } }
