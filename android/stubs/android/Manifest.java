// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android; public final class Manifest { public static final class permission { public static final String CAMERA = "android.permission.CAMERA"; } }
