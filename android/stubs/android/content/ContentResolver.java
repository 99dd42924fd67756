// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.content; public abstract class ContentResolver {
  public final android.os.ParcelFileDescriptor openFileDescriptor(android.net.Uri uri, String mode) throws java.io.FileNotFoundException { return null; }
  public final android.database.Cursor query(android.net.Uri uri, String[] projection, String selection, String[] selectionArgs, String sortOrder) { return null; } }
