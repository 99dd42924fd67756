// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.content; public abstract class Context { public static final int MODE_PRIVATE = 0; public abstract <T> T getSystemService(Class<T> c); public abstract android.content.res.AssetManager getAssets(); public abstract java.io.File getFilesDir(); public abstract int checkSelfPermission(String p); public abstract android.content.res.Resources getResources();
  public abstract ContentResolver getContentResolver(); public abstract SharedPreferences getSharedPreferences(String name, int mode);
  public abstract java.io.File getCacheDir(); public abstract void startActivity(Intent intent); }
