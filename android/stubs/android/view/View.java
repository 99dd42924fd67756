// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.view; public class View { public interface OnHoverListener { boolean onHover(View v, MotionEvent event); } public void setOnHoverListener(OnHoverListener l) {} public boolean post(Runnable action) { return true; } }
