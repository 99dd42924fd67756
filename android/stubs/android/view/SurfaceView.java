// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.view; public class SurfaceView extends View { public SurfaceView(android.content.Context c) {} public SurfaceHolder getHolder() { return null; } }
