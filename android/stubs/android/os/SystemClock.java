// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.os; public final class SystemClock { public static long elapsedRealtimeNanos() { return 0; } public static long uptimeMillis() { return 0; } }
