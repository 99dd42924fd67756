// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.activity.result; public interface ActivityResultCallback<O> { void onActivityResult(O result); }
