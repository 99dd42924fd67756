package org.phantogram

import android.graphics.Rect
import android.os.Bundle
import android.view.MotionEvent
import android.view.View
import androidx.core.view.ViewCompat
import androidx.core.view.accessibility.AccessibilityNodeInfoCompat
import androidx.customview.widget.ExploreByTouchHelper
import kotlin.math.ceil
import kotlin.math.floor

/**
 * TalkBack over the core's screens. The core draws its menu, settings and pages into the
 * surface, so to the system the surface is one opaque view; the core reports what is on it
 * (NativeBridge.nativeAccessibilityNodes: names, roles, states, rectangles in the surface's
 * pixels) and this helper serves those as virtual views. Activation and slider steps go back
 * to the core, which applies them in its next frame as it would a tap.
 *
 * **Important:** the node rectangles are in the surface's pixels; they equal the view's
 * coordinates because the surface fills its SurfaceView at the view's own size (no
 * `setFixedSize`).
 *
 * Threading: the helper lives on the UI thread. [changed] may be called from any thread (the
 * render loop calls it when the core's generation moves); the nodes are read on the UI thread,
 * each read a short JNI call under the engine's lock.
 */
class ScreenReader(private val host: View, private val engine: () -> Long) : ExploreByTouchHelper(host) {
    private var nodes: Array<NativeBridge.AccessibilityNode> = emptyArray()

    /** Attaches the helper to its view: the delegate and the hover events of touch exploration. */
    fun attach() {
        ViewCompat.setAccessibilityDelegate(host, this)
        host.setOnHoverListener { _, event: MotionEvent -> dispatchHoverEvent(event) }
    }

    /** The core's nodes changed: read them again on the UI thread and tell the system. */
    fun changed() {
        host.post {
            val e = engine()
            nodes = if (e != 0L) NativeBridge.nativeAccessibilityNodes(e) else emptyArray()
            invalidateRoot()
        }
    }

    override fun getVirtualViewAt(x: Float, y: Float): Int {
        // Later nodes lie over earlier ones (the banner over the picture).
        for (n in nodes.reversed()) {
            if (x >= n.left && x <= n.right && y >= n.top && y <= n.bottom) return n.id
        }
        return INVALID_ID
    }

    override fun getVisibleVirtualViews(virtualViewIds: MutableList<Int>) {
        for (n in nodes) virtualViewIds.add(n.id)
    }

    @Suppress("DEPRECATION") // ExploreByTouchHelper requires the bounds in the parent
    override fun onPopulateNodeForVirtualView(virtualViewId: Int, node: AccessibilityNodeInfoCompat) {
        val n = nodes.firstOrNull { it.id == virtualViewId }
        if (n == null) {
            // Gone since the system asked: an empty node, as the helper requires some bounds.
            node.setContentDescription("")
            node.setBoundsInParent(Rect(0, 0, 1, 1))
            return
        }
        node.setContentDescription(n.label)
        n.value?.let { node.setStateDescription(it) }
        node.setClassName(
            when (n.role) {
                NativeBridge.AccessibilityNode.ROLE_BUTTON -> "android.widget.Button"
                NativeBridge.AccessibilityNode.ROLE_CHECK_BOX -> "android.widget.CheckBox"
                NativeBridge.AccessibilityNode.ROLE_RADIO_BUTTON -> "android.widget.RadioButton"
                NativeBridge.AccessibilityNode.ROLE_SLIDER -> "android.widget.SeekBar"
                NativeBridge.AccessibilityNode.ROLE_IMAGE -> "android.widget.ImageView"
                else -> "android.widget.TextView"
            }
        )
        node.setBoundsInParent(
            Rect(floor(n.left).toInt(), floor(n.top).toInt(), ceil(n.right).toInt(), ceil(n.bottom).toInt())
        )
        node.setEnabled(!n.has(NativeBridge.AccessibilityNode.FLAG_DISABLED))
        if (n.has(NativeBridge.AccessibilityNode.FLAG_CHECKABLE)) {
            node.setCheckable(true)
            node.setChecked(n.has(NativeBridge.AccessibilityNode.FLAG_CHECKED))
        }
        if (n.has(NativeBridge.AccessibilityNode.FLAG_CLICKABLE)) {
            node.addAction(AccessibilityNodeInfoCompat.ACTION_CLICK)
        }
        if (n.has(NativeBridge.AccessibilityNode.FLAG_ADJUSTABLE)) {
            node.addAction(AccessibilityNodeInfoCompat.ACTION_SCROLL_FORWARD)
            node.addAction(AccessibilityNodeInfoCompat.ACTION_SCROLL_BACKWARD)
        }
    }

    override fun onPerformActionForVirtualView(virtualViewId: Int, action: Int, arguments: Bundle?): Boolean {
        val e = engine()
        if (e == 0L) return false
        return when (action) {
            AccessibilityNodeInfoCompat.ACTION_CLICK -> NativeBridge.nativeAccessibilityClick(e, virtualViewId)
            AccessibilityNodeInfoCompat.ACTION_SCROLL_FORWARD -> NativeBridge.nativeAccessibilityAdjust(e, virtualViewId, 1)
            AccessibilityNodeInfoCompat.ACTION_SCROLL_BACKWARD -> NativeBridge.nativeAccessibilityAdjust(e, virtualViewId, -1)
            else -> false
        }
    }
}
