// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.content.pm; public class PackageInfo { public long lastUpdateTime; }
