// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.camera.core; public class ConcurrentCamera { public java.util.List<Camera> getCameras() { return null; }
  public static final class SingleCameraConfig { public SingleCameraConfig(CameraSelector s, UseCaseGroup g, androidx.lifecycle.LifecycleOwner o) {} } }
