// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.core.view.accessibility;
public class AccessibilityNodeInfoCompat {
    public static final int ACTION_CLICK = 16;
    public static final int ACTION_SCROLL_FORWARD = 4096;
    public static final int ACTION_SCROLL_BACKWARD = 8192;
    public void setText(CharSequence text) {}
    public void setContentDescription(CharSequence description) {}
    public void setStateDescription(CharSequence description) {}
    public void setClassName(CharSequence className) {}
    @Deprecated public void setBoundsInParent(android.graphics.Rect bounds) {}
    public void setEnabled(boolean enabled) {}
    public void setCheckable(boolean checkable) {}
    public void setChecked(boolean checked) {}
    public void addAction(int action) {}
}
