// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.content.res; public class Resources { public android.util.DisplayMetrics getDisplayMetrics() { return null; } public Configuration getConfiguration() { return null; } }
