// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.activity; public class ComponentActivity extends android.content.Context implements androidx.lifecycle.LifecycleOwner {
  protected void onCreate(android.os.Bundle b) {} protected void onResume() {} protected void onPause() {} protected void onDestroy() {}
  public void onConfigurationChanged(android.content.res.Configuration c) {} public boolean onTouchEvent(android.view.MotionEvent e) { return false; }
  public android.view.Window getWindow() { return null; } public android.view.WindowManager getWindowManager() { return null; }
  public void setContentView(android.view.View v) {}
  public java.io.File getCacheDir() { return null; } public void startActivity(android.content.Intent intent) {}
  public <T> T getSystemService(Class<T> c) { return null; } public android.content.res.AssetManager getAssets() { return null; }
  public java.io.File getFilesDir() { return null; } public android.content.ContentResolver getContentResolver() { return null; }
  public android.content.SharedPreferences getSharedPreferences(String name, int mode) { return null; } public android.content.Intent getIntent() { return null; }
  public android.content.pm.PackageManager getPackageManager() { return null; } public String getPackageName() { return null; }
  protected void onNewIntent(android.content.Intent intent) {} public final void runOnUiThread(Runnable r) {}
  public final String getString(int resId, Object... formatArgs) { return null; } public int checkSelfPermission(String p) { return 0; } public android.content.res.Resources getResources() { return null; }
  public final <I, O> androidx.activity.result.ActivityResultLauncher<I> registerForActivityResult(androidx.activity.result.contract.ActivityResultContract<I, O> c, androidx.activity.result.ActivityResultCallback<O> cb) { return null; } }
