// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.activity.result.contract; public abstract class ActivityResultContract<I, O> {}
