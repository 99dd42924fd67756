// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.core.content; public class ContextCompat { public static java.util.concurrent.Executor getMainExecutor(android.content.Context c) { return null; } }
