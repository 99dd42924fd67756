// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.activity.result; public abstract class ActivityResultLauncher<I> { public void launch(I input) {} }
