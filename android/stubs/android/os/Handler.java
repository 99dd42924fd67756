// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.os; public class Handler { public Handler(Looper looper) {} public final boolean post(Runnable r) { return true; } }
