// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.core.content; public class FileProvider { public static android.net.Uri getUriForFile(android.content.Context context, String authority, java.io.File file) { return null; } }
