// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.view; public abstract class Window { public void addFlags(int flags) {} public WindowManager.LayoutParams getAttributes() { return null; } public void setDecorFitsSystemWindows(boolean f) {} public WindowInsetsController getInsetsController() { return null; } }
