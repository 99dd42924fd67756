// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.content; public interface SharedPreferences { String getString(String key, String defValue); long getLong(String key, long defValue); Editor edit();
  interface Editor { Editor putString(String key, String value); Editor putLong(String key, long value); void apply(); } }
