// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.content.res; public final class Configuration { public int orientation; public float fontScale; }
