// Host stub of the Android/AndroidX API surface the shell uses; see android/stubs/README.md.
package androidx.customview.widget;
public abstract class ExploreByTouchHelper extends androidx.core.view.AccessibilityDelegateCompat {
    public static final int INVALID_ID = Integer.MIN_VALUE;
    public static final int HOST_ID = -1;
    public ExploreByTouchHelper(android.view.View host) {}
    public final boolean dispatchHoverEvent(android.view.MotionEvent event) { return false; }
    public final void invalidateRoot() {}
    protected abstract int getVirtualViewAt(float x, float y);
    protected abstract void getVisibleVirtualViews(java.util.List<Integer> virtualViewIds);
    protected abstract void onPopulateNodeForVirtualView(int virtualViewId, androidx.core.view.accessibility.AccessibilityNodeInfoCompat node);
    protected abstract boolean onPerformActionForVirtualView(int virtualViewId, int action, android.os.Bundle arguments);
}
