// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.view; public interface WindowManager { Display getDefaultDisplay(); class LayoutParams { public static final int FLAG_KEEP_SCREEN_ON = 128; public static final int LAYOUT_IN_DISPLAY_CUTOUT_MODE_SHORT_EDGES = 1; public int layoutInDisplayCutoutMode; } }
