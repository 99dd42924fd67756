// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.core.view; public class AccessibilityDelegateCompat { public AccessibilityDelegateCompat() {} }
