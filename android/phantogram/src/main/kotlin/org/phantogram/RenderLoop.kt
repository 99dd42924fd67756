package org.phantogram

import android.os.Handler
import android.os.HandlerThread
import android.util.Log
import android.view.Choreographer
import android.view.Surface
import java.util.concurrent.CountDownLatch
import java.util.concurrent.TimeUnit

/**
 * The render thread: it creates the engine (and so the GPU device), owns every lifecycle and
 * drawing call, and is driven by Choreographer frame callbacks posted on its own looper. The
 * device survives surface loss; only the surface comes and goes.
 *
 * Sensor and camera calls do not go through here: they call NativeBridge directly from their
 * own threads (the bridge never makes them wait for a frame).
 */
class RenderLoop(
    private val onError: (Throwable) -> Unit,
    /** The core's menu asked for a file (called on the render thread). */
    private val onOpenFile: () -> Unit,
    /** The core's camera page: the user wants the camera (called on the render thread). */
    private val onCameraPermission: () -> Unit,
    /** The core's menu: share this PNG of the view, a stereo pair if `pair` (render thread). */
    private val onShare: (png: ByteArray, pair: Boolean) -> Unit,
    /** The room light was switched on or off: run the rear camera or stop it (render thread). */
    private val onRearCamera: (on: Boolean) -> Unit
) : Choreographer.FrameCallback {
    private val thread = HandlerThread("phantogram-render").apply { start() }
    private val handler = Handler(thread.looper)

    /** The engine handle; 0 until created and after destroy. Read from any thread. */
    @Volatile
    var engine: Long = 0
        private set

    private var running = false // render thread only
    private var refreshPeriodNs = 16_666_667L

    /** Called (on the render thread) after a frame whose screen-reader nodes differ from the
     *  last: hand it to [ScreenReader.changed]. */
    @Volatile
    var onAccessibilityChanged: (() -> Unit)? = null
    private var accessibilityGeneration = -1L // render thread only

    fun create(
        facesDir: String?, panel: Panel, anaglyph: String, calibrationPath: String,
        libraryDir: String, bundledDir: String, artifact: String?
    ) = post {
        refreshPeriodNs = periodNs(panel)
        engine = NativeBridge.nativeCreate(null, facesDir, panel.widthPx, panel.heightPx,
            panel.xdpi, panel.ydpi, panel.rotation, anaglyph, calibrationPath, libraryDir, bundledDir, artifact)
        NativeBridge.nativeCalibrationWarning(engine)?.let { Log.w("Phantogram", it) }
    }

    /** The system's font scale (Configuration.fontScale), for the core's screens. */
    fun setTextScale(scale: Float) = post {
        if (engine != 0L) NativeBridge.nativeSetTextScale(engine, scale)
    }

    /** No camera permission yet: the core explains the camera before the system asks. */
    fun cameraPermissionNeeded() = post {
        if (engine != 0L) NativeBridge.nativeCameraPermissionNeeded(engine)
    }

    /** A document the user opened: the engine takes the descriptor over (and closes it). */
    fun importFd(name: String, fd: Int) = post {
        if (engine != 0L) NativeBridge.nativeImportArtifactFd(engine, name, fd)
    }

    /** Hands the id of the artifact on screen to [onArtifact] (on the render thread), to be
     *  saved for the next start. */
    fun reportArtifact(onArtifact: (String?) -> Unit) = post {
        if (engine != 0L) onArtifact(NativeBridge.nativeCurrentArtifact(engine))
    }

    fun surfaceCreated(surface: Surface, width: Int, height: Int) = post {
        if (engine != 0L) NativeBridge.nativeSurfaceCreated(engine, surface, width, height)
    }

    fun surfaceChanged(width: Int, height: Int) = post {
        if (engine != 0L) NativeBridge.nativeSurfaceChanged(engine, width, height)
    }

    /** Blocks until the native window is released: Android requires it before returning from
     *  surfaceDestroyed. */
    fun surfaceDestroyed() = postAndWait {
        if (engine != 0L) NativeBridge.nativeSurfaceDestroyed(engine)
    }

    fun setDisplay(panel: Panel) = post {
        if (engine != 0L) {
            NativeBridge.nativeSetDisplay(engine, panel.widthPx, panel.heightPx, panel.xdpi, panel.ydpi, panel.rotation)
        }
        refreshPeriodNs = periodNs(panel)
    }

    /** One refresh period; 60 Hz when the display reports nonsense. */
    private fun periodNs(panel: Panel): Long =
        if (panel.refreshRateHz in 20f..500f) (1e9 / panel.refreshRateHz).toLong() else 16_666_667L

    fun start() = post {
        if (!running) {
            running = true
            Choreographer.getInstance().postFrameCallback(this)
        }
    }

    fun stop() = post {
        running = false
        Choreographer.getInstance().removeFrameCallback(this)
    }

    fun destroy() {
        postAndWait {
            running = false
            Choreographer.getInstance().removeFrameCallback(this)
            val e = engine
            engine = 0
            if (e != 0L) NativeBridge.nativeDestroy(e)
        }
        thread.quitSafely()
    }

    override fun doFrame(frameTimeNanos: Long) {
        if (!running) return
        // The frame is shown about two refresh periods after the vsync it starts from (one to
        // render, one to scan out): the core predicts the orientation to then.
        val displayNs = Clock.monotonicToSensorNs(frameTimeNanos + 2 * refreshPeriodNs)
        try {
            if (engine != 0L) {
                NativeBridge.nativeDrawFrame(engine, displayNs)
                // What the core's screens ask of the platform.
                when (NativeBridge.nativeTakeShellRequest(engine)) {
                    NativeBridge.REQUEST_OPEN_FILE -> onOpenFile()
                    NativeBridge.REQUEST_CAMERA_PERMISSION -> onCameraPermission()
                    // Taken here, on the thread that owns the engine, without the menu drawn over it.
                    NativeBridge.REQUEST_SHARE_PICTURE -> onShare(NativeBridge.nativeSnapshotPng(engine, 0), false)
                    NativeBridge.REQUEST_SHARE_PAIR -> onShare(NativeBridge.nativeSnapshotPng(engine, 1), true)
                    NativeBridge.REQUEST_REAR_CAMERA_ON -> onRearCamera(true)
                    NativeBridge.REQUEST_REAR_CAMERA_OFF -> onRearCamera(false)
                }
                val generation = NativeBridge.nativeAccessibilityGeneration(engine)
                if (generation != accessibilityGeneration) {
                    accessibilityGeneration = generation
                    onAccessibilityChanged?.invoke()
                }
            }
        } catch (t: RuntimeException) {
            onError(t)
        }
        Choreographer.getInstance().postFrameCallback(this)
    }

    private fun post(block: () -> Unit) {
        handler.post {
            try {
                block()
            } catch (t: RuntimeException) {
                onError(t)
            }
        }
    }

    private fun postAndWait(block: () -> Unit) {
        val done = CountDownLatch(1)
        post {
            try {
                block()
            } finally {
                done.countDown()
            }
        }
        done.await(5, TimeUnit.SECONDS)
    }
}

/** The display panel in its natural (portrait) orientation, and the current rotation. */
data class Panel(
    val widthPx: Int,
    val heightPx: Int,
    val xdpi: Float,
    val ydpi: Float,
    val rotation: Int,
    val refreshRateHz: Float
)
