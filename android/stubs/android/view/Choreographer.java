// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.view; public final class Choreographer { public interface FrameCallback { void doFrame(long frameTimeNanos); } public static Choreographer getInstance() { return null; } public void postFrameCallback(FrameCallback c) {} public void removeFrameCallback(FrameCallback c) {} }
