// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.core.view; public class ViewCompat { public static void setAccessibilityDelegate(android.view.View v, AccessibilityDelegateCompat delegate) {} }
