// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.net; public abstract class Uri implements android.os.Parcelable { public abstract String getLastPathSegment(); }
