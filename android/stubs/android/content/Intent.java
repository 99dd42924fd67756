// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.content; public class Intent { public static final String ACTION_VIEW = "android.intent.action.VIEW"; public static final String ACTION_SEND = "android.intent.action.SEND"; public static final String EXTRA_STREAM = "android.intent.extra.STREAM";
  public static final int FLAG_GRANT_READ_URI_PERMISSION = 1; public Intent(String action) {} public Intent setType(String type) { return this; }
  public Intent putExtra(String name, android.os.Parcelable value) { return this; } public Intent addFlags(int flags) { return this; }
  public static Intent createChooser(Intent target, CharSequence title) { return target; }
  public String getAction() { return null; } public android.net.Uri getData() { return null; } @Deprecated public <T extends android.os.Parcelable> T getParcelableExtra(String name) { return null; } }
