// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.annotation; public @interface SuppressLint { String[] value(); }
