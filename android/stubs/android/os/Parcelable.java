// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package android.os; public interface Parcelable {}
