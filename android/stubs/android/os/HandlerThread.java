// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.os; public class HandlerThread extends Thread { public HandlerThread(String name) {} public Looper getLooper() { return null; } public boolean quitSafely() { return true; } }
