// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.provider; public interface OpenableColumns { String DISPLAY_NAME = "_display_name"; }
