// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.activity.result.contract; public final class ActivityResultContracts { public static final class RequestPermission extends ActivityResultContract<String, Boolean> {}
  public static class OpenDocument extends ActivityResultContract<String[], android.net.Uri> {} }
