// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.database; public interface Cursor extends java.io.Closeable { boolean moveToFirst(); int getColumnIndex(String columnName); String getString(int columnIndex); void close(); }
